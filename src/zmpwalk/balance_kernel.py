# mypy: disallow-untyped-decorators=False
r"""The stabilizer's tick, compiled: :class:`zmpwalk.balance.Stabilizer` calls :func:`tick` once per control tick.

The loops and their equations are those of :mod:`zmpwalk.balance` (its docstring numbers them 1-8); :func:`tick`
runs them in order, one compiled function each, from the package :mod:`zmpwalk.stabilizer`: the compiled leg
(:mod:`~zmpwalk.stabilizer.leg`), the estimates (:mod:`~zmpwalk.stabilizer.estimation`), the feedback loops
(:mod:`~zmpwalk.stabilizer.loops`), landing and stepping (:mod:`~zmpwalk.stabilizer.landing`) and the output onto
the joints (:mod:`~zmpwalk.stabilizer.joints`). They run on plain float64 arrays, compiled by numba ahead of the
first call and cached on disk, so that a tick costs microseconds and allocates nothing: every intermediate lives in
the ``work`` array given by the caller.

Arrays (all float64):

- ``params`` (:data:`PARAMETERS`): the gains, the robot's constants and each leg servo's outer-loop gain, by name
  (:mod:`zmpwalk.stabilizer.layout`: :data:`~zmpwalk.stabilizer.layout.P`).
- ``chain`` (2, 6, 11): each leg chain's joints (:mod:`zmpwalk.stabilizer.leg`).
- ``state`` (:data:`STATE_SIZE`): the filters and offsets that carry from tick to tick
  (:data:`~zmpwalk.stabilizer.layout.S`).
- ``log`` (:data:`LOG_SIZE`): what :class:`zmpwalk.balance.BalanceState` shows (views into it;
  :data:`~zmpwalk.stabilizer.layout.L`).
- ``work`` (6, 7, 12): scratch. ``work[pose]`` for the four poses (left measured, left reference, right
  measured, right reference) holds the product of exponentials: each of the leg's 7 frames' rotation (row-major,
  0:9) and translation (9:12) in the base frame. ``work[4]`` holds the LU factors of the left and right leg's
  Jacobians at the reference (rows 0:6, columns 0:6 and 6:12) and the torso's rotation in world (row 6, 0:9);
  ``work[5]`` the factors' row swaps (row 0, 0:6 and 6:12) and a leg's foot correction (row 1, 0:6).

The frames: *base* is the torso (pelvis) frame, x forward, y left, z up; *world* is the walk's frame, z up against
gravity. Every position is in metres, every angle in radians.
"""

from __future__ import annotations

import math
import sys
from typing import Any

import numpy as np
from numba import njit

from zmpwalk.stabilizer import estimation, joints, landing, leg, loops, rotations
from zmpwalk.stabilizer.estimation import (
    com_estimate,
    floor_slope,
    leg_odometry,
    measured_legs,
    measured_zmp,
    reference_velocity,
    sole_centre,
)
from zmpwalk.stabilizer.freshness import BUILD_KEY, renew_stale
from zmpwalk.stabilizer.joints import joint_corrections, servo_outer_loop
from zmpwalk.stabilizer.landing import AIRBORNE_AIM, landing_and_stepping
from zmpwalk.stabilizer.layout import (
    LEFT_SUPPORT,
    LOG_SIZE,
    PARAMETERS,
    RIGHT_SUPPORT,
    STATE_SIZE,
    L,
    P,
    S,
    initial_state,
)
from zmpwalk.stabilizer.leg import ankle_in_base, factor_pattern_legs, leg_jacobian, leg_kinematics, lu6, lu_solve6
from zmpwalk.stabilizer.loops import (
    ankle_damping,
    com_admittance,
    dcm_feedback,
    distribute,
    foot_force_difference,
    torso_attitude,
    whole_body_rest,
)
from zmpwalk.stabilizer.rotations import rotate3

P_ANKLE_OFFSET = P.ankle_offset  # (2, 3) the ankle point in the last frame of each leg [m]

