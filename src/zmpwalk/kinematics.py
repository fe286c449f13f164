"""Joint trajectories of both legs along a walking pattern, the robot's leg chains, and the legs' reach.

A walking pattern gives the pelvis and both ankles in world (:class:`SampledMotion`); the joint angles and
velocities of the 12 leg joints (:class:`JointTrajectory`, columns :data:`JOINT_COLUMNS`) follow from each
leg's :class:`~zmpwalk.leg_chain.LegChain` (:func:`leg_chains`): a robot file's straight leg in its closed
form with the joint rates as its time derivative, an imported model's legs by their own inverse kinematics
with the base placed under the whole-body centre of mass and the rates from ``J q' = twist``. The reach
checks compare hip-to-ankle distances with the leg's reach before any inverse kinematics runs.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import UnreachableError
from zmpwalk.joint_limits import (  # re-exported (__all__): the columns and their checks live there
    JOINT_COLUMNS,
    LEG_JOINTS,
    JointLimitError,
    check_joint_limits,
    check_sole_roll,
    joint_bounds,
    virtual_columns,
)
from zmpwalk.leg_chain import LegChain
from zmpwalk.leg_chain.rotations import rot_x, rot_y, rot_z  # re-exported (__all__)
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Side
from zmpwalk.slices import Parts, whole
from zmpwalk.whole_body import COM_TOLERANCE, imported_legs_in_parts

Array = NDArray[np.float64]


class SampledMotion(Protocol):
    """What the IK needs of a pattern (:class:`zmpwalk.patterns.result.WalkingPattern` is one), in world, SI:
    times [s] (n,), the pelvis and both ankles' positions [m] (n, 3) and velocities [m/s] (n, 3), the pelvis'
    and feet's yaws [rad] (n,) and yaw rates [rad/s] (n,), and the robot."""

    time: Array
    position_pelvis_in_world: Array
    velocity_pelvis_in_world: Array
    yaw_pelvis_in_world: Array
    yaw_rate_pelvis: Array
    position_left_ankle_in_world: Array
    velocity_left_ankle_in_world: Array
    yaw_left_foot_in_world: Array
    yaw_rate_left_foot: Array
    position_right_ankle_in_world: Array
    velocity_right_ankle_in_world: Array
    yaw_right_foot_in_world: Array
    yaw_rate_right_foot: Array
    robot: RobotModel


def hip_positions_in_world(
    position_pelvis_in_world: Array, yaw_pelvis_in_world: Array, robot: RobotModel
) -> tuple[Array, Array]:
    """Left and right hip joint centres in world [m], each (n, 3)."""
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    result = []
    for side in Side:
        x, y, z = robot.hip_in_pelvis(side)
        result.append(position_pelvis_in_world + np.column_stack([c * x - s * y, s * x + c * y, np.full_like(c, z)]))
    return result[0], result[1]


def leg_reach_excess(
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    position_left_ankle_in_world: Array,
    position_right_ankle_in_world: Array,
    robot: RobotModel,
) -> tuple[Array, Array]:
    """Hip-to-ankle distance minus the leg's reach at its least knee bend [m], left and right, each (n,).

    Positive values are out of reach.
    """
    hip_left, hip_right = hip_positions_in_world(position_pelvis_in_world, yaw_pelvis_in_world, robot)
    reach = robot.max_leg_reach
    return (np.linalg.norm(position_left_ankle_in_world - hip_left, axis=1) - reach,
            np.linalg.norm(position_right_ankle_in_world - hip_right, axis=1) - reach)


def check_leg_reach(
    time: Array,
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    position_left_ankle_in_world: Array,
    position_right_ankle_in_world: Array,
    robot: RobotModel,
) -> None:
    """Raise if a hip-to-ankle distance exceeds the leg's reach at its least knee bend.

    Raises:
        UnreachableError: Names the leg, the first time it is out of reach and
            the largest excess [m]; ``error.sample`` is the first sample index.
    """
    excesses = leg_reach_excess(position_pelvis_in_world, yaw_pelvis_in_world, position_left_ankle_in_world,
                                position_right_ankle_in_world, robot)
    firsts = [int(np.argmax(e > 0)) if np.any(e > 0) else len(time) for e in excesses]
    if min(firsts) == len(time):
        return
    side = 0 if firsts[0] <= firsts[1] else 1
    first = firsts[side]
    excess = excesses[side]
    error = UnreachableError(
        ("left", "right")[side], float(time[first]), float(excess.max()),
        f"hip-to-ankle distance up to {float(excess.max()) + robot.max_leg_reach:.3f} m, "
        f"reach {robot.max_leg_reach:.3f} m",
    )
    error.sample = first
    raise error


@dataclass
class JointTrajectory:
    """The 12 leg joint angles and velocities along a walking pattern.

    Attributes:
        time: [s], (n,).
        angles: [rad], (n, 12), columns :data:`JOINT_COLUMNS` (left leg, then right leg).
        velocities: [rad/s], (n, 12).
        position_base_in_world: For an imported robot, the base origin that puts the whole-body CoM on the
            pattern's point [m], (n, 3); None for the robot-file legs (their pelvis is the pattern's).
    """

    time: Array
    angles: Array
    velocities: Array
    names: tuple[str, ...] = JOINT_COLUMNS
    position_base_in_world: Array | None = None

    def columns(self) -> dict[str, Array]:
        """Angles by column name, for the CSV of ``zmpwalk plan --joints``."""
        return {name: self.angles[:, i] for i, name in enumerate(self.names)}


def joint_trajectory_in_parts(
    time: Array,
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    velocity_pelvis_in_world: Array,
    yaw_rate_pelvis: Array,
    feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]],
    robot: RobotModel,
    knee_forward: bool = True,
    check_limits: bool = True,
) -> Parts[JointTrajectory]:
    """Joint angles and velocities (Jacobian) of both legs with an upright pelvis, in parts (:mod:`zmpwalk.slices`:
    a robot file's legs in closed form, each leg's angles and rates; an imported robot's base under the CoM and its
    legs, compiled, :data:`~zmpwalk.whole_body.IK_CHUNK` samples a part (:mod:`zmpwalk.whole_body`); then the joint
    ranges). :func:`joint_trajectory` runs it whole.

    Args:
        time: [s], (n,).
        position_pelvis_in_world, yaw_pelvis_in_world, velocity_pelvis_in_world, yaw_rate_pelvis:
            the pelvis [m], [rad], [m/s], [rad/s].
        feet: For the left then the right foot: ankle position [m] (n, 3), foot yaw [rad] (n,),
            ankle velocity [m/s] (n, 3) and foot yaw rate [rad/s] (n,), all in world.
        robot: The robot (leg lengths, hip positions, joint ranges).
        knee_forward: Knee branch.
        check_limits: Raise :class:`JointLimitError` when an angle leaves the robot's range.

    Raises:
        UnreachableError: First time an ankle is out of reach, with the largest excess.
        JointLimitError: First joint to leave its range (when ``check_limits``).
    """
    n = len(time)
    angles, velocities = np.empty((n, 12)), np.empty((n, 12))
    base: Array | None = None
    if robot.legs is None:  # closed form, written row by row into (12, n) and returned transposed
        heading = (np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world))
        angles, velocities = yield from _closed_form_legs_in_parts(
            time, position_pelvis_in_world, heading, yaw_pelvis_in_world, velocity_pelvis_in_world, yaw_rate_pelvis,
            feet, robot, knee_forward)
    else:  # an imported robot: the pattern moves the whole-body CoM; the base that puts it there, and the legs
        base, angles, velocities, excess = yield from imported_legs_in_parts(
            time, position_pelvis_in_world, yaw_pelvis_in_world, velocity_pelvis_in_world, yaw_rate_pelvis, feet,
            robot)
        for index, side in enumerate(Side):
            _check_reach(excess[index], time, side.label, "inverse kinematics")
    if check_limits:  # the joint ranges: parts of their own, each half of the samples (the first sample out
        half = (n + 1) // 2  # of range is the first of the first half that has one, else of the second)
        yield
        check_sole_roll(time, angles, robot)  # a five-joint leg's sole roll over the whole walk (none: no work)
        check_joint_limits(time[:half], angles[:half], robot)
        yield
        check_joint_limits(time[half:], angles[half:], robot)
    return JointTrajectory(time, angles, velocities, position_base_in_world=base)


