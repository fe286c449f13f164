"""The straight leg (HUBO's, a chain built from its link lengths): FK(IK) round trips, an independent numerical
IK, Eq. 2, the flat-foot and scalar paths against the general one, their joint rates against J^-1 twist, and the
same closed form as Paden and Kahan's on the same axes."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.optimize import least_squares

from zmpwalk import UnreachableError
from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import leg_chains, rot_z
from zmpwalk.leg_chain import LegChain
from zmpwalk.leg_chain.paden_kahan import solve_closed

POSITION_TOL = 1e-9  # [m]
ANGLE_TOL = 1e-9  # [rad]


def _random_angles(rng, n, flat=False):
    q = np.column_stack([
        rng.uniform(-0.7, 0.7, n), rng.uniform(-0.4, 0.4, n), rng.uniform(-1.2, 0.6, n),
        rng.uniform(0.1, 1.8, n), rng.uniform(-0.8, 0.8, n), rng.uniform(-0.4, 0.4, n),
    ])
    if flat:  # a flat foot: ankle roll undoes hip roll, ankle pitch undoes hip and knee pitch
        q[:, 5] = -q[:, 1]
        q[:, 4] = -(q[:, 2] + q[:, 3])
    return q


def _branch_is_unique(chain, q):
    """The hip stays above the ankle along the foot's z axis (the solution branch of the straight closed form)."""
    thigh, shank = chain.straight.thigh, chain.straight.shank
    vx, vz = -thigh * np.sin(q[:, 3]), thigh * np.cos(q[:, 3]) + shank
    return vx * np.sin(q[:, 4]) + vz * np.cos(q[:, 4]) > 1e-3


def test_a_robot_files_legs_are_straight_chains_of_its_link_lengths(hubo):
    left, right = leg_chains(hubo)
    assert leg_chains(hubo) is leg_chains(hubo)  # built once per robot
    for chain, side in ((left, 1), (right, -1)):
        assert chain.straight == (hubo.hip_in_pelvis(side), hubo.thigh_length, hubo.shank_length)
        assert chain.closed_form and chain.label == ("left" if side > 0 else "right")


def test_a_chain_of_the_same_axes_without_link_lengths_takes_paden_kahan(hubo):
    chain = leg_chains(hubo)[0]
    imported = LegChain(1, chain.joint_names, chain.axes, chain.points, chain.ankle, reference=chain.reference)
    assert imported.straight is None and imported.closed_form
    q = _random_angles(np.random.default_rng(8), 500)
    q = q[_branch_is_unique(chain, q)]
    position, rotation = chain.fk(q)
    straight, straight_excess = chain.solve(position, rotation)
    general, general_excess = imported.solve(position, rotation)
    np.testing.assert_allclose(straight, q, atol=1e-10)
    np.testing.assert_allclose(general, straight, atol=1e-10)
    np.testing.assert_array_equal(general, solve_closed(imported, position, rotation)[0])
    assert np.all(straight_excess <= 0) and np.all(general_excess <= 0)


def test_link_lengths_that_are_not_the_chains_are_rejected(hubo):
    chain = leg_chains(hubo)[0]
    with pytest.raises(InvalidParameterError, match="link_lengths"):
        dataclasses.replace(chain, link_lengths=(chain.straight.thigh + 0.01, chain.straight.shank))
    with pytest.raises(InvalidParameterError, match="link_lengths"):
        dataclasses.replace(chain, axes=chain.axes[[2, 1, 0, 3, 4, 5]])


@pytest.mark.parametrize("robot_name", ["hubo", "mju-biped"])
@pytest.mark.parametrize("side", [1, -1])
def test_fk_of_ik_is_the_pose_for_ten_thousand_random_poses(request, robot_name, side):
    robot = request.getfixturevalue("hubo" if robot_name == "hubo" else "mju")
    chain = leg_chains(robot)[0 if side > 0 else 1]
    rng = np.random.default_rng(11 + side)
    q = _random_angles(rng, 10_000)
    position, rotation = chain.fk(q)
    angles, excess = chain.solve(position, rotation)
    assert np.all(excess <= 0)
    position2, rotation2 = chain.fk(angles)
    np.testing.assert_allclose(position2, position, atol=POSITION_TOL, rtol=0)
    np.testing.assert_allclose(rotation2, rotation, atol=ANGLE_TOL, rtol=0)
    unique = _branch_is_unique(chain, q)
    np.testing.assert_allclose(angles[unique], q[unique], atol=1e-8, rtol=0)


def test_flat_foot_ik_equals_the_general_ik_and_the_scalar_one(hubo):
    chain = leg_chains(hubo)[0]
    rng = np.random.default_rng(2)
    q = _random_angles(rng, 2000, flat=True)
    position, rotation = chain.fk(q)
    yaw = np.arctan2(rotation[:, 1, 0], rotation[:, 0, 0])
    np.testing.assert_allclose(rotation, rot_z(yaw), atol=1e-12)  # the poses are flat
    general = chain.solve(position, rotation)[0]
    fast, _, rates = chain.solve_flat(position, yaw)
    assert rates is None
    np.testing.assert_allclose(fast, general, atol=1e-12)
    for i in range(0, 2000, 97):
        np.testing.assert_allclose(chain.solve_flat_one(tuple(position[i]), float(yaw[i])), general[i], atol=1e-12)


