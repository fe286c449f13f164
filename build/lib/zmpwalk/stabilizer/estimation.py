# mypy: disallow-untyped-decorators=False
r"""What the compiled stabilizer measures each tick (numba, cached on disk): where the soles are (leg odometry), the
floor's slope under them, the CoM and its velocity, and the measured ZMP.

The estimates of :mod:`zmpwalk.balance`'s steps 1 and 7: the CoM from the encoders' leg kinematics tilted by the
IMU, anchored at the sole that has carried load the longest, whose place in world comes from leg odometry; the
floor's normal from both soles' attitude in double support; each loaded sole's CoP from its force-torque sensor.
Each function reads and writes only its own entries of ``state`` (:data:`zmpwalk.stabilizer.layout.S`) and
``log`` (:data:`zmpwalk.stabilizer.layout.L`); ``rot`` is the torso's rotation in world (9, row-major).

*base* is the torso (pelvis) frame, x forward, y left, z up; *world* is the walk's frame, z up against gravity.
Every position is in metres, every angle in radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from zmpwalk.stabilizer.freshness import BUILD_KEY
from zmpwalk.stabilizer.layout import L, P, S
from zmpwalk.stabilizer.leg import FIRST, SECOND, ankle_in_base, com_in_base, leg_kinematics, sole_normal
from zmpwalk.stabilizer.rotations import rotate2, rotate3, rotation_zyx

Vector3 = tuple[float, float, float]


@njit(cache=True, nogil=True, inline="always")
def reference_velocity(params: np.ndarray, state: np.ndarray, com: np.ndarray) -> tuple[float, float]:
    """The pattern's CoM velocity [m/s] by the difference of its CoM points (none at the first tick)."""
    dt = params[P.dt]
    rx, ry = com[0], com[1]
    if not state[S.started] > 0.0:
        state[S.previous_reference], state[S.previous_reference + 1] = rx, ry
    vrx = (rx - state[S.previous_reference]) / dt
    vry = (ry - state[S.previous_reference + 1]) / dt
    state[S.previous_reference], state[S.previous_reference + 1] = rx, ry
    return vrx, vry


@njit(cache=True, nogil=True, inline="always")
def measured_legs(params: np.ndarray, chain: np.ndarray, work: np.ndarray, encoders: np.ndarray, heading: float,
                  attitude: np.ndarray) -> tuple[Vector3, Vector3, Vector3, Vector3, Vector3]:
    """The measured legs (``work[0]``, ``work[2]``) and the torso's rotation in world (``work[4, 6, 0:9]``) from
    the encoders, the IMU's roll and pitch and the ``heading`` [rad]: each measured ankle in the base frame, the
    whole-body CoM in the base frame, and each sole's normal in the base frame."""
    leg_kinematics(chain, FIRST, encoders, work[0])
    leg_kinematics(chain, SECOND, encoders, work[2])
    rotation_zyx(heading, attitude[1], attitude[0], work[4, 6, 0:9])
    a0 = ankle_in_base(params, FIRST, work[0])
    a1 = ankle_in_base(params, SECOND, work[2])
    com = com_in_base(params, chain, work, FIRST)
    # each measured sole's normal (its sole frame's z axis)
    return a0, a1, com, sole_normal(params, FIRST, work[0]), sole_normal(params, SECOND, work[2])


