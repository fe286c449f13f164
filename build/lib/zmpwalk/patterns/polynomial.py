"""The HUBO walking pattern of any step commands: Park, Kim and Oh (2008), Section 3, sampled.

:func:`generate` plans a whole walk with the stage engine (:func:`~zmpwalk.patterns.planning.plan_walk`: one
*stage* per swing, its trajectories fixed at the stage start from boundary conditions, :mod:`zmpwalk.patterns.stages`)
and samples it at a rate; :func:`generate_chunks` gives the same samples in pieces for walks too long to hold at
once. The pelvis is the paper's cubics by default, or their jerk-continuous quintics, or (the hyperbolic generator,
:func:`zmpwalk.patterns.lipm.generate_hyperbolic`) the linear inverted pendulum's own motion
(:mod:`zmpwalk.patterns.pelvis_model`).
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence

import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError
from zmpwalk.patterns.evaluation import Samples as Samples  # re-exported: other modules import these here
from zmpwalk.patterns.evaluation import StageTable as StageTable
from zmpwalk.patterns.evaluation import evaluate as evaluate
from zmpwalk.patterns.evaluation import side_shift_profile as side_shift_profile  # docs/equations.md
from zmpwalk.patterns.lipm_pelvis import hyperbolic_stages as hyperbolic_stages
from zmpwalk.patterns.pelvis_model import PELVIS_CURVES as PELVIS_CURVES
from zmpwalk.patterns.pelvis_model import PelvisModel, pelvis_model
from zmpwalk.patterns.pelvis_model import check_pelvis as check_pelvis
from zmpwalk.patterns.planning import CHUNK_STAGES as CHUNK_STAGES
from zmpwalk.patterns.planning import REACH_CHECK_POINTS as REACH_CHECK_POINTS
from zmpwalk.patterns.planning import check_reach as check_reach
from zmpwalk.patterns.planning import closing_command as closing_command
from zmpwalk.patterns.planning import plan_next as plan_next
from zmpwalk.patterns.planning import plan_next_in_parts as plan_next_in_parts
from zmpwalk.patterns.planning import plan_walk as plan_walk
from zmpwalk.patterns.result import (
    StepRecord,
    SupportPhase,
    WalkingPattern,
    check_rate,
    sample_times,
)
from zmpwalk.patterns.stages import Boundary as Boundary
from zmpwalk.patterns.stages import Stage as Stage
from zmpwalk.patterns.stages import build_stage as build_stage
from zmpwalk.patterns.stages import stage_support_phases as stage_support_phases
from zmpwalk.patterns.stages import standing_stage as standing_stage
from zmpwalk.patterns.stages import sway_times as sway_times
from zmpwalk.patterns.stride_search import STEP_TIME_PROBES as STEP_TIME_PROBES
from zmpwalk.patterns.stride_search import STRIDE_CAUSES as STRIDE_CAUSES
from zmpwalk.patterns.stride_search import STRIDE_FIELDS as STRIDE_FIELDS
from zmpwalk.patterns.stride_search import infeasible_command as infeasible_command
from zmpwalk.patterns.stride_search import largest_command as largest_command
from zmpwalk.patterns.stride_search import names_stride as names_stride
from zmpwalk.patterns.stride_search import step_time_rejection as step_time_rejection
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.sides import Side

Array = NDArray[np.float64]


def generate(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    rate: float = 100.0,
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
    pelvis: str | PelvisModel = "cubic",
) -> WalkingPattern:
    """The HUBO walking pattern of a command sequence, sampled at ``rate`` [Hz].

    Args:
        robot: The robot.
        commands: Step commands in order; a closing stop is added if missing.
        rate: Samples per second (HUBO's reference rate is 100 Hz).
        schedule: Parameter tables; Tables 2-3 of the paper by default.
        labels: How an error names each command (default ``step N``).
        pelvis: ``"cubic"`` or ``"quintic"``, or another pelvis model (:func:`plan_walk`).

    Returns:
        The pattern from the ready posture at t = 0 to standing after the last step.
    """
    check_rate(rate)
    stages, _ = plan_walk(robot, commands, schedule, labels, pelvis)
    return _sampled(stages, robot, rate, sample_times(stages[-1].start, rate), generator_name(pelvis))


def generate_chunks(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    rate: float = 100.0,
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
    chunk_stages: int = CHUNK_STAGES,
    pelvis: str | PelvisModel = "cubic",
) -> Iterator[WalkingPattern]:
    """The pattern of :func:`generate` in consecutive pieces, for walks too long to hold at once.

    The whole walk is planned and its reach checked first (so an infeasible command raises
    before any piece is returned); then each piece of ``chunk_stages`` stages is sampled,
    in memory that does not grow with the walk. The pieces' samples, joined, are those of
    :func:`generate`; each piece carries the steps and support phases of its own stages.

    Raises:
        InvalidParameterError: ``chunk_stages`` < 1.
    """
    check_rate(rate)
    if isinstance(chunk_stages, bool) or not isinstance(chunk_stages, int) or chunk_stages < 1:
        raise InvalidParameterError("chunk_stages", chunk_stages, "an integer >= 1")
    stages, _ = plan_walk(robot, commands, schedule, labels, pelvis)
    return _chunks(stages, robot, rate, chunk_stages, generator_name(pelvis))


def generator_name(pelvis: str | PelvisModel) -> str:
    """The name a pattern of this pelvis model carries: ``"hyperbolic"`` for the pendulum's, ``"polynomial"`` for
    the curves'."""
    return pelvis_model(pelvis).generator


def _chunks(stages: list[Stage], robot: RobotModel, rate: float, chunk_stages: int, generator: str
            ) -> Iterator[WalkingPattern]:
    end = stages[-1].start  # the first sample of standing still closes the walk
    for first in range(0, len(stages), chunk_stages):
        chunk = stages[first:first + chunk_stages]
        last = first + len(chunk) >= len(stages)
        begin_index = first_sample_at(chunk[0].start, rate)
        stop_time = stages[min(first + len(chunk), len(stages) - 1)].start
        # the last piece ends where sample_times ends the whole walk
        stop_index = math.ceil(end * rate - 1e-9) + 1 if last else first_sample_at(stop_time, rate)
        if stop_index > begin_index:
            yield _sampled(chunk, robot, rate, np.arange(begin_index, stop_index) / rate, generator)


def first_sample_at(time: float, rate: float) -> int:
    """Index of the first sample ``k / rate`` at or after ``time`` [s], compared exactly as the sampled times are
    (the sample that :meth:`StageTable.index_at` puts in the stage starting at ``time``)."""
    index = math.ceil(time * rate - 1e-9)
    while index / rate < time:
        index += 1
    while index > 0 and (index - 1) / rate >= time:
        index -= 1
    return index


def _sampled(stages: list[Stage], robot: RobotModel, rate: float, times: Array,
             generator: str = "polynomial") -> WalkingPattern:
    return pattern_from_samples(evaluate(StageTable(stages), times, robot), stages, robot, rate, generator)


def pattern_from_samples(
    samples: Samples, stages: list[Stage], robot: RobotModel, rate: float, generator: str
) -> WalkingPattern:
    """Wrap evaluated samples and their stages into a :class:`WalkingPattern`."""
    n = len(samples.time)
    height = np.full(n, robot.pelvis_height)
    phases: list[SupportPhase] = []
    steps: list[StepRecord] = []
    for stage in stages:
        for begin, end, code, poses in stage_support_phases(stage):
            if end <= begin:
                continue
            feet = [(stage.plan.support_pose, -stage.plan.swing)]
            if len(poses) == 2:
                feet.append((poses[1], stage.plan.swing))
            phases.append(SupportPhase(begin, end, code, tuple(feet)))
        if not stage.standing:
            plan = stage.plan
            parameters: dict[str, float | str] = dict(vars(plan.parameters))
            steps.append(StepRecord(
                start=stage.start, duration=stage.duration, swing=Side(plan.swing).label,
                kind=plan.kind, landing=(plan.swing_end.x, plan.swing_end.y, plan.swing_end.yaw),
                parameters=parameters,
            ))
    return WalkingPattern(
        robot=robot, rate=rate, generator=generator, time=samples.time, support=samples.support,
        position_pelvis_in_world=np.column_stack([samples.pelvis_xy, height]),
        velocity_pelvis_in_world=np.column_stack([samples.pelvis_velocity_xy, np.zeros(n)]),
        yaw_pelvis_in_world=samples.pelvis_yaw, yaw_rate_pelvis=samples.pelvis_yaw_rate,
        position_left_ankle_in_world=samples.left_position, velocity_left_ankle_in_world=samples.left_velocity,
        yaw_left_foot_in_world=samples.left_yaw, yaw_rate_left_foot=samples.left_yaw_rate,
        position_right_ankle_in_world=samples.right_position,
        velocity_right_ankle_in_world=samples.right_velocity,
        yaw_right_foot_in_world=samples.right_yaw, yaw_rate_right_foot=samples.right_yaw_rate,
        zmp_in_world=samples.zmp_xy, steps=steps, support_phases=phases,
    )
