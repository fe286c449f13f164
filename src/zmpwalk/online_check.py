"""A step command's check for the online walker (:class:`zmpwalk.online.OnlineWalker`), in parts.

A command is planned with the stop it would end with when no other follows (:func:`~zmpwalk.patterns.planning.
plan_next_in_parts`), sampled at the control rate into rows (the pattern, and with joints the legs' angles and
rates; without, the legs' reach) in blocks of :data:`SLICE_ROWS` samples, each in parts of tens of microseconds
(:mod:`zmpwalk.slices`), so that the walker runs a few per tick. A refused command is named by the parameter
that cannot be met at any setting of the others, with the largest stride that fits where the stride is the
cause (:mod:`zmpwalk.patterns.stride_search`).

The rows (:data:`ROW_WIDTH` columns, :data:`ROW_WIDTH_WITH_JOINTS` with joints) hold, in world (SI): the pelvis
centre and yaw, each ankle and its foot's yaw, the cart-table ZMP, the support code, and the joint angles and rates.
"""

from __future__ import annotations

import math
from array import array
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InfeasibleCommandError, InvalidParameterError, ZmpwalkError
from zmpwalk.footsteps import Stance
from zmpwalk.kinematics import (
    check_joint_limits,
    check_leg_reach,
    joint_trajectory,
    joint_trajectory_in_parts,
    leg_chains,
)
from zmpwalk.patterns.evaluation import Samples, StageTable, evaluate_in_parts
from zmpwalk.patterns.pelvis_model import check_pelvis
from zmpwalk.patterns.planning import closing_command, plan_next_in_parts
from zmpwalk.patterns.polynomial import first_sample_at
from zmpwalk.patterns.stages import Boundary, Stage
from zmpwalk.patterns.stride_search import (
    STRIDE_CAUSES,
    infeasible_command,
    largest_command,
    step_time_rejection,
)
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.slices import ALONE, Parts, run_to_end

Array = NDArray[np.float64]

# Columns of a sampled row.
ROW_PELVIS, ROW_PELVIS_YAW = slice(0, 3), 3
ROW_LEFT, ROW_LEFT_YAW = slice(4, 7), 7
ROW_RIGHT, ROW_RIGHT_YAW = slice(8, 11), 11
ROW_ZMP, ROW_SUPPORT = slice(12, 14), 14
ROW_JOINTS, ROW_JOINT_RATES = slice(15, 27), slice(27, 39)
ROW_WIDTH = 15
ROW_WIDTH_WITH_JOINTS = 39
SLICE_ROWS = 400  # samples per block of a command's check (each block's pattern and legs in parts of tens of us)
HINT_RATE = 100.0  # [Hz] sampling of the search for the largest stride that fits, in a rejection
HINT_CONFIRMATIONS = 5  # tries at the control rate, each HINT_SHRINK smaller
HINT_SHRINK = 0.98


ONLINE_GENERATORS = ("polynomial", "hyperbolic")


def online_pelvis(pelvis: str, generator: str) -> str:
    """The pelvis model (its name) a walker of a generator and pelvis option plans with
    (:func:`~zmpwalk.patterns.pelvis_model.pelvis_model`).

    Raises:
        InvalidParameterError: An unknown name, or a pelvis curve with the hyperbolic generator.
    """
    if generator not in ONLINE_GENERATORS:
        raise InvalidParameterError("generator", generator, f"one of {', '.join(ONLINE_GENERATORS)}")
    if generator == "hyperbolic":
        if pelvis != "cubic":
            raise InvalidParameterError("pelvis", pelvis, "the default: the hyperbolic generator's pelvis is the "
                                        "pendulum's own motion")
        return "hyperbolic"
    if check_pelvis(pelvis) == "hyperbolic":
        raise InvalidParameterError("pelvis", pelvis, "cubic or quintic (generator=\"hyperbolic\" for the other)")
    return pelvis


@dataclass
class CheckedPlan:
    """A checked command: its stages, where it ends, and its rows from the tick ``first_index`` on."""

    command: StepCommand
    stages: list[Stage]
    stance: Stance
    boundary: Boundary
    rows: Array
    first_index: int
    closing: CheckedPlan | None = None  # the automatic stop after this plan, planned and checked with it
    standing: Array | None = None  # the row of standing still after it, where it ends at rest
    scalars: Scalars = field(default_factory=lambda: row_scalars(np.empty((0, ROW_WIDTH))))  # per row (row_scalars)


Scalars = tuple["array[float]", "array[float]", "array[float]", "array[float]"]
_SCALAR_COLUMNS = (ROW_SUPPORT, ROW_PELVIS_YAW, ROW_LEFT_YAW, ROW_RIGHT_YAW)


def row_scalars(rows: Array) -> Scalars:
    """The rows' support codes and pelvis, left and right yaws, each column an ``array("d")``: a tick reads Python
    floats from it without numpy's scalar conversion (the walker names the support from its code), and a plan
    dropped in a tick frees four buffers (lists of Python floats, one object per value, take about 0.3 ms to free)."""
    support, pelvis, left, right = (array("d", np.ascontiguousarray(rows[:, column]).tobytes())
                                    for column in _SCALAR_COLUMNS)
    return support, pelvis, left, right


@dataclass
class CheckJob:
    """A command under check: where it starts and its planning, in parts run a few per tick."""

    command: StepCommand
    stance: Stance
    boundary: Boundary
    start: int  # index of the tick at which its step begins
    planning: Parts[CheckedPlan | None]
    origin: tuple[Stance, Boundary]  # the walker's end of plan when given: the job is stale once it changes
    expected: int  # parts its check is expected to take
    given: int  # index of the tick at which it was commanded
    buffers: list[Array]  # the rows its planning took (:class:`RowBuffers`), given back if it does not end a plan
    parts: int = 0  # parts run so far


POOL_BUFFERS = 8  # row buffers kept for the next checks (a walker holds at most six plans' at a time)
READY_BUFFERS = 6  # of them made (and their pages touched) with the walker, each for READY_SECONDS of rows
READY_SECONDS = 4.5  # [s] a plan's rows: from standstill the start stage, up to three stages and the stop and
# settle after them fit in 4.5 step times; 4.5 s covers every step of up to 1 s (longer ones take new buffers)