@njit(cache=True, nogil=True, inline="always")
def leg_odometry(params: np.ndarray, state: np.ndarray, rot: np.ndarray, a0: Vector3, a1: Vector3, n0: Vector3,
                 n1: Vector3, ankle_left: np.ndarray, ankle_right: np.ndarray, f0: float, f1: float, loaded0: bool,
                 loaded1: bool) -> int:
    """Leg odometry: the sole that has carried load the longest is the reference (the anchor, returned: 0 left,
    1 right; see :mod:`zmpwalk.balance`, step 1). While it rolls on an edge its ankle moves by the ankle height
    times the change of its normal's horizontal part (``n0``, ``n1`` in world); the other sole is placed from it by
    the measured ankles ``a0``, ``a1`` (base) while both carry load, or when it takes the load alone. The first tick
    starts at the planned ankles."""
    h = params[P.ankle_height]
    if not state[S.started] > 0.0:
        state[S.sole_normals], state[S.sole_normals + 1] = n0[0], n0[1]
        state[S.sole_normals + 2], state[S.sole_normals + 3] = n1[0], n1[1]
        for i in range(3):
            state[S.previous_relative + i] = a0[i]
            state[S.previous_relative + 3 + i] = a1[i]
        state[S.feet], state[S.feet + 1] = ankle_left[0], ankle_left[1]
        state[S.feet + 2], state[S.feet + 3] = ankle_right[0], ankle_right[1]
        state[S.anchor] = 0.0 if f0 >= f1 else 1.0
        state[S.started] = 1.0
    anchor = int(state[S.anchor])
    if loaded0 if anchor == 0 else loaded1:
        now = n0 if anchor == 0 else n1
        o = S.sole_normals + 2 * anchor
        state[S.feet + 2 * anchor] += h * (now[0] - state[o])
        state[S.feet + 2 * anchor + 1] += h * (now[1] - state[o + 1])
    state[S.sole_normals], state[S.sole_normals + 1] = n0[0], n0[1]
    state[S.sole_normals + 2], state[S.sole_normals + 3] = n1[0], n1[1]
    ra = a0 if anchor == 0 else a1  # the anchor's measured ankle in the base
    ro = a1 if anchor == 0 else a0
    loaded_now = 0 if loaded0 else 1
    if (loaded0 and loaded1) or (loaded0 != loaded1 and loaded_now != anchor):
        d = rotate3(rot, ro[0] - ra[0], ro[1] - ra[1], ro[2] - ra[2])
        state[S.feet + 2 * (1 - anchor)] = state[S.feet + 2 * anchor] + d[0]
        state[S.feet + 2 * (1 - anchor) + 1] = state[S.feet + 2 * anchor + 1] + d[1]
    if loaded0 != loaded1:
        anchor = loaded_now
        state[S.anchor] = float(anchor)
    return anchor


@njit(cache=True, nogil=True, inline="always")
def floor_slope(params: np.ndarray, state: np.ndarray, log: np.ndarray, rot: np.ndarray, s0: Vector3, s1: Vector3,
                loaded0: bool, loaded1: bool) -> tuple[float, float]:
    """Floor slope (:mod:`zmpwalk.balance`, step 7): with both soles down, both lie flat on the floor, so their mean
    normal (``s0``, ``s1`` in the base frame, tilted by the IMU) low-pass filtered is the floor's ``n``. Returns
    the CoM's offset uphill ``l (n_x, n_y) / n_z`` [m], no longer than the gain ``com_limit`` (0 with the gain
    ``slope_time_constant`` 0)."""
    slope_on = params[P.slope_time_constant] > 0.0
    if slope_on and loaded0 and loaded1:  # both soles down: both flat on the floor
        m_n = rotate3(rot, (s0[0] + s1[0]) / 2, (s0[1] + s1[1]) / 2, (s0[2] + s1[2]) / 2)
        beta = params[P.dt] / (params[P.slope_time_constant] + params[P.dt])
        for i in range(3):
            state[S.floor_normal + i] += beta * (m_n[i] - state[S.floor_normal + i])
    nx, ny, nz = state[S.floor_normal], state[S.floor_normal + 1], state[S.floor_normal + 2]
    length = params[P.pendulum_length]
    slope_x = length * nx / nz if slope_on else 0.0
    slope_y = length * ny / nz if slope_on else 0.0
    slope_norm = math.hypot(slope_x, slope_y)
    com_limit = params[P.com_limit]
    if slope_norm > com_limit:
        slope_x, slope_y = slope_x * com_limit / slope_norm, slope_y * com_limit / slope_norm
    log[L.slope_offset], log[L.slope_offset + 1] = -slope_x, -slope_y
    return slope_x, slope_y