# --- what tick() returns besides 0: 1 + the index of a vector input with too few values (in the order of the
# arguments: com, zmp, ankle_left, ankle_right, reference, wrench_left, wrench_right, attitude, rate, encoders),
# or BAD_SUPPORT, or SINGULAR_LEG + leg (0 left, 1 right)
INPUT_SIZES = (3, 2, 3, 3, 12, 6, 6, 2, 3, 12)  # the vector inputs' lengths, in that order
BAD_SUPPORT = 11
SINGULAR_LEG = 12
SINGULAR_PIVOT = 1e-6  # [m] or [-]: a smaller pivot of a leg's Jacobian (a straight knee) is a singular posture

_VECTOR = "float64[:]"  # any stride (a row of a Fortran-ordered table)
TICK_SIGNATURE = (f"int64({_VECTOR}, float64[:, :, ::1], {_VECTOR}, {_VECTOR}, float64[:, :, ::1], {_VECTOR}, int64, "
                  f"{_VECTOR}, float64, {_VECTOR}, {_VECTOR}, {_VECTOR}, float64, float64, {_VECTOR}, {_VECTOR}, "
                  f"{_VECTOR}, {_VECTOR}, {_VECTOR}, {_VECTOR}, float64)")


# No reference counting in the tick (numba's _nrt=False): its arrays are the caller's and the views of them that it
# and the loops it inlines make, none outliving the call (counted, each view costs two atomic operations)
_NO_REFCOUNTS: dict[str, Any] = {"_nrt": False}


