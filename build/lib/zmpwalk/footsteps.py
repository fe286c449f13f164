"""Step commands to foot placements: which foot swings, where it lands.

Each command becomes one or more *stages*; a stage is one swing of one foot
lasting the command's ``duration`` (the paper's step, from ``t1`` to ``t2``).
A forward step is one stage; a side or turn step is two (open stance with the
leading foot, then recovery with the other). The feet alternate; when a side
or turn step would have to start with the wrong foot, one plain stage with the
same step time and stride is inserted first, and the stage says so.

Landing rule (top view, Fig. 19 generalised): the swinging foot ``s`` lands
relative to the supporting foot ``o`` at

.. math::
    p_s = p_o + R(\\psi_o) \\left[ (0, \\sigma w/2) + R(\\Delta\\psi)(f, \\sigma (w/2 + a)) \\right],
    \\quad \\psi_s = \\psi_o + \\Delta\\psi

with ``sigma = +1`` for the left foot, ``w`` the ready-posture ankle spacing,
``f`` the stride, ``a`` the side opening and ``Delta psi`` the turn. A turn
thus rotates the feet about the middle of the stance, not about one ankle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule, ShapeParameters
from zmpwalk.sides import Side


@dataclass(frozen=True)
class Pose2D:
    """A foot's pose on the ground: ankle position and yaw in world [m, m, rad]."""

    x: float  # [m]
    y: float  # [m]
    yaw: float  # [rad], unwrapped (continuous over the walk)

    def compose(self, forward: float, left: float, dyaw: float = 0.0) -> Pose2D:
        """The pose ``(forward, left)`` ahead in this pose's frame, rotated by ``dyaw``."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return Pose2D(self.x + c * forward - s * left, self.y + s * forward + c * left, self.yaw + dyaw)


@dataclass(frozen=True)
class StagePlan:
    """Where one swing goes: the output of the footstep planner for one stage.

    Attributes:
        swing: ``LEFT`` (+1) or ``RIGHT`` (-1), the foot that swings.
        support_pose: Pose of the supporting foot (fixed during the stage).
        swing_start: Pose of the swinging foot at the stage start.
        swing_end: Landing pose of the swinging foot.
        forward: The stride ``f`` of this swing [m].
        duration: Step time ``T`` [s].
        parameters: Shape factors and parameters of this stage.
        stop: True if the robot comes to rest at the end of the stage.
        kind: ``"step"``, ``"open"``, ``"recovery"``, ``"inserted"``, ``"stop"`` (the
            closing swing), or, with both feet down, ``"start"`` and ``"settle"``.
    """

    swing: int
    support_pose: Pose2D
    swing_start: Pose2D
    swing_end: Pose2D
    forward: float  # [m]
    duration: float  # [s]
    parameters: ShapeParameters
    stop: bool
    kind: str


@dataclass(frozen=True)
class Stance:
    """Both feet on the ground between stages, and which foot swings next (0 = either)."""

    left: Pose2D
    right: Pose2D
    next_swing: int = 0

    @classmethod
    def ready(cls, robot: RobotModel) -> Stance:
        """The ready posture at the world origin, facing +x."""
        half = robot.hip_spacing / 2
        return cls(Pose2D(0.0, half, 0.0), Pose2D(0.0, -half, 0.0), 0)

    def pose(self, foot: int) -> Pose2D:
        return self.left if foot == Side.LEFT else self.right

    def with_foot(self, foot: int, pose: Pose2D) -> Stance:
        if foot == Side.LEFT:
            return Stance(pose, self.right, Side.RIGHT)
        return Stance(self.left, pose, Side.LEFT)


def landing_pose(support: Pose2D, swing: int, spacing: float, forward: float, opening: float,
                 dyaw: float) -> Pose2D:
    """Landing pose of the swinging foot by the rule of the module docstring."""
    middle = support.compose(0.0, swing * spacing / 2)
    return Pose2D(middle.x, middle.y, support.yaw + dyaw).compose(forward, swing * (spacing / 2 + opening))


def plan_command(
    stance: Stance, command: StepCommand, robot: RobotModel, schedule: Schedule
) -> tuple[list[StagePlan], Stance]:
    """Stages of one command from a stance, and the stance after them.

    Raises:
        InvalidParameterError: The command would make the feet overlap, or its
            double support does not fit in its step time.
    """
    first, second = schedule.stage_parameters(command, robot)
    if first.dsp_time >= command.duration:
        raise InvalidParameterError(
            "duration", command.duration,
            f"a step time longer than the double-support time d = {first.dsp_time:g} s",
        )
    spacing = robot.hip_spacing
    stages: list[StagePlan] = []
    if command.stop:
        swing = stance.next_swing or Side.LEFT
        stages.append(_stage(stance, swing, spacing, 0.0, 0.0, 0.0, command, first, "stop"))
        landed = _after(stance, stages)
        stages.append(grounded_stage(landed, swing, command.duration, first, "settle"))
    elif not command.is_two_stage:
        swing = stance.next_swing or Side.LEFT
        stages.append(_stage(stance, swing, spacing, command.forward, 0.0, 0.0, command, first, "step"))
    else:
        leading = command.leading_side
        if stance.next_swing not in (0, leading):
            plain = replace(command, side=0.0, turn=0.0)
            plain_parameters, _ = schedule.stage_parameters(plain, robot)
            stages.append(
                _stage(stance, -leading, spacing, command.forward, 0.0, 0.0, command, plain_parameters,
                       "inserted")
            )
        current = _after(stance, stages)
        stages.append(
            _stage(current, leading, spacing, command.forward, abs(command.side), command.turn, command, first,
                   "open")
        )
        current = _after(stance, stages)
        stages.append(_stage(current, -leading, spacing, command.forward, 0.0, 0.0, command, second, "recovery"))
    for stage in stages:
        if stage.kind != "settle":
            _check_clearance(stage, robot, command)
            check_swing(stage, robot, command)
    return stages, _after(stance, stages)


GROUNDED_STRETCH = 1.0  # start/settle: the sway cubic to or from rest lasts this many step times


def grounded_stage(stance: Stance, support: int, step_time: float, parameters: ShapeParameters,
                   kind: str) -> StagePlan:
    """A stage with both feet down in which the pelvis sways towards ``support`` and back.

    ``"start"`` begins a walk from standstill; ``"settle"`` ends one (the robot
    comes to rest in the middle of the feet). It lasts
    ``(GROUNDED_STRETCH + (1 - d1) / 2) * step_time``: one slow sway cubic to or
    from rest and one regular cubic (see :func:`zmpwalk.patterns.stages.sway_times`).
    """
    still = stance.pose(-support)
    duration = (GROUNDED_STRETCH + (1.0 - parameters.d1) / 2.0) * step_time
    return StagePlan(-support, stance.pose(support), still, still, 0.0, duration, parameters,
                     kind == "settle", kind)



def _after(stance: Stance, stages: list[StagePlan]) -> Stance:
    for stage in stages:
        stance = stance.with_foot(stage.swing, stage.swing_end)
    return stance


def _stage(
    stance: Stance, swing: int, spacing: float, forward: float, opening: float, dyaw: float,
    command: StepCommand, parameters: ShapeParameters, kind: str, stop: bool = False,
) -> StagePlan:
    support = stance.pose(-swing)
    end = landing_pose(support, swing, spacing, forward, opening, dyaw)
    return StagePlan(swing, support, stance.pose(swing), end, forward, command.duration, parameters, stop, kind)


def _sole_in_ankle(robot: RobotModel) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Sole corners about the ankle, counter-clockwise, x (4,) and y (4,) [m], before the side offset of y."""
    half_l, half_w = robot.foot_length / 2, robot.foot_width / 2
    x = robot.sole_center_x
    return (x - half_l, x + half_l, x + half_l, x - half_l), (-half_w, -half_w, half_w, half_w)


