"""The sole taken in the robot's reference posture (its keyframe), not at zero joint angles: a
biped whose foot box is pitched 10 degrees at zero angles and level in its keyframe imports with its real sole,
keeps that sole level in the inverse kinematics, plans and walks."""

from __future__ import annotations

import json
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots import load_robot
from zmpwalk.robots.collision import SOLE_BAND, collision_points, rigid_bodies

PITCH = math.radians(10.0)  # [rad] the foot box's pitch in the foot body (its keyframe bends the ankle by -PITCH)
BOX_CENTRE = (0.02, 0.0, -0.05)  # [m] the box's centre in the foot body (the ankle point is the body's origin)
BOX_HALF = (0.11, 0.07, 0.01)  # [m] the box's half sizes: a 220 x 140 mm sole


def _inertia(mass: float, x: float, y: float, z: float) -> str:
    return f"{mass / 12 * (y * y + z * z):.6g} {mass / 12 * (x * x + z * z):.6g} {mass / 12 * (x * x + y * y):.6g}"


def _leg(side: str, y: float) -> str:
    """A 6-joint leg (the 18.6 kg biped of tests/test_pd_layer.py as MJCF) whose foot box is pitched by PITCH."""
    quat = f"{math.cos(PITCH / 2):.15f} 0 {math.sin(PITCH / 2):.15f} 0"
    foot = (f'<geom type="box" size="{" ".join(map(str, BOX_HALF))}" pos="{" ".join(map(str, BOX_CENTRE))}" '
            f'quat="{quat}" mass="0"/>')
    links = [("hip_yaw", "0 0 1", f"0 {y} -0.1", 0.5, "0 0 0", "0.001 0.001 0.001", "-0.8 0.8", ""),
             ("hip_roll", "1 0 0", "0 0 0", 0.5, "0 0 0", "0.001 0.001 0.001", "-0.6 0.6", ""),
             ("hip_pitch", "0 1 0", "0 0 0", 1.5, "0 0 -0.15", _inertia(1.5, 0.06, 0.06, 0.3), "-1.6 1.0", ""),
             ("knee", "0 1 0", "0 0 -0.3", 1.0, "0 0 -0.15", _inertia(1.0, 0.05, 0.05, 0.3), "0 2.4", ""),
             ("ankle_pitch", "0 1 0", "0 0 -0.3", 0.2, "0 0 0", "0.0002 0.0002 0.0002", "-1.0 1.0", ""),
             ("ankle_roll", "1 0 0", "0 0 0", 0.6, "0.02 0 -0.05", _inertia(0.6, 0.22, 0.14, 0.02), "-0.5 0.5", foot)]
    inner = ""
    for name, axis, pos, mass, com, inertia, limits, geom in reversed(links):
        inner = (f'<body name="{side}_{name}_link" pos="{pos}"><joint name="{side}_{name}" axis="{axis}" '
                 f'range="{limits}"/><inertial pos="{com}" mass="{mass}" diaginertia="{inertia}"/>{geom}{inner}'
                 "</body>")
    return inner


def pitched_biped(keyframe: bool = True, off_level: float = 0.0) -> str:
    """An 18.6 kg biped without actuators (the joint PD layer drives it) whose foot boxes are pitched 10 degrees at
    zero angles; its keyframe bends each ankle pitch by -10 degrees, which stands the boxes level (``off_level``
    [rad] more: the boxes pitched that much in the keyframe)."""
    angles = " ".join(["0"] * 4 + [f"{-PITCH - off_level:.15f}", "0"])
    key = f'<keyframe><key name="level" qpos="0 0 0.7 1 0 0 0 {angles} {angles}"/></keyframe>' if keyframe else ""
    return f"""<mujoco model="pitched_feet"><compiler angle="radian"/>
<default><joint armature="0.01" damping="0.1" actuatorfrcrange="-60 60"/></default>
<worldbody><geom name="floor" type="plane" size="5 5 .1"/>
<body name="torso" pos="0 0 0.7"><freejoint/>
<inertial pos="0 0 0.1" mass="10" diaginertia="{_inertia(10, .2, .3, .3)}"/>
<geom type="box" size="0.1 0.15 0.15" pos="0 0 0.1" mass="0" contype="0" conaffinity="0"/>
{_leg("l", 0.1)}{_leg("r", -0.1)}</body></worldbody>{key}</mujoco>"""


@pytest.fixture(scope="module")
def model_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("keyframe_sole") / "pitched.xml"
    path.write_text(pitched_biped(), encoding="utf-8")
    return path


def test_at_zero_angles_only_an_edge_is_lowest(model_path: Path) -> None:
    """Why the sole must come from the keyframe: at zero angles the pitched box touches with its toe edge only."""
    model = mujoco.MjModel.from_xml_path(str(model_path))
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)  # qpos0: zero joint angles
    points = collision_points(model, data, rigid_bodies(model, model.body("l_ankle_roll_link").id))
    lowest = points[points[:, 2] < points[:, 2].min() + SOLE_BAND]
    assert np.ptp(lowest[:, 0]) == pytest.approx(0.0, abs=1e-12)  # [m]: a 0 mm long "sole"
    assert np.ptp(lowest[:, 1]) == pytest.approx(0.14, abs=1e-12)


