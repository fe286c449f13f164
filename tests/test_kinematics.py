"""Leg kinematics: FK(IK) round trips, an independent numerical IK, Eq. 2, Jacobian, joint trajectories."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import least_squares

from zmpwalk import StepCommand, UnreachableError, generate
from zmpwalk.kinematics import (
    JointLimitError,
    Leg,
    check_joint_limits,
    leg_fk,
    leg_ik,
    leg_ik_scalar,
    leg_ik_yaw,
    leg_jacobian,
    pattern_joint_trajectory,
    rot_z,
)

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


def _branch_is_unique(leg, q):
    """The hip stays above the ankle along the foot's z axis (the solution branch of leg_ik)."""
    vx, vz = -leg.thigh * np.sin(q[:, 3]), leg.thigh * np.cos(q[:, 3]) + leg.shank
    return vx * np.sin(q[:, 4]) + vz * np.cos(q[:, 4]) > 1e-3


@pytest.mark.parametrize("robot_name", ["hubo", "mju-biped"])
@pytest.mark.parametrize("side", [1, -1])
def test_fk_of_ik_is_the_pose_for_ten_thousand_random_poses(request, robot_name, side):
    robot = request.getfixturevalue("hubo" if robot_name == "hubo" else "mju")
    leg = Leg.of(robot, side)
    rng = np.random.default_rng(11 + side)
    q = _random_angles(rng, 10_000)
    position, rotation = leg_fk(leg, q)
    solution = leg_ik(leg, position, rotation)
    assert np.all(solution.reachable)
    position2, rotation2 = leg_fk(leg, solution.angles)
    np.testing.assert_allclose(position2, position, atol=POSITION_TOL, rtol=0)
    np.testing.assert_allclose(rotation2, rotation, atol=ANGLE_TOL, rtol=0)
    unique = _branch_is_unique(leg, q)
    np.testing.assert_allclose(solution.angles[unique], q[unique], atol=1e-8, rtol=0)


def test_flat_foot_ik_equals_the_general_ik_and_the_scalar_one(hubo):
    leg = Leg.of(hubo, 1)
    rng = np.random.default_rng(2)
    q = _random_angles(rng, 2000, flat=True)
    position, rotation = leg_fk(leg, q)
    yaw = np.arctan2(rotation[:, 1, 0], rotation[:, 0, 0])
    np.testing.assert_allclose(rotation, rot_z(yaw), atol=1e-12)  # the poses are flat
    general = leg_ik(leg, position, rotation).angles
    fast = leg_ik_yaw(leg, position, yaw).angles
    np.testing.assert_allclose(fast, general, atol=1e-12)
    for i in range(0, 2000, 97):
        np.testing.assert_allclose(leg_ik_scalar(leg, tuple(position[i]), float(yaw[i])), general[i], atol=1e-12)


def test_closed_form_agrees_with_an_independent_numerical_ik(mju):
    leg = Leg.of(mju, -1)
    rng = np.random.default_rng(3)
    q = _random_angles(rng, 200)
    q = q[_branch_is_unique(leg, q)]
    position, rotation = leg_fk(leg, q)
    closed = leg_ik(leg, position, rotation).angles
    for i in range(len(q)):
        def residual(x, i=i):
            p, r = leg_fk(leg, x[None, :])
            return np.concatenate([p[0] - position[i], (r[0] - rotation[i]).ravel()])

        start = q[i] + rng.normal(scale=0.05, size=6)
        numeric = least_squares(residual, start, xtol=1e-15, ftol=1e-15, gtol=1e-15).x
        np.testing.assert_allclose(numeric, closed[i], atol=1e-7)


