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

from zmpwalk.errors import InvalidParameterError, UnreachableError
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
    """Joint angles (closed-form IK) and velocities (Jacobian) of both legs with an upright pelvis, in parts
    (:mod:`zmpwalk.slices`: with closed-form legs, each leg's angles and rates, then the joint ranges; an
    imported robot's legs in one part). :func:`joint_trajectory` runs it whole.

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
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    angles, velocities = np.empty((n, 12)), np.empty((n, 12))
    base: Array | None = None
    solutions: list[tuple[Array, Array]] = []
    if robot.legs is not None:
        # An imported robot: the pattern moves the whole-body centre of mass; find the base that puts it there.
        base, solutions = _base_under_com(position_pelvis_in_world, yaw_pelvis_in_world,
                                          [(f[0], f[1]) for f in feet], robot)
        if n > 1:
            velocity_pelvis_in_world = velocity_pelvis_in_world + np.gradient(base - position_pelvis_in_world,
                                                                              time, axis=0)
        position_pelvis_in_world = base
    if robot.legs is None:  # closed form, written row by row into (12, n) and returned transposed
        angles, velocities = yield from _closed_form_legs_in_parts(
            time, position_pelvis_in_world, (c, s), yaw_pelvis_in_world, velocity_pelvis_in_world, yaw_rate_pelvis,
            feet, robot, knee_forward)
    else:  # an imported robot's legs: angles from _base_under_com, rates from J q' = twist
        for index, (side, (position, _, velocity, yaw_rate)) in enumerate(zip(Side, feet, strict=True)):
            rel = position - position_pelvis_in_world
            v = velocity - velocity_pelvis_in_world  # relative velocity in the (rotating) pelvis frame
            v[:, 0] += yaw_rate_pelvis * rel[:, 1]
            v[:, 1] -= yaw_rate_pelvis * rel[:, 0]
            twist = np.column_stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1], v[:, 2],
                                     np.zeros(n), np.zeros(n), yaw_rate - yaw_rate_pelvis])
            chain = robot.legs[index]
            leg_angles, excess = solutions[index]
            _check_reach(excess, time, side.label,
                         "inverse kinematics, " + ("closed form" if chain.closed_form else "numeric"))
            rates = chain.joint_rates(leg_angles, twist)
            order = list(chain.role_order)
            angles[:, 6 * index:6 * index + 6] = leg_angles[:, order]
            velocities[:, 6 * index:6 * index + 6] = rates[:, order]
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
    if np.any(excess > 0):
        first = int(np.argmax(excess > 0))
        raise UnreachableError(label, float(time[first]), float(excess.max()), detail)


COM_TOLERANCE = 1e-6  # [m] the base is placed until the whole-body CoM is this close to the pattern's
COM_ITERATIONS = 12


def _base_under_com(position_com_in_world: Array, yaw_pelvis_in_world: Array, feet: list[tuple[Array, Array]],
                    robot: RobotModel) -> tuple[Array, list[tuple[Array, Array]]]:
    r"""Base positions (n, 3) [m] that put the whole-body CoM of an imported robot on the pattern's point, and
    the leg solutions there.

    The pattern (Eqs. 1-2 of Park et al.) moves one mass; a real robot's legs carry part of it (TALOS: 17 %
    each), so a swinging leg moves the CoM away from where the pattern put it. With the feet fixed in world,
    the base is moved horizontally by the remaining CoM error until it is below :data:`COM_TOLERANCE`:

    .. math:: p_{base}^{k+1} = p_{base}^k + (c_{pattern} - c(p_{base}^k, q^k))_{xy}

    (a contraction: moving the base by ``d`` moves the CoM by about ``d (1 - m_{feet} / M)``).
    The CoM height stays the pattern's (its vertical motion is what the pattern neglects too).
    """
    legs, plant = robot.legs, robot.plant
    if legs is None or plant is None:
        raise InvalidParameterError("robot", robot.name, "an imported robot (leg chains and masses)")
    n = len(yaw_pelvis_in_world)
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    rotation = rot_z(yaw_pelvis_in_world)
    offset = np.array([robot.com_offset[0], robot.com_offset[1], 0.0])
    base = position_com_in_world - np.einsum("nij,j->ni", rotation, offset)
    total = plant.rest_mass + sum(float(leg.link_masses.sum()) for leg in legs)
    starts: list[Array | None] = [None, None]
    solutions: list[tuple[Array, Array]] = []
    for _ in range(COM_ITERATIONS):
        solutions = []
        com_in_base = plant.rest_mass * np.asarray(plant.rest_com)
        com_in_base = np.broadcast_to(com_in_base, (n, 3)).copy()
        for index, (chain, (position, yaw)) in enumerate(zip(legs, feet, strict=True)):
            rel = position - base
            ankle_in_base = np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])
            solution = chain.solve(ankle_in_base, rot_z(yaw - yaw_pelvis_in_world), start=starts[index])
            solutions.append(solution)
            starts[index] = solution[0]
            com_in_base += np.einsum("k,nki->ni", chain.link_masses, chain.link_com_positions(solution[0]))
        com = base + np.einsum("nij,nj->ni", rotation, com_in_base / total)
        error = position_com_in_world[:, :2] - com[:, :2]
        base[:, :2] += error
        if np.max(np.abs(error)) < COM_TOLERANCE:
            break
    return base, solutions


def pattern_joint_trajectory_in_parts(pattern: SampledMotion, knee_forward: bool = True,
                                      check_limits: bool = True) -> Parts[JointTrajectory]:
    """Joint angles and velocities of a :class:`~zmpwalk.patterns.result.WalkingPattern` (any generator), in parts
    (:func:`joint_trajectory_in_parts`); :func:`pattern_joint_trajectory` runs it whole."""
    return joint_trajectory_in_parts(
        pattern.time, pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
        pattern.velocity_pelvis_in_world, pattern.yaw_rate_pelvis,
        ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
          pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
         (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
          pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot)),
        pattern.robot, knee_forward, check_limits)


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


__all__ = ["COM_ITERATIONS", "COM_TOLERANCE", "JOINT_COLUMNS", "LEG_JOINTS", "JointLimitError", "JointTrajectory",
           "SampledMotion", "check_joint_limits", "check_leg_reach", "check_sole_roll", "hip_positions_in_world",
           "joint_bounds", "joint_trajectory", "joint_trajectory_in_parts", "leg_chains", "leg_reach_excess",
           "pattern_joint_trajectory", "rest_mass", "rot_x", "rot_y", "rot_z", "virtual_columns"]