joint_trajectory = whole(joint_trajectory_in_parts, "joint_trajectory")  # the same, run whole


def _closed_form_legs_in_parts(
    time: Array, position_pelvis_in_world: Array, heading: tuple[Array, Array], yaw_pelvis_in_world: Array,
    velocity_pelvis_in_world: Array, yaw_rate_pelvis: Array,
    feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]], robot: RobotModel,
    knee_forward: bool,
) -> Parts[tuple[Array, Array]]:
    """The closed-form legs of :func:`joint_trajectory_in_parts` (``heading``: cos and sin of the pelvis yaw),
    each leg in parts: its ankle in the pelvis frame, the angles, the rates
    (:meth:`~zmpwalk.leg_chain.LegChain.solve_flat_in_parts`). Angles and rates, (n, 12) each."""
    c, s = heading
    n = len(time)
    chains = leg_chains(robot)
    rows_angles, rows_rates = np.empty((12, n)), np.empty((12, n))
    for index, (position, yaw, velocity, yaw_rate) in enumerate(feet):
        yield
        rx, ry = position[:, 0] - position_pelvis_in_world[:, 0], position[:, 1] - position_pelvis_in_world[:, 1]
        vx = velocity[:, 0] - velocity_pelvis_in_world[:, 0] + yaw_rate_pelvis * ry  # in the rotating frame
        vy = velocity[:, 1] - velocity_pelvis_in_world[:, 1] - yaw_rate_pelvis * rx
        rows = slice(6 * index, 6 * index + 6)
        yield
        ankle = (c * rx + s * ry, c * ry - s * rx, position[:, 2] - position_pelvis_in_world[:, 2])
        ankle_rates = (c * vx + s * vy, c * vy - s * vx, velocity[:, 2] - velocity_pelvis_in_world[:, 2],
                       yaw_rate - yaw_rate_pelvis)
        yield
        excess = yield from chains[index].solve_flat_in_parts(ankle, yaw - yaw_pelvis_in_world, ankle_rates,
                                                              knee_forward, rows_angles[rows], rows_rates[rows])
        _check_reach(excess, time, chains[index].label, "inverse kinematics")
    return rows_angles.T, rows_rates.T


def _check_reach(excess: Array, time: Array, label: str, detail: str) -> None:
    """Raise where a leg's IK did not meet its target: ``excess`` (n,) [m] (or [rad]) > 0, or NaN (a sample that is
    not finite), at samples ``time`` [s].

    Raises:
        UnreachableError: Names the leg (``label``), the first such time and the largest excess.
    """
    failed = ~(excess <= 0.0)
    if failed.any():
        first = int(np.argmax(failed))
        raise UnreachableError(label, float(time[first]), float(np.max(excess[failed])), detail)


def _pattern_feet(pattern: SampledMotion) -> tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array,
                                                                                              Array]]:
    """The pattern's feet as :func:`joint_trajectory_in_parts` takes them."""
    return ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
             pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
            (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
             pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot))