def test_straight_walking_reduces_to_eq2_of_lim(mju):
    """Eq. 2: theta1 = 0, theta5 = -theta3 - theta4, theta6 = -theta2 for a foot parallel to the torso."""
    leg = Leg.of(mju, 1)
    rng = np.random.default_rng(4)
    targets = np.column_stack([rng.uniform(-0.05, 0.05, 500), leg.hip[1] + rng.uniform(-0.03, 0.03, 500),
                               rng.uniform(-0.27, -0.2, 500)])
    q = leg_ik_yaw(leg, targets, np.zeros(500)).angles
    np.testing.assert_allclose(q[:, 0], 0.0, atol=1e-12)
    np.testing.assert_allclose(q[:, 4], -q[:, 2] - q[:, 3], atol=1e-12)
    np.testing.assert_allclose(q[:, 5], -q[:, 1], atol=1e-12)


def test_jacobian_matches_finite_differences_of_fk(hubo):
    leg = Leg.of(hubo, -1)
    q = _random_angles(np.random.default_rng(5), 50)
    jacobian = leg_jacobian(leg, q)
    h = 1e-7
    for j in range(6):
        dq = np.zeros(6)
        dq[j] = h
        p1, r1 = leg_fk(leg, q + dq)
        p0, r0 = leg_fk(leg, q - dq)
        np.testing.assert_allclose(jacobian[:, :3, j], (p1 - p0) / (2 * h), atol=1e-7)
        dr = (r1 - r0) / (2 * h) @ np.transpose(leg_fk(leg, q)[1], (0, 2, 1))  # skew(omega)
        omega = np.stack([dr[:, 2, 1], dr[:, 0, 2], dr[:, 1, 0]], axis=1)
        np.testing.assert_allclose(jacobian[:, 3:, j], omega, atol=1e-6)


def test_joint_velocities_are_the_derivative_of_the_angles(hubo):
    rate = 2000.0
    pattern = generate(hubo, [StepCommand(0.8, 0.2), StepCommand(0.8, 0.1, turn=0.15), StepCommand(0.95, side=0.05)],
                       rate=rate)
    joints = pattern_joint_trajectory(pattern)
    derivative = np.gradient(joints.angles, pattern.time, axis=0)
    # away from the acceleration steps of the pattern (phase boundaries) the central difference is O(h^2)
    smooth = np.ones(len(pattern.time), dtype=bool)
    for phase in pattern.support_phases:
        smooth &= np.abs(pattern.time - phase.begin) > 0.01
    np.testing.assert_allclose(derivative[smooth], joints.velocities[smooth], atol=2e-3)


def test_unreachable_poses_raise_with_leg_time_and_distance(hubo):
    leg = Leg.of(hubo, 1)
    with pytest.raises(UnreachableError, match="left ankle out of reach"):
        leg_ik_scalar(leg, (0.0, 0.085, -0.7), 0.0)
    solution = leg_ik_yaw(leg, np.array([[0.0, 0.085, -0.7]]), np.zeros(1))
    assert solution.excess[0] == pytest.approx(0.1, abs=1e-12)


def test_joint_limits_are_checked(hubo):
    angles = np.zeros((3, 12))
    angles[2, 3] = 2.6  # left knee beyond 2.4 rad
    with pytest.raises(JointLimitError, match=r"left_knee = 2\.6000 rad at t = 2\.000 s"):
        check_joint_limits(np.arange(3.0), angles, hubo)


def test_ready_posture_angles(hubo):
    """Straight legs under the hips with the knees bent: hip = ankle = -knee/2."""
    leg = Leg.of(hubo, 1)
    depth = hubo.hip_height - hubo.ankle_height
    q = leg_ik_scalar(leg, (0.0, hubo.hip_spacing / 2, -depth + hubo.hip_drop - hubo.hip_drop), 0.0)
    knee = 2 * math.acos(depth / (2 * hubo.thigh_length))
    assert q == pytest.approx((0.0, 0.0, -knee / 2, knee, -knee / 2, 0.0), abs=1e-12)