class RowBuffers:
    """Row buffers reused from plan to plan. A plan's rows freed in a tick (at every step change) made the C
    allocator give the top of its heap back to the system: 0.1-0.3 ms, measured; given back here instead, a
    buffer is kept for a later check (each at most once: :meth:`zmpwalk.online.OnlineWalker._release`)."""

    def __init__(self, width: int, ready: int = 0, rows: int = 0) -> None:
        """``ready`` buffers of ``rows`` rows are made now and written once: the system maps a page at its first
        write (a page fault, 1-10 us each on a virtual machine: a block's first fill cost up to 0.4 ms)."""
        self.width = width
        self.free: list[Array] = [np.full((rows, width), np.nan) for _ in range(ready)]

    def take(self, count: int) -> Array:
        """``count`` rows: a view of the smallest kept buffer that holds them, else of a new one (a quarter
        larger, for a longer step later)."""
        best = -1
        for number, buffer in enumerate(self.free):
            if len(buffer) >= count and (best < 0 or len(buffer) < len(self.free[best])):
                best = number
        buffer = self.free.pop(best) if best >= 0 else np.empty((count + count // 4 + 1, self.width))
        return buffer[:count]

    def give(self, rows: Array) -> None:
        """Keep the buffer of ``rows`` (a view :meth:`take` gave, or an array of its own) for a later check."""
        buffer: Array = rows if rows.base is None else rows.base
        if len(self.free) < POOL_BUFFERS and buffer.ndim == 2 and buffer.shape[1] == self.width:
            self.free.append(buffer)


def bare_error(error: ZmpwalkError) -> ZmpwalkError:
    """``error`` without its traceback and the errors it was raised in handling, to be kept as the rejection: a
    traceback holds the frames of the failed check's generators, their arrays with them, until it is freed
    (in the next command(), inside the loop)."""
    cause: BaseException | None = error
    while cause is not None:
        following = cause.__cause__ or cause.__context__
        cause.__traceback__ = cause.__cause__ = cause.__context__ = None
        cause = following
    return error


@dataclass
class Rejection:
    """A command refused by its check, where it was to start, and whether the error is the one to give."""

    command: StepCommand
    error: ZmpwalkError
    stance: Stance
    boundary: Boundary
    named: bool = False  # the parameter to fix is named (:attr:`CommandCheck.rejected` has run)


class CommandCheck:
    """The check of a walker's commands: each planned with the one stop it would end with, sampled at the control
    rate and its legs solved (or their reach checked), into rows a tick only reads.

    Args:
        robot: The robot.
        schedule: Parameter tables.
        pelvis: The pelvis model's name (:func:`~zmpwalk.patterns.pelvis_model.pelvis_model`).
        joints: Solve the legs' joint angles and rates into every row.
        buffers: The walker's row buffers, reused from plan to plan.
    """

    def __init__(self, robot: RobotModel, schedule: Schedule, pelvis: str, joints: bool,
                 buffers: RowBuffers) -> None:
        self.robot = robot
        self.schedule = schedule
        self.pelvis = pelvis
        self.joints = joints
        self.buffers = buffers
        self.width = buffers.width

    def checked(self, command: StepCommand, stance: Stance, boundary: Boundary, rate: float,
                buffers: list[Array] | None = None) -> Parts[CheckedPlan | None]:
        """Plan a command and the stop it leads to when no other follows, sampled (and the legs solved) at
        ``rate``, yielding between slices: planned and checked together, so that no accepted command can make
        a later tick fail, and no tick plans. Returns None for a stop while standing.

        Args:
            buffers: For :meth:`command`'s check, in slices: the rows are taken from the walker's buffers
                (:class:`RowBuffers`) and listed here. None: in one pass, in rows of their own."""
        plan = yield from self._plan(command, stance, boundary, rate, buffers)
        if plan is not None and not command.stop:
            yield
            try:
                plan.closing = yield from self._plan(closing_command(command), plan.stance, plan.boundary, rate,
                                                     buffers)
            except ZmpwalkError as error:
                raise error.in_context("the closing step this command would end with (when no other follows)") \
                    from None
        return plan

    def rejected(self, command: StepCommand, stance: Stance, boundary: Boundary, cause: ZmpwalkError,
                 rate: float) -> ZmpwalkError:
        """The rejection of a command its check refused with ``cause``, naming first the parameter that cannot
        be met at any setting of the others (reach before step time): the largest stride that fits where the
        stride is the cause, or fits at no step time (searched at :data:`HINT_RATE` at most, then confirmed, or
        reduced, at the control rate ``rate`` [Hz]); else ``cause``."""
        coarse = min(rate, HINT_RATE)

        def feasible(candidate: StepCommand) -> object:
            return run_to_end(self.checked(candidate, stance, boundary, coarse))

        if isinstance(cause, STRIDE_CAUSES):
            error: ZmpwalkError = infeasible_command(command, cause, feasible)
        else:
            error = step_time_rejection(command, cause, feasible)
        for _ in range(HINT_CONFIRMATIONS):
            if not isinstance(error, InfeasibleCommandError) or not error.largest or coarse == rate:
                break
            try:
                run_to_end(self.checked(largest_command(command, error), stance, boundary, rate))
                break
            except ZmpwalkError:
                error = error.with_largest({k: v * HINT_SHRINK for k, v in error.largest.items()})
        return error

    def _plan(self, command: StepCommand, stance: Stance, boundary: Boundary, rate: float,
              buffers: list[Array] | None) -> Parts[CheckedPlan | None]:
        """Plan, sample (and solve the legs of) one command from a stance at ``rate`` [Hz], yielding after the
        plan and between the parts of every :data:`SLICE_ROWS` samples; None for a stop while standing.

        The legs' reach is checked at every sample: by their inverse kinematics with ``joints``, else by the
        hip-to-ankle distance."""
        stages, next_stance, next_boundary = yield from plan_next_in_parts(
            self.robot, self.schedule, stance, boundary, command, reach=False, pelvis=self.pelvis)
        if not stages:
            return None
        yield
        # the samples of these stages, split from the neighbours' exactly as the batch path splits them
        first_index = first_sample_at(stages[0].start, rate)
        stop_index = first_sample_at(next_boundary.time, rate)
        count = max(stop_index - first_index, 0)
        if buffers is None:
            rows = np.empty((count, self.width))
        else:
            rows = self.buffers.take(count)
            buffers.append(rows)
        yield ALONE  # the stage table's numbers: a long part (a Python loop over the stages' fields)
        table = yield from StageTable.in_parts(stages)
        yield
        # in slices for command(); an imported robot's legs once the step is sampled (its base velocities are
        # differences along the step), in parts of their own
        size = SLICE_ROWS if buffers is not None else max(len(rows), 1)
        scalars = row_scalars(rows[:0])
        whole_step = self.joints and self.robot.legs is not None
        blocks: list[Samples] = []
        for begin in range(0, len(rows), size):
            block = rows[begin:min(begin + size, len(rows))]
            times = np.arange(first_index + begin, first_index + begin + len(block)) / rate
            samples = yield from evaluate_in_parts(table, times, self.robot)
            yield
            yield from self._fill_pattern(block, samples)
            yield
            for column, values in zip(scalars, row_scalars(block), strict=True):
                column.extend(values)
            yield
            if whole_step:
                blocks.append(samples)
            elif self.joints:
                yield from self._fill_joints(block, samples)
            else:
                check_leg_reach(samples.time, block[:, ROW_PELVIS], samples.pelvis_yaw, samples.left_position,
                                samples.right_position, self.robot)
            yield
        if whole_step and blocks:
            samples = Samples.joined(blocks)
            yield
            yield from self._fill_joints(rows, samples)
            yield
        standing = None
        if next_boundary.at_rest:  # the row of standing still (one IK and the joint ranges, 50 us): a long part
            yield ALONE
            standing = self.standing_row(next_stance)
            yield
        return CheckedPlan(command, stages, next_stance, next_boundary, rows, first_index, standing=standing,
                     scalars=scalars)

    def _fill_pattern(self, rows: Array, samples: Samples) -> Parts[None]:
        """Fill ``rows`` with the pattern's samples (the legs: :meth:`_fill_joints`), in two parts."""
        rows[:, 0:2] = samples.pelvis_xy
        rows[:, 2] = self.robot.pelvis_height
        rows[:, ROW_PELVIS_YAW] = samples.pelvis_yaw
        yield
        rows[:, ROW_LEFT] = samples.left_position
        rows[:, ROW_LEFT_YAW] = samples.left_yaw
        rows[:, ROW_RIGHT] = samples.right_position
        rows[:, ROW_RIGHT_YAW] = samples.right_yaw
        rows[:, ROW_ZMP] = samples.zmp_xy
        rows[:, ROW_SUPPORT] = samples.support

    def _fill_joints(self, rows: Array, samples: Samples) -> Parts[None]:
        """Fill ``rows`` with the legs' angles and rates at ``samples``
        (:func:`~zmpwalk.kinematics.joint_trajectory_in_parts`: its parts and its checks)."""
        n = len(samples.time)
        pelvis = np.column_stack([samples.pelvis_xy, np.full(n, self.robot.pelvis_height)])
        velocity = np.column_stack([samples.pelvis_velocity_xy, np.zeros(n)])
        yield
        trajectory = yield from joint_trajectory_in_parts(
            samples.time, pelvis, samples.pelvis_yaw, velocity,
            samples.pelvis_yaw_rate,
            ((samples.left_position, samples.left_yaw, samples.left_velocity, samples.left_yaw_rate),
             (samples.right_position, samples.right_yaw, samples.right_velocity, samples.right_yaw_rate)),
            self.robot)
        rows[:, ROW_JOINTS] = trajectory.angles
        rows[:, ROW_JOINT_RATES] = trajectory.velocities

    def standing_row(self, stance: Stance) -> Array:
        """The row of standing still in ``stance`` (with joints, the legs solved: one IK), pelvis above the middle of
        the ankles."""
        middle = np.array([(stance.left.x + stance.right.x) / 2, (stance.left.y + stance.right.y) / 2])
        row = np.zeros(self.width)
        row[0:2] = middle
        row[2] = self.robot.pelvis_height
        row[ROW_PELVIS_YAW] = (stance.left.yaw + stance.right.yaw) / 2
        row[ROW_LEFT] = (stance.left.x, stance.left.y, self.robot.ankle_height)
        row[ROW_LEFT_YAW] = stance.left.yaw
        row[ROW_RIGHT] = (stance.right.x, stance.right.y, self.robot.ankle_height)
        row[ROW_RIGHT_YAW] = stance.right.yaw
        row[ROW_ZMP] = middle
        row[ROW_SUPPORT] = 0
        if self.joints and self.robot.legs is None:  # closed-form legs: the scalar IK (microseconds)
            c, s = math.cos(row[ROW_PELVIS_YAW]), math.sin(row[ROW_PELVIS_YAW])
            for index, (chain, ankle, yaw) in enumerate(zip(leg_chains(self.robot), (row[ROW_LEFT], row[ROW_RIGHT]),
                                                             (row[ROW_LEFT_YAW], row[ROW_RIGHT_YAW]), strict=True)):
                dx, dy, dz = (float(v) for v in ankle - row[ROW_PELVIS])
                row[15 + 6 * index:21 + 6 * index] = chain.solve_flat_one(
                    (c * dx + s * dy, c * dy - s * dx, dz), float(yaw - row[ROW_PELVIS_YAW]))
            check_joint_limits(np.zeros(1), row[None, ROW_JOINTS], self.robot)
            row[ROW_JOINT_RATES] = 0.0
        elif self.joints:
            z, one = np.zeros((1, 3)), np.zeros(1)
            trajectory = joint_trajectory(
                np.zeros(1), row[None, ROW_PELVIS], row[None, ROW_PELVIS_YAW], z, one,
                ((row[None, ROW_LEFT], row[None, ROW_LEFT_YAW], z, one),
                 (row[None, ROW_RIGHT], row[None, ROW_RIGHT_YAW], z, one)),
                self.robot)
            row[ROW_JOINTS] = trajectory.angles[0]
            row[ROW_JOINT_RATES] = 0.0
        return row
