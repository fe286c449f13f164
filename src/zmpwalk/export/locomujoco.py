"""LocoMuJoCo-style trajectory npz: the model's whole ``qpos`` and ``qvel`` with its joint names and frequency.

Arrays (n frames): ``qpos`` (n, nq) [m, rad; the free base's quaternion **w, x, y, z**], ``qvel`` (n, nv) (base
linear velocity in world [m/s], base angular velocity in the base frame [rad/s], joint rates: MuJoCo's ``qvel``),
``xpos`` (n, nbody, 3) [m] and ``xquat`` (n, nbody, 4) (w, x, y, z) of every body, the world's included (row 0),
``joint_names`` (njnt,) (the free base first), ``body_names`` (nbody,) (the world first), ``frequency`` () [Hz],
``split_points`` (2,) (one trajectory: frames 0 to n). These are the fields of LocoMuJoCo's ``TrajectoryInfo``
(``joint_names``, ``frequency``, ``body_names``) and ``TrajectoryData`` (``qpos``, ``qvel``, ``xpos``, ``xquat``,
``split_points``), written flat; loading them into a ``Trajectory`` is not checked here (LocoMuJoCo was not
installed where this was written).
"""

from __future__ import annotations

import io

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.export.clips import velocities
from zmpwalk.export.names import body_names, joint_names

Array = NDArray[np.float64]


def locomujoco_npz(model: mujoco.MjModel, qpos: Array, fps: float) -> bytes:
    """The clip as a LocoMuJoCo-style trajectory npz (module docstring)."""
    n, data = len(qpos), mujoco.MjData(model)
    xpos, xquat = np.empty((n, model.nbody, 3)), np.empty((n, model.nbody, 4))
    for i in range(n):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        xpos[i], xquat[i] = data.xpos, data.xquat
    buffer = io.BytesIO()
    world = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, 0) or "world"
    np.savez(buffer, qpos=qpos, qvel=velocities(model, qpos, fps), xpos=xpos, xquat=xquat,
             joint_names=np.array(joint_names(model)), body_names=np.array([world, *body_names(model)]),
             frequency=np.array(float(fps)), split_points=np.array([0, n], dtype=np.int64))
    return buffer.getvalue()


def read_locomujoco(path: str) -> tuple[Array, float]:
    """A clip's ``qpos`` rows and frame rate [Hz] back from :func:`locomujoco_npz`'s file."""
    with np.load(path) as archive:
        return np.asarray(archive["qpos"], dtype=np.float64), float(archive["frequency"])