@njit(cache=True, nogil=True, inline="always")
def com_estimate(params: np.ndarray, state: np.ndarray, rot: np.ndarray, com: Vector3, a0: Vector3, a1: Vector3,
                 anchor: int, rate: np.ndarray) -> tuple[float, float, float, float, float, float]:
    """The CoM in world [m] from the anchor sole's place (:func:`leg_odometry`) and the measured legs (``com`` and
    the ankles ``a0``, ``a1`` in the base frame); its velocity, low-pass filtered (the gain ``velocity_filter``),
    into the state. Returns the CoM's x, y and where the left and the right ankle are (x, y each): the swing foot
    follows from the stance foot and the kinematics."""
    ra = a0 if anchor == 0 else a1
    ro = a1 if anchor == 0 else a0
    anchor_x, anchor_y = state[S.feet + 2 * anchor], state[S.feet + 2 * anchor + 1]
    arm = rotate3(rot, com[0] - ra[0], com[1] - ra[1], com[2] - ra[2])
    cx, cy = anchor_x + arm[0], anchor_y + arm[1]
    other = rotate3(rot, ro[0] - ra[0], ro[1] - ra[1], ro[2] - ra[2])
    if anchor == 0:
        left_x, left_y, right_x, right_y = anchor_x, anchor_y, anchor_x + other[0], anchor_y + other[1]
    else:
        left_x, left_y, right_x, right_y = anchor_x + other[0], anchor_y + other[1], anchor_x, anchor_y
    dt = params[P.dt]
    o = S.previous_relative + 3 * anchor
    previous_arm = rotate3(rot, com[0] - state[o], com[1] - state[o + 1], com[2] - state[o + 2])
    spin = rotate3(rot, rate[0], rate[1], rate[2])
    raw_vx = (arm[0] - previous_arm[0]) / dt + (spin[1] * arm[2] - spin[2] * arm[1])
    raw_vy = (arm[1] - previous_arm[1]) / dt + (spin[2] * arm[0] - spin[0] * arm[2])
    for i in range(3):
        state[S.previous_relative + i] = a0[i]
        state[S.previous_relative + 3 + i] = a1[i]
    alpha = dt / (params[P.velocity_filter] + dt)
    state[S.com_velocity] += alpha * (raw_vx - state[S.com_velocity])
    state[S.com_velocity + 1] += alpha * (raw_vy - state[S.com_velocity + 1])
    return cx, cy, left_x, left_y, right_x, right_y


@njit(cache=True, nogil=True, inline="always")
def sole_centre(params: np.ndarray, foot: int, fx: float, fy: float, yaw: float) -> tuple[float, float]:
    """The centre of the sole of ``foot`` (0 left, 1 right) whose ankle is at ``(fx, fy)`` with ``yaw``."""
    side = 1.0 if foot == 0 else -1.0
    ox, oy = rotate2(params[P.sole_center_x], side * params[P.sole_center_y], yaw)
    return fx + ox, fy + oy


@njit(cache=True, nogil=True, inline="always")
def sole_cop(wrench: np.ndarray, ankle_height: float, x: float, y: float, yaw: float) -> tuple[float, float]:
    """The centre of pressure in world [m] of a loaded sole whose ankle is at ``(x, y)`` with ``yaw``, from the
    ground's wrench on the foot about the ankle, in the foot frame (force [N], torque [N m]): the point on the
    sole (``ankle_height`` below the ankle) where the torque's horizontal part vanishes."""
    lx, ly = rotate2(-(wrench[4] + ankle_height * wrench[0]) / wrench[2],
                     (wrench[3] - ankle_height * wrench[1]) / wrench[2], yaw)
    return x + lx, y + ly


@njit(cache=True, nogil=True, inline="always")
def measured_zmp(params: np.ndarray, log: np.ndarray, wrench_left: np.ndarray, wrench_right: np.ndarray,
                 loaded0: bool, loaded1: bool, feet: tuple[float, float, float, float], yaw_left: float,
                 yaw_right: float) -> tuple[float, float, float, float, float, float]:
    """Each loaded sole's CoP (0 for a bare one) and the measured ZMP, their mean weighted by the normal forces
    (nan with no sole loaded), in world [m], from the ankles ``feet`` (left x, y, right x, y) and the foot yaws:
    (CoP left x, y, CoP right x, y, ZMP x, y)."""
    h = params[P.ankle_height]
    f0, f1 = wrench_left[2], wrench_right[2]
    cop0x = cop0y = cop1x = cop1y = 0.0
    if loaded0:
        cop0x, cop0y = sole_cop(wrench_left, h, feet[0], feet[1], yaw_left)
    if loaded1:
        cop1x, cop1y = sole_cop(wrench_right, h, feet[2], feet[3], yaw_right)
    zmx = zmy = math.nan
    if loaded0 or loaded1:
        w0 = f0 if loaded0 else 0.0
        w1 = f1 if loaded1 else 0.0
        zmx = (w0 * cop0x + w1 * cop1x) / (w0 + w1)
        zmy = (w0 * cop0y + w1 * cop1y) / (w0 + w1)
    log[L.zmp_measured], log[L.zmp_measured + 1] = zmx, zmy
    return cop0x, cop0y, cop1x, cop1y, zmx, zmy


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY
