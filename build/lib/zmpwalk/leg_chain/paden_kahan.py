r"""Closed-form inverse kinematics of a leg whose three hip axes meet and whose two ankle axes meet.

Wherever the three hip axes meet in one point ``H`` and the two ankle axes meet
in one point ``A_0`` (any axis order: yaw-roll-pitch as HUBO and TALOS,
pitch-roll-yaw, ...), the leg :math:`T_{foot}(q) = e^{\hat\xi_1 q_1} \cdots
e^{\hat\xi_6 q_6} M` (:mod:`zmpwalk.leg_chain.chain`) is solved by three
subproblems of Paden and Kahan (Murray, Li and Sastry, *A Mathematical
Introduction to Robotic Manipulation*, 1994, Sec. 3.3), with the target
``g = T_d M^{-1}``:

1. the knee (subproblem 3): the hip joints turn about ``H`` and the ankle joints
   fix ``A_0``, so ``|e^{\hat\xi_4 q_4} A_0 - H| = |g A_0 - H|``;
2. the ankle (subproblem 2, two intersecting axes):
   ``e^{\hat\xi_5 q_5} e^{\hat\xi_6 q_6} (g^{-1} H) = e^{-\hat\xi_4 q_4} H``;
3. the hip (subproblem 2 on the third hip axis, then subproblem 1):
   ``e^{\hat\xi_1 q_1} e^{\hat\xi_2 q_2} e^{\hat\xi_3 q_3} = g\,(e^{\hat\xi_4 q_4} e^{\hat\xi_5 q_5}
   e^{\hat\xi_6 q_6})^{-1}``.

Each subproblem has up to two solutions; zmpwalk takes, at each, the one
nearest the leg's reference angles (the ready posture), so the knee keeps the
branch it stands in.
"""

from __future__ import annotations

import math

import numpy as np

from zmpwalk.leg_chain.geometry import ChainGeometry
from zmpwalk.leg_chain.rotations import Array, rodrigues, wrap


def solve_closed(chain: ChainGeometry, p: Array, rotation: Array) -> tuple[Array, Array]:
    """Angles (n, 6) [rad] in chain order for ankle positions ``p`` (n, 3) [m] and the chain's own rotations
    ``g`` (n, 3, 3) (the sole's target turned back by :attr:`LegChain.sole_rotation`), and per sample how far
    the target is out of reach [m] (> 0 unreachable)."""
    n = len(p)
    w, r = chain.axes, chain.points
    hip = chain.hip
    ankle0 = chain.ankle_point
    reference = chain.reference

    def g_point(x: Array) -> Array:  # g = T_d M^-1 applied to points (3,) or (n, 3)
        return np.asarray(np.einsum("nij,nj->ni", rotation, np.broadcast_to(x - chain.ankle, (n, 3))) + p)

    # 1. knee: |exp(xi4 q4) A0 - H| = delta (subproblem 3)
    delta = np.linalg.norm(g_point(ankle0) - hip, axis=1)
    u = ankle0 - r[3]
    v = hip - r[3]
    up, vp = u - w[3] * (w[3] @ u), v - w[3] * (w[3] @ v)
    along = float(w[3] @ (ankle0 - hip))
    delta_p2 = delta * delta - along * along
    delta_p = np.sqrt(np.maximum(delta_p2, 0.0))
    lu, lv = float(np.linalg.norm(up)), float(np.linalg.norm(vp))
    excess = np.maximum(delta_p - (lu + lv), abs(lu - lv) - delta_p)
    theta0 = math.atan2(float(w[3] @ np.cross(up, vp)), float(up @ vp))
    phi = np.arccos(np.clip((lu * lu + lv * lv - delta_p2) / (2 * lu * lv), -1.0, 1.0))
    q4 = _nearest([wrap(theta0 + phi), wrap(theta0 - phi)], reference[3])
    # 2. ankle: exp(xi5 q5) exp(xi6 q6) (g^-1 H) = exp(-xi4 q4) H (subproblem 2 about A0)
    h_seen = np.einsum("nji,nj->ni", rotation, hip - p) + chain.ankle  # g^-1 H
    knee_back = np.einsum("nij,j->ni", rodrigues(w[3], -q4), hip - r[3]) + r[3]
    solutions, _ = _subproblem2(w[4], w[5], h_seen - ankle0, knee_back - ankle0)
    choice = _pick(solutions, reference[4], reference[5])
    q5, q6 = choice
    # 3. hip: R1 R2 R3 = R_d (R4 R5 R6)^T (subproblem 2 on axis 3, then subproblem 1)
    lower = rodrigues(w[3], q4) @ rodrigues(w[4], q5) @ rodrigues(w[5], q6)
    hip_rotation = rotation @ np.swapaxes(lower, 1, 2)
    target = hip_rotation @ w[2]
    solutions, _ = _subproblem2(w[0], w[1], np.broadcast_to(w[2], (n, 3)), target)
    q1, q2 = _pick(solutions, reference[0], reference[1])
    perpendicular = np.cross(w[2], np.eye(3)[int(np.argmin(np.abs(w[2])))])
    perpendicular /= np.linalg.norm(perpendicular)
    upper = rodrigues(w[0], q1) @ rodrigues(w[1], q2)
    seen = np.einsum("nji,njk,k->ni", upper, hip_rotation, perpendicular)  # (R1 R2)^T R_hip x
    q3 = _subproblem1(w[2], np.broadcast_to(perpendicular, (n, 3)), seen)
    angles = np.column_stack([q1, q2, q3, q4, q5, q6])
    # Where the ankle cannot turn the foot as asked (no exact solution), report the residual.
    position, _ = chain.fk_chain(angles)
    residual = np.linalg.norm(position - p, axis=1)
    excess = np.where(excess > 0, excess, np.where(residual > 1e-6, residual, excess))
    return angles, excess


