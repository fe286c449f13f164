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
  walk (with the start stage of :func:`zmpwalk.patterns.planning.plan_next`).
* :meth:`OnlineWalker.command` gives the command that runs after the step now under way, replacing one
  given before it started. It only stores the command (microseconds). Its whole check, the step and the
  stop it would end with, every sample at the control rate (the pattern, the legs' angles and rates, the
  joint ranges or, without joints, the legs' reach), runs while the step under way goes on, cut into parts
  of tens of microseconds (:mod:`zmpwalk.slices`): the footsteps, each stage (with the hyperbolic generator
  each stage's pendulum), then blocks of :data:`SLICE_ROWS` samples, each in parts (the swing ankle, each
  pelvis axis, the sway, each foot; each leg's angles and rates in parts; the joint ranges). A tick runs
  parts while the next one, taken as long as the mean of the tick's so far, ends within its budget
  (:func:`work_budget`: :data:`WORK_BUDGET`, 50 us, or :data:`WORK_FRACTION` of the control period where
  that is longer, 100 us at 100 Hz, at most :data:`WORK_LIMIT`), at least one, and none begins after the budget
  is spent (with a :class:`~zmpwalk.control.WalkingController`, the budget less the tick's own work); a check behind
  its pace (its share of the parts left, per tick) runs its share up to :data:`CATCH_UP` times the budget (an
  imported robot's legs, long parts on a busy machine). A tick's work is bounded by that and one part, whenever
  commands come. So a check ends as early as the budget
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
* If no command is queued when the step under way ends, the walker stops safely: a closing step of the last
  step time (the swinging foot lands beside the other one) and a settle stage, after which it stands still in the
  ready posture until the next command. :meth:`OnlineWalker.stop` asks for the same explicitly. That closing step
  is planned, sampled and checked (reach, joint ranges) with the command before it: a command whose own stop is
  infeasible is rejected, so no accepted command makes a later tick fail, and :meth:`~OnlineWalker.stop` and the
  automatic stop cost a tick nothing.
* The trajectories of a command (and of its stop) are sampled when the command is checked, so a tick reads a row.
"""

from __future__ import annotations

import math
import numbers
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError, ZmpwalkError
from zmpwalk.footsteps import Stance
from zmpwalk.online_check import (
    READY_BUFFERS,
    READY_SECONDS,
    ROW_JOINT_RATES,
    ROW_JOINTS,
    ROW_LEFT,
    ROW_PELVIS,
    ROW_RIGHT,
    ROW_WIDTH,
    ROW_WIDTH_WITH_JOINTS,
    ROW_ZMP,
    SLICE_ROWS,
    CheckedPlan,
    CheckJob,
    CommandCheck,
    Rejection,
    RowBuffers,
    bare_error,
    online_pelvis,
    row_scalars,
)
from zmpwalk.patterns.polynomial import first_sample_at
from zmpwalk.patterns.result import check_rate
from zmpwalk.patterns.stages import Boundary
from zmpwalk.robots.model import RobotModel
from zmpwalk.sample import WalkingSample as WalkingSample  # re-exported: where a loop has always found it
from zmpwalk.schedule import Schedule
from zmpwalk.sides import SUPPORT_LABELS
from zmpwalk.slices import UNFINISHED, run_for, run_to_end
from zmpwalk.whole_body import leg_parts

Array = NDArray[np.float64]

START_DELAY = 0.6  # [s] a walk commanded from standstill starts this much later (its check is done by then)


def start_delay_ticks(rate: float) -> int:
    """:data:`START_DELAY` in whole ticks at ``rate`` [Hz] (rounded up)."""
    return math.ceil(START_DELAY * rate - 1e-9)


_SUPPORT_OF_CODE = {float(code): name for code, name in enumerate(SUPPORT_LABELS)}
_clock = time.perf_counter  # [s] the clock of the budget (a test replaces it with one that counts parts)
WORK_BUDGET = 50e-6  # [s] a tick runs parts of a check while the next one is expected to end within this
WORK_FRACTION = 0.01  # [-] ... or within this fraction of the control period, where that is longer (below 200 Hz)
WORK_LIMIT = 500e-6  # [s] ... but never over this (below 20 Hz): a tick's work stays well under a millisecond
WORK_SHARE = 0.5  # [-] of the budget a check's parts get however long the loop's own work in the tick took
CATCH_UP = 2.0  # [-] of the budget a check behind its pace may take to run its share of parts in a tick
PARTS_PER_BLOCK = 45  # parts of a block of SLICE_ROWS samples (a first guess of a check's length; an imported robot's
# legs add theirs, zmpwalk.whole_body.leg_parts)
FINISH_EARLY = 0.95  # [-] a check is paced to end within this fraction of the ticks before its step begins


def work_budget(rate: float) -> float:
    """The time [s] a tick at ``rate`` [Hz] spends on a check's parts: :data:`WORK_BUDGET`, or
    :data:`WORK_FRACTION` of the control period where that is longer, at most :data:`WORK_LIMIT`."""
    return min(max(WORK_BUDGET, WORK_FRACTION / rate), WORK_LIMIT)


def _checked_budget(budget: object, rate: float) -> float:
    """``budget`` [s] as a float: a positive number below the control period at ``rate`` [Hz].

    Raises:
        InvalidParameterError: Anything else.
    """
    if isinstance(budget, bool) or not isinstance(budget, numbers.Real) or not 0.0 < float(budget) < 1.0 / rate:
        raise InvalidParameterError("budget", budget, f"a time in (0, {1.0 / rate:g}) s, the control period")
    return float(budget)


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
        generator: ``"polynomial"`` (the HUBO pattern) or ``"hyperbolic"`` (the linear inverted
            pendulum pattern of Lim et al., stage by stage: :mod:`zmpwalk.patterns.lipm_stage`; same
            footsteps, swings and continuity; a command whose ZMP would leave the feet is rejected); None: the
            robot's :attr:`~zmpwalk.robots.model.RobotModel.default_generator`, as the command line's.
        budget: The time [s] a tick may spend on a command's check, one part over at most (default
            :func:`work_budget`: 50 us, or 1 % of the control period where that is longer, at most 500 us).
            Smaller: shorter ticks, and checks that take more ticks, so that more commands come too late for the
            step they were given in (and walk a step later: module docstring).
        clock: The budget's clock [s] (default ``time.perf_counter``, the machine's); a simulation gives one that
            counts parts (:class:`~zmpwalk.slices.CountingClock`), so that its walk is the same under any load.

    Raises:
        InvalidParameterError: An unknown ``pelvis`` or ``generator``, ``pelvis="quintic"`` with the
            hyperbolic generator (its pelvis is the pendulum's own motion), or a ``budget`` that is not a
            positive number of seconds below the control period.
    """

    def __init__(self, robot: RobotModel, rate: float = 100.0, schedule: Schedule | None = None,
                 joints: bool = False, pelvis: str = "cubic", generator: str | None = None,
                 budget: float | None = None, clock: Callable[[], float] | None = None) -> None:
        check_rate(rate)
        self.budget = work_budget(rate) if budget is None else _checked_budget(budget, rate)
        if clock is not None and not callable(clock):
            raise InvalidParameterError("clock", clock, "a callable returning seconds, or None (the machine's)")
        self._own_clock = clock
        self._pelvis = online_pelvis(pelvis, robot.default_generator if generator is None else generator)
        self.robot, self.rate, self.joints = robot, float(rate), bool(joints)
        self._width = ROW_WIDTH_WITH_JOINTS if self.joints else ROW_WIDTH
        self._schedule = schedule or Schedule.hubo()
        self._index = 0
        self._stance = Stance.ready(robot)
        self._boundary = Boundary(0.0)
        self._current: CheckedPlan | None = None
        self._pending: CheckedPlan | None = None
        self._job: CheckJob | None = None
        self._rejection: Rejection | None = None
        self._check_parts = 0  # parts the last completed check took
        self._block_parts = PARTS_PER_BLOCK + (leg_parts(robot, SLICE_ROWS) if self.joints else 0)  # a first guess
        self._buffers = RowBuffers(self._width, READY_BUFFERS, math.ceil(READY_SECONDS * self.rate))
        self._check = CommandCheck(robot, self._schedule, self._pelvis, self.joints, self._buffers)
        self._set_standing(self._check.standing_row(self._stance))

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
        expected = max(self._check_parts, self._block_parts * blocks, retry + retry // 8 + 1)
        if boundary.at_rest:
            delay = 0 if wait else start_delay_ticks(self.rate)
            if retry:  # time enough for one part a tick
                delay = max(delay, math.ceil(expected / FINISH_EARLY) + 1)
            boundary = self._rest_start(boundary, given + delay)
        if wait:
            try:
                plan = run_to_end(self._check.checked(command, stance, boundary, self.rate))
            except ZmpwalkError as error:
                raise self._check.rejected(command, stance, boundary, error, self.rate) from None
            self._drop_job()  # a command given now supersedes one still being checked
            self._rejection = None
            dropped, self._pending = self._pending, plan  # None: a stop while standing
            self._release(dropped)
            return
        self._rejection = None
        start = first_sample_at(boundary.time, self.rate)
        self._drop_job()
        buffers: list[Array] = []
        self._job = CheckJob(command, stance, boundary, start,
                         self._check.checked(command, stance, boundary, self.rate, buffers), origin, expected, given,
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
        fits at no step time (:func:`~zmpwalk.patterns.stride_search.step_time_rejection`), the stride, with the
        largest that fits, searched by bisection the first time this is read (tens of milliseconds): read it
        outside the hard real-time part of the loop, e.g. when :attr:`checking` has become None without the
        command being :attr:`queued`.
        """
        if self._rejection is None:
            return None
        rejection = self._rejection
        if not rejection.named:
            rejection.error = bare_error(self._check.rejected(rejection.command, rejection.stance,
                                                              rejection.boundary, rejection.error, self.rate))
            rejection.named = True
        return rejection.error

    def now(self) -> float:
        """The budget's clock [s] (the constructor's ``clock``): what a loop times its own work in the tick with, for
        :meth:`work`'s ``spent``."""
        return (self._own_clock or _clock)()

    def work(self, spent: float = 0.0) -> None:
        """The parts of a command's check that :meth:`tick` runs, where it was called with ``work=False``: within
        the tick's budget less ``spent`` [s] (the loop's own work in the tick: the stabilizer's) but at least
        :data:`WORK_SHARE` of it, and at least one part."""
        if self._job is not None:
            self._work(spent)

    def _work(self, spent: float = 0.0) -> None:
        """A few parts of the given command's check (:data:`WORK_BUDGET` less ``spent``, at least its share of the
        parts left, never its rest at once: the rule of the module docstring for a check not complete when its
        step begins)."""
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
            plan, parts = run_for(job.planning, max(self.budget - spent, WORK_SHARE * self.budget), quota,
                                  self._own_clock or _clock, CATCH_UP * self.budget - spent)
            job.parts += parts
        except ZmpwalkError as error:
            self._drop_job()
            self._rejection = Rejection(job.command, bare_error(error), job.stance, job.boundary)
            return
        if plan is UNFINISHED:
            return
        self._check_parts = job.parts
        self._job = None  # its buffers are the plan's rows now
        self._rejection = None
        dropped, self._pending = self._pending, plan if isinstance(plan, CheckedPlan) else None
        self._release(dropped)

    def _drop_job(self) -> None:
        """Drop the check under way, if any, and keep the rows its planning took."""
        if self._job is not None:
            for rows in self._job.buffers:
                self._buffers.give(rows)
            self._job = None

    def _release(self, *plans: CheckedPlan | None) -> None:
        """Keep the rows of ``plans`` and their stops for later checks, where the walker holds them no more (as
        the step under way, the queued command, or their stops); each once, and a released plan keeps no rows."""
        held = [plan for plan in (self._current, self._pending) if plan is not None]
        held += [plan.closing for plan in held if plan.closing is not None]
        for plan in plans:
            for part in (plan, plan.closing) if plan is not None else ():
                if part is not None and len(part.rows) and not any(part is other for other in held):
                    self._buffers.give(part.rows)
                    part.rows = part.rows[:0]

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

    def stand_at(self, stance: Stance) -> None:
        """Stand still with the feet at ``stance`` from the next tick (the walking controller's capture step left
        them there), dropping every command; raises as the standing pose's legs do, the walker then unchanged."""
        row = self._check.standing_row(stance)
        self._drop_job()
        dropped, self._current, self._pending, self._rejection = (self._current, self._pending), None, None, None
        self._release(*dropped)
        self._stance, self._boundary = stance, Boundary(self.time)
        self._set_standing(row)

    def tick(self, *, work: bool = True) -> WalkingSample:
        """The sample at :attr:`time`, then advance by one control period; ``work=False``: without the parts of a
        command's check, which :meth:`work` then runs (a loop that times its own work into the budget)."""
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
        if work and self._job is not None:
            self._work()
        return self._sample(index, row, code, pelvis_yaw, left_yaw, right_yaw)

    def peek(self, ahead: int = 0) -> WalkingSample | None:
        """The sample :meth:`tick` will return ``ahead`` ticks after the next one (0: the next), where the step under
        way holds it (None beyond that step's rows, or standing): what the walk plays there unless a command or a
        stop changes the step after. Bounded: one row copy."""
        current, index = self._current, self._index + ahead
        if current is None or not current.first_index <= index < current.first_index + len(current.rows):
            return None
        offset = index - current.first_index
        codes, pelvis_yaws, left_yaws, right_yaws = current.scalars
        return self._sample(index, current.rows[offset].copy(), codes[offset], pelvis_yaws[offset], left_yaws[offset],
                            right_yaws[offset])

    def _sample(self, index: int, row: Array, code: float, pelvis_yaw: float, left_yaw: float,
                right_yaw: float) -> WalkingSample:
        """The sample of tick ``index`` from its row (a copy the sample owns) and scalars."""
        return WalkingSample(
            time=index / self.rate,
            support=_SUPPORT_OF_CODE[code],
            position_pelvis_in_world=row[ROW_PELVIS],
            yaw_pelvis_in_world=pelvis_yaw,
            position_left_ankle_in_world=row[ROW_LEFT],
            yaw_left_foot_in_world=left_yaw,
            position_right_ankle_in_world=row[ROW_RIGHT],
            yaw_right_foot_in_world=right_yaw,
            zmp_in_world=row[ROW_ZMP],
            joint_angles=row[ROW_JOINTS] if self.joints else None,
            joint_velocities=row[ROW_JOINT_RATES] if self.joints else None,
        )

    def _advance(self, index: int) -> CheckedPlan | None:
        """Make the queued command (or the automatic stop) current; None when standing. A command still under
        check waits (module docstring): no tick runs the rest of a check at once."""
        dropped: list[CheckedPlan | None] = []
        try:
            return self._next_plan(index, dropped)
        finally:
            self._release(*dropped)

    def _next_plan(self, index: int, dropped: list[CheckedPlan | None]) -> CheckedPlan | None:
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
                standing = plan.standing if plan.standing is not None else self._check.standing_row(plan.stance)
                self._set_standing(standing)
            if index < plan.first_index + len(plan.rows):
                return plan

    def _set_standing(self, row: Array) -> None:
        self._standing = row
        self._standing_scalars = tuple(column[0] for column in row_scalars(row[None, :]))  # Python floats