def foot_corners(pose: Pose2D, foot: int, robot: RobotModel) -> np.ndarray:
    """Sole corners of a foot in world, counter-clockwise, shape (4, 2) [m]."""
    local_x, local_y = _sole_in_ankle(robot)
    offset = foot * robot.sole_center_y
    c, s = math.cos(pose.yaw), math.sin(pose.yaw)
    return np.array([(pose.x + c * x - s * (y + offset), pose.y + s * x + c * (y + offset))
                     for x, y in zip(local_x, local_y, strict=True)])


def sole_corners(x: np.ndarray, y: np.ndarray, yaw: np.ndarray, foot: np.ndarray, robot: RobotModel) -> np.ndarray:
    """:func:`foot_corners` of many feet at once, shape (n, 4, 2) [m].

    Args:
        x, y, yaw: Ankle poses in world [m], [m], [rad], shape (n,).
        foot: +1 left, -1 right, shape (n,).
    """
    corner_x, corner_y = _sole_in_ankle(robot)
    local_x = np.array(corner_x)
    local_y = np.asarray(foot, dtype=float)[:, None] * robot.sole_center_y + np.array(corner_y)
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    corners = np.empty((len(x), 4, 2))
    corners[..., 0] = np.asarray(x)[:, None] + c * local_x - s * local_y
    corners[..., 1] = np.asarray(y)[:, None] + s * local_x + c * local_y
    return corners


def _rectangles_overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Separating-axis test for two convex quadrilaterals (4, 2) [m]."""
    pa, pb = a.tolist(), b.tolist()
    for polygon in (pa, pb):
        for i in range(4):
            (x0, y0), (x1, y1) = polygon[i], polygon[(i + 1) % 4]
            nx, ny = y0 - y1, x1 - x0  # normal of the edge
            on_a = [nx * x + ny * y for x, y in pa]
            on_b = [nx * x + ny * y for x, y in pb]
            if max(on_a) < min(on_b) or max(on_b) < min(on_a):
                return False
    return True


SWAY_SPEED_FRACTION = 0.5  # [-] the pelvis sways at most this fraction of the swing foot's speed limit
SMOOTHSTEP_PEAK_SLOPE = 15.0 / 8.0  # [-] max of d/dx (10x^3 - 15x^4 + 6x^5), at x = 1/2
SMOOTHSTEP_PEAK_CURVATURE = 10.0 / math.sqrt(3.0)  # [-] max of its second derivative, at x = (3 -+ sqrt 3)/6


def swing_peaks(along: float, across: float, lift: float, up_ratio: float) -> tuple[float, float]:
    r"""Bounds on the swinging ankle's peak speed and acceleration, per unit swing time.

    The ankle moves ``along`` [m] on the cycloid of Eq. 11 (peak speed ``2 a / T_s`` at mid-swing,
    peak acceleration ``2 pi a / T_s^2``), ``across`` [m] on the half cosine of Eqs. 14-17
    (``pi c / (2 T_s)``, ``pi^2 c / (2 T_s^2)``) and rises ``lift`` [m] on the quintic of Fig. 12 in
    the shorter of ``u T_s`` and ``(1 - u) T_s`` (``15 h / (8 u T_s)``, ``10 h / (sqrt(3) u^2 T_s^2)``).

    .. math::
        |v| \le \sqrt{(2a + \tfrac{\pi}{2} c)^2 + (\tfrac{15 h}{8 u})^2} / T_s, \qquad
        |\dot v| \le \sqrt{(2\pi a + \tfrac{\pi^2}{2} c)^2 + (\tfrac{10 h}{\sqrt 3 u^2})^2} / T_s^2

    Returns:
        ``(speed, acceleration)`` times ``T_s`` and ``T_s^2``: [m], [m].
    """
    shorter = min(up_ratio, 1.0 - up_ratio)
    speed = math.hypot(2.0 * along + 0.5 * math.pi * across, SMOOTHSTEP_PEAK_SLOPE * lift / shorter)
    acceleration = math.hypot(2.0 * math.pi * along + 0.5 * math.pi**2 * across,
                              SMOOTHSTEP_PEAK_CURVATURE * lift / shorter**2)
    return speed, acceleration


def check_swing(stage: StagePlan, robot: RobotModel, command: StepCommand) -> None:
    """Reject a swing faster than the robot's foot speed or acceleration limit, or lifted too high.

    Raises:
        InvalidParameterError: Names ``foot_lift`` (apex above :attr:`RobotModel.max_foot_lift`),
            ``lateral_velocity`` (the pelvis swaying faster than :data:`SWAY_SPEED_FRACTION` of the foot
            speed limit) or ``duration`` with the shortest step time this swing allows.
    """
    parameters = stage.parameters
    # Eq. 20: the pelvis crosses the step change at alpha1 V_y over the returning sway cubic's time (1 - d1) T / 2
    back_time = (1.0 - parameters.d1) * stage.duration / 2.0
    sway_speed_limit = SWAY_SPEED_FRACTION * robot.max_foot_speed
    if parameters.alpha1 * parameters.lateral_velocity > sway_speed_limit * back_time:
        raise InvalidParameterError(
            "lateral_velocity", parameters.lateral_velocity,
            f"a V_y in [0, {sway_speed_limit * back_time / max(parameters.alpha1, 1e-12):.3f}] m for this step "
            f"(alpha1 {parameters.alpha1:g}, d1 {parameters.d1:g}, {stage.duration:g} s): the pelvis sways at most "
            f"{sway_speed_limit:.2f} m/s, half the robot's foot speed limit")
    if parameters.foot_lift > robot.max_foot_lift:
        raise InvalidParameterError(
            "foot_lift", parameters.foot_lift,
            f"a swing apex in [0, {robot.max_foot_lift:.3f}] m (half the hip's height above the ankle)")
    dx, dy = stage.swing_end.x - stage.swing_start.x, stage.swing_end.y - stage.swing_start.y
    c, s = math.cos(stage.support_pose.yaw), math.sin(stage.support_pose.yaw)
    along, across = abs(c * dx + s * dy), abs(-s * dx + c * dy)
    speed, acceleration = swing_peaks(along, across, parameters.foot_lift, parameters.up_ratio)
    v_max, a_max = robot.max_foot_speed, robot.max_foot_acceleration
    shortest = max(speed / v_max, math.sqrt(acceleration / a_max))  # [s] of swing
    if stage.duration - parameters.dsp_time < shortest:
        raise InvalidParameterError(
            "duration", command.duration,
            f"a step time >= {shortest + parameters.dsp_time:.3f} s for this swing ({along:.3f} m along, "
            f"{across:.3f} m across, {parameters.foot_lift:.3f} m lift with up_ratio {parameters.up_ratio:g}, "
            f"{parameters.dsp_time:g} s double support): the swinging foot's speed stays within {v_max:.2f} m/s "
            f"and its acceleration within {a_max:.1f} m/s^2 (the robot's limits)")


def _check_clearance(stage: StagePlan, robot: RobotModel, command: StepCommand) -> None:
    """Reject a landing that puts one sole on top of the other."""
    swing = foot_corners(stage.swing_end, stage.swing, robot)
    support = foot_corners(stage.support_pose, -stage.swing, robot)
    if _rectangles_overlap(swing, support):
        name = "turn" if command.turn != 0 else ("side" if command.side != 0 else "forward")
        value = getattr(command, name)
        if command.turn != 0:
            hint = "split a large turn into several steps, or open the stance with a side step towards it, Fig. 19"
        else:
            hint = (f"the robot's soles ({robot.foot_width:g} m wide) do not fit side by side at its hip spacing "
                    f"({robot.hip_spacing:g} m)")
        sole = Side(stage.swing).label
        raise InvalidParameterError(
            name, value,
            f"a step whose landing foot does not overlap the supporting foot (the {sole} sole would land on the "
            f"other one; {hint})",
        )
