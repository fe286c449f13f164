"""OnlineWalker in a control loop: commands at random ticks, 1 Hz to 1 kHz, hostile ones among them.

No test here asserts a timing: ``bench/bench_control_loop.py`` measures the ticks. These check what the loop
relies on whatever the timing of commands and however fast the machine is: no tick raises, every rejection
lands in ``walker.rejection`` (a ZmpwalkError naming a parameter), and every accepted command walks unless a
later command or ``stop()`` replaced it (the rule of :mod:`zmpwalk.online` for a check not complete when its
step would begin: it walks a step later).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from command_strategies import HOSTILE_STEPS, ORDINARY_STEPS, parts_clock
from zmpwalk import InvalidParameterError, OnlineWalker, StepCommand, ZmpwalkError
from zmpwalk.online import work_budget

ACTION = st.one_of(ORDINARY_STEPS, ORDINARY_STEPS, HOSTILE_STEPS, st.just("stop"))


@dataclass
class Outcomes:
    """What became of the commands given to one walker."""

    given: list[StepCommand] = field(default_factory=list)
    actions: int = 0  # command() and stop() calls so far
    queued: dict[int, int] = field(default_factory=dict)  # id of a command -> actions when it was first queued
    walked: set[int] = field(default_factory=set)
    rejected: set[int] = field(default_factory=set)

    def watch(self, walker: OnlineWalker, checking: StepCommand | None) -> None:
        """After a tick: the queued command, the step under way, and a check that ended without a plan."""
        if walker.queued is not None:
            self.queued.setdefault(id(walker.queued), self.actions)
        current = walker._current
        if current is not None:
            self.walked.add(id(current.command))
        if checking is not None and walker.checking is None and walker.queued is not checking \
                and id(checking) not in self.walked and walker.rejection is not None:
            self.rejected.add(id(checking))
            error = walker.rejection  # names the largest stride that fits, where that is the cause
            assert isinstance(error, ZmpwalkError) and error.parameter and error.parameter in str(error)

    def replaced(self, command: StepCommand) -> bool:
        """A command() or stop() came after ``command`` was queued (or, never queued, after it was given)."""
        return self.queued.get(id(command), self.given.index(command) + 1) < self.actions


def _loop(walker: OnlineWalker, actions: list[tuple[float, object]], outcomes: Outcomes,
          note: Callable[[str], None]) -> float:
    """Give each action ``wait`` seconds after the one before, ticking; then tick until the walk ends (at most
    40 s or 3000 ticks: at 1 Hz a check may take one tick a part). The largest move of the pelvis or an ankle
    between two ticks [m]; ``note`` counts what happened (hypothesis's event)."""
    rate = walker.rate
    previous, largest = None, 0.0
    for wait, action in [*actions, (None, None)]:
        ticks = max(round(40.0 * rate), 3000) if wait is None else max(int(wait * rate), 0)
        for _ in range(ticks):
            checking = walker.checking
            sample = walker.tick()  # a tick never raises
            outcomes.watch(walker, checking)
            position = np.concatenate([sample.position_pelvis_in_world, sample.position_left_ankle_in_world,
                                       sample.position_right_ankle_in_world])
            if previous is not None:
                largest = max(largest, float(np.abs(position - previous).max()))
            previous = position
            if wait is None and walker.checking is None and not walker.walking:
                break
        if action is None:
            break
        outcomes.actions += 1
        if action == "stop":
            walker.stop()
            continue
        try:
            command = StepCommand(**action)  # type: ignore[arg-type]
        except InvalidParameterError as error:  # a zero or nan step time: refused when made, as a loop catches it
            assert error.parameter == "duration"
            note("refused when made")
            continue
        outcomes.given.append(command)
        walker.command(command)
    return largest


def _check(walker: OnlineWalker, outcomes: Outcomes, largest: float, note: Callable[[str], None]) -> None:
    assert walker.checking is None and not walker.walking  # every check ended, every walk stopped
    assert largest < max(walker.robot.max_foot_speed / walker.rate, 0.5)  # no jump: at most the swing foot's speed
    for command in outcomes.given:
        if id(command) in outcomes.rejected:
            note("rejected")
        elif outcomes.replaced(command):
            note("replaced by a later command or stop()")
        else:
            assert id(command) in outcomes.walked, command  # accepted and not replaced: it walked
            note("walked")


@pytest.mark.parametrize("joints", [False, True])
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rate=st.sampled_from([1.0, 7.0, 50.0, 100.0, 333.0, 1000.0]), part=st.sampled_from([0.02, 0.2, 1.0, 4.0]),
       actions=st.lists(st.tuples(st.floats(0.0, 1.2), ACTION), min_size=1, max_size=10))
def test_commands_at_random_ticks_never_make_a_tick_raise_and_accepted_ones_walk(hubo, joints, rate, part, actions,
                                                                                 monkeypatch):
    """Random commands (hostile ones among them) at random ticks, 1 Hz to 1 kHz, on a machine where every part
    of a check costs 2 % to 4 times the tick's budget: no tick raises, every rejection is a ZmpwalkError naming
    a parameter, every accepted command walks unless replaced, and the walk ends standing."""
    parts_clock(monkeypatch, part * work_budget(rate))
    walker = OnlineWalker(hubo, rate=rate, joints=joints)
    outcomes = Outcomes()
    largest = _loop(walker, actions, outcomes, event)
    _check(walker, outcomes, largest, event)