@njit(TICK_SIGNATURE, cache=True, nogil=True, **_NO_REFCOUNTS)
def tick(params: np.ndarray, chain: np.ndarray, state: np.ndarray, log: np.ndarray, work: np.ndarray,
         targets: np.ndarray, support: int, com: np.ndarray, yaw: float, zmp: np.ndarray, ankle_left: np.ndarray,
         ankle_right: np.ndarray, yaw_left: float, yaw_right: float, reference: np.ndarray,
         wrench_left: np.ndarray, wrench_right: np.ndarray, attitude: np.ndarray, rate: np.ndarray,
         encoders: np.ndarray, measured_yaw: float) -> int:
    """One tick of the stabilizer: ``targets`` (12) <- the corrected joint targets [rad].

    Returns 0; or, changing nothing, 1 + the index of a vector input with too few values, or
    :data:`BAD_SUPPORT` for a support that is not 0, 1 or 2, or :data:`SINGULAR_LEG` + the leg for pattern
    angles where a leg's Jacobian is singular (a straight knee: no foot correction maps onto the joints).
    Compiled for float64 vectors only (the signature :data:`TICK_SIGNATURE`): other inputs raise TypeError.

    Inputs in world unless said otherwise: the pattern's support (0 double, 1 left, 2 right), CoM point (3) [m],
    pelvis yaw [rad], ZMP (2) [m], planned ankles (3 each) [m], foot yaws [rad] and joint angles (12) [rad]; the
    measured wrenches (6 each: force [N], torque about the ankle [N m], foot frame), torso roll and pitch (2)
    [rad], gyro (3) [rad/s] in the base frame, joint encoders (12) [rad], and the torso's yaw [rad] (nan: the
    pattern's).
    """
    if support < 0 or support > 2:
        return BAD_SUPPORT
    given = (com.shape[0], zmp.shape[0], ankle_left.shape[0], ankle_right.shape[0], reference.shape[0],
             wrench_left.shape[0], wrench_right.shape[0], attitude.shape[0], rate.shape[0], encoders.shape[0])
    for i in range(len(INPUT_SIZES)):
        if given[i] < INPUT_SIZES[i]:
            return i + 1
    # the pattern's legs and their Jacobians' factors, which map the foot corrections onto the joints at the end;
    # a singular one is rejected before anything is written
    singular, p0, p1 = factor_pattern_legs(params, chain, work, reference, SINGULAR_PIVOT)
    if singular >= 0:
        return SINGULAR_LEG + singular
    whole_x, whole_y = whole_body_rest(params, chain, work, log, yaw)
    velocity = reference_velocity(params, state, com)
    # --- what is measured: the soles' loads, the legs and the torso, where the soles and the CoM are, the ZMP
    f0, f1 = wrench_left[2], wrench_right[2]
    loaded0, loaded1 = f0 > params[P.load_threshold], f1 > params[P.load_threshold]
    heading = yaw if math.isnan(measured_yaw) else measured_yaw
    a0, a1, com_base, s0, s1 = measured_legs(params, chain, work, encoders, heading, attitude)
    rot = work[4, 6, 0:9]  # the torso's rotation in world
    n0, n1 = rotate3(rot, s0[0], s0[1], s0[2]), rotate3(rot, s1[0], s1[1], s1[2])  # the soles' normals in world
    anchor = leg_odometry(params, state, rot, a0, a1, n0, n1, ankle_left, ankle_right, f0, f1, loaded0, loaded1)
    slope_x, slope_y = floor_slope(params, state, log, rot, s0, s1, loaded0, loaded1)
    cx, cy, left_x, left_y, right_x, right_y = com_estimate(params, state, rot, com_base, a0, a1, anchor, rate)
    c0, c1 = sole_centre(params, 0, left_x, left_y, yaw_left), sole_centre(params, 1, right_x, right_y, yaw_right)
    cop0x, cop0y, cop1x, cop1y, zmx, zmy = measured_zmp(params, log, wrench_left, wrench_right, loaded0, loaded1,
                                                        (left_x, left_y, right_x, right_y), yaw_left, yaw_right)
    # --- the loops (zmpwalk.balance, steps 1-6), then the corrections onto the joints and the servo loop (8)
    ex, ey, pdx, pdy = dcm_feedback(params, state, log, com, velocity, (cx, cy), zmp, support, c0, c1, yaw_left,
                                    yaw_right)
    # a swinging sole that touches down early (loaded again after it lifted): the admittance answers the stance
    # sole's CoP alone
    if support == LEFT_SUPPORT and loaded0 and state[S.lifted + 1] > 0.0:
        zmx, zmy = cop0x, cop0y
    elif support == RIGHT_SUPPORT and loaded1 and state[S.lifted] > 0.0:
        zmx, zmy = cop1x, cop1y
    offset = com_admittance(params, state, log, loaded0 or loaded1, (zmx, zmy), (pdx, pdy), -(slope_x + whole_x),
                            -(slope_y + whole_y), support, yaw)
    shares = distribute(pdx, pdy, support, c0[0], c0[1], c1[0], c1[1])
    ankle_damping(params, state, log, loaded0, loaded1, shares, (cop0x, cop0y, cop1x, cop1y), yaw_left, yaw_right)
    height = foot_force_difference(params, state, log, support, f0, f1, loaded0, loaded1, shares[0], shares[1])
    turn = torso_attitude(params, log, attitude, rate)
    landing_and_stepping(params, state, rot, support, anchor, a0 if anchor == 0 else a1, p0, p1, ankle_left,
                         ankle_right, yaw, heading, (offset[0], offset[1], ex, ey), turn, (f0, f1), loaded0, loaded1)
    joint_corrections(state, chain, work, targets, reference, p0, p1, offset, yaw, (yaw_left, yaw_right), height,
                      turn)
    servo_outer_loop(params, targets, encoders)
    return 0


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY


# the tick's cached code holds its callees': renew it all where a module or the layout changed since it was built
renew_stale((rotations, leg, estimation, loops, landing, joints, sys.modules[__name__]))

__all__ = ["AIRBORNE_AIM", "BAD_SUPPORT", "INPUT_SIZES", "LOG_SIZE", "PARAMETERS", "P_ANKLE_OFFSET", "SINGULAR_LEG",
           "SINGULAR_PIVOT", "STATE_SIZE", "TICK_SIGNATURE", "L", "P", "S", "ankle_in_base", "distribute",
           "initial_state", "leg_jacobian", "leg_kinematics", "lu6", "lu_solve6", "tick"]
