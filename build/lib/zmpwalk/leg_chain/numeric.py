r"""Numeric inverse kinematics of any leg: damped least squares on every sample at once.

Where the axes do not meet, such as Booster T1's hip (pitch, roll and yaw axes
2 cm and 8.2 cm apart), the leg has no closed form. The angles are found by
damped least squares, warm-started from the reference angles (or a given start)
and iterated on every sample at once:

.. math:: \Delta q = J^T (J J^T + \lambda^2 I)^{-1} e

with ``e`` the foot's position error and the rotation vector of its
orientation error. It stops when every sample is within :data:`IK_TOLERANCE`;
a sample that does not converge is reported with its remaining error as the
``excess`` of :meth:`~zmpwalk.leg_chain.LegChain.solve`, and a joint trajectory then raises
:class:`~zmpwalk.errors.UnreachableError` naming the leg and the time.
"""

from __future__ import annotations

import numpy as np

from zmpwalk.leg_chain.geometry import ChainGeometry
from zmpwalk.leg_chain.rotations import Array, wrap

IK_TOLERANCE = 1e-10  # [m] and [rad]: convergence of the numeric IK
IK_MAX_ITERATIONS = 100
IK_DAMPING = 1e-6  # lambda of the damped least squares [-]
IK_MAX_STEP = 0.3  # [rad] largest joint change of one iteration (keeps far targets from overshooting)


def solve_numeric(chain: ChainGeometry, p: Array, rotation: Array, start: Array | None = None) -> tuple[Array, Array]:
    """Angles (n, 6) [rad] in chain order for ankle positions ``p`` (n, 3) [m] and the chain's own rotations
    (n, 3, 3), from ``start`` (n, 6) [rad] (default: the chain's reference angles), and per sample the remaining
    error where it did not converge [m] (> 0), else -1."""
    n = len(p)
    q = np.broadcast_to(chain.reference, (n, 6)).copy() if start is None else start.copy()
    eye = np.eye(6)
    error = np.zeros((n, 6))
    for _ in range(IK_MAX_ITERATIONS):
        position, current = chain.fk_chain(q)
        error[:, :3] = p - position
        error[:, 3:] = _rotation_vector(rotation @ np.swapaxes(current, 1, 2))
        norm = np.max(np.abs(error), axis=1)
        active = norm > IK_TOLERANCE
        if not active.any():
            break
        jacobian = chain.jacobian(q[active])
        jjt = jacobian @ np.swapaxes(jacobian, 1, 2) + IK_DAMPING**2 * eye
        step = np.einsum("nji,nj->ni", jacobian, np.linalg.solve(jjt, error[active][..., None])[..., 0])
        largest = np.max(np.abs(step), axis=1, keepdims=True)
        q[active] += step * np.minimum(1.0, IK_MAX_STEP / np.maximum(largest, 1e-300))
    position, current = chain.fk_chain(q)
    residual = np.linalg.norm(p - position, axis=1)
    residual = np.maximum(residual, np.linalg.norm(_rotation_vector(rotation @ np.swapaxes(current, 1, 2)),
                                                   axis=1))
    excess = np.where(residual > 1e3 * IK_TOLERANCE, residual, -1.0)
    return wrap(q), excess


def _rotation_vector(rotation: Array) -> Array:
    """Axis times angle of rotations (n, 3, 3), (n, 3) (accurate near the identity and up to pi)."""
    cos = np.clip((np.trace(rotation, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    vee = 0.5 * np.stack([rotation[:, 2, 1] - rotation[:, 1, 2], rotation[:, 0, 2] - rotation[:, 2, 0],
                          rotation[:, 1, 0] - rotation[:, 0, 1]], axis=-1)
    sin = np.sin(angle)
    scale = np.where(sin > 1e-9, angle / np.where(sin > 1e-9, sin, 1.0), 1.0 + angle * angle / 6.0)
    return np.asarray(vee * scale[:, None], dtype=np.float64)


__all__ = ["IK_DAMPING", "IK_MAX_ITERATIONS", "IK_MAX_STEP", "IK_TOLERANCE", "solve_numeric"]
