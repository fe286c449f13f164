"""Rotations of the leg's kinematics: about the pelvis frame's axes, about any axis, cross products, angle wrap."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def rot_x(angle: Array) -> Array:
    """Rotation matrices about x, shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(angle: Array) -> Array:
    """Rotation matrices about y, shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(angle: Array) -> Array:
    """Rotation matrices about z, shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def rodrigues(axis: Array, angle: Array) -> Array:  # the IK's few rotations; LegChain.transforms has its own
    """Rotation matrices about a fixed unit ``axis`` (3,) by ``angle`` (n,), shape (n, 3, 3)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.asarray(np.eye(3) + s * k + (1.0 - c) * (k @ k), dtype=np.float64)


def cross3(a: Array, b: Array) -> Array:
    """Cross products along the last axis of 3-vectors (``np.cross`` without its axis handling, which
    dominates on the small arrays of one control tick)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def wrap(angle: Array) -> Array:
    """Angles into [-pi, pi) [rad]."""
    return np.asarray((angle + np.pi) % (2 * np.pi) - np.pi, dtype=np.float64)


__all__ = ["cross3", "rodrigues", "rot_x", "rot_y", "rot_z", "wrap"]
