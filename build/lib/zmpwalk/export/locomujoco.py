"""LocoMuJoCo's trajectory npz (``loco_mujoco.trajectory.Trajectory.save`` / ``Trajectory.load``, v1.0).

The flat keys ``Trajectory.load`` sorts into its three parts, and only those (it refuses others):

- ``TrajectoryInfo``: ``joint_names`` (njnt,) (every joint, the free base first, model order), ``frequency``
  () [Hz], ``body_names`` (nbody,) (the world first);
- ``TrajectoryModel``: ``njnt``, ``jnt_type`` (njnt,), ``nbody``, ``body_rootid``, ``body_weldid``,
  ``body_mocapid``, ``body_pos`` [m], ``body_quat`` (w, x, y, z), ``body_ipos`` [m], ``body_iquat``: the model's;
- ``TrajectoryData``: ``qpos`` (n, nq) [m, rad; the free base's quaternion **w, x, y, z**], ``qvel`` (n, nv)
  (MuJoCo's: base linear velocity in world [m/s], base angular velocity in the base frame [rad/s], joint rates;
  central differences of the frames), ``xpos`` (n, nbody, 3) [m] and ``xquat`` (n, nbody, 4) (w, x, y, z) of
  every body (the world's row included), ``split_points`` (2,): one trajectory, frames 0 to n.

The key set was taken from loco-mujoco 1.0.0's source; its loader was not run here (it pins mujoco 3.2.7 and
numpy < 2).
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
    structure = {"njnt": np.array(model.njnt), "jnt_type": model.jnt_type.copy(), "nbody": np.array(model.nbody),
                 **{key: getattr(model, key).copy() for key in ("body_rootid", "body_weldid", "body_mocapid",
                                                               "body_pos", "body_quat", "body_ipos", "body_iquat")}}
    np.savez(buffer, qpos=qpos, qvel=velocities(model, qpos, fps), xpos=xpos, xquat=xquat,
             joint_names=np.array(joint_names(model)), body_names=np.array([world, *body_names(model)]),
             frequency=np.array(float(fps)), split_points=np.array([0, n], dtype=np.int64), **structure)
    return buffer.getvalue()


def read_locomujoco(path: str) -> tuple[Array, float]:
    """A clip's ``qpos`` rows and frame rate [Hz] back from :func:`locomujoco_npz`'s file."""
    with np.load(path) as archive:
        return np.asarray(archive["qpos"], dtype=np.float64), float(archive["frequency"])
