"""Online use: :class:`OnlineWalker` takes step commands and returns samples at the control rate.

.. code-block:: python

    walker = OnlineWalker(load_robot("hubo"), rate=1000)
    walker.command(StepCommand(duration=0.8, forward=0.2))
    while running:
        sample = walker.tick()          # one sample per control period
        send(sample.position_pelvis_in_world, ...)
        if operator_has_new_step:
            walker.command(next_step)   # stored in microseconds; checked a few parts per tick
        if walker.rejection is not None:
            ...                         # the last command could not be followed (the walk goes on without it)

Behaviour:

* The walker starts standing in the ready posture. The first command starts a
  walk (with the start stage of :func:`zmpwalk.patterns.polynomial.plan_next`).
* :meth:`OnlineWalker.command` gives the command that runs after the step now under way, replacing one
  given before it started. It only stores the command (microseconds). Its whole check, the step and the
  stop it would end with, every sample at the control rate (the pattern, the legs' angles and rates, the
  joint ranges or, without joints, the legs' reach), runs while the step under way goes on, cut into parts
  of tens of microseconds (:mod:`zmpwalk.slices`): the footsteps, each stage (with the hyperbolic generator
  each stage's pendulum), then blocks of :data:`SLICE_ROWS` samples, each in parts (the swing ankle, each
  pelvis axis, the sway, each foot; each leg's angles and rates in parts; the joint ranges). A tick runs
  parts while the next one, taken as long as the mean of the tick's so far, ends within its budget
  (:func:`work_budget`: :data:`WORK_BUDGET`, 50 us, or :data:`WORK_FRACTION` of the control period where
  that is longer, 100 us at 100 Hz), at least one, and none begins after the budget is spent: a tick's work
  is bounded by its budget and one part, whenever commands come. So a check ends as early as the budget
  allows (a few hundred ticks at 1 kHz), and most ticks have nothing to do. When the check completes the
  command is :attr:`~OnlineWalker.queued`; when it fails the reason is kept in
  :attr:`~OnlineWalker.rejection` and the walk goes on as if the command had not been given (no tick ever
  raises).
* **A check that is not complete when its step would begin never finishes inside a tick.** The walk takes
  what was checked: the command queued before it, if any, else the closing stop of the step under way
  (checked with that step, as when no command comes). The command is checked again, in parts, from where
  that leaves the walk: after the queued step, or, after the stop, as a walk from standstill commanded
  right after the stop's first tick (the rule below: it starts when the settle has ended and
  :data:`START_DELAY` after the stop began). A walk from standstill whose check is not complete when it was
  to start (a machine too slow for the budget) starts later: checked again, with time for one part a tick.
  A command given in the last ticks of a step is thus walked a step later; none is dropped for coming late.
* ``command(step, wait=True)`` runs the same check whole in the call (milliseconds: scripts, tests,
  loops without a hard deadline): a rejected command raises and leaves the walker exactly as it was (the
  queued command, if any, stays), and a walk from standstill starts at once.
* A walk commanded while the walker stands, or while it stops (its closing step and settle), starts from
  the standing state the stop ends in, at the first tick at or after both the end of the settle and
  :data:`START_DELAY` (in whole ticks, rounded up) after the tick of the command (without the delay with
  ``wait``). It starts on a tick, so whichever tick it was commanded at, its footsteps and trajectories
  are the same, shifted by whole ticks (the cart-table ZMP too, except that a sample falling exactly on a
  stage boundary, to rounding, may take either stage's value where the ZMP jumps there).
* If no command is queued when the step under way ends, the walker stops
  safely: a closing step of the last step time (the swinging foot lands beside
  the other one) and a settle stage, after which it stands still in the ready
  posture until the next command. :meth:`OnlineWalker.stop` asks for the same
  explicitly. That closing step is planned, sampled and checked (reach, joint
  ranges) with the command before it: a command whose own stop is
  infeasible is rejected, so no accepted command makes a later tick fail, and
  :meth:`~OnlineWalker.stop` and the automatic stop cost a tick nothing.
* The trajectories of a command (and of its stop) are sampled when the command
  is checked, so a :meth:`~OnlineWalker.tick` only reads a row.
"""

from __future__ import annotations

