"""Elementary curves of both papers, vectorised over numpy arrays.

Each function takes a normalised parameter ``s`` (any shape; callers clip it
to [0, 1]) and returns the value and its first and second derivatives with
respect to ``s``. Chain-rule factors for physical time are the caller's.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]
Curve = tuple[Array, Array, Array]

TWO_PI = 2.0 * np.pi


def hermite_cubic(p0: Array, m0: Array, p1: Array, m1: Array, s: Array) -> Curve:
    """Cubic with end values ``p0, p1`` and end slopes ``m0, m1`` (per unit ``s``).

    This is the polynomial of Eqs. 3-5 and 12 of Park et al. (2008) written in
    Hermite form, which is the closed form of the inverse matrix of Eq. 4:

    .. math::
        x(s) = (2s^3 - 3s^2 + 1) p_0 + (s^3 - 2s^2 + s) m_0
             + (-2s^3 + 3s^2) p_1 + (s^3 - s^2) m_1

    Args:
        p0, m0, p1, m1: Boundary values; broadcast against ``s``.
        s: Normalised time.

    Returns:
        Value, first and second derivative with respect to ``s``.
    """
    s2 = s * s
    s3 = s2 * s
    value = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (3 * s2 - 2 * s3) * p1 + (s3 - s2) * m1
    slope = (6 * s2 - 6 * s) * (p0 - p1) + (3 * s2 - 4 * s + 1) * m0 + (3 * s2 - 2 * s) * m1
    curvature = (12 * s - 6) * (p0 - p1) + (6 * s - 4) * m0 + (6 * s - 2) * m1
    return value, slope, curvature


def hermite_quintic(p0: Array, m0: Array, p1: Array, m1: Array, s: Array) -> Curve:
    r"""Quintic with end values ``p0, p1``, end slopes ``m0, m1`` (per unit ``s``) and zero curvature at both
    ends: the jerk-continuous counterpart of :func:`hermite_cubic` (the pelvis option ``"quintic"``).

    .. math::
        x(s) = p_0 + (p_1 - p_0)(10s^3 - 15s^4 + 6s^5) + (s - 6s^3 + 8s^4 - 3s^5) m_0
             + (-4s^3 + 7s^4 - 3s^5) m_1

    Joined end to end with the same slopes, such curves have continuous value, slope and curvature,
    so the cart-table ZMP :math:`x - (l/g)\ddot x` is continuous too.

    Returns:
        Value, first and second derivative with respect to ``s``.
    """
    s2 = s * s
    s3 = s2 * s
    rise, rise1, rise2 = smoothstep5(s)
    span = p1 - p0
    value = (p0 + span * rise + (s - 6 * s3 + 8 * s2 * s2 - 3 * s3 * s2) * m0
             + (-4 * s3 + 7 * s2 * s2 - 3 * s3 * s2) * m1)
    slope = (span * rise1 + (1 - 18 * s2 + 32 * s3 - 15 * s2 * s2) * m0
             + (-12 * s2 + 28 * s3 - 15 * s2 * s2) * m1)
    curvature = span * rise2 + (-36 * s + 96 * s2 - 60 * s3) * m0 + (-24 * s + 84 * s2 - 60 * s3) * m1
    return value, slope, curvature


def cycloid(s: Array) -> Curve:
    """Unit cycloid of Eq. 11 (Park 2008): ``s - sin(2 pi s) / (2 pi)``.

    Rises from 0 to 1 with zero velocity at both ends.
    """
    angle = TWO_PI * s
    return s - np.sin(angle) / TWO_PI, 1.0 - np.cos(angle), TWO_PI * np.sin(angle)


def cosine_blend(s: Array) -> Curve:
    """Half-cosine ramp of Eqs. 14-17 and 21-22 (Park 2008): ``(1 - cos(pi s)) / 2``."""
    angle = np.pi * s
    return (
        0.5 * (1.0 - np.cos(angle)),
        0.5 * np.pi * np.sin(angle),
        0.5 * np.pi**2 * np.cos(angle),
    )


def smoothstep5(s: Array) -> Curve:
    """Quintic 10-15-6 smoothstep of Eq. 17 (Lim et al.): zero slope and curvature at both ends."""
    s2 = s * s
    s3 = s2 * s
    return (
        s3 * (10.0 - 15.0 * s + 6.0 * s2),
        30.0 * s2 * (1.0 - 2.0 * s + s2),
        60.0 * s * (1.0 - 3.0 * s + 2.0 * s2),
    )


def lift_profile(s: Array, up_ratio: Array | float) -> Curve:
    """Foot-height profile of Fig. 12 (Park 2008), normalised to a unit apex.

    The paper prints no formula, only the up/down time ratio ``u``: the foot
    rises during the first ``u`` of the swing and lands during the rest. Both
    halves are the quintic smoothstep of Eq. 17 (Lim et al.), so height,
    velocity and acceleration are continuous (C2), also at lift-off, at the
    apex and at touch-down.

    Args:
        s: Normalised swing time in [0, 1].
        up_ratio: ``u`` in (0, 1); the paper keeps it <= 0.5 (slower landing).

    Returns:
        Height fraction and its first and second derivatives with respect to ``s``.
    """
    u = np.asarray(up_ratio, dtype=float)
    rising = s < u
    span = np.where(rising, u, 1.0 - u)
    local = np.where(rising, s / u, (s - u) / (1.0 - u))
    value, slope, curvature = smoothstep5(local)
    sign = np.where(rising, 1.0, -1.0)
    height = np.where(rising, value, 1.0 - value)
    return height, sign * slope / span, sign * curvature / span**2
