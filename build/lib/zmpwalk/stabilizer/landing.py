# mypy: disallow-untyped-decorators=False
r"""Landing and stepping, compiled (numba, cached on disk): where the stabilizer aims each swinging foot
(:mod:`zmpwalk.balance`, step 6).

The swinging foot aims at its planned place in world from the odometry's base, seen through the measured pelvis
attitude, moved by the gain ``step_gain`` times the DCM error beyond ``step_deadband``, towards where the body falls
(the capture point of Pratt et al. 2006), and turns by the torso's measured yaw error (within
``landing_yaw_limit``) so that it lands at its planned heading in world; it never steps across the stance foot
(``feet_clearance``). With ``landing_height_limit`` above 0 it also aims at its planned height above the stance
sole, on the floor's estimated plane, plus the stance sole's compression ``(f / k)^(1/e)`` under its measured
force. The corrections are released (``landing_release``) once the plan puts the foot down, unless its sole has
carried no load for over :data:`AIRBORNE_AIM` (a late touchdown). They live in ``state``
(:data:`zmpwalk.stabilizer.layout.S`: ``landing``, ``landing_yaw``, ``landing_height``, ``airborne``).

Positions are in metres, world x forward, y left, z up; angles in radians; ``rot`` is the torso's rotation in
world (9, row-major); the planned ankles ``p0``, ``p1`` are in the base frame (the torso's).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from zmpwalk.stabilizer.freshness import BUILD_KEY
from zmpwalk.stabilizer.layout import LEFT_SUPPORT, RIGHT_SUPPORT, P, S
from zmpwalk.stabilizer.rotations import clip, rotate2, rotate3, rotate3_back

AIRBORNE_AIM = 0.02  # [s] a sole the plan has down that has carried no load this long keeps its landing aim
Vector3 = tuple[float, float, float]


@njit(cache=True, nogil=True, inline="always")
def capture_step(params: np.ndarray, ex: float, ey: float) -> tuple[float, float]:
    """The step towards where the body falls [m]: the gain ``step_gain`` times the DCM error ``(ex, ey)`` [m]
    beyond ``step_deadband`` (Pratt et al. 2006: 1 puts the foot on the capture point)."""
    error_norm = math.hypot(ex, ey)
    step = (params[P.step_gain] * max(error_norm - params[P.step_deadband], 0.0) / error_norm if error_norm > 0.0
            else 0.0)
    return step * ex, step * ey


@njit(cache=True, nogil=True, inline="always")
def landing_height(params: np.ndarray, state: np.ndarray, foot: int, rot: np.ndarray, world: np.ndarray,
                   planned: Vector3, planned_anchor: np.ndarray, stance: Vector3, base: tuple[float, float],
                   anchor: tuple[float, float], stance_force: float, turn: tuple[float, float]) -> None:
    """The swinging foot's height correction [m] towards its planned height (``world``, the planned ankle in world;
    ``planned``, in the base frame) above the stance sole (the odometry's reference ``anchor`` in world and
    ``stance`` in the base frame, its planned ankle ``planned_anchor``), on the floor's estimated plane, from the
    measured base (its origin ``base`` in world); less the pelvis turn's (roll, pitch) share, which every foot
    gets."""
    nx, ny, nz = state[S.floor_normal], state[S.floor_normal + 1], state[S.floor_normal + 2]
    rise = -(nx * (world[0] - anchor[0]) + ny * (world[1] - anchor[1])) / nz
    above = world[2] - planned_anchor[2] + rise + stance[2]
    if params[P.sole_stiffness] > 0.0 and stance_force > 0.0:  # the stance sole is pressed into the floor
        above += (stance_force / params[P.sole_stiffness]) ** (1.0 / params[P.sole_exponent])
    seen_z = rot[2] * (world[0] - base[0]) + rot[5] * (world[1] - base[1]) + rot[8] * above
    aim_z = seen_z - planned[2] + turn[0] * planned[1] - turn[1] * planned[0]
    o = S.landing_height + foot
    state[o] += params[P.dt] / params[P.landing_time_constant] * (aim_z - state[o])
    state[o] = clip(state[o], params[P.landing_height_limit])


@njit(cache=True, nogil=True, inline="always")
def keep_clear(params: np.ndarray, state: np.ndarray, foot: int, p0: Vector3, p1: Vector3, yaw: float) -> None:
    """No step across the stance foot: the soles' inner edges keep the gain ``feet_clearance`` between them (the
    correction's part across the pelvis, whose yaw is ``yaw``; the planned feet relative to the pelvis from the
    reference)."""
    o = S.landing + 2 * foot
    swing, stance_ankle = (p0, p1) if foot == 0 else (p1, p0)
    side = 1.0 if foot == 0 else -1.0
    least = params[P.half_width] * 2.0 - 2.0 * params[P.sole_center_y] + params[P.feet_clearance]
    along, across = rotate2(state[o], state[o + 1], -yaw)
    planned_gap = side * (swing[1] - stance_ankle[1])
    if planned_gap + side * across < least:
        across = side * (least - planned_gap)
        state[o], state[o + 1] = rotate2(along, across, yaw)


@njit(cache=True, nogil=True, inline="always")
def landing_and_stepping(params: np.ndarray, state: np.ndarray, rot: np.ndarray, support: int, anchor: int,
                         ra: Vector3, p0: Vector3, p1: Vector3, ankle_left: np.ndarray, ankle_right: np.ndarray,
                         yaw: float, heading: float, shift: tuple[float, float, float, float],
                         turn: tuple[float, float], forces: tuple[float, float], loaded0: bool, loaded1: bool) -> None:
    """Each foot's landing corrections in world for one tick (the module docstring): ``ra`` is the anchor sole's
    measured ankle in the base frame, ``ankle_left`` and ``ankle_right`` the planned ankles in world, ``yaw`` and
    ``heading`` the pattern's and the measured torso yaw [rad], ``shift`` the CoM offset and the DCM error (x, y
    each) [m], ``turn`` the pelvis turn (roll, pitch) [rad], ``forces`` the soles' normal forces [N]."""
    dt = params[P.dt]
    stance = rotate3(rot, ra[0], ra[1], ra[2])
    anchor_x, anchor_y = state[S.feet + 2 * anchor], state[S.feet + 2 * anchor + 1]
    base_ex, base_ey = anchor_x - stance[0], anchor_y - stance[1]
    planned_anchor = ankle_left if anchor == 0 else ankle_right
    step_x, step_y = capture_step(params, shift[2], shift[3])
    landing_rate, release_rate = dt / params[P.landing_time_constant], dt / params[P.landing_release]
    turn_yaw = yaw - heading
    turn_yaw -= 2.0 * math.pi * round(turn_yaw / (2.0 * math.pi))  # math.remainder(turn_yaw, tau)
    yaw_aim = clip(turn_yaw, params[P.landing_yaw_limit])
    for foot in range(2):
        o = S.landing + 2 * foot
        swinging = (support == LEFT_SUPPORT and foot == 1) or (support == RIGHT_SUPPORT and foot == 0)
        loaded = loaded0 if foot == 0 else loaded1
        state[S.airborne + foot] = 0.0 if loaded else state[S.airborne + foot] + dt
        # a sole the plan has put down that has not touched down yet (a late touchdown) keeps aiming
        aiming = swinging or state[S.airborne + foot] > AIRBORNE_AIM
        oy = S.landing_yaw + foot
        if aiming:
            state[oy] += landing_rate * (yaw_aim - state[oy])
        else:
            state[oy] += -release_rate * state[oy]
        if aiming:
            planned = p0 if foot == 0 else p1
            world = ankle_left if foot == 0 else ankle_right
            seen = rotate3_back(rot, world[0] - base_ex, world[1] - base_ey, planned[2])
            aim = rotate2(seen[0] - planned[0] + turn[1] * planned[2], seen[1] - planned[1] - turn[0] * planned[2],
                          yaw)
            state[o] += landing_rate * (aim[0] + shift[0] + step_x - state[o])
            state[o + 1] += landing_rate * (aim[1] + shift[1] + step_y - state[o + 1])
            if params[P.landing_height_limit] > 0.0 and anchor != foot:
                landing_height(params, state, foot, rot, world, planned, planned_anchor, stance, (base_ex, base_ey),
                               (anchor_x, anchor_y), forces[anchor], turn)
        else:
            state[o] -= release_rate * state[o]
            state[o + 1] -= release_rate * state[o + 1]
            state[S.landing_height + foot] -= release_rate * state[S.landing_height + foot]
        state[o] = clip(state[o], params[P.landing_limit])
        state[o + 1] = clip(state[o + 1], params[P.landing_limit])
        if aiming:
            keep_clear(params, state, foot, p0, p1, yaw)


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY
