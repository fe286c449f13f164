"""mjlab's motion npz (the tracking task's ``motion.npz``).

Arrays (n frames, J hinge or slide joints after the free base, B bodies: every body of the model but the world,
in the model's order):

- ``fps`` (1,) [Hz], int64;
- ``joint_names`` (J,) and ``body_names`` (B,), strings in the model's order;
- ``joint_pos`` (n, J) [rad or m] and ``joint_vel`` (n, J) [rad/s or m/s]: ``qpos[7:]`` and ``qvel[6:]``;
- ``body_pos_w`` (n, B, 3) [m] and ``body_quat_w`` (n, B, 4): each body's frame in world, quaternion
  **w, x, y, z** (MuJoCo's order, unit norm);
- ``body_lin_vel_w`` (n, B, 3) [m/s] and ``body_ang_vel_w`` (n, B, 3) [rad/s]: each body frame origin's velocity
  in world axes (mjlab's ``body_link_*_vel_w``: :func:`mujoco.mj_objectVelocity` moved from the body's centre of
  mass to its frame origin).

The free base is body 1 of the model (``body_pos_w[:, 0]``, ``body_quat_w[:, 0]``), so the clip's ``qpos`` is
``body_pos_w[:, 0], body_quat_w[:, 0], joint_pos``. Velocities are central differences of the frames.
"""

from __future__ import annotations

import io

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.export.clips import velocities
from zmpwalk.export.names import body_names, joint_names

Array = NDArray[np.float64]


def body_states(model: mujoco.MjModel, qpos: Array, qvel: Array) -> tuple[Array, Array, Array, Array]:
    """Each body's (but the world's) position [m], quaternion (w, x, y, z), linear [m/s] and angular [rad/s]
    velocity in world, per frame: (n, B, 3), (n, B, 4), (n, B, 3), (n, B, 3)."""
    n, bodies = len(qpos), model.nbody - 1
    position, quaternion = np.empty((n, bodies, 3)), np.empty((n, bodies, 4))
    linear, angular = np.empty((n, bodies, 3)), np.empty((n, bodies, 3))
    data, twist = mujoco.MjData(model), np.empty(6)
    for i in range(n):
        data.qpos[:], data.qvel[:] = qpos[i], qvel[i]
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_comVel(model, data)
        position[i], quaternion[i] = data.xpos[1:], data.xquat[1:]
        for b in range(1, model.nbody):
            mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_BODY, b, twist, 0)
            # the twist's linear part is at the body's centre of mass: moved to the body frame's origin
            angular[i, b - 1] = twist[:3]
            linear[i, b - 1] = twist[3:] + np.cross(twist[:3], data.xpos[b] - data.xipos[b])
    return position, quaternion, linear, angular


def mjlab_npz(model: mujoco.MjModel, qpos: Array, fps: float) -> bytes:
    """The clip as mjlab's motion npz (module docstring)."""
    qvel = velocities(model, qpos, fps)
    position, quaternion, linear, angular = body_states(model, qpos, qvel)
    buffer = io.BytesIO()
    np.savez(buffer, fps=np.array([round(fps)], dtype=np.int64), joint_names=np.array(joint_names(model)[1:]),
             body_names=np.array(body_names(model)), joint_pos=qpos[:, 7:].astype(np.float32),
             joint_vel=qvel[:, 6:].astype(np.float32), body_pos_w=position.astype(np.float32),
             body_quat_w=quaternion.astype(np.float32), body_lin_vel_w=linear.astype(np.float32),
             body_ang_vel_w=angular.astype(np.float32))
    return buffer.getvalue()


def read_mjlab(path: str) -> tuple[Array, float]:
    """A clip's ``qpos`` rows and frame rate [Hz] back from an mjlab npz written by :func:`mjlab_npz`."""
    with np.load(path) as archive:
        qpos = np.column_stack([archive["body_pos_w"][:, 0], archive["body_quat_w"][:, 0], archive["joint_pos"]])
        return qpos.astype(np.float64), float(archive["fps"][0])