def _nearest(candidates: list[Array], reference: float) -> Array:
    """Per sample, the candidate angle (each (n,)) nearest ``reference`` (wrap-aware)."""
    stacked = np.stack(candidates)
    distance = np.abs(wrap(stacked - reference))
    return np.asarray(stacked[np.argmin(distance, axis=0), np.arange(stacked.shape[1])], dtype=np.float64)


def _subproblem1(axis: Array, u: Array, v: Array) -> Array:
    """Angle about ``axis`` (3,) taking vectors ``u`` to ``v`` (n, 3) (Paden-Kahan 1; projections)."""
    up = u - np.outer(u @ axis, axis)
    vp = v - np.outer(v @ axis, axis)
    return np.asarray(np.arctan2(np.einsum("ni,ni->n", np.cross(up, vp), np.broadcast_to(axis, up.shape)),
                                 np.einsum("ni,ni->n", up, vp)), dtype=np.float64)


def _subproblem2(axis1: Array, axis2: Array, u: Array, v: Array) -> tuple[list[tuple[Array, Array]], Array]:
    """``exp(axis1 t1) exp(axis2 t2) u = v`` for vectors (n, 3) about axes through one point (Paden-Kahan 2).

    Returns:
        The two solutions ``(t1, t2)`` and ``gamma^2`` (< 0 where none exists; the nearest is taken there).
    """
    w12 = float(axis1 @ axis2)
    cross = np.cross(axis1, axis2)
    denominator = w12 * w12 - 1.0
    a = (w12 * (u @ axis2) - v @ axis1) / denominator
    b = (w12 * (v @ axis1) - u @ axis2) / denominator
    gamma2 = (np.einsum("ni,ni->n", u, u) - a * a - b * b - 2 * a * b * w12) / float(cross @ cross)
    gamma = np.sqrt(np.maximum(gamma2, 0.0))
    solutions = []
    for sign in (1.0, -1.0):
        z = np.outer(a, axis1) + np.outer(b, axis2) + np.outer(sign * gamma, cross)
        solutions.append((_subproblem1(axis1, z, v), _subproblem1(axis2, u, z)))
    return solutions, np.asarray(gamma2, dtype=np.float64)


def _pick(solutions: list[tuple[Array, Array]], reference1: float, reference2: float) -> tuple[Array, Array]:
    """The solution pair nearest the reference angles, per sample."""
    cost = np.stack([np.abs(wrap(a - reference1)) + np.abs(wrap(b - reference2)) for a, b in solutions])
    best = np.argmin(cost, axis=0)
    first = np.where(best == 0, solutions[0][0], solutions[1][0])
    second = np.where(best == 0, solutions[0][1], solutions[1][1])
    return first, second


__all__ = ["solve_closed"]