def test_closed_form_joint_rates_equal_the_jacobian_solve_on_random_walks(hubo):
    """The IK's own time derivative (leg_ik_yaw_rates) against J(q)^-1 twist, and its angles against the
    rotation-matrix IK (leg_ik), on random walks mixing every mode: 1e-9 rad/s and 1e-9 rad."""
    rng = np.random.default_rng(21)
    commands = [StepCommand(duration=float(rng.uniform(0.7, 1.0)), forward=float(rng.uniform(-0.1, 0.25)),
                            side=float(rng.choice([0.0, 0.05, -0.05])), turn=float(rng.choice([0.0, 0.15, -0.15])))
                for _ in range(12)]
    pattern = generate(hubo, commands, rate=500.0)
    joints = pattern_joint_trajectory(pattern)
    c, s = np.cos(pattern.yaw_pelvis_in_world), np.sin(pattern.yaw_pelvis_in_world)
    feet = ((1, pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
             pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
            (-1, pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
             pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot))
    for index, (side, position, yaw, velocity, yaw_rate) in enumerate(feet):
        leg = Leg.of(hubo, side)
        rel = position - pattern.position_pelvis_in_world
        v = velocity - pattern.velocity_pelvis_in_world
        v[:, 0] += pattern.yaw_rate_pelvis * rel[:, 1]
        v[:, 1] -= pattern.yaw_rate_pelvis * rel[:, 0]
        n = len(c)
        twist = np.column_stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1], v[:, 2], np.zeros(n),
                                 np.zeros(n), yaw_rate - pattern.yaw_rate_pelvis])
        angles = joints.angles[:, 6 * index:6 * index + 6]
        expected_rates = np.linalg.solve(leg_jacobian(leg, angles), twist[..., None])[..., 0]
        np.testing.assert_allclose(joints.velocities[:, 6 * index:6 * index + 6], expected_rates, atol=1e-9)
        ankle = np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])
        general = leg_ik(leg, ankle, rot_z(yaw - pattern.yaw_pelvis_in_world)).angles
        np.testing.assert_allclose(angles, general, atol=ANGLE_TOL)


def test_flat_foot_ik_and_rates_everywhere_in_reach_ankle_above_the_hip_included(hubo):
    """leg_ik_yaw_rates against the rotation-matrix IK and J^-1 twist on random reachable targets all around the
    hip (above it too, where q1 and q3 turn by pi), random foot yaws up to +-3 rad and random twists."""
    from zmpwalk.kinematics import leg_ik_yaw_rates

    rng = np.random.default_rng(33)
    leg = Leg.of(hubo, 1)
    n = 2000
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    targets = np.asarray(leg.hip) + direction * rng.uniform(0.1, 0.58, n)[:, None]  # reach 0.6 m
    yaw = rng.uniform(-3.0, 3.0, n)
    velocity, yaw_rate = rng.normal(size=(n, 3)), rng.normal(size=n)
    solution, rates = leg_ik_yaw_rates(leg, targets, yaw, velocity, yaw_rate)
    assert np.any(targets[:, 2] > leg.hip[2])  # the ankle above the hip occurs
    general = leg_ik(leg, targets, rot_z(yaw)).angles
    np.testing.assert_allclose(solution.angles, general, atol=ANGLE_TOL)
    position, rotation = leg_fk(leg, solution.angles)
    np.testing.assert_allclose(position, targets, atol=POSITION_TOL)
    np.testing.assert_allclose(rotation, rot_z(yaw), atol=ANGLE_TOL)
    twist = np.column_stack([velocity, np.zeros(n), np.zeros(n), yaw_rate])
    jacobian = leg_jacobian(leg, solution.angles)
    well_posed = np.linalg.cond(jacobian) < 1e4  # away from the stretched and folded leg
    expected = np.linalg.solve(jacobian[well_posed], twist[well_posed][..., None])[..., 0]
    np.testing.assert_allclose(rates[well_posed], expected, rtol=1e-7, atol=1e-7)  # [rad/s]
