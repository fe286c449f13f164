"""The elementary curves: end values, and derivatives against finite differences."""

from __future__ import annotations

import numpy as np
import pytest

from zmpwalk import curves

H = 1e-6  # finite-difference step
S = np.linspace(0.01, 0.99, 57)


def _check_derivatives(function, s=S, tol=1e-6):
    _, slope, curvature = function(s)
    numeric_slope = (function(s + H)[0] - function(s - H)[0]) / (2 * H)
    numeric_curvature = (function(s + H)[1] - function(s - H)[1]) / (2 * H)
    np.testing.assert_allclose(slope, numeric_slope, atol=tol)
    np.testing.assert_allclose(curvature, numeric_curvature, atol=tol * 10)


@pytest.mark.parametrize("function", [curves.cycloid, curves.cosine_blend, curves.smoothstep5])
def test_unit_ramps_go_from_zero_to_one_at_rest(function):
    value, slope, _ = function(np.array([0.0, 1.0]))
    np.testing.assert_allclose(value, [0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(slope, [0.0, 0.0], atol=1e-12)
    _check_derivatives(function)


def test_smoothstep_has_zero_curvature_at_both_ends():  # Eq. 17 of Lim et al.
    _, _, curvature = curves.smoothstep5(np.array([0.0, 1.0]))
    np.testing.assert_allclose(curvature, 0.0, atol=1e-12)


def test_hermite_cubic_meets_its_boundary_values_and_derivatives():
    rng = np.random.default_rng(1)
    p0, m0, p1, m1 = rng.normal(size=4)

    def cubic(s):
        return curves.hermite_cubic(p0, m0, p1, m1, s)

    value, slope, _ = cubic(np.array([0.0, 1.0]))
    np.testing.assert_allclose(value, [p0, p1], atol=1e-14)
    np.testing.assert_allclose(slope, [m0, m1], atol=1e-14)
    _check_derivatives(cubic)


@pytest.mark.parametrize("u", [0.3, 0.425, 0.47, 0.5, 0.7])
def test_lift_profile_is_c2_with_apex_at_u(u):  # Fig. 12 of Park et al.
    s = np.array([0.0, u, 1.0])
    value, slope, curvature = curves.lift_profile(s, u)
    np.testing.assert_allclose(value, [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(slope, 0.0, atol=1e-12)
    np.testing.assert_allclose(curvature, 0.0, atol=1e-9)
    grid = np.linspace(0.0, 1.0, 2001)
    assert curves.lift_profile(grid, u)[0].max() <= 1.0 + 1e-15
    assert grid[np.argmax(curves.lift_profile(grid, u)[0])] == pytest.approx(u, abs=1e-3)
    _check_derivatives(lambda x: curves.lift_profile(x, u), s=S[np.abs(S - u) > 2 * H])