def pattern_joint_trajectory_in_parts(pattern: SampledMotion, knee_forward: bool = True,
                                      check_limits: bool = True) -> Parts[JointTrajectory]:
    """Joint angles and velocities of a :class:`~zmpwalk.patterns.result.WalkingPattern` (any generator), in parts
    (:func:`joint_trajectory_in_parts`); :func:`pattern_joint_trajectory` runs it whole."""
    return joint_trajectory_in_parts(
        pattern.time, pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
        pattern.velocity_pelvis_in_world, pattern.yaw_rate_pelvis, _pattern_feet(pattern), pattern.robot,
        knee_forward, check_limits)


pattern_joint_trajectory = whole(pattern_joint_trajectory_in_parts, "pattern_joint_trajectory")


_STRAIGHT_CHAINS: dict[int, tuple[weakref.ref[RobotModel], tuple[LegChain, LegChain]]] = {}  # by id(robot)


def leg_chains(robot: RobotModel) -> tuple[LegChain, LegChain]:
    """Both legs as :class:`~zmpwalk.leg_chain.LegChain` in the pelvis (base) frame, for any robot.

    An imported robot has its own; the robot-file leg (yaw-roll-pitch-pitch-pitch-roll, links along -z)
    is the straight leg of its link lengths (:meth:`~zmpwalk.leg_chain.LegChain.from_lengths`), with the
    ``[bodies]`` masses of thigh, shank and foot where the file has them. Built once per robot.
    """
    if robot.legs is not None:
        return robot.legs
    known = _STRAIGHT_CHAINS.get(id(robot))
    if known is not None and known[0]() is robot:
        return known[1]
    key = id(robot)
    chains = (_straight_chain(robot, 1), _straight_chain(robot, -1))
    _STRAIGHT_CHAINS[key] = (weakref.ref(robot, lambda _: _STRAIGHT_CHAINS.pop(key, None)), chains)
    return chains


def _straight_chain(robot: RobotModel, side: int) -> LegChain:
    """The robot file's left (``side = +1``) or right (-1) leg in the pelvis frame (a robot file has no
    :attr:`~zmpwalk.robots.model.RobotModel.com_offset`: its pattern's pelvis point is the pelvis origin)."""
    label = Side(side).label
    limits = [robot.limits_of(f"{label}_{joint}") for joint in LEG_JOINTS]
    chain = LegChain.from_lengths(
        side, tuple(f"{label}_{joint}" for joint in LEG_JOINTS),
        (robot.hip_x, side * robot.hip_spacing / 2, -robot.hip_drop), robot.thigh_length, robot.shank_length,
        reference=np.array([0.0, 0.0, -0.5, 1.0, -0.5, 0.0]),
        lower=np.array([lo for lo, _ in limits]), upper=np.array([hi for _, hi in limits]))
    if not robot.links:
        return chain
    masses, coms = np.zeros(6), np.zeros((6, 3))
    for index, name in ((2, "thigh"), (3, "shank"), (5, "foot")):  # each from its joint: hip, knee, ankle
        link = robot.links[name]
        masses[index] = link.mass
        coms[index] = chain.points[index] + np.array(link.com) * [1.0, side, 1.0]
    return replace(chain, link_masses=masses, link_coms=coms)


def rest_mass(robot: RobotModel) -> tuple[float, Array]:
    """Mass [kg] and centre of mass in the pelvis frame [m] of everything but the leg segments."""
    if robot.plant is not None:
        return robot.plant.rest_mass, np.array(robot.plant.rest_com)
    if robot.links:
        return robot.links["torso"].mass, np.array(robot.links["torso"].com)
    return robot.mass, np.zeros(3)


__all__ = ["COM_TOLERANCE", "JOINT_COLUMNS", "LEG_JOINTS", "JointLimitError", "JointTrajectory",
           "SampledMotion", "check_joint_limits", "check_leg_reach", "check_sole_roll",
           "hip_positions_in_world", "joint_bounds", "joint_trajectory", "joint_trajectory_in_parts", "leg_chains",
           "leg_reach_excess", "pattern_joint_trajectory", "rest_mass", "rot_x", "rot_y", "rot_z",
           "virtual_columns"]
