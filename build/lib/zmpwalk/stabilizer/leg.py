# mypy: disallow-untyped-decorators=False
r"""The compiled leg (numba, cached on disk): a leg chain's product of exponentials, ankle point, sole normal,
Jacobian and the whole-body CoM on plain float64 arrays, and the 6 x 6 LU solve that maps a foot correction onto
the joints. :func:`zmpwalk.balance_kernel.tick` runs them twice per tick (the measured legs and the pattern's);
they agree with :class:`zmpwalk.leg_chain.LegChain`, the general chain (``tests/test_compiled_leg.py``).

Arrays (all float64):

- ``chain`` (2, 6, 11): per leg (left, right) and chain joint: the joint's axis (0:3) and a point on it (3:6) in
  the base frame at zero angles, its link's CoM (6:9) in that frame, the link's mass (9), and the joint's column
  among the leg's 6 role-ordered columns (10) (:data:`zmpwalk.kinematics.JOINT_COLUMNS`).
- ``frames`` (7, 12): each of the leg's 7 frames' rotation (row-major, 0:9) and translation (9:12) in the base
  frame; ``work`` (6, 7, 12) holds four of them, ``work[pose]`` for the poses left measured, left reference,
  right measured, right reference.
- ``params``: the stabilizer's parameters (:mod:`zmpwalk.stabilizer.layout`), of which these read the robot's
  mass, the rest of the body's mass moment, and each leg's ankle offset and sole normal.

*base* is the torso (pelvis) frame, x forward, y left, z up. Every position is in metres, every angle in radians.
"""

from __future__ import annotations

import math
from typing import cast

import numpy as np
from numba import njit

from zmpwalk.stabilizer.freshness import BUILD_KEY
from zmpwalk.stabilizer.layout import P

# The two legs' indices as numpy integers: numba types a Python int constant argument as a literal and compiles
# the callee once per value; an int64 once for both (one compile less per leg function on the first run).
FIRST, SECOND = cast(int, np.int64(0)), cast(int, np.int64(1))  # typed int64 by numba, int by mypy


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
    mx, my, mz = params[P.rest_moment], params[P.rest_moment + 1], params[P.rest_moment + 2]
    for leg in range(2):
        frames = work[2 * leg + planned]
        for i in range(6):
            f = frames[i + 1]
            cx, cy, cz = chain[leg, i, 6], chain[leg, i, 7], chain[leg, i, 8]
            mass = chain[leg, i, 9]
            mx += mass * (f[0] * cx + f[1] * cy + f[2] * cz + f[9])
            my += mass * (f[3] * cx + f[4] * cy + f[5] * cz + f[10])
            mz += mass * (f[6] * cx + f[7] * cy + f[8] * cz + f[11])
    total = params[P.mass]
    return mx / total, my / total, mz / total


@njit(cache=True, nogil=True)
def ankle_in_base(params: np.ndarray, leg: int, frames: np.ndarray) -> tuple[float, float, float]:
    """The ankle point of the leg's last frame, in the base frame [m]."""
    f = frames[6]
    o = P.ankle_offset + 3 * leg
    x, y, z = params[o], params[o + 1], params[o + 2]
    return (f[9] + f[0] * x + f[1] * y + f[2] * z, f[10] + f[3] * x + f[4] * y + f[5] * z,
            f[11] + f[6] * x + f[7] * y + f[8] * z)


@njit(cache=True, nogil=True)
def sole_normal(params: np.ndarray, leg: int, frames: np.ndarray) -> tuple[float, float, float]:
    """The leg's sole normal in the base frame: the last frame's rotation times the sole frame's z axis
    (:attr:`zmpwalk.leg_chain.LegChain.sole_rotation`; the last frame's own z axis where the sole is level at zero
    angles)."""
    f = frames[6]
    o = P.sole_normal + 3 * leg
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


@njit(cache=True, nogil=True, inline="always")
def factor_pattern_legs(params: np.ndarray, chain: np.ndarray, work: np.ndarray, reference: np.ndarray,
                        least_pivot: float) -> tuple[int, tuple[float, float, float], tuple[float, float, float]]:
    """The pattern's legs at the angles ``reference`` (``work[1]``, ``work[3]``) and the LU factors of their
    Jacobians (``work[4]``, row swaps in ``work[5, 0]``), which map the foot corrections onto the joints; returns
    the first leg (0 left, 1 right) whose Jacobian has a pivot below ``least_pivot`` (a straight knee), else -1,
    and each planned ankle in the base frame [m]."""
    leg_kinematics(chain, FIRST, reference, work[1])
    leg_kinematics(chain, SECOND, reference, work[3])
    p0 = ankle_in_base(params, FIRST, work[1])
    p1 = ankle_in_base(params, SECOND, work[3])
    for leg in range(2):
        factors, swaps = work[4, 0:6, 6 * leg:6 * leg + 6], work[5, 0, 6 * leg:6 * leg + 6]
        leg_jacobian(chain, leg, work[2 * leg + 1], p0 if leg == 0 else p1, factors)
        if lu6(factors, swaps) < least_pivot:
            return leg, p0, p1
    return -1, p0, p1


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY
