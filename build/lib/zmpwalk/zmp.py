"""ZMP of the cart-table (inverted pendulum) model, its boundary maps, and support polygons.

Section 2 of Park et al. (2008). With the pelvis at constant height ``l`` the
ZMP is (Eqs. 1-2)

.. math:: x_{zmp} = x - \\frac{l}{g} \\ddot x .

A cubic pelvis therefore has a cubic ZMP, and the boundary values (position,
velocity at both ends) of the two map linearly onto each other (Eq. 7 for one
interval, Eq. 9 for the half intervals of the lateral sway). The paper prints
the maps with time in units of the step time (T = 1 s). For an interval of
``T`` seconds the acceleration of a cubic in ``s = t/T`` is ``x_ss / T^2``, so
``l/g`` becomes ``kappa = l/(g T^2)`` in the normalised map; in physical units
(velocities in m/s) the map is ``D^-1 M(kappa) D`` with ``D = diag(1, T, 1, T)``.
Eq. 9 is the same map for an interval of ``T/2`` (velocities still per unit
step time), which :func:`half_interval_zmp_map` reproduces.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError

Array = NDArray[np.float64]

# Eq. 4: coefficients [b3, b2, b1, b0] of a cubic on [0, 1] from [x0, x0', x1, x1'].
CUBIC_FROM_BOUNDARY = np.array([[2.0, 1.0, -2.0, 1.0], [-3.0, -2.0, 3.0, -1.0], [0.0, 1.0, 0.0, 0.0],
                                [1.0, 0.0, 0.0, 0.0]])
# Left-hand matrix of Eq. 4 (its inverse is CUBIC_FROM_BOUNDARY).
BOUNDARY_FROM_CUBIC = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 0.0], [1.0, 1.0, 1.0, 1.0],
                                [3.0, 2.0, 1.0, 0.0]])
# Eq. 8, first interval [0, 1/2]: coefficients from [y0, y0', y_1/2, y_1/2'].
CUBIC_FROM_HALF_BOUNDARY_FIRST = np.array([[16.0, 4.0, -16.0, 4.0], [-12.0, -4.0, 12.0, -2.0],
                                           [0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]])
# Eq. 8, second interval [1/2, 1]: coefficients from [y_1/2, y_1/2', y1, y1'].
CUBIC_FROM_HALF_BOUNDARY_SECOND = np.array([[16.0, 4.0, -16.0, 4.0], [-36.0, -10.0, 36.0, -8.0],
                                            [24.0, 8.0, -24.0, 5.0], [-4.0, -2.0, 5.0, -1.0]])


def normalized_zmp_map(kappa: float) -> Array:
    """Eq. 7 with ``l/g`` replaced by ``kappa``: ZMP boundary from pelvis boundary, unit-time interval.

    .. math::
        M(\\kappa) = \\begin{bmatrix} 1+6\\kappa & 4\\kappa & -6\\kappa & 2\\kappa \\\\
        -12\\kappa & 1-6\\kappa & 12\\kappa & -6\\kappa \\\\
        -6\\kappa & -2\\kappa & 1+6\\kappa & -4\\kappa \\\\
        -12\\kappa & -6\\kappa & 12\\kappa & 1-6\\kappa \\end{bmatrix}
    """
    k = kappa
    return np.array([
        [1 + 6 * k, 4 * k, -6 * k, 2 * k],
        [-12 * k, 1 - 6 * k, 12 * k, -6 * k],
        [-6 * k, -2 * k, 1 + 6 * k, -4 * k],
        [-12 * k, -6 * k, 12 * k, 1 - 6 * k],
    ])


def zmp_from_pelvis_boundary(duration: float, pendulum_length: float, gravity: float = 9.81) -> Array:
    """Map pelvis boundary values to ZMP boundary values for an interval of ``duration`` seconds.

    Both vectors are ``[x(0) [m], x'(0) [m/s], x(T) [m], x'(T) [m/s]]``. At
    ``duration = 1`` s this is the printed Eq. 7.

    Raises:
        InvalidParameterError: A non-positive duration, length or gravity.
    """
    for name, value in (("duration", duration), ("pendulum_length", pendulum_length), ("gravity", gravity)):
        if not np.isfinite(value) or value <= 0:
            raise InvalidParameterError(name, value, "a finite value > 0")
    kappa = pendulum_length / (gravity * duration**2)  # l/(g T^2), the time-scaled l/g of Eq. 7
    scale = np.diag([1.0, duration, 1.0, duration])  # physical -> per unit normalised time
    return np.asarray(np.linalg.solve(scale, normalized_zmp_map(kappa) @ scale), dtype=np.float64)


def zmp_from_pelvis_boundary_quintic(duration: float, pendulum_length: float, gravity: float = 9.81) -> Array:
    r"""The boundary map of Eq. 7 for the quintic pelvis (:func:`zmpwalk.curves.hermite_quintic`), any step time.

    With zero pelvis acceleration at both ends the ZMP there is the pelvis itself; its slope is
    :math:`\dot z = \dot x - (l/g)\dddot x` with the quintic's end jerks (per unit normalised time
    :math:`60\Delta - 36 m_0 - 24 m_1` at the start and :math:`60\Delta - 24 m_0 - 36 m_1` at the end,
    :math:`\Delta = x_1 - x_0`). With :math:`\kappa = l / (g T^2)`, per unit normalised time:

    .. math::
        \begin{bmatrix} z_0 \\ z_0' \\ z_1 \\ z_1' \end{bmatrix} =
        \begin{bmatrix} 1 & 0 & 0 & 0 \\ 60\kappa & 1 + 36\kappa & -60\kappa & 24\kappa \\
        0 & 0 & 1 & 0 \\ 60\kappa & 24\kappa & -60\kappa & 1 + 36\kappa \end{bmatrix}
        \begin{bmatrix} x_0 \\ x_0' \\ x_1 \\ x_1' \end{bmatrix}

    Args:
        duration: Step time ``T`` [s] (> 0).
        pendulum_length: ``l`` [m] (> 0).
        gravity: [m/s^2] (> 0).

    Returns:
        (4, 4) map from ``[x0, v0, x1, v1]`` to ``[z0, z0_dot, z1, z1_dot]`` in SI ([m], [m/s]).
    """
    for name, value in (("duration", duration), ("pendulum_length", pendulum_length), ("gravity", gravity)):
        if not np.isfinite(value) or value <= 0:
            raise InvalidParameterError(name, value, "a finite value > 0")
    kappa = pendulum_length / (gravity * duration**2)
    normalized = np.array([
        [1.0, 0.0, 0.0, 0.0],
        [60.0 * kappa, 1.0 + 36.0 * kappa, -60.0 * kappa, 24.0 * kappa],
        [0.0, 0.0, 1.0, 0.0],
        [60.0 * kappa, 24.0 * kappa, -60.0 * kappa, 1.0 + 36.0 * kappa],
    ])
    scale = np.diag([1.0, duration, 1.0, duration])  # physical -> per unit normalised time
    return np.asarray(np.linalg.solve(scale, normalized @ scale), dtype=np.float64)


def pelvis_from_zmp_boundary(duration: float, pendulum_length: float, gravity: float = 9.81) -> Array:
    """Inverse of :func:`zmp_from_pelvis_boundary`: pelvis boundary values from a designed ZMP."""
    return np.asarray(np.linalg.inv(zmp_from_pelvis_boundary(duration, pendulum_length, gravity)), dtype=np.float64)


def half_interval_zmp_map(pendulum_length_over_gravity: float) -> Array:
    """Eq. 9: the ZMP map of a half step, velocities per unit (whole) step time.

    Derived as Eq. 7 on an interval of length 1/2: ``kappa = 4 l/g`` and the
    velocities rescaled by 2; the result is the printed matrix with entries
    ``24 l/g``, ``8 l/g``, ``96 l/g``, ``4 l/g``.
    """
    kappa = 4.0 * pendulum_length_over_gravity
    scale = np.diag([1.0, 0.5, 1.0, 0.5])  # per unit step time -> per unit half-step time
    return np.asarray(np.linalg.solve(scale, normalized_zmp_map(kappa) @ scale), dtype=np.float64)


def cart_table_zmp(position: Array, acceleration: Array, pendulum_length: float, gravity: float = 9.81) -> Array:
    """Eqs. 1-2: ZMP of a point mass at constant height ``l`` [m], from position [m] and acceleration [m/s^2]."""
    return np.asarray(position) - (pendulum_length / gravity) * np.asarray(acceleration)


def convex_hull(points: Array) -> Array:
    """Convex hull of 2-D points, counter-clockwise, without repeated or collinear points (monotone chain)."""
    pts = sorted({(float(x), float(y)) for x, y in np.asarray(points, dtype=float)})
    if len(pts) <= 2:
        return np.array(pts)

    def cross(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list[tuple[float, float]] = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def signed_margin(points: Array, polygon: Array) -> Array:
    """Signed distance of points to a convex polygon's boundary [m]: > 0 inside, < 0 outside.

    Args:
        points: Shape (n, 2).
        polygon: Convex polygon, counter-clockwise, shape (m, 2).
    """
    pts = np.atleast_2d(points)
    a = polygon
    b = np.roll(polygon, -1, axis=0)
    edge = b - a
    length = np.linalg.norm(edge, axis=1)
    normal_in = np.stack([-edge[:, 1], edge[:, 0]], axis=1) / length[:, None]  # left of a CCW edge
    rel = pts[:, None, :] - a[None, :, :]
    inside_distance = np.einsum("nmk,mk->nm", rel, normal_in)
    inside = np.all(inside_distance >= 0, axis=1)
    along = np.clip(np.einsum("nmk,mk->nm", rel, edge) / (length**2)[None, :], 0.0, 1.0)
    nearest = a[None, :, :] + along[:, :, None] * edge[None, :, :]
    outside_distance = np.min(np.linalg.norm(pts[:, None, :] - nearest, axis=2), axis=1)
    return np.asarray(np.where(inside, np.min(inside_distance, axis=1), -outside_distance), dtype=np.float64)


def point_margin(x: float, y: float, polygon: Sequence[tuple[float, float]]) -> float:
    """:func:`signed_margin` of one point [m] in plain Python floats (a few microseconds; for planners that
    check a handful of points, where numpy's per-call overhead would dominate).

    Args:
        x, y: The point [m].
        polygon: Convex polygon's vertices, counter-clockwise [m].
    """
    inside, outside = math.inf, math.inf
    count = len(polygon)
    for index in range(count):
        ax, ay = polygon[index]
        bx, by = polygon[(index + 1) % count]
        ex, ey = bx - ax, by - ay
        length2 = ex * ex + ey * ey
        rx, ry = x - ax, y - ay
        inside = min(inside, (ex * ry - ey * rx) / math.sqrt(length2))  # left of a CCW edge: inside
        along = min(max((rx * ex + ry * ey) / length2, 0.0), 1.0)
        outside = min(outside, math.hypot(rx - along * ex, ry - along * ey))
    return inside if inside >= 0.0 else -outside


def hull_edges(vertices: Array) -> tuple[Array, Array, NDArray[np.bool_]]:
    """Counter-clockwise convex-hull edges of many small vertex sets at once.

    Args:
        vertices: (p, m, 2) [m], any order, repeated points allowed, at least three not collinear per set.

    Returns:
        ``(start, edge, valid)``: each set's edges as start points (p, q, 2) [m] and edge vectors
        (p, q, 2) [m], ``valid`` (p, q) marking the real ones (sets have different edge counts).

    A directed pair (i, j) of distinct points is a hull edge when no point lies on its right
    and none lies on the segment between them (collinear points split a side into edges).
    """
    p, m = vertices.shape[:2]
    same = np.all(np.abs(vertices[:, :, None, :] - vertices[:, None, :, :]) <= 1e-12, axis=3)
    first = np.argmax(same, axis=2) == np.arange(m)  # (p, m): the first of equal points
    i, j = np.where(~np.eye(m, dtype=bool))
    a, b = vertices[:, i], vertices[:, j]  # (p, pairs, 2)
    edge = b - a
    rel = vertices[:, None, :, :] - a[:, :, None, :]  # (p, pairs, m, 2)
    cross = edge[..., None, 0] * rel[..., 1] - edge[..., None, 1] * rel[..., 0]
    length = np.hypot(edge[..., 0], edge[..., 1])
    scale = np.maximum(length, 1e-12)
    tolerance = 1e-12 * scale[..., None]
    along = (edge[..., None, 0] * rel[..., 0] + edge[..., None, 1] * rel[..., 1]) / scale[..., None] ** 2
    between = (np.abs(cross) <= tolerance) & (along > 1e-12) & (along < 1.0 - 1e-12) & first[:, None, :]
    valid = (np.all(cross >= -tolerance, axis=2) & ~np.any(between, axis=2) & (length > 1e-12)
             & first[:, i] & first[:, j])
    width = max(1, int(valid.sum(axis=1).max()) if p else 1)
    order = np.argsort(~valid, axis=1, kind="stable")[:, :width]
    start = np.take_along_axis(a, order[..., None], axis=1)
    edge = np.take_along_axis(edge, order[..., None], axis=1)
    return start, edge, np.take_along_axis(valid, order, axis=1)


def edge_margin(points: Array, start: Array, edge: Array, valid: NDArray[np.bool_]) -> Array:
    """Signed distance of each point to its own convex polygon given by edges [m] (> 0 inside).

    Args:
        points: (n, 2) [m].
        start, edge, valid: (n, q, 2), (n, q, 2), (n, q): each point's polygon as from :func:`hull_edges`.

    Inside, the margin is the smallest distance to the edges' lines; outside, minus the
    distance to the nearest edge segment.
    """
    px = points[:, 0:1] - start[..., 0]
    py = points[:, 1:2] - start[..., 1]
    ex, ey = edge[..., 0], edge[..., 1]
    scale = np.maximum(np.hypot(ex, ey), 1e-12)
    line = (ex * py - ey * px) / scale
    along = np.clip((px * ex + py * ey) / scale**2, 0.0, 1.0)
    segment = np.hypot(px - along * ex, py - along * ey)
    inside = np.all(line >= 0, axis=1, where=valid)
    line_min = np.min(line, axis=1, where=valid, initial=np.inf)
    segment_min = np.min(segment, axis=1, where=valid, initial=np.inf)
    return np.asarray(np.where(inside, line_min, -segment_min), dtype=np.float64)


def batch_hull_margin(points: Array, vertices: Array) -> Array:
    """:func:`signed_margin` of one point to the convex hull of its own vertex set, for many at once.

    Args:
        points: (n, 2) [m].
        vertices: (n, m, 2) [m], any order, repeated points allowed, at least three not collinear.

    Returns:
        (n,) signed distances [m], > 0 inside.

    No hull is built. With the hull's support function ``h(u) = max_k u . v_k``, a point ``x`` inside lies
    ``min_u h(u) - u . x`` from the boundary, the minimum taken at an edge's outward normal; every hull
    edge joins two of the vertices, so the normals of all vertex pairs, both ways, hold the minimiser, and
    any other direction gives a larger value. The point is outside when that minimum is negative, and its
    distance is then the least distance to a segment between two vertices (each lies in the hull, and
    the hull's edges are among them).

    .. math:: d(x) = \\min_{(i, j)} \\min_{\\pm} \\left( h(\\pm u_{ij}) \\mp u_{ij} \\cdot x \\right)
    """
    m = vertices.shape[1]
    i, j = np.triu_indices(m, 1)
    start = vertices[:, i]  # (n, pairs, 2)
    edge = vertices[:, j] - start
    length = np.hypot(edge[..., 0], edge[..., 1])
    distinct = length > 1e-12
    scale = np.where(distinct, length, 1.0)
    ux, uy = edge[..., 1] / scale, -edge[..., 0] / scale  # one unit normal of each pair's line
    projection = ux[..., None] * vertices[:, None, :, 0] + uy[..., None] * vertices[:, None, :, 1]
    point = ux * points[:, 0:1] + uy * points[:, 1:2]
    inner = np.minimum(projection.max(axis=2) - point, point - projection.min(axis=2))
    inner = np.min(inner, axis=1, where=distinct, initial=np.inf)
    margin = np.asarray(inner, dtype=np.float64)
    out = inner < 0.0
    if out.any():
        start, edge, scale = start[out], edge[out], scale[out]
        rx, ry = points[out, 0:1] - start[..., 0], points[out, 1:2] - start[..., 1]
        along = np.clip((rx * edge[..., 0] + ry * edge[..., 1]) / scale**2, 0.0, 1.0)
        margin[out] = -np.min(np.hypot(rx - along * edge[..., 0], ry - along * edge[..., 1]), axis=1)
    return margin