@pytest.mark.parametrize(("rate", "joints"), [(1000.0, True), (100.0, False), (10.0, True)])
def test_a_seeded_loop_on_the_machines_own_clock(hubo, rate, joints):
    """The same on this machine's own clock (the budget in real time: which checks end in time depends on the
    machine, what becomes of each command does not change the rules), 40 random commands at random ticks. The
    budget is half the control period, so that some checks end in time whatever the machine's load (at the default
    budget, 500 us at 10 Hz, no command walked in two runs on this shared 2-core machine, one of them alone)."""
    rng = np.random.default_rng(int(rate))
    actions: list[tuple[float, object]] = []
    for _ in range(40):
        kind = rng.random()
        if kind < 0.15:
            action: object = "stop"
        elif kind < 0.3:
            action = {"duration": 0.8, "forward": float(rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.0))}
        elif kind < 0.35:
            action = {"duration": 0.0, "forward": 0.1}
        else:
            action = {"duration": float(rng.uniform(0.7, 1.0)), "forward": float(rng.uniform(-0.1, 0.2)),
                      "turn": float(rng.uniform(-0.1, 0.1))}
        actions.append((float(rng.uniform(0.0, 1.0)), action))
    walker = OnlineWalker(hubo, rate=rate, joints=joints, budget=0.5 / rate)
    outcomes = Outcomes()
    largest = _loop(walker, actions, outcomes, lambda _: None)
    _check(walker, outcomes, largest, lambda _: None)
    assert outcomes.walked and outcomes.rejected  # both occur in this loop


@settings(max_examples=200, deadline=None)
@given(costs=st.lists(st.tuples(st.floats(0.0, 3.0), st.booleans()), min_size=1, max_size=40),
       budget=st.floats(0.0, 5.0), quota=st.integers(1, 10), cap=st.one_of(st.none(), st.floats(0.0, 10.0)))
def test_run_for_begins_no_part_after_its_budget_and_gives_the_same_result(costs, budget, quota, cap):
    """slices.run_for on a clock that each part advances by its cost: at least one part, none begun once the
    budget is spent (so the time is at most the budget and one part), or with a cap, once the cap is spent and
    past the budget only the call's first ``quota``; a part marked ALONE only while at most a quarter of the
    budget is spent; and, run until done, the result that run_to_end gives."""
    from zmpwalk.slices import ALONE, LONG_PART_START, UNFINISHED, Parts, run_for, run_to_end

    now = [0.0]
    begun: list[tuple[float, bool]] = []  # when each part began, and whether it was marked ALONE

    def computation() -> Parts[int]:
        alone = False
        for cost, mark in costs:
            begun.append((now[0], alone))
            now[0] += cost
            alone = mark
            yield ALONE if mark else None
        return len(costs)

    parts, total, result = computation(), 0, UNFINISHED
    while result is UNFINISHED:
        start, first = now[0], len(begun)
        result, count = run_for(parts, budget, quota, lambda: now[0], cap)
        total += count
        assert count >= 1
        later = begun[first + 1:]  # the parts begun after the call's first one
        limit = budget if cap is None else max(cap, budget)
        assert all(time - start < limit for time, _ in later)
        assert all(time - start < budget for i, (time, _) in enumerate(later, start=1) if i >= quota)
        assert all(time - start <= LONG_PART_START * budget for time, alone in later if alone)
    begun.clear()
    assert result == run_to_end(computation()) == len(costs) and total == len(costs) + 1


@pytest.mark.parametrize("rate", [100.0, 1000.0])
def test_the_loop_leaves_no_reference_cycles(hubo, rate):
    """A walker driven by random commands (rejections, late checks, stop(), walks from standstill) leaves no
    cyclic garbage of its own: everything it drops is freed by its reference count, so a hard loop may run
    with the garbage collector disabled (docs/speed.md) and leak nothing."""
    import gc
    import types

    rng = np.random.default_rng(5)
    actions: list[tuple[float, object]] = []
    for _ in range(25):
        kind = rng.random()
        action: object = "stop" if kind < 0.1 else {"duration": 0.8, "forward": 0.9} if kind < 0.3 else {
            "duration": float(rng.uniform(0.7, 1.0)), "forward": float(rng.uniform(-0.1, 0.2))}
        actions.append((float(rng.uniform(0.0, 1.0)), action))
    actions.append((0.5, {"duration": 0.8, "forward": 0.9}))  # the last: nothing replaces it, its rejection is sure
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    gc.set_debug(gc.DEBUG_SAVEALL)
    try:
        walker = OnlineWalker(hubo, rate=rate, joints=True)
        outcomes = Outcomes()
        _loop(walker, actions, outcomes, lambda _: None)
        assert outcomes.walked and outcomes.rejected
        del walker, outcomes
        gc.collect()
        ours = [o for o in gc.garbage if type(o).__module__.startswith("zmpwalk")
                or isinstance(o, types.GeneratorType | types.FrameType | np.ndarray | BaseException)]
        assert not ours
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        if enabled:
            gc.enable()