import math
import numbers
import time
from array import array
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.errors import (
    InfeasibleCommandError,
    InvalidParameterError,
    ZmpwalkError,
)
from zmpwalk.footsteps import Stance
from zmpwalk.kinematics import (
    check_joint_limits,
    check_leg_reach,
    joint_trajectory,
    joint_trajectory_in_parts,
    leg_chains,
)
from zmpwalk.patterns.evaluation import Samples, StageTable, evaluate_in_parts
from zmpwalk.patterns.polynomial import (
    STRIDE_CAUSES,
    Boundary,
    Stage,
    check_pelvis,
    closing_command,
    first_sample_at,
    hyperbolic_stages,
    infeasible_command,
    largest_command,
    plan_next_in_parts,
    step_time_rejection,
)
from zmpwalk.patterns.result import SUPPORT_NAMES, check_rate
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.slices import ALONE, UNFINISHED, Parts, run_for, run_to_end

Array = NDArray[np.float64]

# Columns of a sampled row.
_PELVIS, _PELVIS_YAW = slice(0, 3), 3
_LEFT, _LEFT_YAW = slice(4, 7), 7
_RIGHT, _RIGHT_YAW = slice(8, 11), 11
_ZMP, _SUPPORT = slice(12, 14), 14
_JOINTS, _JOINT_RATES = slice(15, 27), slice(27, 39)
_WIDTH = 15
_WIDTH_WITH_JOINTS = 39
SLICE_ROWS = 400  # samples per block of a command's check (each block's pattern and legs in parts of tens of us)
START_DELAY = 0.6  # [s] a walk commanded from standstill starts this much later (its check is done by then)


def start_delay_ticks(rate: float) -> int:
    """:data:`START_DELAY` in whole ticks at ``rate`` [Hz] (rounded up)."""
    return math.ceil(START_DELAY * rate - 1e-9)
HINT_RATE = 100.0  # [Hz] sampling of the search for the largest stride that fits, in a rejection
HINT_CONFIRMATIONS = 5  # tries at the control rate, each HINT_SHRINK smaller
HINT_SHRINK = 0.98


ONLINE_GENERATORS = ("polynomial", "hyperbolic")


