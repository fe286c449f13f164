"""Section 2 of Park et al. (2008): Eqs. 4, 7, 8, 9 and their time scaling; support polygons."""

from __future__ import annotations

import numpy as np
import pytest

from zmpwalk import StepCommand, generate
from zmpwalk import zmp as zmp_maps

L_OVER_G = 0.063  # an arbitrary l/g [s^2] for the printed (T = 1 s) matrices


def test_eq4_matrices_are_inverse():
    np.testing.assert_allclose(zmp_maps.CUBIC_FROM_BOUNDARY @ zmp_maps.BOUNDARY_FROM_CUBIC, np.eye(4), atol=1e-15)


def test_eq8_matrices_are_the_printed_inverses():
    first = np.array([[0, 0, 0, 1], [0, 0, 1, 0], [1 / 8, 1 / 4, 1 / 2, 1], [3 / 4, 1, 1, 0]])
    second = np.array([[1 / 8, 1 / 4, 1 / 2, 1], [3 / 4, 1, 1, 0], [1, 1, 1, 1], [3, 2, 1, 0]])
    np.testing.assert_allclose(np.linalg.inv(first), zmp_maps.CUBIC_FROM_HALF_BOUNDARY_FIRST, atol=1e-12)
    np.testing.assert_allclose(np.linalg.inv(second), zmp_maps.CUBIC_FROM_HALF_BOUNDARY_SECOND, atol=1e-12)


def test_eq7_at_one_second_is_the_printed_matrix():
    k = L_OVER_G
    printed = np.array([
        [1 + 6 * k, 4 * k, -6 * k, 2 * k],
        [-12 * k, 1 - 6 * k, 12 * k, -6 * k],
        [-6 * k, -2 * k, 1 + 6 * k, -4 * k],
        [-12 * k, -6 * k, 12 * k, 1 - 6 * k],
    ])
    np.testing.assert_allclose(zmp_maps.zmp_from_pelvis_boundary(1.0, k * 9.81, 9.81), printed, atol=1e-14)


def test_eq7_follows_from_eq6_coefficient_matching():
    """ZMP cubic b = a - (l/g)[0, 0, 6 a3, 2 a2] (Eq. 6), boundary values by Eq. 4."""
    rng = np.random.default_rng(7)
    pelvis = rng.normal(size=4)
    a3, a2, a1, a0 = zmp_maps.CUBIC_FROM_BOUNDARY @ pelvis
    b = np.array([a3, a2, a1 - 6 * a3 * L_OVER_G, a0 - 2 * a2 * L_OVER_G])
    expected = zmp_maps.normalized_zmp_map(L_OVER_G) @ pelvis
    np.testing.assert_allclose(zmp_maps.BOUNDARY_FROM_CUBIC @ b, expected, atol=1e-14)


def test_eq9_is_the_printed_matrix():
    k = L_OVER_G
    printed = np.array([
        [1 + 24 * k, 8 * k, -24 * k, 4 * k],
        [-96 * k, 1 - 24 * k, 96 * k, -24 * k],
        [-24 * k, -4 * k, 1 + 24 * k, -8 * k],
        [-96 * k, -24 * k, 96 * k, 1 - 24 * k],
    ])
    np.testing.assert_allclose(zmp_maps.half_interval_zmp_map(k), printed, atol=1e-13)


def test_zmp_and_pelvis_maps_are_inverse():
    forward = zmp_maps.zmp_from_pelvis_boundary(0.8, 0.62)
    np.testing.assert_allclose(forward @ zmp_maps.pelvis_from_zmp_boundary(0.8, 0.62), np.eye(4), atol=1e-12)


@pytest.mark.parametrize("duration", [0.6, 0.7, 0.8, 0.95, 1.3])
def test_time_scaled_eq7_matches_finite_differences_of_the_pattern(hubo, duration):
    """For any T, the map predicts the ZMP boundary values of the sampled pelvis x (step 3: b = f = 0.15)."""
    rate = 1000.0
    pattern = generate(hubo, [StepCommand(duration, 0.15)] * 4, rate=rate)
    step = [s for s in pattern.steps if s.kind == "step"][2]
    t1, t2 = step.start, step.start + step.duration
    i1, i2 = round(t1 * rate), round(t2 * rate)
    assert pattern.time[i1] == pytest.approx(t1, abs=1e-9) and pattern.time[i2] == pytest.approx(t2, abs=1e-9)
    x = pattern.position_pelvis_in_world[:, 0]
    v = pattern.velocity_pelvis_in_world[:, 0]
    h = 1.0 / rate
    l_over_g = hubo.pendulum_length / hubo.gravity
    # Central second differences are exact for a cubic; stay one sample inside the step.
    idx = np.arange(i1 + 1, i2)
    zmp = x[idx] - l_over_g * (x[idx + 1] - 2 * x[idx] + x[idx - 1]) / h**2
    # ZMP boundary values by extrapolating the (cubic) ZMP samples to the step ends.
    tt = pattern.time[idx]
    coefficients = np.polyfit(tt - t1, zmp, 3)
    measured = np.array([
        np.polyval(coefficients, 0.0), np.polyval(np.polyder(coefficients), 0.0),
        np.polyval(coefficients, duration), np.polyval(np.polyder(coefficients), duration),
    ])
    pelvis = np.array([x[i1], v[i1], x[i2], v[i2]])  # velocity is continuous at the step ends
    predicted = zmp_maps.zmp_from_pelvis_boundary(duration, hubo.pendulum_length, hubo.gravity) @ pelvis
    np.testing.assert_allclose(measured[[0, 2]], predicted[[0, 2]], atol=1e-6)  # [m]
    np.testing.assert_allclose(measured[[1, 3]], predicted[[1, 3]], atol=1e-5)  # [m/s]
    # The printed T = 1 s form is wrong here unless T = 1 (READING-NOTES): check it differs.
    if abs(duration - 1.0) > 0.1:
        unscaled = zmp_maps.normalized_zmp_map(l_over_g) @ (pelvis * [1, duration, 1, duration])
        assert abs(unscaled[0] - measured[0]) > 1e-3


