"""Joint trajectories of both legs: the angles' derivative, the joint ranges, the closed form's joint rates against
the Jacobian solve on random walks (the straight leg's own closed form: tests/test_leg_chain_straight.py)."""

from __future__ import annotations

import numpy as np
import pytest

from zmpwalk import StepCommand, generate
from zmpwalk.kinematics import (
    JointLimitError,
    check_joint_limits,
    leg_chains,
    pattern_joint_trajectory,
    rot_z,
)

ANGLE_TOL = 1e-9  # [rad]


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


def test_joint_limits_are_checked(hubo):
    angles = np.zeros((3, 12))
    angles[2, 3] = 2.6  # left knee beyond 2.4 rad
    with pytest.raises(JointLimitError, match=r"left_knee = 2\.6000 rad at t = 2\.000 s"):
        check_joint_limits(np.arange(3.0), angles, hubo)


def test_closed_form_joint_rates_equal_the_jacobian_solve_on_random_walks(hubo):
    """The trajectory's joint rates (the straight leg's own time derivative) against J(q)^-1 twist, and its
    angles against the rotation-matrix IK, on random walks mixing every mode: 1e-9 rad/s and 1e-9 rad."""
    rng = np.random.default_rng(21)
    commands = [StepCommand(duration=float(rng.uniform(0.7, 1.0)), forward=float(rng.uniform(-0.1, 0.25)),
                            side=float(rng.choice([0.0, 0.05, -0.05])), turn=float(rng.choice([0.0, 0.15, -0.15])))
                for _ in range(12)]
    pattern = generate(hubo, commands, rate=500.0)
    joints = pattern_joint_trajectory(pattern)
    c, s = np.cos(pattern.yaw_pelvis_in_world), np.sin(pattern.yaw_pelvis_in_world)
    feet = ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
             pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
            (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
             pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot))
    for index, (position, yaw, velocity, yaw_rate) in enumerate(feet):
        chain = leg_chains(hubo)[index]
        rel = position - pattern.position_pelvis_in_world
        v = velocity - pattern.velocity_pelvis_in_world
        v[:, 0] += pattern.yaw_rate_pelvis * rel[:, 1]
        v[:, 1] -= pattern.yaw_rate_pelvis * rel[:, 0]
        n = len(c)
        twist = np.column_stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1], v[:, 2], np.zeros(n),
                                 np.zeros(n), yaw_rate - pattern.yaw_rate_pelvis])
        angles = joints.angles[:, 6 * index:6 * index + 6]
        expected_rates = np.linalg.solve(chain.jacobian(angles), twist[..., None])[..., 0]
        np.testing.assert_allclose(joints.velocities[:, 6 * index:6 * index + 6], expected_rates, atol=1e-9)
        ankle = np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])
        general = chain.solve(ankle, rot_z(yaw - pattern.yaw_pelvis_in_world))[0]
        np.testing.assert_allclose(angles, general, atol=ANGLE_TOL)
