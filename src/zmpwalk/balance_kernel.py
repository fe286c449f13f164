r"""The stabilizer's tick, compiled: :class:`zmpwalk.balance.Stabilizer` calls :func:`tick` once per control tick.

The loops and their equations are those of :mod:`zmpwalk.balance` (its docstring numbers them 1-8). Here they run
on plain float64 arrays, compiled by numba ahead of the first call and cached on disk, so that a tick costs
microseconds and allocates nothing: every intermediate lives in the ``work`` array given by the caller.

Arrays (all float64):

- ``params`` (:data:`PARAMETERS`): the gains, the robot's constants and each leg servo's outer-loop gain.
- ``chain`` (2, 6, 11): per leg (left, right) and chain joint: the joint's axis (0:3) and a point on it (3:6) in
  the base frame at zero angles, its link's CoM (6:9) in that frame, the link's mass (9), and the joint's column
  among the leg's 6 role-ordered columns (10) (:data:`zmpwalk.kinematics.JOINT_COLUMNS`).
- ``state`` (:data:`STATE_SIZE`): the filters and offsets that carry from tick to tick (layout below).
- ``log`` (:data:`LOG_SIZE`): what :class:`zmpwalk.balance.BalanceState` shows (views into it).
- ``work`` (6, 7, 12): scratch. ``work[pose]`` for the four poses (left measured, left reference, right
  measured, right reference) holds the product of exponentials: each of the leg's 7 frames' rotation (row-major,
  0:9) and translation (9:12) in the base frame. ``work[4]`` holds the LU factors of the left and right leg's
  Jacobians at the reference (rows 0:6, columns 0:6 and 6:12) and the torso's rotation in world (row 6, 0:9);
  ``work[5]`` the factors' row swaps (row 0, 0:6 and 6:12) and a leg's foot correction (row 1, 0:6).

A five-joint leg's chain (:mod:`zmpwalk.leg_chain`) carries its virtual ankle roll as a sixth joint: its Jacobian
stays 6 x 6 and invertible, and the change the solve gives that joint is sent nowhere (the plant has no joint
there, :mod:`zmpwalk.sim.plant`); its measured angle is 0. What the five real joints then do is the correction less
a roll of the sole about its centre line, the one motion they cannot make (:mod:`zmpwalk.balance`, "Five-joint
legs").

The frames: *base* is the torso (pelvis) frame, x forward, y left, z up; *world* is the walk's frame, z up against
gravity. Every position is in metres, every angle in radians.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MIN_SHARE = 1e-9  # [-] a sole's share of the desired ZMP below which its CoP is not controlled

# --- params: the gains (zmpwalk.balance.StabilizerGains), then the robot's constants
P_DCM = 0
P_COM_ADMITTANCE = 1
P_COM_STIFFNESS = 2
P_COM_DAMPING = 3
P_COM_LIMIT = 4
P_ANKLE_GAIN = 5
P_ANKLE_TIME_CONSTANT = 6
P_ANKLE_LIMIT = 7
P_FORCE_GAIN = 8
P_FORCE_TIME_CONSTANT = 9
P_FORCE_LIMIT = 10
P_ATTITUDE_GAIN = 11
P_ATTITUDE_DAMPING = 12
P_ATTITUDE_LIMIT = 13
P_ZMP_MARGIN = 14
P_VELOCITY_FILTER = 15
P_LANDING_TIME_CONSTANT = 16
P_LANDING_RELEASE = 17
P_LANDING_LIMIT = 18
P_SLOPE_TIME_CONSTANT = 19
P_STEP_GAIN = 20
P_STEP_DEADBAND = 21
P_LANDING_YAW_LIMIT = 22
P_DT = 23  # [s] control period
P_OMEGA = 24  # [1/s] sqrt(g / l)
P_MASS = 25  # [kg]
P_REST_MOMENT = 26  # (3) mass times CoM of everything but the legs, in the base frame [kg m]
P_HALF_LENGTH = 29  # [m] of the sole
P_HALF_WIDTH = 30  # [m]
P_ANKLE_HEIGHT = 31  # [m]
P_PENDULUM_LENGTH = 32  # [m]
P_SOLE_CENTER_X = 33  # [m] the sole's centre ahead of the ankle
P_SOLE_CENTER_Y = 34  # [m] outwards of the left ankle (mirrored for the right)
P_LOAD_THRESHOLD = 35  # [N] a sole carries load above this normal force
P_ANKLE_OFFSET = 36  # (2, 3) the ankle point in the last frame of each leg [m]
P_SERVO_GAIN = 42  # (12) outer-loop gain per joint column [-]
P_STIFFEN = 54  # 1 when any servo gets the outer loop
P_FEET_CLEARANCE = 55  # [m] the gain feet_clearance
P_TOUCHDOWN_SPEED = 56  # [m/s] the gain touchdown_speed
P_LANDING_HEIGHT_LIMIT = 57  # [m] the gain landing_height_limit
P_SOLE_STIFFNESS = 58  # [N/m^e] k of the sole's contact law f = k x^e (0: a rigid sole)
P_SOLE_EXPONENT = 59  # [-] e
P_WHOLE_BODY_REST = 60  # [-] the gain whole_body_rest where the CoM input is a pelvis point, else 0
P_SOLE_NORMAL = 61  # (2, 3) each sole's normal in the last frame of its leg (the sole frame's z axis) [-]
PARAMETERS = 67
GAIN_NAMES = ("dcm", "com_admittance", "com_stiffness", "com_damping", "com_limit", "ankle_gain",
              "ankle_time_constant", "ankle_limit", "force_gain", "force_time_constant", "force_limit",
              "attitude_gain", "attitude_damping", "attitude_limit", "zmp_margin", "velocity_filter",
              "landing_time_constant", "landing_release", "landing_limit", "slope_time_constant", "step_gain",
              "step_deadband", "landing_yaw_limit")  # params[0:23] in this order

# --- state
S_STARTED = 0
S_PREVIOUS_REFERENCE = 1  # (2) the CoM reference of the last tick [m]
S_PREVIOUS_RELATIVE = 3  # (2, 3) each measured ankle in the base frame, last tick [m]
S_COM_VELOCITY = 9  # (2) filtered [m/s]
S_OFFSET = 11  # (2) CoM admittance offset [m]
S_OFFSET_RATE = 13  # (2) [m/s]
S_ANKLE = 15  # (2, 2) foot turns (roll, pitch) [rad]
S_HEIGHT = 19  # height difference [m]
S_FEET = 20  # (2, 2) estimated ankles in world (leg odometry) [m]
S_LANDING = 24  # (2, 2) landing corrections in world [m]
S_LANDING_YAW = 28  # (2) [rad]
S_ANCHOR = 30  # the reference sole of the odometry (0 left, 1 right)
S_FLOOR_NORMAL = 31  # (3) filtered, in world
S_SOLE_NORMALS = 34  # (2, 2) horizontal parts of each sole's normal in world, last tick
S_LANDING_HEIGHT = 38  # (2) height corrections of the swinging feet [m]
S_LIFTED = 40  # (2) 1 once the swinging sole has carried no load in this single support
S_AIRBORNE = 42  # (2) how long each sole has carried no load, up to this tick [s]
STATE_SIZE = 44

# --- log (zmpwalk.balance.BalanceState)
L_ZMP_DESIRED = 0  # (2)
L_ZMP_MEASURED = 2  # (2)
L_DCM_ERROR = 4  # (2)
L_COM_OFFSET = 6  # (2)
L_ANKLE_OFFSETS = 8  # (2, 2)
L_HEIGHT_DIFFERENCE = 12
L_PELVIS_TURN = 13  # (2)
L_SLOPE_OFFSET = 15  # (2)
L_WHOLE_BODY_OFFSET = 17  # (2)
LOG_SIZE = 19

# --- what tick() returns besides 0: 1 + the index of a vector input with too few values (in the order of the
# arguments: com, zmp, ankle_left, ankle_right, reference, wrench_left, wrench_right, attitude, rate, encoders),
# or BAD_SUPPORT, or SINGULAR_LEG + leg (0 left, 1 right)
INPUT_SIZES = (3, 2, 3, 3, 12, 6, 6, 2, 3, 12)  # the vector inputs' lengths, in that order
BAD_SUPPORT = 11
SINGULAR_LEG = 12
AIRBORNE_AIM = 0.02  # [s] a sole the plan has down that has carried no load this long keeps its landing aim
SINGULAR_PIVOT = 1e-6  # [m] or [-]: a smaller pivot of a leg's Jacobian (a straight knee) is a singular posture


def initial_state(state: np.ndarray, log: np.ndarray) -> None:
    """Reset ``state`` and ``log`` in place (the next tick starts from the reference)."""
    state[:] = 0.0
    state[S_FLOOR_NORMAL + 2] = 1.0
    log[:] = 0.0
    log[L_ZMP_MEASURED:L_ZMP_MEASURED + 2] = math.nan


@njit(cache=True, nogil=True)
def rotate2(x: float, y: float, angle: float) -> tuple[float, float]:
    """``(x, y)`` turned by ``angle`` [rad] about z."""
    c, s = math.cos(angle), math.sin(angle)
    return c * x - s * y, s * x + c * y


@njit(cache=True, nogil=True)
def leg_kinematics(chain: np.ndarray, leg: int, columns: np.ndarray, frames: np.ndarray) -> None:
    """Product of exponentials of one leg: its 7 frames (7, 12) for the angles ``columns`` (12, role-ordered
    columns of both legs [rad]).

    .. math:: e^{\\hat\\xi q} x = R x + (I - R) r, \\quad R = I + \\sin q\\, K + (1 - \\cos q) K^2,
        \\quad (I - R) r = -\\sin q\\, K r - (1 - \\cos q) K^2 r

    with ``K`` the skew matrix of the joint's axis and ``r`` a point on it; frame ``i + 1`` is frame ``i``
    composed with joint ``i``.
    """
    for m in range(12):
        frames[0, m] = 0.0
    frames[0, 0] = frames[0, 4] = frames[0, 8] = 1.0
    for i in range(6):
        ax, ay, az = chain[leg, i, 0], chain[leg, i, 1], chain[leg, i, 2]
        px, py, pz = chain[leg, i, 3], chain[leg, i, 4], chain[leg, i, 5]
        q = columns[6 * leg + int(chain[leg, i, 10])]
        s, v = math.sin(q), 1.0 - math.cos(q)
        # K and K^2 (K^2 = a a^T - |a|^2 I)
        k00, k01, k02, k10, k11, k12, k20, k21, k22 = 0.0, -az, ay, az, 0.0, -ax, -ay, ax, 0.0
        q00 = k01 * k10 + k02 * k20
        q01 = k02 * k21
        q02 = k01 * k12
        q10 = k12 * k20
        q11 = k10 * k01 + k12 * k21
        q12 = k10 * k02
        q20 = k21 * k10
        q21 = k20 * k01
        q22 = k20 * k02 + k21 * k12
        j00, j01, j02 = 1.0 + s * k00 + v * q00, s * k01 + v * q01, s * k02 + v * q02
        j10, j11, j12 = s * k10 + v * q10, 1.0 + s * k11 + v * q11, s * k12 + v * q12
        j20, j21, j22 = s * k20 + v * q20, s * k21 + v * q21, 1.0 + s * k22 + v * q22
        # (I - R) r
        kr0, kr1, kr2 = k01 * py + k02 * pz, k10 * px + k12 * pz, k20 * px + k21 * py
        qr0 = q00 * px + q01 * py + q02 * pz
        qr1 = q10 * px + q11 * py + q12 * pz
        qr2 = q20 * px + q21 * py + q22 * pz
        d0, d1, d2 = -(s * kr0 + v * qr0), -(s * kr1 + v * qr1), -(s * kr2 + v * qr2)
        f = frames[i]
        g = frames[i + 1]
        for row in range(3):
            r0, r1, r2 = f[3 * row], f[3 * row + 1], f[3 * row + 2]
            g[3 * row] = r0 * j00 + r1 * j10 + r2 * j20
            g[3 * row + 1] = r0 * j01 + r1 * j11 + r2 * j21
            g[3 * row + 2] = r0 * j02 + r1 * j12 + r2 * j22
            g[9 + row] = f[9 + row] + r0 * d0 + r1 * d1 + r2 * d2


@njit(cache=True, nogil=True)
def com_in_base(params: np.ndarray, chain: np.ndarray, work: np.ndarray, planned: int) -> tuple[float, float, float]:
    """The whole-body CoM in the base frame [m] from the legs' frames in ``work`` (:func:`leg_kinematics`'s:
    the measured legs' for ``planned`` 0, the pattern's for 1) and the rest of the body."""
    mx, my, mz = params[P_REST_MOMENT], params[P_REST_MOMENT + 1], params[P_REST_MOMENT + 2]
    for leg in range(2):
        frames = work[2 * leg + planned]
        for i in range(6):
            f = frames[i + 1]
            cx, cy, cz = chain[leg, i, 6], chain[leg, i, 7], chain[leg, i, 8]
            mass = chain[leg, i, 9]
            mx += mass * (f[0] * cx + f[1] * cy + f[2] * cz + f[9])
            my += mass * (f[3] * cx + f[4] * cy + f[5] * cz + f[10])
            mz += mass * (f[6] * cx + f[7] * cy + f[8] * cz + f[11])
    total = params[P_MASS]
    return mx / total, my / total, mz / total


@njit(cache=True, nogil=True)
def ankle_in_base(params: np.ndarray, leg: int, frames: np.ndarray) -> tuple[float, float, float]:
    """The ankle point of the leg's last frame, in the base frame [m]."""
    f = frames[6]
    o = P_ANKLE_OFFSET + 3 * leg
    x, y, z = params[o], params[o + 1], params[o + 2]
    return (f[9] + f[0] * x + f[1] * y + f[2] * z, f[10] + f[3] * x + f[4] * y + f[5] * z,
            f[11] + f[6] * x + f[7] * y + f[8] * z)


