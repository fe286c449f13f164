"""A ROS 2 bag (MCAP storage) of a clip, which Foxglove Studio and RViz open, written with ``rosbags``.

The bag is a folder (``<clip>.bag/``: ``metadata.yaml`` and one ``.mcap`` file, as ``ros2 bag record -s mcap``
writes it; Foxglove opens the ``.mcap`` alone). Its topics, each message stamped with the frame's time from the
clip's first frame [s]:

- ``/joint_states`` (``sensor_msgs/msg/JointState``): every hinge or slide joint of the model by its own name, in
  the model's order, position [rad or m] and velocity [rad/s or m/s] (``qpos[7:]``, ``qvel[6:]`` of
  :func:`zmpwalk.export.clips.velocities`);
- ``/tf`` (``tf2_msgs/msg/TFMessage``): ``world`` to the free base's body (its name in the model) and ``world`` to
  ``left_foot`` and ``right_foot`` (the ankle sites' frames); rotations as ROS quaternions (x, y, z, w);
- ``/zmpwalk/markers`` (``visualization_msgs/msg/MarkerArray``, frame ``world``): each frame the reference ZMP
  (``ns`` ``zmp``, a green sphere on the floor) and, in a simulated clip, the measured CoP (``cop``, red; none
  while the robot is off the floor); each footprint (``footprints``, a closed line around the sole) once, when its
  stance phase begins (:func:`zmpwalk.export.verify.stance_phases`), kept to the end.

Messages are of ROS 2 Humble's definitions (:data:`TYPESTORE`). :func:`read_bag` reads a bag back as the clip's
``qpos`` rows and frame rate (the base from ``/tf``, the joints from ``/joint_states``).
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError
from zmpwalk.export.clips import velocities
from zmpwalk.export.names import body_names, joint_names
from zmpwalk.export.verify import stance_phases
from zmpwalk.footsteps import Pose2D, foot_corners
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Side
from zmpwalk.sim.mujoco_plant import _ankle_sites

Array = NDArray[np.float64]

TYPESTORE = "ROS2_HUMBLE"  # the message definitions written (rosbags.typesys.Stores)
WORLD = "world"  # [-] the fixed frame
MARKER_SIZE = 0.03  # [m] diameter of the ZMP and CoP spheres
FOOTPRINT_LINE = 0.004  # [m] width of a footprint's line


@dataclass(frozen=True)
class BagExtras:
    """What a bag shows besides the motion, per frame of the clip.

    Attributes:
        zmp: The reference ZMP in world (n, 2) [m].
        cop: The measured CoP in world (n, 2) [m] (NaN where no sole carries load), or None (a planned clip).
    """

    zmp: Array  # [m]
    cop: Array | None = None  # [m]


def _typestore() -> Any:
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(getattr(Stores, TYPESTORE))


def _stamp(store: Any, seconds: float) -> Any:
    sec, nanosec = divmod(round(seconds * 1e9), 10**9)
    return store.types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec)


def _header(store: Any, seconds: float, frame: str) -> Any:
    return store.types["std_msgs/msg/Header"](stamp=_stamp(store, seconds), frame_id=frame)


def _transform(store: Any, seconds: float, child: str, position: Array, quaternion_wxyz: Array) -> Any:
    """A ``geometry_msgs/msg/TransformStamped`` of ``child`` in ``world``."""
    t = store.types
    w, x, y, z = (float(v) for v in quaternion_wxyz)
    return t["geometry_msgs/msg/TransformStamped"](
        header=_header(store, seconds, WORLD), child_frame_id=child,
        transform=t["geometry_msgs/msg/Transform"](
            translation=t["geometry_msgs/msg/Vector3"](x=float(position[0]), y=float(position[1]),
                                                       z=float(position[2])),
            rotation=t["geometry_msgs/msg/Quaternion"](x=x, y=y, z=z, w=w)))


def _marker(store: Any, seconds: float, ns: str, ident: int, kind: int, rgba: tuple[float, float, float, float],
            points: list[tuple[float, float, float]] | None = None, position: tuple[float, float, float] = (0, 0, 0),
            size: float = MARKER_SIZE) -> Any:
    """A ``visualization_msgs/msg/Marker`` in ``world``: a sphere at ``position`` or a line through ``points``."""
    t = store.types
    point, vector = t["geometry_msgs/msg/Point"], t["geometry_msgs/msg/Vector3"]
    return t["visualization_msgs/msg/Marker"](
        header=_header(store, seconds, WORLD), ns=ns, id=ident, type=kind, action=0,
        pose=t["geometry_msgs/msg/Pose"](position=point(x=float(position[0]), y=float(position[1]),
                                                        z=float(position[2])),
                                         orientation=t["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0)),
        scale=vector(x=size, y=size, z=size), color=t["std_msgs/msg/ColorRGBA"](r=rgba[0], g=rgba[1], b=rgba[2],
                                                                                  a=rgba[3]),
        lifetime=t["builtin_interfaces/msg/Duration"](sec=0, nanosec=0), frame_locked=False,
        points=[point(x=float(x), y=float(y), z=float(z)) for x, y, z in (points or [])], colors=[],
        texture_resource="", texture=t["sensor_msgs/msg/CompressedImage"](
            header=_header(store, seconds, WORLD), format="", data=np.zeros(0, dtype=np.uint8)),
        uv_coordinates=[], text="", mesh_resource="",
        mesh_file=t["visualization_msgs/msg/MeshFile"](filename="", data=np.zeros(0, dtype=np.uint8)),
        mesh_use_embedded_materials=False)


def _feet(model: mujoco.MjModel, qpos: Array) -> tuple[Array, Array]:
    """The ankle sites' positions (n, 2, 3) [m] and quaternions (n, 2, 4) (w, x, y, z) in world."""
    data, sites = mujoco.MjData(model), _ankle_sites(model)
    positions, quaternions = np.empty((len(qpos), 2, 3)), np.empty((len(qpos), 2, 4))
    for i, row in enumerate(qpos):
        data.qpos[:] = row
        mujoco.mj_kinematics(model, data)
        for foot, site in enumerate(sites):
            positions[i, foot] = data.site_xpos[site]
            mujoco.mju_mat2Quat(quaternions[i, foot], data.site_xmat[site])
    return positions, quaternions


def _footprints(model: mujoco.MjModel, robot: RobotModel, qpos: Array, fps: float, feet: tuple[Array, Array]
                ) -> list[tuple[int, Array]]:
    """Each stance phase's first frame and the sole's corners there (4, 2) [m]."""
    positions, quaternions = feet
    prints = []
    for side in Side:
        for first, _ in stance_phases(model, qpos, fps).phases[side.index]:
            w, x, y, z = quaternions[first, side.index]
            yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
            x0, y0 = positions[first, side.index, :2]
            prints.append((first, foot_corners(Pose2D(float(x0), float(y0), yaw), side, robot)))
    return sorted(prints, key=lambda p: p[0])


def _markers(store: Any, seconds: float, frame: int, extras: BagExtras, prints: list[tuple[int, Array]]) -> Any:
    """The frame's ``MarkerArray``: the ZMP, the CoP where measured, and the footprints whose stance begins."""
    marker = store.types["visualization_msgs/msg/Marker"]
    items = [_marker(store, seconds, "zmp", 0, marker.SPHERE, (0.1, 0.8, 0.2, 1.0),
                     position=(*extras.zmp[frame], 0.0))]
    if extras.cop is not None and np.all(np.isfinite(extras.cop[frame])):
        items.append(_marker(store, seconds, "cop", 0, marker.SPHERE, (0.9, 0.1, 0.1, 1.0),
                             position=(*extras.cop[frame], 0.0)))
    for ident, (first, corners) in enumerate(prints):
        if first == frame:
            loop = [(float(x), float(y), 0.001) for x, y in (*corners, corners[0])]
            items.append(_marker(store, seconds, "footprints", ident, marker.LINE_STRIP, (0.2, 0.4, 0.9, 1.0),
                                 points=loop, size=FOOTPRINT_LINE))
    return store.types["visualization_msgs/msg/MarkerArray"](markers=items)


def write_bag(path: Path, model: mujoco.MjModel, robot: RobotModel, qpos: Array, fps: float,
              extras: BagExtras) -> None:
    """Write the clip ``qpos`` (n, nq) at ``fps`` [Hz] as a ROS 2 bag folder at ``path`` (module docstring),
    replacing one there.

    Raises:
        FileFormatError: ``path`` cannot be written.
    """
    from rosbags.rosbag2 import StoragePlugin, Writer, WriterError

    store, names, base = _typestore(), joint_names(model)[1:], body_names(model)[0]
    qvel, feet = velocities(model, qpos, fps), _feet(model, qpos)
    prints = _footprints(model, robot, qpos, fps, feet)
    if path.is_symlink() or (path.exists() and not path.is_dir()):
        raise FileFormatError(str(path), "is not a folder: a bag is written as a folder")
    partial = path.with_name(f".{path.name}.partial")
    try:
        if partial.exists():
            shutil.rmtree(partial)
        with Writer(partial, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
            joints = writer.add_connection("/joint_states", "sensor_msgs/msg/JointState", typestore=store)
            tf = writer.add_connection("/tf", "tf2_msgs/msg/TFMessage", typestore=store)
            markers = writer.add_connection("/zmpwalk/markers", "visualization_msgs/msg/MarkerArray",
                                            typestore=store)
            for i in range(len(qpos)):
                seconds = i / fps
                stamp = round(seconds * 1e9)
                state = store.types["sensor_msgs/msg/JointState"](
                    header=_header(store, seconds, WORLD), name=names, position=qpos[i, 7:].astype(np.float64),
                    velocity=qvel[i, 6:].astype(np.float64), effort=np.zeros(0))
                writer.write(joints, stamp, store.serialize_cdr(state, state.__msgtype__))
                frames = [_transform(store, seconds, base, qpos[i, 0:3], qpos[i, 3:7])]
                frames += [_transform(store, seconds, f"{side.label}_foot", feet[0][i, side.index],
                                      feet[1][i, side.index]) for side in Side]
                message = store.types["tf2_msgs/msg/TFMessage"](transforms=frames)
                writer.write(tf, stamp, store.serialize_cdr(message, message.__msgtype__))
                array = _markers(store, seconds, i, extras, prints)
                writer.write(markers, stamp, store.serialize_cdr(array, array.__msgtype__))
        _replace_folder(partial, path)
    except (OSError, WriterError) as error:
        shutil.rmtree(partial, ignore_errors=True)
        raise FileFormatError(str(path), f"cannot be written: {getattr(error, 'strerror', None) or error}") from None


def _replace_folder(new: Path, path: Path) -> None:
    """Put the written folder ``new`` at ``path``: an old folder there is renamed away first and removed after,
    so that ``path`` never holds a bag partly written."""
    old = path.with_name(f".{path.name}.old")
    if path.exists():
        if old.exists():
            shutil.rmtree(old)
        path.rename(old)
    new.rename(path)
    shutil.rmtree(old, ignore_errors=True)


def read_bag(path: str) -> tuple[Array, float]:
    """A clip's ``qpos`` rows and frame rate [Hz] back from a bag written by :func:`write_bag`.

    Raises:
        FileFormatError: Not such a bag.
    """
    from rosbags.rosbag2 import Reader, ReaderError

    store, rows, stamps = _typestore(), [], []
    try:
        with Reader(path) as reader:
            topics = {c.topic: c for c in reader.connections}
            wanted = [topics[t] for t in ("/joint_states", "/tf")]
            bases: list[Array] = []
            for connection, stamp, raw in reader.messages(connections=wanted):
                message = store.deserialize_cdr(raw, connection.msgtype)
                if connection.topic == "/joint_states":
                    rows.append(np.asarray(message.position, dtype=np.float64))
                    stamps.append(stamp)
                else:
                    t = message.transforms[0].transform
                    bases.append(np.array([t.translation.x, t.translation.y, t.translation.z, t.rotation.w,
                                           t.rotation.x, t.rotation.y, t.rotation.z]))
    except (KeyError, OSError, ValueError, ReaderError) as error:
        raise FileFormatError(path, f"is not a bag of a clip ({error})") from None
    if not rows or len(bases) != len(rows):
        raise FileFormatError(path, "is not a bag of a clip (joint states and base frames do not pair)")
    fps = (len(stamps) - 1) / ((stamps[-1] - stamps[0]) * 1e-9) if len(stamps) > 1 else math.nan
    return np.column_stack([np.asarray(bases), np.asarray(rows)]), float(fps)
