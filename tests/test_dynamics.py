"""The multibody ZMP of Eq. 3 on cases computed by hand, and against the cart-table ZMP."""

from __future__ import annotations

import numpy as np
import pytest

from zmpwalk import StepCommand, generate
from zmpwalk.dynamics import angular_momenta, compare_zmp, multibody_zmp
from zmpwalk.kinematics import rot_y

G = 9.81
TIME = np.linspace(0.0, 2.0, 4001)


def test_static_bodies_put_the_zmp_under_the_centre_of_mass():
    masses = np.array([2.0, 1.0, 3.0])
    points = np.array([[0.1, 0.0, 0.5], [-0.2, 0.1, 0.3], [0.05, -0.05, 0.1]])
    positions = np.broadcast_to(points, (len(TIME), 3, 3)).copy()
    zmp = multibody_zmp(TIME, masses, positions, np.zeros_like(positions), G)
    expected = masses @ points[:, :2] / masses.sum()
    np.testing.assert_allclose(zmp, np.broadcast_to(expected, zmp.shape), atol=1e-12)


def test_point_mass_at_constant_height_is_the_cart_table():
    """x = A sin(w t) at height h: ZMP = x - (h/g) x'' = A sin(w t) (1 + h w^2 / g)."""
    amplitude, w, h = 0.05, 3.0, 0.6
    x = amplitude * np.sin(w * TIME)
    positions = np.stack([x, 0.02 * np.ones_like(x), h * np.ones_like(x)], axis=1)[:, None, :]
    zmp = multibody_zmp(TIME, np.array([5.0]), positions, np.zeros_like(positions), G)
    expected = x * (1 + h * w * w / G)
    np.testing.assert_allclose(zmp[2:-2, 0], expected[2:-2], atol=2e-6)  # central differences, h = 0.5 ms
    np.testing.assert_allclose(zmp[:, 1], 0.02, atol=1e-12)


def test_spinning_body_shifts_the_zmp_by_its_momentum_rate():
    """A box pitching with omega = c t about its fixed centre: dL_y/dt = I_y c, x_ZMP = -I_y c / (m g)."""
    c, mass = 0.8, 4.0
    inertia = np.array([[0.02, 0.05, 0.03]])
    rotations = rot_y(0.5 * c * TIME**2)[:, None, :, :]
    momenta = angular_momenta(TIME, rotations, inertia)
    np.testing.assert_allclose(momenta[5:-5, 0, 1], 0.05 * c * TIME[5:-5], atol=1e-6)
    positions = np.zeros((len(TIME), 1, 3))
    positions[..., 2] = 0.4
    zmp = multibody_zmp(TIME, np.array([mass]), positions, momenta, G)
    np.testing.assert_allclose(zmp[5:-5, 0], -0.05 * c / (mass * G), atol=1e-6)
    np.testing.assert_allclose(zmp[:, 1], 0.0, atol=1e-9)


def test_standing_robot_zmp_is_its_centre_of_mass(hubo):
    """The final (ready) posture held for a second: Eq. 3 reduces to the centre of mass."""
    pattern = generate(hubo, [StepCommand(0.8, 0.0)], rate=500)
    last = len(pattern.time) - 1
    for name, value in list(vars(pattern).items()):
        if isinstance(value, np.ndarray) and value.shape[:1] == (last + 1,):
            setattr(pattern, name, np.repeat(value[last:], 500, axis=0))
    pattern.time = np.arange(500) / 500.0
    comparison = compare_zmp(pattern)
    np.testing.assert_allclose(comparison.multibody, comparison.center_of_mass[:, :2], atol=1e-9)
    assert comparison.center_of_mass[-1, 2] == pytest.approx(0.632, abs=0.01)  # [m] near l = 0.62 m
    assert comparison.center_of_mass[-1, 0] > 0.0  # the bent knees put the legs' mass ahead of the hips


def test_walking_difference_is_reported(hubo):
    pattern = generate(hubo, [StepCommand(0.8, 0.2)] * 4, rate=1000)
    comparison = compare_zmp(pattern)
    assert 0.0 < comparison.rms < comparison.max < 0.2  # [m]
    assert comparison.difference.shape == (len(pattern.time), 2)
