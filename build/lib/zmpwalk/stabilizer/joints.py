# mypy: disallow-untyped-decorators=False
r"""The compiled stabilizer's output (numba, cached on disk): the feet's corrections relative to the pelvis mapped
onto the joints through each leg's Jacobian at the pattern's angles (``Delta q = J^{-1} Delta x``), and the
servo stiffness loop on the encoders (:mod:`zmpwalk.balance`, step 8).

A five-joint leg's chain carries its virtual ankle roll as a sixth joint: the change the solve gives that joint is
sent nowhere (the plant has no joint there), so what the five real joints do is the correction less a roll of the
sole about its centre line (:mod:`zmpwalk.balance`, "Five-joint legs").

Targets and encoders are the 12 role-ordered joint columns [rad] (:data:`zmpwalk.kinematics.JOINT_COLUMNS`);
positions in metres, angles in radians.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from zmpwalk.stabilizer.freshness import BUILD_KEY
from zmpwalk.stabilizer.layout import P, S
from zmpwalk.stabilizer.leg import lu_solve6
from zmpwalk.stabilizer.rotations import rotate2

Vector3 = tuple[float, float, float]


@njit(cache=True, nogil=True, inline="always")
def joint_corrections(state: np.ndarray, chain: np.ndarray, work: np.ndarray, targets: np.ndarray,
                      reference: np.ndarray, p0: Vector3, p1: Vector3, offset: tuple[float, float], yaw: float,
                      foot_yaws: tuple[float, float], height: float, turn: tuple[float, float]) -> None:
    """``targets`` <- the pattern's angles ``reference`` plus each leg's foot correction through the LU factors of
    its Jacobian (``work[4]``, ``work[5, 0]``): the landing correction in world less the CoM ``offset`` [m] (both
    turned by the pelvis ``yaw`` [rad] into the pelvis' heading), half the height difference [m] (left lowered),
    the foot turns (in the foot's yaw ``foot_yaws``) and the pelvis ``turn`` (roll, pitch) [rad] acting about
    the planned ankles ``p0``, ``p1`` (base frame), and the landing yaw."""
    turn_roll, turn_pitch = turn
    shift = rotate2(offset[0], offset[1], -yaw)
    changes = work[5, 1, 0:6]
    for i in range(12):
        targets[i] = reference[i]
    for leg in range(2):
        planned = p0 if leg == 0 else p1
        px, py, pz = planned[0], planned[1], planned[2]
        landing = rotate2(state[S.landing + 2 * leg], state[S.landing + 2 * leg + 1], -yaw)
        foot_turn = rotate2(state[S.ankle + 2 * leg], state[S.ankle + 2 * leg + 1], foot_yaws[leg] - yaw)
        changes[0] = landing[0] - shift[0] - turn_pitch * pz
        changes[1] = landing[1] - shift[1] + turn_roll * pz
        changes[2] = ((-height / 2 if leg == 0 else height / 2) - (turn_roll * py - turn_pitch * px)
                      + state[S.landing_height + leg])
        changes[3] = foot_turn[0] - turn_roll
        changes[4] = foot_turn[1] - turn_pitch
        changes[5] = state[S.landing_yaw + leg]
        lu_solve6(work[4, 0:6, 6 * leg:6 * leg + 6], work[5, 0, 6 * leg:6 * leg + 6], changes)
        for i in range(6):
            targets[6 * leg + int(chain[leg, i, 10])] += changes[i]


@njit(cache=True, nogil=True, inline="always")
def servo_outer_loop(params: np.ndarray, targets: np.ndarray, encoders: np.ndarray) -> None:
    """Servo stiffness (:mod:`zmpwalk.balance`, step 8): ``u = q_d + G (q_d - q)`` on each joint whose servo is
    softer than the gain ``servo_stiffness`` asks (``G``, the robot constant ``servo_gain``, 0 elsewhere)."""
    if params[P.stiffen] > 0.0:
        for i in range(12):
            targets[i] += params[P.servo_gain + i] * (targets[i] - encoders[i])


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY
