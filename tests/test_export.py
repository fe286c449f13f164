"""zmpwalk export: reference motions in mjlab, LocoMuJoCo, AMP, CSV and ROS 2 bag formats, each replayed and checked.

One export (HUBO's box model, one command, six swings at 0.7 s: about 10 s) is shared by the tests.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from zmpwalk.cli import main
from zmpwalk.errors import InvalidParameterError
from zmpwalk.export import Grid, export_motions, replay_check
from zmpwalk.export.amp import read_amp
from zmpwalk.export.locomujoco import read_locomujoco
from zmpwalk.export.names import body_names, joint_names, qpos_names
from zmpwalk.export.verify import CONTACT_HEIGHT, MAX_PENETRATION, MAX_SLIDE, contact_slide
from zmpwalk.robots import loaded_robot
from zmpwalk.sim.plant import build_plant

FPS = 50.0
LOCOMUJOCO_KEYS = {"joint_names", "frequency", "body_names", "njnt", "jnt_type", "nbody", "body_rootid",
                   "body_weldid", "body_mocapid", "body_pos", "body_quat", "body_ipos", "body_iquat", "qpos", "qvel",
                   "xpos", "xquat", "split_points"}


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, Any]]:
    out = tmp_path_factory.mktemp("motions")
    status = main(["export", "--robot", "hubo", "--out", str(out), "--forward", "0.15", "--step-time", "0.7",
                   "--swings", "6", "--workers", "1", "--json"])
    assert status == 0
    return out, json.loads((out / "manifest.json").read_text())


@pytest.fixture(scope="module")
def model() -> mujoco.MjModel:
    return build_plant(loaded_robot("hubo")).model


def _clip(manifest: dict[str, Any], kind: str, span: str) -> dict[str, Any]:
    return next(c for c in manifest["clips"] if c["kind"] == kind and c["span"] == span)


def test_manifest_lists_four_verified_clips(exported: tuple[Path, dict[str, Any]]) -> None:
    out, manifest = exported
    assert manifest["count"] == 4 and manifest["verified"] == 4
    assert manifest["quaternion_order"] == "wxyz"
    for clip in manifest["clips"]:
        assert clip["verified"] and clip["verdict"] == "PASS"
        assert clip["command"] == {"forward": 0.15, "side": 0.0, "turn": 0.0, "step_time": 0.7}
        assert clip["replay"]["slide"] <= MAX_SLIDE and clip["replay"]["penetration"] <= MAX_PENETRATION
        assert clip["cop_rms"] == pytest.approx(0.015, abs=0.015) and clip["zmp_margin"] > 0.0
        assert set(clip["files"]) == {"mjlab", "locomujoco", "amp", "csv", "ros2bag"}
        assert all((out / name).exists() for name in clip["files"].values())


def test_cyclic_clip_closes_its_loop(exported: tuple[Path, dict[str, Any]]) -> None:
    _, manifest = exported
    planned, simulated = _clip(manifest, "planned", "cyclic"), _clip(manifest, "simulated", "cyclic")
    assert planned["loop_error"]["joints"] == pytest.approx(0.0, abs=1e-6)
    assert simulated["loop_error"]["joints"] == pytest.approx(0.0, abs=0.02)
    assert simulated["loop_error"]["base_height"] == pytest.approx(0.0, abs=0.002)
    first, last = simulated["loop"]
    assert first == 0 and last == simulated["frames"] - 1
    whole = _clip(manifest, "simulated", "whole")
    assert whole["loop"][1] - whole["loop"][0] == last
    assert last / FPS == pytest.approx(2 * 0.7, abs=1e-9)  # one gait cycle of two 0.7 s swings


def test_mjlab_fields(exported: tuple[Path, dict[str, Any]], model: mujoco.MjModel) -> None:
    out, manifest = exported
    clip = _clip(manifest, "simulated", "whole")
    files = clip["files"]
    with np.load(out / files["mjlab"]) as npz:
        n, joints, bodies = clip["frames"], model.njnt - 1, model.nbody - 1
        assert int(npz["fps"][0]) == 50
        assert list(npz["joint_names"]) == joint_names(model)[1:] and list(npz["body_names"]) == body_names(model)
        assert npz["joint_pos"].shape == (n, joints) and npz["joint_vel"].shape == (n, joints)
        for key, width in (("body_pos_w", 3), ("body_quat_w", 4), ("body_lin_vel_w", 3), ("body_ang_vel_w", 3)):
            assert npz[key].shape == (n, bodies, width)
        assert np.abs(np.linalg.norm(npz["body_quat_w"], axis=2) - 1.0).max() < 1e-5
        qpos, _ = read_locomujoco(str(out / files["locomujoco"]))
        assert np.abs(npz["body_pos_w"][:, 0] - qpos[:, 0:3]).max() < 1e-5  # the base is body 1
        assert np.abs(npz["body_quat_w"][:, 0] - qpos[:, 3:7]).max() < 1e-5  # w, x, y, z, as qpos
        assert np.abs(npz["joint_pos"] - qpos[:, 7:]).max() < 1e-5
        speed = np.gradient(qpos[:, 0], 1.0 / FPS)
        assert np.abs(npz["body_lin_vel_w"][:, 0, 0] - speed).max() < 1e-3  # [m/s], central differences


def test_locomujoco_fields(exported: tuple[Path, dict[str, Any]], model: mujoco.MjModel) -> None:
    out, manifest = exported
    clip = _clip(manifest, "planned", "whole")
    with np.load(out / clip["files"]["locomujoco"]) as npz:
        assert set(npz.files) == LOCOMUJOCO_KEYS  # Trajectory.load refuses any other key
        n = clip["frames"]
        assert npz["qpos"].shape == (n, model.nq) and npz["qvel"].shape == (n, model.nv)
        assert npz["xquat"].shape == (n, model.nbody, 4) and float(npz["frequency"]) == FPS
        assert list(npz["joint_names"]) == joint_names(model) and list(npz["split_points"]) == [0, n]
        assert list(npz["jnt_type"]) == list(model.jnt_type) and int(npz["njnt"]) == model.njnt
        assert np.abs(np.linalg.norm(npz["qpos"][:, 3:7], axis=1) - 1.0).max() < 1e-9


def test_amp_and_csv_fields(exported: tuple[Path, dict[str, Any]], model: mujoco.MjModel) -> None:
    out, manifest = exported
    for span, mode in (("whole", "None"), ("cyclic", "Wrap")):
        clip = _clip(manifest, "simulated", span)
        document = json.loads((out / clip["files"]["amp"]).read_text())
        assert document["LoopMode"] == mode and document["QuaternionOrder"] == "wxyz"
        assert document["FrameDuration"] == pytest.approx(1 / FPS, abs=1e-12)
        assert document["FrameLayout"] == qpos_names(model)
        frames = np.array(document["Frames"])
        assert frames.shape == (clip["frames"], model.nq)
        assert np.abs(np.linalg.norm(frames[:, 3:7], axis=1) - 1.0).max() < 1e-6
        lines = (out / clip["files"]["csv"]).read_text().splitlines()
        assert lines[0].split(",") == ["time", "root_x", "root_y", "root_z", "root_qw", "root_qx", "root_qy",
                                       "root_qz", *joint_names(model)[1:]]
        assert len(lines) == 1 + clip["frames"]
        assert float(lines[2].split(",")[0]) == pytest.approx(1 / FPS, abs=1e-9)


def test_replay_check_passes_a_good_clip_and_fails_a_corrupted_one(exported: tuple[Path, dict[str, Any]],
                                                                    model: mujoco.MjModel) -> None:
    out, manifest = exported
    qpos, fps = read_amp(str(out / _clip(manifest, "planned", "whole")["files"]["amp"]))
    good = replay_check(model, qpos, fps)
    assert good.passed and good.phases >= 6 and good.slide <= MAX_SLIDE
    drifting = qpos.copy()
    drifting[:, 1] += np.linspace(0.0, 0.2, len(qpos))  # the base drifts 0.2 m sideways (25 mm/s): feet slide
    slid = replay_check(model, drifting, fps)
    assert not slid.passed and slid.slide > MAX_SLIDE
    sunk = qpos.copy()
    sunk[:, 2] -= 0.004  # 4 mm into the floor: still stance, too deep with the soft contact's own
    sunk[len(qpos) // 2:, 2] -= 0.004
    deep = replay_check(model, sunk, fps)
    assert not deep.passed and deep.penetration == pytest.approx(0.008, abs=0.001)


def _sole_box(frames: int) -> np.ndarray:
    """The eight corners of a 0.2 x 0.1 x 0.02 m foot box resting on the floor, repeated ``frames`` times."""
    corners = np.array([[x, y, z] for x in (-0.1, 0.1) for y in (-0.05, 0.05) for z in (0.0, 0.02)])
    return np.repeat(corners[None], frames, axis=0)


def _rotated(points: np.ndarray, axis: int, angles: np.ndarray, about: np.ndarray) -> np.ndarray:
    """``points`` (n, m, 3) rotated per frame by ``angles`` [rad] about the line through ``about`` along ``axis``."""
    out = points.copy()
    for k, angle in enumerate(angles):
        c, s = np.cos(angle), np.sin(angle)
        i, j = [a for a in range(3) if a != axis]
        rel = points[k] - about
        out[k, :, i] = about[i] + c * rel[:, i] - s * rel[:, j]
        out[k, :, j] = about[j] + s * rel[:, i] + c * rel[:, j]
    return out


def test_slide_counts_sole_points_moving_on_the_floor_not_a_sole_rocking_on_its_edge() -> None:
    """A sole rocking 0.06 rad on its heel edge moves a point 0.1 m above it 6 mm, its toe corners lift and its heel
    corners stay: no slide. The same sole turning 0.06 rad about one corner on the floor slides its other corners
    (the far one 0.224 m x 0.06 = 13 mm); shifted 3 mm along the floor it slides 3 mm; a foot still 1 mm above the
    floor while it moves does not slide."""
    n = 30
    heel = np.array([-0.1, 0.0, 0.0])
    pitch = np.linspace(0.0, 0.06, n)  # toe up: rotation about y through the heel edge
    rocking = _rotated(_sole_box(n), 1, pitch, heel)
    toes = rocking[-1, _sole_box(1)[0, :, 0] > 0.0]
    assert toes[:, 2].min() > 0.01 and contact_slide(rocking) == pytest.approx(0.0, abs=1e-12)
    ankle = _rotated(np.array([[[0.0, 0.0, 0.1]]] * n), 1, pitch, heel)
    assert np.linalg.norm(ankle[-1, 0, :2] - ankle[0, 0, :2]) > MAX_SLIDE  # what the foot origin would have said
    turning = _rotated(_sole_box(n), 2, np.linspace(0.0, 0.06, n), np.array([-0.1, -0.05, 0.0]))
    assert contact_slide(turning) == pytest.approx(np.hypot(0.2, 0.1) * 2 * np.sin(0.03), rel=1e-9)
    shifted = _sole_box(n)
    shifted[:, :, 0] += np.linspace(0.0, 0.003, n)[:, None]
    assert contact_slide(shifted) == pytest.approx(0.003, rel=1e-9)
    hovering = shifted.copy()
    hovering[:, :, 2] += CONTACT_HEIGHT + 0.001
    assert contact_slide(hovering) == 0.0


def test_grid_file_and_options(tmp_path: Path) -> None:
    grid_file = tmp_path / "grid.toml"
    grid_file.write_text("forward = [0.0, 0.1]\nside = [0.0, 0.05]\nturn = [0.0]\nstep_time = [0.8]\n")
    grid = Grid.from_toml(grid_file)
    assert len(grid.commands()) == 4 and grid.commands()[-1].side == 0.05
    assert main(["export", "--robot", "hubo", "--grid", str(grid_file), "--forward", "0.1"]) == 2
    with pytest.raises(InvalidParameterError) as error:
        export_motions("hubo", grid, tmp_path, fps=0.0)
    assert error.value.parameter == "fps"
    with pytest.raises(InvalidParameterError) as error:
        export_motions("hubo", grid, tmp_path, workers=0)
    assert error.value.parameter == "workers"


def test_locomujoco_loads_the_clip(exported: tuple[Path, dict[str, Any]]) -> None:
    """LocoMuJoCo's own loader, where it is installed (it pins mujoco 3.2.7 and numpy < 2: not here)."""
    trajectory = pytest.importorskip("loco_mujoco.trajectory")
    out, manifest = exported
    clip = _clip(manifest, "simulated", "cyclic")
    loaded = trajectory.Trajectory.load(str(out / clip["files"]["locomujoco"]), backend=np)
    assert loaded.info.frequency == FPS and loaded.data.qpos.shape[0] == clip["frames"]


def test_ros2_bag_topics_read_by_rosbags(exported: tuple[Path, dict[str, Any]], model: mujoco.MjModel) -> None:
    """The bag opens with rosbags' own reader: MCAP storage, joint states by the model's names at the frame rate,
    the base and both feet in /tf matching the clip, the ZMP every frame, the CoP and footprints on the floor."""
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore

    from zmpwalk.export.amp import read_amp

    out, manifest = exported
    store = get_typestore(Stores.ROS2_HUMBLE)
    clip = _clip(manifest, "simulated", "whole")
    qpos, _ = read_amp(str(out / clip["files"]["amp"]))
    bag = out / clip["files"]["ros2bag"]
    assert (bag / "metadata.yaml").is_file() and len(list(bag.glob("*.mcap"))) == 1
    with Reader(bag) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == {
            "/joint_states": "sensor_msgs/msg/JointState", "/tf": "tf2_msgs/msg/TFMessage",
            "/zmpwalk/markers": "visualization_msgs/msg/MarkerArray"}
        messages: dict[str, list[tuple[int, Any]]] = {"/joint_states": [], "/tf": [], "/zmpwalk/markers": []}
        for connection, stamp, raw in reader.messages():
            messages[connection.topic].append((stamp, store.deserialize_cdr(raw, connection.msgtype)))
    n = clip["frames"]
    assert all(len(rows) == n for rows in messages.values())
    stamps = np.array([stamp for stamp, _ in messages["/joint_states"]])
    assert np.abs(np.diff(stamps) - 1e9 / FPS).max() <= 1  # [ns]
    state = messages["/joint_states"][n // 2][1]
    assert list(state.name) == joint_names(model)[1:]
    assert np.abs(np.asarray(state.position) - qpos[n // 2, 7:]).max() < 1e-6  # [rad] (the AMP file's 7 digits)
    tf = messages["/tf"][n // 2][1].transforms
    assert [t.child_frame_id for t in tf] == [body_names(model)[0], "left_foot", "right_foot"]
    base = tf[0].transform
    assert np.allclose([base.translation.x, base.translation.y, base.translation.z], qpos[n // 2, :3], atol=1e-6)
    assert np.allclose([base.rotation.w, base.rotation.x, base.rotation.y, base.rotation.z], qpos[n // 2, 3:7],
                       atol=1e-6)
    marker_ns = [[m.ns for m in array.markers] for _, array in messages["/zmpwalk/markers"]]
    assert all("zmp" in names for names in marker_ns)
    assert sum("cop" in names for names in marker_ns) > 0.9 * n  # the CoP wherever a sole carries load
    prints = [m for _, array in messages["/zmpwalk/markers"] for m in array.markers if m.ns == "footprints"]
    assert len(prints) >= 6  # both feet at the start, then every landing of the six swings
    for marker in prints:
        assert len(marker.points) == 5 and all(abs(p.z) < 0.01 for p in marker.points)  # [m] closed, on the floor


def test_a_bag_replaces_its_folder_whole_and_refuses_a_file(exported: tuple[Path, dict[str, Any]], tmp_path: Path,
                                                           model: mujoco.MjModel) -> None:
    """Writing a bag over an old one leaves only the new one (no partial folder beside it); a path that is a file
    is refused with one FileFormatError and left as it was; a file that is not a bag is one FileFormatError."""
    from zmpwalk.errors import FileFormatError
    from zmpwalk.export.amp import read_amp
    from zmpwalk.export.rosbag import BagExtras, read_bag, write_bag

    out, manifest = exported
    qpos, fps = read_amp(str(out / _clip(manifest, "planned", "cyclic")["files"]["amp"]))
    extras = BagExtras(np.zeros((len(qpos), 2)))
    bag = tmp_path / "clip.bag"
    write_bag(bag, model, loaded_robot("hubo"), qpos[:10], fps, extras)
    write_bag(bag, model, loaded_robot("hubo"), qpos, fps, extras)
    back, back_fps = read_bag(str(bag))
    assert back.shape == qpos.shape and back_fps == pytest.approx(fps, abs=1e-6)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.bag"]
    plain = tmp_path / "plain.bag"
    plain.write_text("not a folder")
    with pytest.raises(FileFormatError, match=r"plain\.bag"):
        write_bag(plain, model, loaded_robot("hubo"), qpos, fps, extras)
    assert plain.read_text() == "not a folder"
    with pytest.raises(FileFormatError, match=r"plain\.bag"):
        read_bag(str(plain))