def test_the_sole_is_the_keyframe_sole(model_path: Path) -> None:
    robot = load_robot(model_path)
    assert (robot.foot_length, robot.foot_width) == pytest.approx((0.22, 0.14), abs=1e-9)  # [m]
    # In the sole frame (level in the keyframe) the box centre is R_y(-PITCH) times its place in the foot body.
    x, _, z = BOX_CENTRE
    centre = (x * math.cos(PITCH) + -z * math.sin(PITCH), x * math.sin(PITCH) + z * math.cos(PITCH))
    assert robot.sole_center_x == pytest.approx(centre[0], abs=1e-9)  # 28.4 mm ahead of the ankle
    assert robot.sole_center_y == pytest.approx(0.0, abs=1e-9)
    assert robot.ankle_height == pytest.approx(-centre[1] + BOX_HALF[2], abs=1e-9)  # 55.8 mm
    assert robot.legs is not None
    for chain in robot.legs:
        rotation = np.array([[math.cos(PITCH), 0, math.sin(PITCH)], [0, 1, 0], [-math.sin(PITCH), 0, math.cos(PITCH)]])
        assert chain.sole_rotation == pytest.approx(rotation, abs=1e-12)  # R_y(10 deg): the sole in the last link
        assert chain.sole_tilt_reference == pytest.approx((0.0, 0.0), abs=1e-9)  # [rad] level in the keyframe


def test_a_keyframe_a_little_off_level_gives_the_box_face_as_the_sole(tmp_path: Path) -> None:
    """Feet 2 degrees off level in the keyframe (a model's standing pose): the lowest 2 mm of the box would be its
    heel edge; the box's own bottom face is taken instead (within FACE_TILT of level), and the IK keeps that face
    level: the same sole and sole frame as with a level keyframe."""
    from zmpwalk.robots.collision import FACE_TILT

    off = math.radians(2.0)
    assert off < FACE_TILT
    path = tmp_path / "off_level.xml"
    path.write_text(pitched_biped(off_level=off), encoding="utf-8")
    robot = load_robot(path)
    assert (robot.foot_length, robot.foot_width) == pytest.approx((0.22, 0.14), abs=1e-9)  # [m]
    assert robot.legs is not None
    rotation = np.array([[math.cos(PITCH), 0, math.sin(PITCH)], [0, 1, 0], [-math.sin(PITCH), 0, math.cos(PITCH)]])
    for chain in robot.legs:
        assert chain.sole_rotation == pytest.approx(rotation, abs=1e-12)  # the box face, not the keyframe's level


def test_without_a_level_posture_the_import_names_the_remedy(tmp_path: Path) -> None:
    path = tmp_path / "no_key.xml"
    path.write_text(pitched_biped(keyframe=False), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"0\.0 x 140\.0 mm sole .* give a keyframe in which the feet stand"):
        load_robot(path)


def test_the_ik_keeps_the_sole_level(model_path: Path) -> None:
    """FK of the IK's angles on the model itself: every sample's sole (the box's bottom face) within 1e-6 rad of
    level, through a walk with a turn and a side step."""
    robot = load_robot(model_path)
    commands = [StepCommand(duration=0.8, forward=0.05), StepCommand(duration=0.8, forward=0.05, turn=0.2),
                StepCommand(duration=0.8, side=0.03)]
    pattern = generate(robot, commands, rate=100.0)
    joints = pattern_joint_trajectory(pattern)
    assert robot.plant is not None and joints.position_base_in_world is not None
    model = mujoco.MjModel.from_xml_path(str(model_path))
    data = mujoco.MjData(model)
    boxes = [int(np.flatnonzero(model.geom_bodyid == model.body(f"{s}_ankle_roll_link").id)[0]) for s in "lr"]
    worst = 0.0
    for k in range(len(joints.time)):
        data.qpos[:] = robot.plant.qpos_reference
        data.qpos[0:3] = joints.position_base_in_world[k]
        yaw = pattern.yaw_pelvis_in_world[k]
        data.qpos[3:7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        for column, joint in enumerate(robot.plant.joints):
            data.qpos[model.joint(joint.name).qposadr[0]] = joints.angles[k, column]
        mujoco.mj_kinematics(model, data)
        for box in boxes:
            normal = data.geom_xmat[box].reshape(3, 3)[:, 2]
            worst = max(worst, math.acos(min(1.0, float(normal[2]))))
    assert worst < 1e-6  # [rad]


def test_it_plans_walks_and_prints_the_tilts(model_path: Path, tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.cli import main

    steps = tmp_path / "steps.toml"
    steps.write_text("[[steps]]\nduration = 0.8\nforward = 0.05\nrepeat = 4\n", encoding="utf-8")
    assert main(["plan", "--robot", str(model_path), str(steps), "--joints", "--out", str(tmp_path / "p.csv")]) == 0
    assert main(["robot", str(model_path)]) == 0
    out = capsys.readouterr().out
    assert "sole 220.0 x 140.0 mm" in out
    assert "at zero angles left (+0.0000, +0.1745)" in out  # [rad] pitched 10 degrees
    assert "in the reference posture (level) left (+0.0000, +0.0000)" in out
    assert main(["simulate", "--robot", str(model_path), str(steps), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["verdict"]["state"] == "PASS" and not summary["fell"]
    assert summary["final_feet_error"] < 0.02  # [m]
    assert summary["distance"] == pytest.approx(0.20, abs=0.03)  # [m]: four 5 cm steps and the closing one