@njit(cache=True, nogil=True)
def sole_normal(params: np.ndarray, leg: int, frames: np.ndarray) -> tuple[float, float, float]:
    """The leg's sole normal in the base frame: the last frame's rotation times the sole frame's z axis
    (:attr:`zmpwalk.leg_chain.LegChain.sole_rotation`; the last frame's own z axis where the sole is level at zero
    angles)."""
    f = frames[6]
    o = P_SOLE_NORMAL + 3 * leg
    x, y, z = params[o], params[o + 1], params[o + 2]
    return f[0] * x + f[1] * y + f[2] * z, f[3] * x + f[4] * y + f[5] * z, f[6] * x + f[7] * y + f[8] * z


@njit(cache=True, nogil=True)
def leg_jacobian(chain: np.ndarray, leg: int, frames: np.ndarray, ankle: tuple[float, float, float],
                 jacobian: np.ndarray) -> None:
    """Geometric Jacobian (6, 6) of the ankle point in the base frame, rows (v, omega), columns the chain's joints
    (:meth:`zmpwalk.leg_chain.LegChain.jacobian`): column ``i`` is ``(a_i x (p - o_i), a_i)``."""
    for i in range(6):
        f = frames[i]
        ax, ay, az = chain[leg, i, 0], chain[leg, i, 1], chain[leg, i, 2]
        px, py, pz = chain[leg, i, 3], chain[leg, i, 4], chain[leg, i, 5]
        wx = f[0] * ax + f[1] * ay + f[2] * az
        wy = f[3] * ax + f[4] * ay + f[5] * az
        wz = f[6] * ax + f[7] * ay + f[8] * az
        ox = f[0] * px + f[1] * py + f[2] * pz + f[9]
        oy = f[3] * px + f[4] * py + f[5] * pz + f[10]
        oz = f[6] * px + f[7] * py + f[8] * pz + f[11]
        rx, ry, rz = ankle[0] - ox, ankle[1] - oy, ankle[2] - oz
        jacobian[0, i] = wy * rz - wz * ry
        jacobian[1, i] = wz * rx - wx * rz
        jacobian[2, i] = wx * ry - wy * rx
        jacobian[3, i] = wx
        jacobian[4, i] = wy
        jacobian[5, i] = wz


