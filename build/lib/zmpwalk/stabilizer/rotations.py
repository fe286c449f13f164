# mypy: disallow-untyped-decorators=False
"""Rotations and limits on plain floats for the compiled stabilizer (numba, cached on disk): rotation matrices are
9-float rows, row-major; angles in radians."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from zmpwalk.stabilizer.freshness import BUILD_KEY


@njit(cache=True, nogil=True)
def rotate2(x: float, y: float, angle: float) -> tuple[float, float]:
    """``(x, y)`` turned by ``angle`` [rad] about z."""
    c, s = math.cos(angle), math.sin(angle)
    return c * x - s * y, s * x + c * y


@njit(cache=True, nogil=True)
def rotation_zyx(yaw: float, pitch: float, roll: float, r: np.ndarray) -> None:
    """``r`` (9) <- ``Rz(yaw) Ry(pitch) Rx(roll)``, row-major."""
    cz, sz, cy, sy = math.cos(yaw), math.sin(yaw), math.cos(pitch), math.sin(pitch)
    cx, sx = math.cos(roll), math.sin(roll)
    r[0], r[1], r[2] = cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx
    r[3], r[4], r[5] = sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx
    r[6], r[7], r[8] = -sy, cy * sx, cy * cx


@njit(cache=True, nogil=True)
def rotate3(r: np.ndarray, x: float, y: float, z: float) -> tuple[float, float, float]:
    """``r (x, y, z)``: a vector of the rotated frame in the frame ``r`` is given in."""
    return (r[0] * x + r[1] * y + r[2] * z, r[3] * x + r[4] * y + r[5] * z, r[6] * x + r[7] * y + r[8] * z)


@njit(cache=True, nogil=True)
def rotate3_back(r: np.ndarray, x: float, y: float, z: float) -> tuple[float, float, float]:
    """``r^T (x, y, z)``: the inverse of :func:`rotate3`."""
    return (r[0] * x + r[3] * y + r[6] * z, r[1] * x + r[4] * y + r[7] * z, r[2] * x + r[5] * y + r[8] * z)


@njit(cache=True, nogil=True)
def clip(value: float, limit: float) -> float:
    """``value`` kept within ``[-limit, limit]``."""
    return min(max(value, -limit), limit)


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY
