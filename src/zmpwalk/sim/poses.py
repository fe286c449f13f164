"""Posing a plant's model: the floating root placed so that the legs' base is where a plan puts it (through the held
waist where the legs hang below one: :func:`zmpwalk.robots.tree.root_from_base`), the leg joints at their angles and
every other joint at the reference pose; the standing start of a walk."""

from __future__ import annotations

import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.robots.collision import collision_points, rigid_bodies
from zmpwalk.robots.linkages import close_or_refuse
from zmpwalk.robots.tree import root_from_base
from zmpwalk.sim.plant import Plant

Array = NDArray[np.float64]


def set_base_pose(plant: Plant, qpos: Array, position_base: Array, yaw: float,
                  quaternion_base: Array | None = None) -> None:
    """Write the floating root's pose into ``qpos`` (its first 7 values) that puts the legs' base at
    ``position_base`` [m], upright at ``yaw`` [rad] (or turned by ``quaternion_base`` (w, x, y, z), where given)."""
    if plant.mount is None:
        qpos[0:3] = position_base
        qpos[3:7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)) if quaternion_base is None else quaternion_base
        return
    root = plant.root_in_base
    if quaternion_base is None and root is not None:  # upright at yaw, scalar arithmetic (a tick's feedforward)
        ox, oy, oz, w, x, y, z = root
        c, s = math.cos(yaw), math.sin(yaw)
        px, py, pz = (float(v) for v in position_base)
        qpos[0], qpos[1], qpos[2] = px + c * ox - s * oy, py + s * ox + c * oy, pz + oz
        cw, sz = math.cos(yaw / 2), math.sin(yaw / 2)  # (cw, 0, 0, sz) * (w, x, y, z)
        qpos[3], qpos[4], qpos[5], qpos[6] = cw * w - sz * z, cw * x - sz * y, cw * y + sz * x, cw * z + sz * w
        return
    quaternion = np.array([math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)] if quaternion_base is None
                          else quaternion_base, dtype=np.float64)  # a copy: the caller's stays as given
    rotation_base = np.empty(9)
    mujoco.mju_quat2Mat(rotation_base, quaternion)
    position_root, rotation_root = root_from_base(plant.mount, np.asarray(position_base, dtype=np.float64),
                                                  rotation_base.reshape(3, 3))
    qpos[0:3] = position_root
    mujoco.mju_mat2Quat(quaternion, rotation_root.flatten())
    qpos[3:7] = quaternion


def set_initial_state(plant: Plant, data: mujoco.MjData, position_base: Array, yaw: float, angles: Array,
                      penetration: float = 0.0) -> None:
    """Stand the plant in the first pose at rest: the base origin [m] and yaw [rad], the leg angles (12,)
    [rad], the other joints at the reference pose, the lowest sole ``penetration`` [m] into the ground."""
    model = plant.model
    data.qpos[:] = plant.qpos_hold
    set_base_pose(plant, data.qpos, position_base, yaw)
    data.qpos[plant.leg_qpos] = angles[plant.leg_columns]
    data.qvel[:] = 0.0
    data.ctrl[:] = plant.ctrl_hold
    data.ctrl[plant.leg_actuators] = angles
    close_loops(plant, data)
    mujoco.mj_kinematics(model, data)
    soles = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_ankle") for s in ("left", "right")]
    if plant.imported:
        bottom = min(float(collision_points(model, data, rigid_bodies(model, int(model.site_bodyid[site])))[:, 2]
                           .min()) for site in soles)
    else:
        geoms = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{s}_sole") for s in ("left", "right")]
        bottom = min(float(data.geom_xpos[g][2] - model.geom_size[g][2]) for g in geoms)
    data.qpos[2] += -bottom - penetration
    mujoco.mj_forward(model, data)


def close_loops(plant: Plant, data: mujoco.MjData) -> None:
    """Place the joints the driven joints move through an equality (:attr:`Plant.coupled_dofs`: a parallel ankle's
    or waist's cranks and rods, a geared hip yaw's drive) where the model's equalities hold with the legs and the
    held joints as ``data.qpos`` has them (:func:`zmpwalk.robots.linkages.close_equalities`), so that the simulation
    does not start with its linkages torn apart (MuJoCo's stiff equalities would snap them together in the first
    steps, jolting the feet). Nothing to do where the robot has no such joints.

    Raises:
        InvalidParameterError: The loops do not close (:func:`zmpwalk.robots.linkages.close_or_refuse`).
    """
    close_or_refuse(plant.model, data, plant.coupled_dofs)


def plant_qpos(plant: Plant, position_base: Array, yaw: Array, angles: Array) -> Array:
    """Full ``qpos`` rows (n, nq) of the planned motion: the base origin [m] (n, 3) and yaw [rad] (upright),
    leg joint columns (n, 12), the other joints at the reference pose."""
    n = len(yaw)
    qpos = np.repeat(plant.qpos_hold[None, :], n, axis=0)
    if plant.mount is None:
        qpos[:, 0:3] = position_base
        qpos[:, 3:7] = np.column_stack([np.cos(yaw / 2), np.zeros(n), np.zeros(n), np.sin(yaw / 2)])
    else:
        for row, position, angle in zip(qpos, position_base, yaw, strict=True):
            set_base_pose(plant, row, position, float(angle))
    qpos[:, plant.leg_qpos] = angles[:, plant.leg_columns]
    return qpos