def test_closed_form_agrees_with_an_independent_numerical_ik(mju):
    chain = leg_chains(mju)[1]
    rng = np.random.default_rng(3)
    q = _random_angles(rng, 200)
    q = q[_branch_is_unique(chain, q)]
    position, rotation = chain.fk(q)
    closed = chain.solve(position, rotation)[0]
    for i in range(len(q)):
        def residual(x, i=i):
            p, r = chain.fk(x[None, :])
            return np.concatenate([p[0] - position[i], (r[0] - rotation[i]).ravel()])

        start = q[i] + rng.normal(scale=0.05, size=6)
        numeric = least_squares(residual, start, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        np.testing.assert_allclose(numeric, closed[i], atol=1e-7)


def test_straight_walking_reduces_to_eq2_of_lim(mju):
    """Eq. 2: theta1 = 0, theta5 = -theta3 - theta4, theta6 = -theta2 for a foot parallel to the torso."""
    chain = leg_chains(mju)[0]
    rng = np.random.default_rng(4)
    targets = np.column_stack([rng.uniform(-0.05, 0.05, 500), chain.straight.hip[1] + rng.uniform(-0.03, 0.03, 500),
                               rng.uniform(-0.27, -0.2, 500)])
    q = chain.solve_flat(targets, np.zeros(500))[0]
    np.testing.assert_allclose(q[:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(q[:, 4], -q[:, 2] - q[:, 3], atol=1e-12)
    np.testing.assert_allclose(q[:, 5], -q[:, 1], atol=1e-12)


def test_jacobian_matches_finite_differences_of_fk(hubo):
    chain = leg_chains(hubo)[1]
    q = _random_angles(np.random.default_rng(5), 50)
    jacobian = chain.jacobian(q)
    h = 1e-7
    for j in range(6):
        dq = np.zeros(6)
        dq[j] = h
        p1, r1 = chain.fk(q + dq)
        p0, r0 = chain.fk(q - dq)
        np.testing.assert_allclose(jacobian[:, :3, j], (p1 - p0) / (2 * h), atol=1e-7)
        dr = (r1 - r0) / (2 * h) @ np.transpose(chain.fk(q)[1], (0, 2, 1))  # skew(omega)
        omega = np.stack([dr[:, 2, 1], dr[:, 0, 2], dr[:, 1, 0]], axis=1)
        np.testing.assert_allclose(jacobian[:, 3:, j], omega, atol=1e-6)


def test_unreachable_poses_raise_with_leg_time_and_distance(hubo):
    chain = leg_chains(hubo)[0]
    with pytest.raises(UnreachableError, match="left ankle out of reach"):
        chain.solve_flat_one((0.0, 0.085, -0.7), 0.0)
    _, excess, _ = chain.solve_flat(np.array([[0.0, 0.085, -0.7]]), np.zeros(1))
    assert excess[0] == pytest.approx(0.1, abs=1e-12)


def test_ready_posture_angles(hubo):
    """Straight legs under the hips with the knees bent: hip = ankle = -knee/2."""
    chain = leg_chains(hubo)[0]
    depth = hubo.hip_height - hubo.ankle_height
    q = chain.solve_flat_one((0.0, hubo.hip_spacing / 2, -depth + hubo.hip_drop - hubo.hip_drop), 0.0)
    knee = 2 * math.acos(depth / (2 * hubo.thigh_length))
    assert q == pytest.approx((0.0, 0.0, -knee / 2, knee, -knee / 2, 0.0), abs=1e-12)


def test_flat_foot_ik_and_rates_everywhere_in_reach_ankle_above_the_hip_included(hubo):
    """The flat-foot path's angles and rates against the rotation-matrix IK and J^-1 twist on random reachable
    targets all around the hip (above it too, where q1 and q3 turn by pi), random foot yaws up to +-3 rad and
    random twists."""
    rng = np.random.default_rng(33)
    chain = leg_chains(hubo)[0]
    n = 2000
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    targets = np.asarray(chain.straight.hip) + direction * rng.uniform(0.1, 0.58, n)[:, None]  # reach 0.6 m
    yaw = rng.uniform(-3.0, 3.0, n)
    velocity, yaw_rate = rng.normal(size=(n, 3)), rng.normal(size=n)
    angles, _, rates = chain.solve_flat(targets, yaw, velocity, yaw_rate)
    assert np.any(targets[:, 2] > chain.straight.hip[2])  # the ankle above the hip occurs
    general = chain.solve(targets, rot_z(yaw))[0]
    np.testing.assert_allclose(angles, general, atol=ANGLE_TOL)
    position, rotation = chain.fk(angles)
    np.testing.assert_allclose(position, targets, atol=POSITION_TOL)
    np.testing.assert_allclose(rotation, rot_z(yaw), atol=ANGLE_TOL)
    twist = np.column_stack([velocity, np.zeros(n), np.zeros(n), yaw_rate])
    jacobian = chain.jacobian(angles)
    well_posed = np.linalg.cond(jacobian) < 1e4  # away from the stretched and folded leg
    expected = np.linalg.solve(jacobian[well_posed], twist[well_posed][..., None])[..., 0]
    np.testing.assert_allclose(rates[well_posed], expected, rtol=1e-7, atol=1e-7)  # [rad/s]
    np.testing.assert_array_equal(chain.joint_rates(angles[well_posed], twist[well_posed]),
                                  np.linalg.solve(jacobian[well_posed], twist[well_posed][..., None])[..., 0])