def online_pelvis(pelvis: str, generator: str) -> str:
    """The pelvis curves of :func:`~zmpwalk.patterns.polynomial.plan_next` for a generator and pelvis option.

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


@dataclass(slots=True)  # not frozen: a frozen dataclass's __init__ costs 1 us more, a third of a tick
class WalkingSample:
    """The pattern at one control tick, in world (SI).

    A new object every tick, its arrays copies of the walker's row: changing it changes nothing in the walker.

    Attributes:
        time: [s].
        support: ``"double"``, ``"left"`` or ``"right"``.
        position_pelvis_in_world: Pelvis centre [m], shape (3,).
        yaw_pelvis_in_world: [rad].
        position_left_ankle_in_world, position_right_ankle_in_world: [m], shape (3,).
        yaw_left_foot_in_world, yaw_right_foot_in_world: [rad].
        zmp_in_world: Cart-table ZMP [m], shape (2,).
        joint_angles: The 12 leg joint angles [rad] in the order of
            :data:`zmpwalk.kinematics.JOINT_COLUMNS`, or None unless the walker was made with ``joints=True``.
        joint_velocities: Their rates [rad/s], or None.
    """

    time: float
    support: str
    position_pelvis_in_world: Array
    yaw_pelvis_in_world: float
    position_left_ankle_in_world: Array
    yaw_left_foot_in_world: float
    position_right_ankle_in_world: Array
    yaw_right_foot_in_world: float
    zmp_in_world: Array
    joint_angles: Array | None = None
    joint_velocities: Array | None = None


@dataclass
class _Plan:
    command: StepCommand
    stages: list[Stage]
    stance: Stance
    boundary: Boundary
    rows: Array
    first_index: int
    closing: _Plan | None = None  # the automatic stop after this plan, planned and checked with it
    standing: Array | None = None  # the row of standing still after it, where it ends at rest
    scalars: Scalars = field(default_factory=lambda: _scalars(np.empty((0, _WIDTH))))  # per row (:func:`_scalars`)


_SUPPORT_OF_CODE = {float(code): name for code, name in enumerate(SUPPORT_NAMES)}
Scalars = tuple["array[float]", "array[float]", "array[float]", "array[float]"]
_SCALAR_COLUMNS = (_SUPPORT, _PELVIS_YAW, _LEFT_YAW, _RIGHT_YAW)


def _scalars(rows: Array) -> Scalars:
    """The rows' support codes and pelvis, left and right yaws, each column an ``array("d")``: a tick reads Python
    floats from it without numpy's scalar conversion (:data:`_SUPPORT_OF_CODE` names the support), and a plan
    dropped in a tick frees four buffers (lists of Python floats, one per value, took 0.3 ms to free)."""
    support, pelvis, left, right = (array("d", np.ascontiguousarray(rows[:, column]).tobytes())
                                    for column in _SCALAR_COLUMNS)
    return support, pelvis, left, right


@dataclass
class _Job:
    """A command under check: where it starts and its planning, in parts run a few per tick."""

    command: StepCommand
    stance: Stance
    boundary: Boundary
    start: int  # index of the tick at which its step begins
    planning: Parts[_Plan | None]
    origin: tuple[Stance, Boundary]  # the walker's end of plan when given: the job is stale once it changes
    expected: int  # parts its check is expected to take
    given: int  # index of the tick at which it was commanded
    buffers: list[Array]  # the rows its planning took (:class:`_RowBuffers`), given back if it does not end a plan
    parts: int = 0  # parts run so far


POOL_BUFFERS = 8  # row buffers kept for the next checks (a walker holds at most six plans' at a time)
READY_BUFFERS = 6  # of them made (and their pages touched) with the walker, each for READY_SECONDS of rows
READY_SECONDS = 4.5  # [s] a plan's rows: from standstill the start stage, up to three stages and the stop and
# settle after them fit in 4.5 step times; 4.5 s covers every step of up to 1 s (longer ones take new buffers)


class _RowBuffers:
    """Row buffers reused from plan to plan. A plan's rows freed in a tick (at every step change) made the C
    allocator give the top of its heap back to the system: 0.1-0.3 ms, measured; given back here instead, a
    buffer is kept for a later check (each at most once: :meth:`OnlineWalker._release`)."""

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


_clock = time.perf_counter  # [s] the clock of the budget (a test replaces it with one that counts parts)
WORK_BUDGET = 50e-6  # [s] a tick runs parts of a check while the next one is expected to end within this
WORK_FRACTION = 0.01  # [-] ... or within this fraction of the control period, where that is longer (below 200 Hz)
PARTS_PER_BLOCK = 45  # parts of a block of SLICE_ROWS samples (a first guess of a check's length, before one has run)
FINISH_EARLY = 0.95  # [-] a check is paced to end within this fraction of the ticks before its step begins


def work_budget(rate: float) -> float:
    """The time [s] a tick at ``rate`` [Hz] spends on a check's parts: :data:`WORK_BUDGET`, or
    :data:`WORK_FRACTION` of the control period where that is longer."""
    return max(WORK_BUDGET, WORK_FRACTION / rate)


def _bare(error: ZmpwalkError) -> ZmpwalkError:
    """``error`` without its traceback and the errors it was raised in handling, to be kept as the rejection: a
    traceback holds the frames of the failed check's generators, their arrays with them, until it is freed
    (in the next command(), inside the loop)."""
    cause: BaseException | None = error
    while cause is not None:
        following = cause.__cause__ or cause.__context__
        cause.__traceback__ = cause.__cause__ = cause.__context__ = None
        cause = following
    return error


def _checked_budget(budget: object, rate: float) -> float:
    """``budget`` [s] as a float: a positive number below the control period at ``rate`` [Hz].

    Raises:
        InvalidParameterError: Anything else.
    """
    if isinstance(budget, bool) or not isinstance(budget, numbers.Real) or not 0.0 < float(budget) < 1.0 / rate:
        raise InvalidParameterError("budget", budget, f"a time in (0, {1.0 / rate:g}) s, the control period")
    return float(budget)


@dataclass
class _Rejection:
    """A command refused by its check, where it was to start, and whether the error is the one to give."""

    command: StepCommand
    error: ZmpwalkError
    stance: Stance
    boundary: Boundary
    named: bool = False  # the parameter to fix is named (:meth:`OnlineWalker._rejected` has run)


class OnlineWalker:
    """Step-by-step generator of the HUBO pattern for a control loop.

    Args:
        robot: The robot.
        rate: Control rate [Hz] (HUBO: 100 Hz; 1 kHz servo loops are common).
        schedule: Parameter tables (Tables 2-3 of the paper by default).
        joints: Also return the 12 joint angles and velocities at every tick
            (closed-form IK, computed when a command is queued; a command whose
            pattern leaves the legs' reach or joint ranges is rejected).
        pelvis: ``"cubic"`` (the paper's curves) or ``"quintic"`` (jerk-continuous: the cart-table ZMP
            is continuous at every stage boundary).
        generator: ``"polynomial"`` (the HUBO pattern, default) or ``"hyperbolic"`` (the linear inverted
            pendulum pattern of Lim et al., stage by stage: :mod:`zmpwalk.patterns.lipm_stage`; same
            footsteps, swings and continuity; a command whose ZMP would leave the feet is rejected).
        budget: The time [s] a tick may spend on a command's check, one part over at most (default
            :func:`work_budget`: 50 us, or 1 % of the control period where that is longer). Smaller: shorter
            ticks, and checks that take more ticks, so that more commands come too late for the step they were
            given in (and walk a step later: module docstring).

    Raises:
        InvalidParameterError: An unknown ``pelvis`` or ``generator``, ``pelvis="quintic"`` with the
            hyperbolic generator (its pelvis is the pendulum's own motion), or a ``budget`` that is not a
            positive number of seconds below the control period.
    """

    def __init__(self, robot: RobotModel, rate: float = 100.0, schedule: Schedule | None = None,
                 joints: bool = False, pelvis: str = "cubic", generator: str = "polynomial",
                 budget: float | None = None) -> None:
        check_rate(rate)
        self._budget = work_budget(rate) if budget is None else _checked_budget(budget, rate)
        self._pelvis = online_pelvis(pelvis, generator)
        self.robot = robot
        self.rate = float(rate)
        self.joints = bool(joints)
        self._width = _WIDTH_WITH_JOINTS if self.joints else _WIDTH
        self._schedule = schedule or Schedule.hubo()
        self._index = 0
        self._stance = Stance.ready(robot)
        self._boundary = Boundary(0.0)
        self._current: _Plan | None = None
        self._pending: _Plan | None = None
        self._job: _Job | None = None
        self._rejection: _Rejection | None = None
        self._check_parts = 0  # parts the last completed check took
        self._buffers = _RowBuffers(self._width, READY_BUFFERS, math.ceil(READY_SECONDS * self.rate))
        self._set_standing(self._standing_row(self._stance))

    @property
    def time(self) -> float:
        """Time of the next tick [s]."""
        return self._index / self.rate

    @property
    def walking(self) -> bool:
        """True while a walk is under way or queued (False: standing still)."""
        return self._current is not None or self._pending is not None

    @property
    def queued(self) -> StepCommand | None:
        """The command waiting for the step under way to end, if any."""
        return self._pending.command if self._pending else None

    @property
    def current(self) -> StepCommand | None:
        """The command whose step is under way (a stop's closing step and settle included, as the stop command),
        or None while standing still (a walk commanded from standstill that has not begun included)."""
        return self._current.command if self._current is not None else None

    @property
    def rejected(self) -> StepCommand | None:
        """The last command, where its check refused it (None: none refused since the last :meth:`command`).

        Free to read in a hard loop: it names no parameter (:attr:`rejection` does, searching the largest
        stride that fits the first time it is read)."""
        return self._rejection.command if self._rejection is not None else None

    def command(self, command: StepCommand, *, wait: bool = False) -> None:
        """Give ``command`` for after the step under way, replacing one given before it started.

        Only the command's type is checked here (microseconds); its whole check runs in parts, a few per
        :meth:`tick` within the tick's budget (module docstring). When it completes the command is
        :attr:`queued`; when it fails the reason is in :attr:`rejection` and the walker goes on as if the
        command had not been given. A later command replaces one still being checked. A check not complete
        when its step would begin is never finished inside a tick: the walk takes the command queued before
        it, or else its closing stop, and the command follows that, a step later (after a stop, as a walk
        from standstill commanded right after the stop's first tick).

        Args:
            command: The step.
            wait: Check it whole in this call instead (milliseconds), raise if it is rejected, and start a
                walk from standstill at once (a stopping walker: at the first tick of standing still) rather
                than :data:`START_DELAY` later.

        Raises:
            InvalidParameterError: ``command`` is not a :class:`StepCommand`.
            ZmpwalkError: With ``wait``: the command is not feasible from where the walk will be when it
                starts; the walker is unchanged. As :attr:`rejection`: it names first the parameter that no
                setting of the others makes fit (a stride out of reach at every step time, not the step time).
        """
        if not isinstance(command, StepCommand):
            raise InvalidParameterError("command", command, "a StepCommand")
        self._submit(command, self._index, wait)

    def _submit(self, command: StepCommand, given: int, wait: bool, retry: int = 0) -> None:
        """:meth:`command` given at tick ``given``; ``retry``: the parts a check of it from standstill ran without
        ending before its walk was to start (its walk then starts later: :meth:`_work`)."""
        stance, boundary = self._stance, self._boundary
        origin = (stance, boundary)
        # parts to expect: as many as the last check took, at least a guess from the samples (the step, its
        # stop and the settle, and from standstill the start stage; blocks of SLICE_ROWS), more than a late one ran
        blocks = math.ceil((3.0 if self._current is not None else 4.0) * command.duration * self.rate / SLICE_ROWS)
        expected = max(self._check_parts, PARTS_PER_BLOCK * blocks, retry + retry // 8 + 1)
        if boundary.at_rest:
            delay = 0 if wait else start_delay_ticks(self.rate)
            if retry:  # time enough for one part a tick
                delay = max(delay, math.ceil(expected / FINISH_EARLY) + 1)
            boundary = self._rest_start(boundary, given + delay)
        if wait:
            try:
                plan = run_to_end(self._checked(command, stance, boundary, self.rate))
            except ZmpwalkError as error:
                raise self._rejected(command, stance, boundary, error) from None
            self._drop_job()  # a command given now supersedes one still being checked
            self._rejection = None
            dropped, self._pending = self._pending, plan  # None: a stop while standing
            self._release(dropped)
            return
        self._rejection = None
        start = first_sample_at(boundary.time, self.rate)
        self._drop_job()
        buffers: list[Array] = []
        self._job = _Job(command, stance, boundary, start,
                         self._checked(command, stance, boundary, self.rate, buffers), origin, expected, given,
                         buffers)

    def _rest_start(self, rest: Boundary, earliest: int) -> Boundary:
        """Where a walk from standstill starts: from the standing state (the pelvis at rest above the middle of
        the ankles, as the standing row holds it), at the first tick at or after both the end of the walk
        before it (``rest``: its settle) and tick ``earliest``.

        On a tick exactly, so that the walk's samples fall at the same times after its start whenever in the
        settle (or after it) it was commanded: the same walk, shifted by whole ticks."""
        index = max(first_sample_at(rest.time, self.rate), earliest)
        return Boundary(index / self.rate)

    @property
    def checking(self) -> StepCommand | None:
        """The command whose check is under way, if any."""
        return self._job.command if self._job is not None else None

    @property
    def rejection(self) -> ZmpwalkError | None:
        """Why the last command was rejected (None: none since the last :meth:`command`).

        It names first the parameter that cannot be met at any setting of the others, reach before step time:
        where the legs are the cause, or the check refused the step time (or another parameter) but the stride
        fits at no step time (:func:`~zmpwalk.patterns.polynomial.step_time_rejection`), the stride, with the
        largest that fits, searched by bisection the first time this is read (tens of milliseconds): read it
        outside the hard real-time part of the loop, e.g. when :attr:`checking` has become None without the
        command being :attr:`queued`.
        """
        if self._rejection is None:
            return None
        rejection = self._rejection
        if not rejection.named:
            rejection.error = _bare(self._rejected(rejection.command, rejection.stance, rejection.boundary,
                                                   rejection.error))
            rejection.named = True
        return rejection.error

    def _work(self) -> None:
        """A few parts of the given command's check (:data:`WORK_BUDGET`, at least its share of the parts left,
        never its rest at once: the rule of the module docstring for a check not complete when its step begins)."""
        job = self._job
        if job is None:
            return
        if job.origin[0] is not self._stance or job.origin[1] is not self._boundary:
            # the step it was to follow has begun or changed (the walk took what was checked: the queued command,
            # or the closing stop): check it again from the new end of the walk, after a stop as given now
            self._submit(job.command, self._index if self._boundary.at_rest else job.given, wait=False)
            job = self._job
        elif job.start < self._index:  # a walk from standstill not checked by its start (this tick's): later
            self._submit(job.command, self._index, wait=False, retry=job.parts)
            job = self._job
        if job is None:  # pragma: no cover - _submit always sets a job
            return
        ticks_left = max(int(FINISH_EARLY * (job.start - self._index)), 1)
        expected = max(job.expected, job.parts + job.parts // 8 + 1)  # a longer check than expected
        quota = -(-(expected - job.parts) // ticks_left)  # its share of the parts left
        plan: object
        try:
            plan, parts = run_for(job.planning, self._budget, quota, _clock)
            job.parts += parts
        except ZmpwalkError as error:
            self._drop_job()
            self._rejection = _Rejection(job.command, _bare(error), job.stance, job.boundary)
            return
        if plan is UNFINISHED:
            return
        self._check_parts = job.parts
        self._job = None  # its buffers are the plan's rows now
        self._rejection = None
        dropped, self._pending = self._pending, plan if isinstance(plan, _Plan) else None
        self._release(dropped)

    def _drop_job(self) -> None:
        """Drop the check under way, if any, and keep the rows its planning took."""
        if self._job is not None:
            for rows in self._job.buffers:
                self._buffers.give(rows)
            self._job = None

    def _release(self, *plans: _Plan | None) -> None:
        """Keep the rows of ``plans`` and their stops for later checks, where the walker holds them no more (as
        the step under way, the queued command, or their stops); each once, and a released plan keeps no rows."""
        held = [plan for plan in (self._current, self._pending) if plan is not None]
        held += [plan.closing for plan in held if plan.closing is not None]
        for plan in plans:
            for part in (plan, plan.closing) if plan is not None else ():
                if part is not None and len(part.rows) and not any(part is other for other in held):
                    self._buffers.give(part.rows)
                    part.rows = part.rows[:0]

    def _checked(self, command: StepCommand, stance: Stance, boundary: Boundary, rate: float,
                 buffers: list[Array] | None = None) -> Parts[_Plan | None]:
        """Plan a command and the stop it leads to when no other follows, sampled (and the legs solved) at
        ``rate``, yielding between slices: planned and checked together, so that no accepted command can make
        a later tick fail, and no tick plans. Returns None for a stop while standing.

        Args:
            buffers: For :meth:`command`'s check, in slices: the rows are taken from the walker's buffers
                (:class:`_RowBuffers`) and listed here. None: in one pass, in rows of their own."""
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

    def _rejected(self, command: StepCommand, stance: Stance, boundary: Boundary,
                  cause: ZmpwalkError) -> ZmpwalkError:
        """The rejection of a command its check refused with ``cause``, naming first the parameter that cannot
        be met at any setting of the others (reach before step time): the largest stride that fits where the
        stride is the cause, or fits at no step time (searched at :data:`HINT_RATE` at most, then confirmed, or
        reduced, at the control rate); else ``cause``."""
        coarse = min(self.rate, HINT_RATE)

        def feasible(candidate: StepCommand) -> object:
            return run_to_end(self._checked(candidate, stance, boundary, coarse))

        if isinstance(cause, STRIDE_CAUSES):
            error: ZmpwalkError = infeasible_command(command, cause, feasible)
        else:
            error = step_time_rejection(command, cause, feasible)
        for _ in range(HINT_CONFIRMATIONS):
            if not isinstance(error, InfeasibleCommandError) or not error.largest or coarse == self.rate:
                break
            try:
                run_to_end(self._checked(largest_command(command, error), stance, boundary, self.rate))
                break
            except ZmpwalkError:
                error = error.with_largest({k: v * HINT_SHRINK for k, v in error.largest.items()})
        return error

    def _plan(self, command: StepCommand, stance: Stance, boundary: Boundary, rate: float,
              buffers: list[Array] | None) -> Parts[_Plan | None]:
        """Plan, sample (and solve the legs of) one command from a stance at ``rate`` [Hz], yielding after the
        plan and between the parts of every :data:`SLICE_ROWS` samples; None for a stop while standing.

        The legs' reach is checked at every sample: by their inverse kinematics with ``joints``, else by the
        hip-to-ankle distance."""
        hyperbolic = self._pelvis == "hyperbolic"
        stages, next_stance, next_boundary = yield from plan_next_in_parts(
            self.robot, self._schedule, stance, boundary, command, reach=False,
            pelvis="cubic" if hyperbolic else self._pelvis)
        if not stages:
            return None
        yield
        if hyperbolic:  # the pendulum's pelvis
            stages = yield from hyperbolic_stages(stages, boundary, self.robot)
            next_boundary = stages[-1].end
        # the samples of these stages, split from the neighbours' exactly as the batch path splits them
        first_index = first_sample_at(stages[0].start, rate)
        stop_index = first_sample_at(next_boundary.time, rate)
        count = max(stop_index - first_index, 0)
        if buffers is None:
            rows = np.empty((count, self._width))
        else:
            rows = self._buffers.take(count)
            buffers.append(rows)
        yield ALONE  # the stage table's numbers: a long part (a Python loop over the stages' fields)
        table = yield from StageTable.in_parts(stages)
        yield
        # in slices for command(); an imported robot's legs in one pass (its base velocities are differences
        # along the step)
        size = SLICE_ROWS if buffers is not None and self.robot.legs is None else max(len(rows), 1)
        scalars = _scalars(rows[:0])
        for begin in range(0, len(rows), size):
            block = rows[begin:min(begin + size, len(rows))]
            times = np.arange(first_index + begin, first_index + begin + len(block)) / rate
            samples = yield from evaluate_in_parts(table, times, self.robot)
            yield
            yield from self._fill_pattern(block, samples)
            yield
            for column, values in zip(scalars, _scalars(block), strict=True):
                column.extend(values)
            yield
            if self.joints:
                yield from self._fill_joints(block, samples)
            else:
                check_leg_reach(samples.time, block[:, _PELVIS], samples.pelvis_yaw, samples.left_position,
                                samples.right_position, self.robot)
            yield
        standing = None
        if next_boundary.at_rest:  # the row of standing still (one IK) in a slice of its own
            standing = self._standing_row(next_stance)
            yield
        return _Plan(command, stages, next_stance, next_boundary, rows, first_index, standing=standing,
                     scalars=scalars)

    def stop(self) -> None:
        """Queue a closing step into the ready posture (nothing happens when standing).

        The closing step has the step time and shape-factor overrides of the step under way; it was
        planned and checked with that step, so asking for it costs nothing. A command queued or being
        checked is dropped.
        """
        self._drop_job()
        current, dropped = self._current, self._pending
        if current is not None and not current.command.stop:
            self._pending = current.closing
        elif current is None and self._pending is not None and self._boundary.at_rest:
            self._pending = None  # a walk queued from standstill that has not started
        elif current is not None:
            self._pending = None  # the step under way is a stop already
        self._release(dropped)

    def tick(self) -> WalkingSample:
        """The sample at :attr:`time`, then advance by one control period."""
        index = self._index
        current = self._current
        if current is None or index >= current.first_index + len(current.rows):
            current = self._advance(index)
        self._index = index + 1
        # one copy per tick: the caller's arrays never alias the walker's buffers
        if current is None:
            row, (code, pelvis_yaw, left_yaw, right_yaw) = self._standing.copy(), self._standing_scalars
        else:
            offset = index - current.first_index
            row, (codes, pelvis_yaws, left_yaws, right_yaws) = current.rows[offset].copy(), current.scalars
            code, pelvis_yaw, left_yaw, right_yaw = codes[offset], pelvis_yaws[offset], left_yaws[offset], \
                right_yaws[offset]
        if self._job is not None:
            self._work()
        return WalkingSample(
            time=index / self.rate,
            support=_SUPPORT_OF_CODE[code],
            position_pelvis_in_world=row[_PELVIS],
            yaw_pelvis_in_world=pelvis_yaw,
            position_left_ankle_in_world=row[_LEFT],
            yaw_left_foot_in_world=left_yaw,
            position_right_ankle_in_world=row[_RIGHT],
            yaw_right_foot_in_world=right_yaw,
            zmp_in_world=row[_ZMP],
            joint_angles=row[_JOINTS] if self.joints else None,
            joint_velocities=row[_JOINT_RATES] if self.joints else None,
        )

    def _advance(self, index: int) -> _Plan | None:
        """Make the queued command (or the automatic stop) current; None when standing. A command still under
        check waits (module docstring): no tick runs the rest of a check at once."""
        dropped: list[_Plan | None] = []
        try:
            return self._next_plan(index, dropped)
        finally:
            self._release(*dropped)

    def _next_plan(self, index: int, dropped: list[_Plan | None]) -> _Plan | None:
        """:meth:`_advance`, listing the plans it drops in ``dropped``."""
        while True:
            if self._pending is None and not self._boundary.at_rest and self._current is not None:
                # the automatic stop, planned and checked when its step was commanded
                self._pending = self._current.closing
            plan = self._pending
            dropped.append(self._current)
            if plan is None:
                self._current = None
                return None
            if index < plan.first_index:  # a walk commanded from standstill begins START_DELAY later
                self._current = None
                return None
            self._pending = None
            self._current = plan
            self._stance, self._boundary = plan.stance, plan.boundary
            if plan.boundary.at_rest:
                self._set_standing(plan.standing if plan.standing is not None else self._standing_row(plan.stance))
            if index < plan.first_index + len(plan.rows):
                return plan

    def _fill_pattern(self, rows: Array, samples: Samples) -> Parts[None]:
        """Fill ``rows`` with the pattern's samples (the legs: :meth:`_fill_joints`), in two parts."""
        rows[:, 0:2] = samples.pelvis_xy
        rows[:, 2] = self.robot.pelvis_height
        rows[:, _PELVIS_YAW] = samples.pelvis_yaw
        yield
        rows[:, _LEFT] = samples.left_position
        rows[:, _LEFT_YAW] = samples.left_yaw
        rows[:, _RIGHT] = samples.right_position
        rows[:, _RIGHT_YAW] = samples.right_yaw
        rows[:, _ZMP] = samples.zmp_xy
        rows[:, _SUPPORT] = samples.support

    def _fill_joints(self, rows: Array, samples: Samples) -> Parts[None]:
        n = len(samples.time)
        pelvis = np.column_stack([samples.pelvis_xy, np.full(n, self.robot.pelvis_height)])
        trajectory = yield from joint_trajectory_in_parts(
            samples.time, pelvis, samples.pelvis_yaw, np.column_stack([samples.pelvis_velocity_xy, np.zeros(n)]),
            samples.pelvis_yaw_rate,
            ((samples.left_position, samples.left_yaw, samples.left_velocity, samples.left_yaw_rate),
             (samples.right_position, samples.right_yaw, samples.right_velocity, samples.right_yaw_rate)),
            self.robot)
        rows[:, _JOINTS] = trajectory.angles
        rows[:, _JOINT_RATES] = trajectory.velocities

    def _set_standing(self, row: Array) -> None:
        self._standing = row
        self._standing_scalars = tuple(column[0] for column in _scalars(row[None, :]))  # Python floats

    def _standing_row(self, stance: Stance) -> Array:
        middle = np.array([(stance.left.x + stance.right.x) / 2, (stance.left.y + stance.right.y) / 2])
        row = np.zeros(self._width)
        row[0:2] = middle
        row[2] = self.robot.pelvis_height
        row[_PELVIS_YAW] = (stance.left.yaw + stance.right.yaw) / 2
        row[_LEFT] = (stance.left.x, stance.left.y, self.robot.ankle_height)
        row[_LEFT_YAW] = stance.left.yaw
        row[_RIGHT] = (stance.right.x, stance.right.y, self.robot.ankle_height)
        row[_RIGHT_YAW] = stance.right.yaw
        row[_ZMP] = middle
        row[_SUPPORT] = 0
        if self.joints and self.robot.legs is None:  # closed-form legs: the scalar IK (microseconds)
            c, s = math.cos(row[_PELVIS_YAW]), math.sin(row[_PELVIS_YAW])
            for index, (chain, ankle, yaw) in enumerate(zip(leg_chains(self.robot), (row[_LEFT], row[_RIGHT]),
                                                             (row[_LEFT_YAW], row[_RIGHT_YAW]), strict=True)):
                dx, dy, dz = (float(v) for v in ankle - row[_PELVIS])
                row[15 + 6 * index:21 + 6 * index] = chain.solve_flat_one(
                    (c * dx + s * dy, c * dy - s * dx, dz), float(yaw - row[_PELVIS_YAW]))
            check_joint_limits(np.zeros(1), row[None, _JOINTS], self.robot)
            row[_JOINT_RATES] = 0.0
        elif self.joints:
            z, one = np.zeros((1, 3)), np.zeros(1)
            trajectory = joint_trajectory(
                np.zeros(1), row[None, _PELVIS], row[None, _PELVIS_YAW], z, one,
                ((row[None, _LEFT], row[None, _LEFT_YAW], z, one), (row[None, _RIGHT], row[None, _RIGHT_YAW], z, one)),
                self.robot)
            row[_JOINTS] = trajectory.angles[0]
            row[_JOINT_RATES] = 0.0
        return row