def test_signed_margin_of_a_square():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    points = np.array([[0.5, 0.5], [0.9, 0.5], [1.5, 0.5], [2.0, 2.0], [0.0, 0.3]])
    np.testing.assert_allclose(zmp_maps.signed_margin(points, square), [0.5, 0.1, -0.5, -np.sqrt(2), 0.0], atol=1e-12)


def test_convex_hull_of_two_feet_is_counter_clockwise():
    points = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [2, 0.5]], dtype=float)
    hull = zmp_maps.convex_hull(points)
    assert len(hull) == 5
    x, y = hull[:, 0], hull[:, 1]
    assert 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y) > 0  # positive area: CCW


def test_hull_edges_margin_equals_the_hull_polygons_margin():
    """Many vertex sets at once (two soles, one sole twice, collinear sides) against convex_hull + signed_margin."""
    rng = np.random.default_rng(7)
    square = np.array([[0.0, 0.0], [0.2, 0.0], [0.2, 0.1], [0.0, 0.1]])
    sets = []
    for k in range(60):
        shift = rng.uniform(-0.3, 0.3, 2) if k % 3 else np.array([0.0, 0.2])  # every third: aligned feet
        angle = rng.uniform(-0.5, 0.5) if k % 3 else 0.0
        c, s = np.cos(angle), np.sin(angle)
        other = square @ np.array([[c, s], [-s, c]]) + shift
        sets.append(np.vstack([square, square if k % 5 == 0 else other]))
    vertices = np.array(sets)
    points = rng.uniform(-0.4, 0.6, (60, 2))
    expected = [zmp_maps.signed_margin(points[k:k + 1], zmp_maps.convex_hull(vertices[k]))[0] for k in range(60)]
    np.testing.assert_allclose(zmp_maps.batch_hull_margin(points, vertices), expected, atol=1e-12)  # [m]


@pytest.mark.parametrize("duration", [0.35, 0.7, 1.0, 1.6])
def test_quintic_boundary_map_against_the_sampled_curve(duration):
    """zmp_from_pelvis_boundary_quintic against z = x - (l/g) x'' of hermite_quintic, differentiated numerically."""
    from zmpwalk.curves import hermite_quintic

    length = 0.62  # [m]
    l_over_g = length / 9.81
    rng = np.random.default_rng(8)
    for _ in range(20):
        x0, v0, x1, v1 = rng.uniform(-0.2, 0.2, 4)  # [m], [m/s]

        def zmp(t, x0=x0, v0=v0, x1=x1, v1=v1):
            value, _, curvature = hermite_quintic(x0, v0 * duration, x1, v1 * duration, t / duration)
            return value - l_over_g * curvature / duration**2

        h = 1e-6
        measured = np.array([zmp(0.0), (zmp(h) - zmp(0.0)) / h, zmp(duration), (zmp(duration) - zmp(duration - h)) / h])
        predicted = zmp_maps.zmp_from_pelvis_boundary_quintic(duration, length) @ np.array([x0, v0, x1, v1])
        np.testing.assert_allclose(measured[[0, 2]], predicted[[0, 2]], atol=1e-12)  # [m]: z = x at the ends
        np.testing.assert_allclose(measured[[1, 3]], predicted[[1, 3]], rtol=1e-3, atol=1e-4)  # [m/s]


def test_point_margin_equals_signed_margin():
    """The plain-Python margin of one point against the vectorised one: random hulls and points, inside and out."""
    from zmpwalk.zmp import convex_hull, point_margin, signed_margin

    rng = np.random.default_rng(21)
    for _ in range(200):
        polygon = convex_hull(rng.uniform(-0.2, 0.2, (8, 2)))
        point = rng.uniform(-0.3, 0.3, 2)
        expected = float(signed_margin(point[None, :], polygon)[0])
        vertices = [(float(x), float(y)) for x, y in polygon]
        assert point_margin(float(point[0]), float(point[1]), vertices) == pytest.approx(expected, abs=1e-12)

