"""The stage engine: step commands to stages, one command at a time or a whole walk.

:func:`plan_next` turns one command, from the stance and continuity state the walk is in, into its stages: the
footsteps (:func:`zmpwalk.footsteps.plan_command`), from standstill a start stage first, then the pelvis of the
chosen pelvis model over each stage (:mod:`zmpwalk.patterns.pelvis_model`), and the legs' reach checked at every
stage (:func:`check_reach`). :func:`plan_walk` plans a whole walk from the ready posture, closed by a stop and a
standing stage, and names a rejected command with the largest stride that fits
(:mod:`zmpwalk.patterns.stride_search`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.errors import UnreachableError, ZmpwalkError
from zmpwalk.footsteps import StagePlan, Stance, grounded_stage, plan_command
from zmpwalk.kinematics import check_leg_reach
from zmpwalk.patterns.evaluation import StageTable, evaluate
from zmpwalk.patterns.pelvis_model import PelvisModel, pelvis_model
from zmpwalk.patterns.stages import Boundary, Stage, standing_stage
from zmpwalk.patterns.stride_search import STRIDE_CAUSES, infeasible_command, step_time_rejection
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.sides import Side
from zmpwalk.slices import ALONE, Parts, whole

REACH_CHECK_POINTS = 25  # samples per stage at which the leg reach is checked
CHUNK_STAGES = 1000  # stages evaluated in one vectorised pass on long walks (bounds the memory)


def check_reach(stages: Sequence[Stage], robot: RobotModel) -> None:
    """Raise :class:`~zmpwalk.errors.UnreachableError` if a leg cannot follow the stages.

    The hip-to-ankle distance is checked at :data:`REACH_CHECK_POINTS` times of
    every stage (both ends included), in one vectorised pass. The error has the
    attribute ``stage`` (index into ``stages``).
    """
    fraction = np.linspace(0.0, 1.0, REACH_CHECK_POINTS)
    for first in range(0, len(stages), CHUNK_STAGES):  # bounded memory on long walks
        chunk = list(stages[first:first + CHUNK_STAGES])
        table = StageTable(chunk)
        index = np.repeat(np.arange(len(chunk)), REACH_CHECK_POINTS)
        times = table.start[index] + np.tile(fraction, len(chunk)) * table.duration[index]
        samples = evaluate(table, times, robot, index)
        pelvis = np.column_stack([samples.pelvis_xy, np.full(len(times), robot.pelvis_height)])
        try:
            check_leg_reach(times, pelvis, samples.pelvis_yaw, samples.left_position, samples.right_position, robot)
        except UnreachableError as error:
            error.stage = first + int(index[error.sample])
            raise


def plan_next_in_parts(
    robot: RobotModel, schedule: Schedule, stance: Stance, boundary: Boundary, command: StepCommand,
    reach: bool = True, pelvis: str | PelvisModel = "cubic",
) -> Parts[tuple[list[Stage], Stance, Boundary]]:
    """Stages of one command from a stance and boundary state; nothing is changed on error.
    In parts (the footsteps, then each stage; :mod:`zmpwalk.slices`); :func:`plan_next` runs it whole.

    From standstill a walk begins with a *start* stage: one step time in double
    support in which the pelvis sways towards the first swinging foot and comes
    back through the middle at the sway speed ``alpha1 V_y`` of Eq. 20, so that
    the first swing starts like every other one. A stop command at standstill
    does nothing.

    Args:
        reach: Check the legs' reach here (a caller that checks many commands at
            once with :func:`check_reach` passes False).
        pelvis: ``"cubic"`` (the paper's curves), ``"quintic"`` (jerk-continuous) or ``"hyperbolic"``
            (the pendulum's own motion under a piecewise-constant ZMP: :mod:`zmpwalk.patterns.lipm_stage`), or a
            :class:`~zmpwalk.patterns.pelvis_model.PelvisModel` of one's own.

    Raises:
        ZmpwalkError: The command is infeasible for this robot (reach, overlap, timing, and for the
            hyperbolic pelvis a ZMP outside the feet).
    """
    model = pelvis_model(pelvis)
    if boundary.at_rest and command.stop:
        return [], stance, boundary
    yield ALONE
    schedule.stage_parameters(command, robot)  # the tables' lookups, kept by the schedule: parts of their own
    if command.is_two_stage and stance.next_swing not in (0, command.leading_side):  # a plain step inserted
        yield ALONE
        schedule.stage_parameters(replace(command, side=0.0, turn=0.0), robot)
    yield ALONE
    plans, next_stance = plan_command(stance, command, robot, schedule)
    if boundary.at_rest:
        first = plans[0]
        plans = [grounded_stage(stance, first.swing, command.duration, first.parameters, "start"), *plans]
    stages = yield from model.stages_in_parts(plans, boundary, robot)
    boundary = stages[-1].end if stages else boundary
    if reach:
        check_reach(stages, robot)
    if command.stop:
        next_stance = Stance(next_stance.left, next_stance.right, 0)
    return stages, next_stance, boundary


plan_next = whole(plan_next_in_parts, "plan_next")  # the same, run whole

def closing_command(last: StepCommand) -> StepCommand:
    """The stop added after ``last``: same step time and shape-factor overrides, no motion."""
    return replace(last, forward=0.0, side=0.0, turn=0.0, stop=True)


def plan_walk(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
    pelvis: str | PelvisModel = "cubic",
) -> tuple[list[Stage], Stance]:
    """Stages of a whole walk from the ready posture, closed by a stop and a standing stage.

    A walk whose last command is not a stop gets a closing stop step of the
    last step time and shape factors (:func:`closing_command`), so every
    pattern ends standing in the ready posture.

    Args:
        robot: The robot.
        commands: The step commands.
        schedule: Parameter tables.
        labels: How an error names each command (default ``step N``, 1-based).
        pelvis: ``"cubic"`` (the paper's curves) or ``"quintic"`` (jerk-continuous, zero acceleration at
            every curve's ends: the cart-table ZMP is continuous; the parameters keep their meaning), or another
            pelvis model (:func:`plan_next`).

    Raises:
        ZmpwalkError: With the command's label in front, for the first command that fails.
    """
    pelvis_model(pelvis)
    schedule = schedule or Schedule.hubo()
    stance = Stance.ready(robot)
    boundary = Boundary(0.0)
    stages: list[Stage] = []
    sequence = list(commands)
    if sequence and not sequence[-1].stop:
        sequence.append(closing_command(sequence[-1]))
    walk = _Walk(robot, schedule, pelvis, sequence, labels, len(commands))
    for number, command in enumerate(sequence, start=1):
        walk.starts.append((stance, boundary))
        try:
            new, stance, boundary = plan_next(robot, schedule, stance, boundary, command, reach=False,
                                              pelvis=pelvis)
        except ZmpwalkError as error:
            walk.check_reach(stages)  # a step before it beyond the legs' reach is named first
            if not isinstance(error, STRIDE_CAUSES):  # the stride before the step time (the ZMP: the step)
                error = step_time_rejection(command, error, walk.feasible(number))
            raise error.in_context(walk.label(number)) from None
        stages.extend(new)
        walk.numbers.extend([number] * len(new))
    walk.check_reach(stages)
    stages.append(standing_stage(_standing_plan(stance, robot, schedule), boundary.time))
    return stages, stance


@dataclass
class _Walk:
    """What :func:`plan_walk` knows of a walk to name a rejection: the commands, their labels, where each starts."""

    robot: RobotModel
    schedule: Schedule
    pelvis: str | PelvisModel
    sequence: list[StepCommand]  # the commands and the closing stop
    labels: Sequence[str] | None
    given: int  # commands given (the closing stop follows them)
    starts: list[tuple[Stance, Boundary]] = field(default_factory=list)  # where each command starts from
    numbers: list[int] = field(default_factory=list)  # each stage's command, 1-based

    def check_reach(self, stages: list[Stage]) -> None:
        """Raise for the first stage of ``stages`` beyond the legs' reach, naming its command's stride."""
        try:
            check_reach(stages, self.robot)
        except UnreachableError as error:
            number = self.numbers[error.stage]
            if number > 1 and self.sequence[number - 1].stop:
                number -= 1  # a stop fails for the stride before it
            raise infeasible_command(self.sequence[number - 1], error, self.feasible(number)).in_context(
                self.label(number)) from None

    def feasible(self, number: int) -> Callable[[StepCommand], None]:
        """Raises for a command that does not fit in place of command ``number`` (1-based), or its stop."""
        stance, boundary = self.starts[number - 1]

        def feasible(candidate: StepCommand) -> None:  # the command, and the stop after it
            _, after, after_boundary = plan_next(self.robot, self.schedule, stance, boundary, candidate,
                                                 pelvis=self.pelvis)
            if not candidate.stop:
                plan_next(self.robot, self.schedule, after, after_boundary, closing_command(candidate),
                          pelvis=self.pelvis)

        return feasible

    def label(self, number: int) -> str:
        """How error messages name command ``number`` (1-based): its label (default ``step N``, N counted from 1),
        or for the closing stop added after the last, ``the closing stop after`` the last one's."""
        if number > self.given:
            return f"the closing stop after {self.label(self.given)}"
        if self.labels is None or number > len(self.labels):
            return f"step {number}"
        return self.labels[number - 1]


def _standing_plan(stance: Stance, robot: RobotModel, schedule: Schedule) -> StagePlan:
    parameters, _ = schedule.stage_parameters(StepCommand(duration=1.0), robot)
    return StagePlan(Side.LEFT, stance.right, stance.left, stance.left, 0.0, 1.0, parameters, True, "stand")
