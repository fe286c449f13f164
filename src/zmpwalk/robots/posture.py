"""An imported robot's ready posture: the hips above the ankles at a hip-to-ankle distance, the soles level, the
centre of mass over the point between the feet (docs/robot-import.md, "The pattern fits the robot").

The distance is the keyframe's, at most :data:`READY_STRETCH` of the straight leg (a bent knee for walking), or a
``ready_stretch`` given (a robot file's ``[posture]``, or :mod:`zmpwalk.ready_fit` fitting the posture to a walk).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError, InvalidParameterError
from zmpwalk.leg_chain import LegChain
from zmpwalk.robots.collision import collision_points, rigid_bodies
from zmpwalk.robots.tree import Mount, root_from_base

Array = NDArray[np.float64]

READY_STRETCH = 0.92  # [-] hip-to-ankle distance of the ready posture, at most this fraction of the straight leg
STRETCH_RANGE = (0.5, 1.0)  # [-] a ready_stretch given: above the first, below the second (a straight leg)


def check_stretch(stretch: object) -> float:
    """``stretch`` as a float, a ready posture's hip-to-ankle distance over the straight leg [-].

    Raises:
        InvalidParameterError: Not a number within :data:`STRETCH_RANGE`.
    """
    if isinstance(stretch, bool) or not isinstance(stretch, (int, float)) \
            or not STRETCH_RANGE[0] < stretch < STRETCH_RANGE[1]:
        raise InvalidParameterError("ready_stretch", stretch, f"a fraction of the straight leg above "
                                    f"{STRETCH_RANGE[0]} and below {STRETCH_RANGE[1]} (a straight leg)")
    return float(stretch)


def posture_set_by(values: dict[str, float]) -> str:
    """The field of a robot's given ``values`` that sets its ready posture, ``"ready_stretch"`` or
    ``"pelvis_height"``; empty: none (the keyframe's).

    Raises:
        InvalidParameterError: Both are given.
    """
    given = sorted({"ready_stretch", "pelvis_height"} & set(values))
    if len(given) > 1:
        raise InvalidParameterError("overrides", given, "one of ready_stretch and pelvis_height: both set the ready "
                                    "posture")
    return given[0] if given else ""


def hip_to_ankle(chain: LegChain) -> float:
    """The hip centre's distance from the ankle point in ``chain``'s reference posture [m]."""
    ankle, _ = chain.fk(chain.reference[None])
    return float(np.linalg.norm(ankle[0] - chain.hip))


def reference_reach(model: Any, data: Any, qpos_reference: Array, base: int, hip: Array, foot: int,
                     ankle_height: float, straight: float, stretch: float | None) -> tuple[float, float]:
    """The ready posture's hip-to-ankle distance [m], ``stretch`` times the ``straight`` leg, or (None) the
    keyframe's, at most :data:`READY_STRETCH` of it, and the robot's height above its sole in the reference
    posture [m] (``data`` left there).

    Raises:
        InvalidParameterError: ``stretch`` is not a number within :data:`STRETCH_RANGE`.
    """
    import mujoco

    if stretch is not None:
        check_stretch(stretch)
    data.qpos[:] = qpos_reference
    mujoco.mj_kinematics(model, data)
    key_hip = data.xpos[base] + data.xmat[base].reshape(3, 3) @ hip
    key_foot_bottom = min(float(p[2]) for p in collision_points(model, data, rigid_bodies(model, foot)))
    key_distance = float(key_hip[2] - key_foot_bottom - ankle_height)
    distance = min(key_distance if key_distance > 0 else straight, READY_STRETCH * straight) if stretch is None \
        else stretch * straight
    return distance, float(np.max(data.geom_xpos[:, 2]) - key_foot_bottom)


def ready_posture(model: Any, data: Any, chains: list[LegChain], legs: list[list[int]], qpos_reference: Array,
                   root: tuple[int, Mount | None], distance: float, hip_x: float, hip_spacing: float,
                   hip_drop: float, ankle_height: float, pelvis_height_override: float | None, source: str
                   ) -> tuple[float, float, Array, list[LegChain], Array]:
    """The ready posture: the ankles ``hip_spacing`` apart below the pattern's point with the soles level, the
    hip-to-ankle distance ``distance`` [m]. The pattern moves the CoM: its offset from the base origin moves the
    posture, which moves the CoM, to a fixed point (within 1e-7 m). ``root``: the floating root's ``qpos`` address
    and where the legs' base sits on it (:func:`~zmpwalk.robots.tree.base_mount`).

    Returns:
        The pelvis height [m], the pendulum length (the CoM's height) [m], the CoM offset from the base origin
        [m] (2,), the chains with the ready posture as their reference angles, and the posture's ``qpos``.

    Raises:
        FileFormatError: A leg cannot reach the ready posture.
    """
    import mujoco

    com_offset = np.zeros(2)
    pelvis_height = pendulum = 0.0
    chains_ready = chains
    qpos = qpos_reference.copy()
    adr, mount = root
    for _ in range(8):  # fixed point: posture -> CoM offset -> posture
        dx = hip_x - com_offset[0]
        vertical = math.sqrt(max(distance * distance - dx * dx, 1e-12))
        pelvis_height = float(ankle_height + hip_drop + vertical if pelvis_height_override is None
                              else pelvis_height_override)
        chains_ready = []
        qpos = qpos_reference.copy()
        position_root, rotation_root = root_from_base(mount, np.array([0.0, 0.0, pelvis_height]), np.eye(3))
        qpos[adr:adr + 3] = position_root
        mujoco.mju_mat2Quat(qpos[adr + 3:adr + 7], rotation_root.flatten())
        for chain, side, leg in zip(chains, (1, -1), legs, strict=True):
            # the ankle below the pattern point, which is the CoM offset from the base origin; the sole level
            target = np.array([[com_offset[0], side * hip_spacing / 2 + com_offset[1], ankle_height - pelvis_height]])
            angles, excess = chain.solve(target, np.eye(3)[None])
            if excess[0] > 0:
                raise FileFormatError(source, f"the {chain.label} leg cannot reach the ready posture "
                                      f"(pelvis height {pelvis_height:.3f} m)")
            chains_ready.append(replace(chain, reference=angles[0]))
            for j, angle in zip(leg, angles[0], strict=False):  # a five-joint leg's virtual roll has no qpos
                qpos[model.jnt_qposadr[j]] = angle
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        com = data.subtree_com[0]
        new_offset = np.array([com[0], com[1]])
        pendulum = float(com[2])
        converged = np.max(np.abs(new_offset - com_offset)) < 1e-7
        com_offset = new_offset
        if converged:
            break
    return pelvis_height, pendulum, com_offset, chains_ready, qpos
