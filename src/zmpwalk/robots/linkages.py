"""Closed linkages in a robot's model (a parallel ankle: two cranks on the shank pushing the foot through rods and
``<connect>`` equalities; a parallel waist): the loops the equalities close, placing the loop's passive joints
where the equalities hold, and the torque its motors give the joints they turn."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError

Array = NDArray[np.float64]

LOOP_TOLERANCE = 1e-9  # [m, rad] the equalities' residual a closed loop is placed within
LOOP_ITERATIONS = 50  # Gauss-Newton steps at most
LOOP_CLOSED = 1e-6  # [m, rad] the residual above which a loop counts as not closed


def equality_pairs(model: Any) -> list[tuple[int, int]]:
    """The two bodies of each active connect or weld equality (given by bodies or by sites on them)."""
    import mujoco

    pairs = []
    for e in range(model.neq):
        if not model.eq_active0[e] or int(model.eq_type[e]) not in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD):
            continue
        first, second = int(model.eq_obj1id[e]), int(model.eq_obj2id[e])
        if int(model.eq_objtype[e]) == mujoco.mjtObj.mjOBJ_SITE:
            first, second = int(model.site_bodyid[first]), int(model.site_bodyid[second])
        elif int(model.eq_objtype[e]) != mujoco.mjtObj.mjOBJ_BODY:
            continue
        pairs.append((first, second))
    return pairs


def equality_bodies(model: Any) -> set[int]:
    """Every body an active connect or weld equality acts on."""
    return {body for pair in equality_pairs(model) for body in pair}


def equality_loops(model: Any) -> list[set[int]]:
    """The joints of each loop an active connect or weld equality closes within the robot (a loop through its
    floating joint ties it to the world: not a linkage of its own)."""
    import mujoco

    loops = [_loop_joints(model, first, second) for first, second in equality_pairs(model)]
    return [loop for loop in loops if all(int(model.jnt_type[j]) != mujoco.mjtJoint.mjJNT_FREE for j in loop)]


def joint_id(model: Any, name: str) -> int:
    """The id of the joint ``name`` (``#N``: the unnamed joint N, as :func:`zmpwalk.robots.pd.element_name` names
    it).

    Raises:
        InvalidParameterError: No such joint in ``model``.
    """
    import mujoco

    index = int(name[1:]) if name.startswith("#") and name[1:].isdigit() else \
        mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
    if not 0 <= index < model.njnt:
        raise InvalidParameterError("joint", name, f"a joint of the model (it has {model.njnt})")
    return index


def _loop_joints(model: Any, first: int, second: int) -> set[int]:
    """The joints of the loop an equality between bodies ``first`` and ``second`` closes: those on the tree's
    paths from each body up to their nearest common ancestor."""
    def chain(body: int) -> list[int]:
        bodies = [body]
        while body > 0:
            body = int(model.body_parentid[body])
            bodies.append(body)
        return bodies

    up, other = chain(first), set(chain(second))
    common = next(body for body in up if body in other)
    joints: set[int] = set()
    for start in (first, second):
        body = start
        while body != common:
            adr, count = int(model.body_jntadr[body]), int(model.body_jntnum[body])
            joints.update(range(adr, adr + count))
            body = int(model.body_parentid[body])
    return joints


def joint_dofs(model: Any, joints: list[int]) -> NDArray[np.intp]:
    """The degrees of freedom of ``joints``, in order."""
    import mujoco

    count = {int(mujoco.mjtJoint.mjJNT_FREE): 6, int(mujoco.mjtJoint.mjJNT_BALL): 3,
             int(mujoco.mjtJoint.mjJNT_SLIDE): 1, int(mujoco.mjtJoint.mjJNT_HINGE): 1}
    return np.array([int(model.jnt_dofadr[j]) + k for j in joints for k in range(count[int(model.jnt_type[j])])],
                    dtype=np.intp)


def close_equalities(model: Any, data: Any, dofs: NDArray[np.intp]) -> float:
    """Move the degrees of freedom ``dofs`` of ``data.qpos`` until the equalities they take part in hold: Gauss-Newton
    on those equalities' residuals (``efc_pos``) over ``dofs`` alone, every other joint kept. Returns the largest
    residual left [m or rad] (below :data:`LOOP_TOLERANCE` once closed; 0 with no ``dofs``)."""
    import mujoco

    largest = 0.0
    step = np.zeros(model.nv)
    for _ in range(LOOP_ITERATIONS if len(dofs) else 0):
        mujoco.mj_forward(model, data)
        rows = np.flatnonzero(data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        jacobian = equality_jacobian(model, data, rows)[:, dofs]
        moved = np.abs(jacobian).max(axis=1, initial=0.0) > 0.0  # the equalities these joints take part in
        jacobian, residual = jacobian[moved], data.efc_pos[rows[moved]]
        largest = float(np.max(np.abs(residual), initial=0.0))
        if largest < LOOP_TOLERANCE:
            break
        step[:] = 0.0
        step[dofs] = -np.linalg.lstsq(jacobian, residual, rcond=None)[0]
        mujoco.mj_integratePos(model, data.qpos, step, 1.0)
    return largest


def close_or_refuse(model: Any, data: Any, dofs: NDArray[np.intp]) -> None:
    """:func:`close_equalities`, and an error where the loops do not close.

    Raises:
        InvalidParameterError: A residual over :data:`LOOP_CLOSED` is left (a linkage the posture cannot
            close: a rod too short for where the legs put the foot).
    """
    residual = close_equalities(model, data, dofs)
    if residual > LOOP_CLOSED:
        raise InvalidParameterError("linkage residual", f"{residual:.3g} m", f"at most {LOOP_CLOSED:g} m: the "
                                    "model's equalities (its linkages' rods) must close in the ready posture")


def equality_jacobian(model: Any, data: Any, rows: NDArray[np.intp]) -> Array:
    """The constraint Jacobian's ``rows`` (k, nv), dense whatever the model's ``jacobian`` option."""
    import mujoco

    if mujoco.mj_isSparse(model):
        dense = np.zeros((data.nefc, model.nv))
        mujoco.mju_sparse2dense(dense, data.efc_J, data.efc_J_rownnz, data.efc_J_rowadr, data.efc_J_colind)
        return dense[rows]
    return np.asarray(data.efc_J[:data.nefc * model.nv].reshape(data.nefc, model.nv)[rows], dtype=np.float64)


def driven_torque_limits(model: Any, data: Any, driven: list[int], motors: list[int], passive: list[int],
                         motor_limits: list[float]) -> list[float]:
    """The largest torque [N m] each of the ``driven`` hinges of one linkage can get from its ``motors`` (joint ids,
    their torque limits ``motor_limits`` [N m]), the other driven hinges' torques 0, in ``data``'s closed posture:
    by virtual work ``tau_driven = G^T tau_motors`` with ``G = d q_motors / d q_driven``, solved from the
    equalities' Jacobian (``J_m q'_m + J_p q'_p = -J_d q'_d``, the ``passive`` joints free). Where the motors do not
    turn the driven hinges one to one (a count that differs, a singular map), inf: no limit derived."""
    import mujoco

    mujoco.mj_forward(model, data)
    rows = np.flatnonzero(data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    jacobian = equality_jacobian(model, data, rows)
    d, m, p = joint_dofs(model, driven), joint_dofs(model, motors), joint_dofs(model, passive)
    involved = np.abs(jacobian[:, np.concatenate([d, m, p])]).max(axis=1, initial=0.0) > 0.0
    jacobian = jacobian[involved]
    if len(m) != len(d) or len(m) == 0 or not len(jacobian):
        return [math.inf] * len(driven)
    free = np.linalg.lstsq(jacobian[:, np.concatenate([m, p])], -jacobian[:, d], rcond=None)[0]
    gear = free[:len(m)]  # d q_motors / d q_driven, (motors, driven)
    if abs(float(np.linalg.det(gear))) < 1e-9:
        return [math.inf] * len(driven)
    to_motors = np.linalg.inv(gear.T)  # tau_motors = G^-T tau_driven
    limits = np.asarray(motor_limits, dtype=float)
    return [float(np.min(limits / np.maximum(np.abs(to_motors[:, j]), 1e-12))) for j in range(len(driven))]