@njit(cache=True, nogil=True)
def lu6(a: np.ndarray, swaps: np.ndarray) -> float:
    """``a`` (6, 6) <- its LU factors by Gaussian elimination with partial pivoting (``P a = L U``, the unit
    ``L``'s multipliers below the diagonal), the row swapped into place at each column in ``swaps`` (6);
    returns the smallest pivot's magnitude (0 for a singular ``a``, and the factoring stops there)."""
    least = math.inf
    for col in range(6):
        pivot = col
        for row in range(col + 1, 6):
            if abs(a[row, col]) > abs(a[pivot, col]):
                pivot = row
        swaps[col] = pivot
        if pivot != col:
            for m in range(6):
                a[col, m], a[pivot, m] = a[pivot, m], a[col, m]
        least = min(least, abs(a[col, col]))
        if least == 0.0:
            return 0.0
        for row in range(col + 1, 6):
            factor = a[row, col] / a[col, col]
            a[row, col] = factor
            for m in range(col + 1, 6):
                a[row, m] -= factor * a[col, m]
    return least


@njit(cache=True, nogil=True)
def lu_solve6(a: np.ndarray, swaps: np.ndarray, b: np.ndarray) -> None:
    """``b <- A^{-1} b`` from the factors of :func:`lu6` (a non-singular ``A``)."""
    for col in range(6):
        pivot = int(swaps[col])
        if pivot != col:
            b[col], b[pivot] = b[pivot], b[col]
    for row in range(6):
        for m in range(row):
            b[row] -= a[row, m] * b[m]
    for row in range(5, -1, -1):
        total = b[row]
        for m in range(row + 1, 6):
            total -= a[row, m] * b[m]
        b[row] = total / a[row, row]


@njit(cache=True, nogil=True)
def sole_centre(params: np.ndarray, foot: int, fx: float, fy: float, yaw: float) -> tuple[float, float]:
    """The centre of the sole of ``foot`` (0 left, 1 right) whose ankle is at ``(fx, fy)`` with ``yaw``."""
    side = 1.0 if foot == 0 else -1.0
    ox, oy = rotate2(params[P_SOLE_CENTER_X], side * params[P_SOLE_CENTER_Y], yaw)
    return fx + ox, fy + oy


@njit(cache=True, nogil=True)
def clamp_zmp(params: np.ndarray, zx: float, zy: float, support: int, c0x: float, c0y: float, c1x: float,
              c1y: float, yaw_left: float, yaw_right: float) -> tuple[float, float]:
    """The ZMP moved into the support polygon shrunk by the margin (single support: the sole; double: the segment
    between the soles' centres widened by the soles' half widths, a conservative hull). The soles are given by
    their centres in world [m] (:func:`sole_centre`) and yaws [rad]."""
    margin = params[P_ZMP_MARGIN]
    lx, ly = max(params[P_HALF_LENGTH] - margin, 0.0), max(params[P_HALF_WIDTH] - margin, 0.0)
    if support == 1 or support == 2:
        cx, cy, yaw = (c0x, c0y, yaw_left) if support == 1 else (c1x, c1y, yaw_right)
        local_x, local_y = rotate2(zx - cx, zy - cy, -yaw)
        bx, by = rotate2(min(max(local_x, -lx), lx), min(max(local_y, -ly), ly), yaw)
        return cx + bx, cy + by
    sx, sy = c1x - c0x, c1y - c0y
    length = math.hypot(sx, sy)
    if length < 1e-9:
        return zx, zy
    ax, ay = sx / length, sy / length
    rx, ry = zx - c0x, zy - c0y
    along = min(max(rx * ax + ry * ay, 0.0), length)
    across = min(max(-rx * ay + ry * ax, -lx), lx)
    return c0x + along * ax - across * ay, c0y + along * ay + across * ax


@njit(cache=True, nogil=True)
def distribute(zx: float, zy: float, support: int, c0x: float, c0y: float, c1x: float,
               c1y: float) -> tuple[float, float, float, float, float, float]:
    """Load shares of the feet and each sole's CoP target [m] for a desired ZMP, given the soles' centres in world
    [m]: (share left, share right, target left x, y, target right x, y)."""
    if support == 1:
        return 1.0, 0.0, zx, zy, c1x, c1y
    if support == 2:
        return 0.0, 1.0, c0x, c0y, zx, zy
    sx, sy = c1x - c0x, c1y - c0y
    ratio = min(max(((zx - c0x) * sx + (zy - c0y) * sy) / max(sx * sx + sy * sy, 1e-12), 0.0), 1.0)
    dx, dy = zx - (c0x + ratio * sx), zy - (c0y + ratio * sy)
    return 1.0 - ratio, ratio, c0x + dx, c0y + dy, c1x + dx, c1y + dy


@njit(cache=True, nogil=True)
def sole_cop(wrench: np.ndarray, ankle_height: float, x: float, y: float, yaw: float) -> tuple[float, float]:
    """The centre of pressure in world [m] of a loaded sole whose ankle is at ``(x, y)`` with ``yaw``, from the
    ground's wrench on the foot about the ankle, in the foot frame (force [N], torque [N m]): the point on the
    sole (``ankle_height`` below the ankle) where the torque's horizontal part vanishes."""
    lx, ly = rotate2(-(wrench[4] + ankle_height * wrench[0]) / wrench[2],
                     (wrench[3] - ankle_height * wrench[1]) / wrench[2], yaw)
    return x + lx, y + ly


@njit(cache=True, nogil=True)
def _rotation_zyx(yaw: float, pitch: float, roll: float, r: np.ndarray) -> None:
    """``r`` (9) <- ``Rz(yaw) Ry(pitch) Rx(roll)``, row-major."""
    cz, sz, cy, sy = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    cx, sx = math.cos(roll), math.sin(roll)
    r[0], r[1], r[2] = cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx
    r[3], r[4], r[5] = sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx
    r[6], r[7], r[8] = -sy, cy * sx, cy * cx


@njit(cache=True, nogil=True)
def _rotate3(r: np.ndarray, x: float, y: float, z: float) -> tuple[float, float, float]:
    return (r[0] * x + r[1] * y + r[2] * z, r[3] * x + r[4] * y + r[5] * z, r[6] * x + r[7] * y + r[8] * z)


@njit(cache=True, nogil=True)
def _rotate3_back(r: np.ndarray, x: float, y: float, z: float) -> tuple[float, float, float]:
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z, r[2] * x + r[5] * y + r[8] * z)


@njit(cache=True, nogil=True)
def _clip(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)


_VECTOR = "float64[:]"  # any stride (a row of a Fortran-ordered table)
TICK_SIGNATURE = (f"int64({_VECTOR}, float64[:, :, ::1], {_VECTOR}, {_VECTOR}, float64[:, :, ::1], {_VECTOR}, int64, "
                  f"{_VECTOR}, float64, {_VECTOR}, {_VECTOR}, {_VECTOR}, float64, float64, {_VECTOR}, {_VECTOR}, "
                  f"{_VECTOR}, {_VECTOR}, {_VECTOR}, {_VECTOR}, float64)")


@njit(TICK_SIGNATURE, cache=True, nogil=True)
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
    p = params
    # the pattern's legs and their Jacobians' factors, which map the foot corrections onto the joints at the end;
    # a singular one is rejected before anything is written
    leg_kinematics(chain, 0, reference, work[1])
    leg_kinematics(chain, 1, reference, work[3])
    p0 = ankle_in_base(p, 0, work[1])
    p1 = ankle_in_base(p, 1, work[3])
    for leg in range(2):
        factors, swaps = work[4, 0:6, 6 * leg:6 * leg + 6], work[5, 0, 6 * leg:6 * leg + 6]
        leg_jacobian(chain, leg, work[2 * leg + 1], p0 if leg == 0 else p1, factors)
        if lu6(factors, swaps) < SINGULAR_PIVOT:
            return SINGULAR_LEG + leg
    dt, omega, h = p[P_DT], p[P_OMEGA], p[P_ANKLE_HEIGHT]
    started = state[S_STARTED] > 0.0
    rx, ry = com[0], com[1]
    # the planned whole-body CoM's offset from a pelvis point (the pattern's legs at their planned angles)
    whole_x = whole_y = 0.0
    if p[P_WHOLE_BODY_REST] > 0.0:
        qx, qy, _ = com_in_base(p, chain, work, 1)
        whole_x, whole_y = rotate2(p[P_WHOLE_BODY_REST] * qx, p[P_WHOLE_BODY_REST] * qy, yaw)
    if not started:
        state[S_PREVIOUS_REFERENCE], state[S_PREVIOUS_REFERENCE + 1] = rx, ry
    vrx = (rx - state[S_PREVIOUS_REFERENCE]) / dt
    vry = (ry - state[S_PREVIOUS_REFERENCE + 1]) / dt
    state[S_PREVIOUS_REFERENCE], state[S_PREVIOUS_REFERENCE + 1] = rx, ry
    # --- measured sole wrenches
    f0, f1 = wrench_left[2], wrench_right[2]
    threshold = p[P_LOAD_THRESHOLD]
    loaded0, loaded1 = f0 > threshold, f1 > threshold
    # --- CoM estimate: kinematics of the measured legs, tilted by the IMU, anchored at the loaded sole
    roll, pitch = attitude[0], attitude[1]
    heading = yaw if math.isnan(measured_yaw) else measured_yaw
    leg_kinematics(chain, 0, encoders, work[0])
    leg_kinematics(chain, 1, encoders, work[2])
    rot = work[4, 6, 0:9]
    _rotation_zyx(heading, pitch, roll, rot)
    # measured ankles (base), reference ankles (base)
    a0 = ankle_in_base(p, 0, work[0])
    a1 = ankle_in_base(p, 1, work[2])
    # CoM in the base from the measured legs
    com_bx, com_by, com_bz = com_in_base(p, chain, work, 0)
    # each measured sole's normal (its sole frame's z axis, sole_normal) in world, horizontal part
    s0 = sole_normal(p, 0, work[0])
    s1 = sole_normal(p, 1, work[2])
    n0 = _rotate3(rot, s0[0], s0[1], s0[2])
    n1 = _rotate3(rot, s1[0], s1[1], s1[2])
    if not started:
        state[S_SOLE_NORMALS], state[S_SOLE_NORMALS + 1] = n0[0], n0[1]
        state[S_SOLE_NORMALS + 2], state[S_SOLE_NORMALS + 3] = n1[0], n1[1]
        for i in range(3):
            state[S_PREVIOUS_RELATIVE + i] = a0[i]
            state[S_PREVIOUS_RELATIVE + 3 + i] = a1[i]
        state[S_FEET], state[S_FEET + 1] = ankle_left[0], ankle_left[1]
        state[S_FEET + 2], state[S_FEET + 3] = ankle_right[0], ankle_right[1]
        state[S_ANCHOR] = 0.0 if f0 >= f1 else 1.0
        state[S_STARTED] = 1.0
    # Leg odometry: the sole that has carried load the longest is the reference (see zmpwalk.balance).
    anchor = int(state[S_ANCHOR])
    if loaded0 if anchor == 0 else loaded1:
        now = n0 if anchor == 0 else n1
        o = S_SOLE_NORMALS + 2 * anchor
        state[S_FEET + 2 * anchor] += h * (now[0] - state[o])
        state[S_FEET + 2 * anchor + 1] += h * (now[1] - state[o + 1])
    state[S_SOLE_NORMALS], state[S_SOLE_NORMALS + 1] = n0[0], n0[1]
    state[S_SOLE_NORMALS + 2], state[S_SOLE_NORMALS + 3] = n1[0], n1[1]
    ra = a0 if anchor == 0 else a1  # the anchor's measured ankle in the base
    ro = a1 if anchor == 0 else a0
    loaded_now = 0 if loaded0 else 1
    if (loaded0 and loaded1) or (loaded0 != loaded1 and loaded_now != anchor):
        d = _rotate3(rot, ro[0] - ra[0], ro[1] - ra[1], ro[2] - ra[2])
        state[S_FEET + 2 * (1 - anchor)] = state[S_FEET + 2 * anchor] + d[0]
        state[S_FEET + 2 * (1 - anchor) + 1] = state[S_FEET + 2 * anchor + 1] + d[1]
    if loaded0 != loaded1:
        anchor = loaded_now
        state[S_ANCHOR] = float(anchor)
    ra = a0 if anchor == 0 else a1
    ro = a1 if anchor == 0 else a0
    anchor_x, anchor_y = state[S_FEET + 2 * anchor], state[S_FEET + 2 * anchor + 1]
    # --- 7. floor slope: the soles' normal in world (IMU and measured kinematics), low-pass filtered
    slope_on = p[P_SLOPE_TIME_CONSTANT] > 0.0
    if slope_on and loaded0 and loaded1:  # both soles down: both flat on the floor
        m_n = _rotate3(rot, (s0[0] + s1[0]) / 2, (s0[1] + s1[1]) / 2, (s0[2] + s1[2]) / 2)
        beta = dt / (p[P_SLOPE_TIME_CONSTANT] + dt)
        for i in range(3):
            state[S_FLOOR_NORMAL + i] += beta * (m_n[i] - state[S_FLOOR_NORMAL + i])
    nx, ny, nz = state[S_FLOOR_NORMAL], state[S_FLOOR_NORMAL + 1], state[S_FLOOR_NORMAL + 2]
    length = p[P_PENDULUM_LENGTH]
    slope_x = length * nx / nz if slope_on else 0.0
    slope_y = length * ny / nz if slope_on else 0.0
    slope_norm = math.hypot(slope_x, slope_y)
    com_limit = p[P_COM_LIMIT]
    if slope_norm > com_limit:
        slope_x, slope_y = slope_x * com_limit / slope_norm, slope_y * com_limit / slope_norm
    arm = _rotate3(rot, com_bx - ra[0], com_by - ra[1], com_bz - ra[2])
    cx, cy = anchor_x + arm[0], anchor_y + arm[1]
    # where the feet are (odometry; the swing foot follows from the stance foot and the kinematics)
    other = _rotate3(rot, ro[0] - ra[0], ro[1] - ra[1], ro[2] - ra[2])
    if anchor == 0:
        left_x, left_y, right_x, right_y = anchor_x, anchor_y, anchor_x + other[0], anchor_y + other[1]
    else:
        left_x, left_y, right_x, right_y = anchor_x + other[0], anchor_y + other[1], anchor_x, anchor_y
    c0x, c0y = sole_centre(p, 0, left_x, left_y, yaw_left)
    c1x, c1y = sole_centre(p, 1, right_x, right_y, yaw_right)
    cop0x = cop0y = cop1x = cop1y = 0.0
    if loaded0:
        cop0x, cop0y = sole_cop(wrench_left, h, left_x, left_y, yaw_left)
    if loaded1:
        cop1x, cop1y = sole_cop(wrench_right, h, right_x, right_y, yaw_right)
    zmx = zmy = math.nan
    if loaded0 or loaded1:
        w0 = f0 if loaded0 else 0.0
        w1 = f1 if loaded1 else 0.0
        zmx = (w0 * cop0x + w1 * cop1x) / (w0 + w1)
        zmy = (w0 * cop0y + w1 * cop1y) / (w0 + w1)
    o = S_PREVIOUS_RELATIVE + 3 * anchor
    previous_arm = _rotate3(rot, com_bx - state[o], com_by - state[o + 1], com_bz - state[o + 2])
    spin = _rotate3(rot, rate[0], rate[1], rate[2])
    raw_vx = (arm[0] - previous_arm[0]) / dt + (spin[1] * arm[2] - spin[2] * arm[1])
    raw_vy = (arm[1] - previous_arm[1]) / dt + (spin[2] * arm[0] - spin[0] * arm[2])
    for i in range(3):
        state[S_PREVIOUS_RELATIVE + i] = a0[i]
        state[S_PREVIOUS_RELATIVE + 3 + i] = a1[i]
    alpha = dt / (p[P_VELOCITY_FILTER] + dt)
    state[S_COM_VELOCITY] += alpha * (raw_vx - state[S_COM_VELOCITY])
    state[S_COM_VELOCITY + 1] += alpha * (raw_vy - state[S_COM_VELOCITY + 1])
    # --- 1. DCM feedback -> desired ZMP inside the support polygon
    ex = (cx + state[S_COM_VELOCITY] / omega) - (rx + vrx / omega)
    ey = (cy + state[S_COM_VELOCITY + 1] / omega) - (ry + vry / omega)
    gain = 1.0 + p[P_DCM] / omega
    pdx, pdy = clamp_zmp(p, zmp[0] + gain * ex, zmp[1] + gain * ey, support, c0x, c0y, c1x, c1y, yaw_left,
                         yaw_right)
    # --- 2. CoM admittance
    if loaded0 or loaded1:
        ax, ay = p[P_COM_ADMITTANCE] * (zmx - pdx), p[P_COM_ADMITTANCE] * (zmy - pdy)
    else:
        ax = ay = 0.0
    # the offset rests where the slope wants the CoM and, against a pelvis point, where the planned whole-body CoM
    # stands on that point (the cart-table's mass)
    rest_x, rest_y = -(slope_x + whole_x), -(slope_y + whole_y)
    ax -= p[P_COM_DAMPING] * state[S_OFFSET_RATE] + p[P_COM_STIFFNESS] * (state[S_OFFSET] - rest_x)
    ay -= p[P_COM_DAMPING] * state[S_OFFSET_RATE + 1] + p[P_COM_STIFFNESS] * (state[S_OFFSET + 1] - rest_y)
    state[S_OFFSET_RATE] += ax * dt
    state[S_OFFSET_RATE + 1] += ay * dt
    state[S_OFFSET] += state[S_OFFSET_RATE] * dt
    state[S_OFFSET + 1] += state[S_OFFSET_RATE + 1] * dt
    norm = math.hypot(state[S_OFFSET], state[S_OFFSET + 1])
    if norm > com_limit:
        state[S_OFFSET] *= com_limit / norm
        state[S_OFFSET + 1] *= com_limit / norm
        state[S_OFFSET_RATE] = state[S_OFFSET_RATE + 1] = 0.0
    offset_x, offset_y = state[S_OFFSET], state[S_OFFSET + 1]
    # --- 3. ankle damping: each loaded sole's CoP follows its share of p_d
    share0, share1, t0x, t0y, t1x, t1y = distribute(pdx, pdy, support, c0x, c0y, c1x, c1y)
    decay = dt / p[P_ANKLE_TIME_CONSTANT]
    ankle_limit, ankle_gain = p[P_ANKLE_LIMIT], p[P_ANKLE_GAIN]
    for foot in range(2):
        o = S_ANKLE + 2 * foot
        loaded = loaded0 if foot == 0 else loaded1
        share = share0 if foot == 0 else share1
        if loaded and share > MIN_SHARE:
            if foot == 0:
                error = rotate2(t0x - cop0x, t0y - cop0y, -yaw_left)
            else:
                error = rotate2(t1x - cop1x, t1y - cop1y, -yaw_right)
            state[o] += dt * (-ankle_gain * error[1])
            state[o + 1] += dt * (ankle_gain * error[0])
        state[o] = _clip(state[o] - decay * state[o], ankle_limit)
        state[o + 1] = _clip(state[o + 1] - decay * state[o + 1], ankle_limit)
    # --- 4. foot force difference (double support); a sole the plan has down that carries no load (a late
    # touchdown, an early lift) reads the whole weight as the difference and is lowered at the touchdown speed;
    # in single support a swinging sole that carries load (an early touchdown) is raised at that speed
    weight = f0 + f1
    if support == 0:
        state[S_LIFTED] = state[S_LIFTED + 1] = 0.0
    elif support == 1 and not loaded1:
        state[S_LIFTED + 1] = 1.0
    elif support == 2 and not loaded0:
        state[S_LIFTED] = 1.0
    # the swinging sole touches down early: it carries load after it has lifted (not while it lifts)
    early = (support == 1 and loaded1 and state[S_LIFTED + 1] > 0.0) or (support == 2 and loaded0
                                                                          and state[S_LIFTED] > 0.0)
    if (early or (support == 0 and (loaded0 or loaded1))) and weight > 0:
        wanted = (share0 - share1) * weight
        rate_gain = p[P_FORCE_GAIN] if loaded0 and loaded1 and not early else p[P_TOUCHDOWN_SPEED]
        state[S_HEIGHT] += dt * rate_gain * (wanted - (f0 - f1)) / weight
    state[S_HEIGHT] -= dt / p[P_FORCE_TIME_CONSTANT] * state[S_HEIGHT]
    state[S_HEIGHT] = _clip(state[S_HEIGHT], p[P_FORCE_LIMIT])
    height = state[S_HEIGHT]
    # --- 5. torso attitude
    turn_roll = _clip(-p[P_ATTITUDE_GAIN] * roll - p[P_ATTITUDE_DAMPING] * rate[0], p[P_ATTITUDE_LIMIT])
    turn_pitch = _clip(-p[P_ATTITUDE_GAIN] * pitch - p[P_ATTITUDE_DAMPING] * rate[1], p[P_ATTITUDE_LIMIT])
    # --- 6. landing and stepping (see zmpwalk.balance)
    stance = _rotate3(rot, ra[0], ra[1], ra[2])
    base_ex, base_ey = anchor_x - stance[0], anchor_y - stance[1]
    planned_anchor = ankle_left if anchor == 0 else ankle_right
    height_limit = p[P_LANDING_HEIGHT_LIMIT]
    error_norm = math.hypot(ex, ey)
    step = (p[P_STEP_GAIN] * max(error_norm - p[P_STEP_DEADBAND], 0.0) / error_norm if error_norm > 0.0
            else 0.0)
    step_x, step_y = step * ex, step * ey
    landing_rate, release_rate = dt / p[P_LANDING_TIME_CONSTANT], dt / p[P_LANDING_RELEASE]
    landing_limit = p[P_LANDING_LIMIT]
    yaw_limit = p[P_LANDING_YAW_LIMIT]
    turn = yaw - heading
    turn -= 2.0 * math.pi * round(turn / (2.0 * math.pi))  # math.remainder(turn, tau)
    yaw_aim = _clip(turn, yaw_limit)
    for foot in range(2):
        o = S_LANDING + 2 * foot
        swinging = (support == 1 and foot == 1) or (support == 2 and foot == 0)
        loaded = loaded0 if foot == 0 else loaded1
        state[S_AIRBORNE + foot] = 0.0 if loaded else state[S_AIRBORNE + foot] + dt
        # a sole the plan has put down that has not touched down yet (a late touchdown) keeps aiming
        aiming = swinging or state[S_AIRBORNE + foot] > AIRBORNE_AIM
        oy = S_LANDING_YAW + foot
        if aiming:
            state[oy] += landing_rate * (yaw_aim - state[oy])
        else:
            state[oy] += -release_rate * state[oy]
        if aiming:
            planned = p0 if foot == 0 else p1
            world = ankle_left if foot == 0 else ankle_right
            seen = _rotate3_back(rot, world[0] - base_ex, world[1] - base_ey, planned[2])
            aim = rotate2(seen[0] - planned[0] + turn_pitch * planned[2],
                          seen[1] - planned[1] - turn_roll * planned[2], yaw)
            state[o] += landing_rate * (aim[0] + offset_x + step_x - state[o])
            state[o + 1] += landing_rate * (aim[1] + offset_y + step_y - state[o + 1])
            if height_limit > 0.0 and anchor != foot:
                # the planned height above the stance sole (the odometry's reference once the swinging sole has
                # handed its load over), on the floor's estimated plane, from the measured base; less the
                # pelvis turn's share, which every foot gets (see below)
                rise = -(nx * (world[0] - anchor_x) + ny * (world[1] - anchor_y)) / nz
                above = world[2] - planned_anchor[2] + rise + stance[2]
                stance_force = f0 if anchor == 0 else f1
                if p[P_SOLE_STIFFNESS] > 0.0 and stance_force > 0.0:  # the stance sole is pressed into the floor
                    above += (stance_force / p[P_SOLE_STIFFNESS]) ** (1.0 / p[P_SOLE_EXPONENT])
                seen_z = rot[2] * (world[0] - base_ex) + rot[5] * (world[1] - base_ey) + rot[8] * above
                aim_z = seen_z - planned[2] + turn_roll * planned[1] - turn_pitch * planned[0]
                state[S_LANDING_HEIGHT + foot] += landing_rate * (aim_z - state[S_LANDING_HEIGHT + foot])
                state[S_LANDING_HEIGHT + foot] = _clip(state[S_LANDING_HEIGHT + foot], height_limit)
        else:
            state[o] -= release_rate * state[o]
            state[o + 1] -= release_rate * state[o + 1]
            state[S_LANDING_HEIGHT + foot] -= release_rate * state[S_LANDING_HEIGHT + foot]
        state[o] = _clip(state[o], landing_limit)
        state[o + 1] = _clip(state[o + 1], landing_limit)
        if aiming:
            # No step across the stance foot: the soles' inner edges keep feet_clearance between them (the
            # correction's part across the pelvis; the planned feet relative to the pelvis from the reference).
            swing, stance_ankle = (p0, p1) if foot == 0 else (p1, p0)
            side = 1.0 if foot == 0 else -1.0
            least = params[P_HALF_WIDTH] * 2.0 - 2.0 * params[P_SOLE_CENTER_Y] + params[P_FEET_CLEARANCE]
            along, across = rotate2(state[o], state[o + 1], -yaw)
            planned_gap = side * (swing[1] - stance_ankle[1])
            if planned_gap + side * across < least:
                across = side * (least - planned_gap)
                state[o], state[o + 1] = rotate2(along, across, yaw)
    # --- corrections of the feet relative to the pelvis, onto the joints through the Jacobians
    shift = rotate2(offset_x, offset_y, -yaw)
    changes = work[5, 1, 0:6]
    for i in range(12):
        targets[i] = reference[i]
    for leg in range(2):
        planned = p0 if leg == 0 else p1
        px, py, pz = planned[0], planned[1], planned[2]
        landing = rotate2(state[S_LANDING + 2 * leg], state[S_LANDING + 2 * leg + 1], -yaw)
        foot_yaw = yaw_left if leg == 0 else yaw_right
        foot_turn = rotate2(state[S_ANKLE + 2 * leg], state[S_ANKLE + 2 * leg + 1], foot_yaw - yaw)
        changes[0] = landing[0] - shift[0] - turn_pitch * pz
        changes[1] = landing[1] - shift[1] + turn_roll * pz
        changes[2] = ((-height / 2 if leg == 0 else height / 2) - (turn_roll * py - turn_pitch * px)
                      + state[S_LANDING_HEIGHT + leg])
        changes[3] = foot_turn[0] - turn_roll
        changes[4] = foot_turn[1] - turn_pitch
        changes[5] = state[S_LANDING_YAW + leg]
        lu_solve6(work[4, 0:6, 6 * leg:6 * leg + 6], work[5, 0, 6 * leg:6 * leg + 6], changes)
        for i in range(6):
            targets[6 * leg + int(chain[leg, i, 10])] += changes[i]
    if p[P_STIFFEN] > 0.0:  # --- 8. servo stiffness: the encoder loop on the soft servos
        for i in range(12):
            targets[i] += p[P_SERVO_GAIN + i] * (targets[i] - encoders[i])
    log[L_ZMP_DESIRED], log[L_ZMP_DESIRED + 1] = pdx, pdy
    log[L_ZMP_MEASURED], log[L_ZMP_MEASURED + 1] = zmx, zmy
    log[L_DCM_ERROR], log[L_DCM_ERROR + 1] = ex, ey
    log[L_COM_OFFSET], log[L_COM_OFFSET + 1] = offset_x, offset_y
    for i in range(4):
        log[L_ANKLE_OFFSETS + i] = state[S_ANKLE + i]
    log[L_HEIGHT_DIFFERENCE] = height
    log[L_PELVIS_TURN], log[L_PELVIS_TURN + 1] = turn_roll, turn_pitch
    log[L_SLOPE_OFFSET], log[L_SLOPE_OFFSET + 1] = -slope_x, -slope_y
    log[L_WHOLE_BODY_OFFSET], log[L_WHOLE_BODY_OFFSET + 1] = whole_x, whole_y
    return 0
