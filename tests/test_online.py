"""OnlineWalker: same pattern as the offline generator, queueing, stopping, rejected commands."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from zmpwalk import (
    InfeasibleCommandError,
    InvalidParameterError,
    OnlineWalker,  # the public API: from zmpwalk import OnlineWalker, StepCommand, load_robot
    StepCommand,
    UnreachableError,
    ZmpwalkError,
    generate,
    generate_hyperbolic,
    load_robot,
)
from zmpwalk.slices import CountingClock

TOL = 1e-12  # [m] the walker and the generator evaluate the same closed forms


def _rows(sample):
    return np.concatenate([sample.position_pelvis_in_world, [sample.yaw_pelvis_in_world],
                           sample.position_left_ankle_in_world, sample.position_right_ankle_in_world,
                           sample.zmp_in_world])


def _pattern_rows(pattern):
    return np.column_stack([pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
                            pattern.position_left_ankle_in_world, pattern.position_right_ankle_in_world,
                            pattern.zmp_in_world])


def _drive(walker, commands, ticks):
    """Queue each command as soon as the previous one has started; tick."""
    pending = list(commands)
    out = []
    for _ in range(ticks):
        if pending and walker.queued is None:
            walker.command(pending.pop(0), wait=True)
        out.append(_rows(walker.tick()))
    return np.array(out)


@pytest.mark.parametrize("rate", [100.0, 1000.0])
@pytest.mark.parametrize("generator", ["polynomial", "hyperbolic"])
def test_walker_reproduces_the_offline_pattern(hubo, rate, generator):
    commands = [StepCommand(0.95, 0.0), StepCommand(0.8, 0.2), StepCommand(0.7, 0.1, turn=0.1),
                StepCommand(0.8, side=0.05), StepCommand(0.95, -0.1)]
    pattern = (generate if generator == "polynomial" else generate_hyperbolic)(hubo, commands, rate=rate)
    walker = OnlineWalker(hubo, rate=rate, generator=generator)
    rows = _drive(walker, commands, len(pattern.time))
    np.testing.assert_allclose(rows, _pattern_rows(pattern), atol=TOL, rtol=0)
    assert not walker.walking  # it stopped by itself into the ready posture


def test_walker_stands_still_until_commanded(hubo):
    walker = OnlineWalker(hubo, rate=100)
    first = walker.tick()
    for _ in range(50):
        sample = walker.tick()
    np.testing.assert_array_equal(_rows(sample), _rows(first))
    assert sample.support == "double" and sample.time == pytest.approx(0.5)
    walker.command(StepCommand(0.8, 0.2), wait=True)
    assert walker.walking


def test_queued_command_is_replaced_before_it_starts(hubo):
    walker = OnlineWalker(hubo, rate=100)
    walker.command(StepCommand(0.8, 0.1), wait=True)
    walker.tick()
    walker.command(StepCommand(0.8, 0.2), wait=True)
    walker.command(StepCommand(0.8, 0.25), wait=True)  # replaces the 0.2 before it starts
    assert walker.queued == StepCommand(0.8, 0.25)


def test_rejected_command_leaves_the_walker_exactly_as_it_was(hubo):
    commands = [StepCommand(0.8, 0.2)] * 3
    reference = OnlineWalker(hubo, rate=200)
    expected = _drive(reference, commands, 1200)
    walker = OnlineWalker(hubo, rate=200)
    pending = list(commands)
    rows = []
    for tick in range(1200):
        if pending and walker.queued is None:
            walker.command(pending.pop(0), wait=True)
        if tick % 97 == 0:
            queued = walker.queued
            for bad in (StepCommand(0.8, 0.9), StepCommand(0.1, 0.1), StepCommand(0.3, 0.3)):
                with pytest.raises((UnreachableError, InvalidParameterError)):
                    walker.command(bad, wait=True)
            with pytest.raises(InvalidParameterError):
                walker.command("forward please", wait=True)  # type: ignore[arg-type]
            assert walker.queued == queued
        rows.append(_rows(walker.tick()))
    np.testing.assert_array_equal(np.array(rows), expected)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(st.sampled_from([0.7, 0.8, 0.95]), st.floats(0.0, 0.25)), min_size=2, max_size=6),
       st.integers(0, 40))
def test_stop_request_ends_in_the_ready_posture(hubo, steps, stop_after):
    walker = OnlineWalker(hubo, rate=100)
    for duration, forward in steps:
        walker.command(StepCommand(duration, forward), wait=True)
        while walker.queued is not None:
            walker.tick()
    for _ in range(stop_after):
        walker.tick()
    walker.stop()
    for _ in range(2000):
        sample = walker.tick()
        if not walker.walking:
            break
    assert not walker.walking
    left, right = sample.position_left_ankle_in_world, sample.position_right_ankle_in_world
    np.testing.assert_allclose(left - right, [0.0, hubo.hip_spacing, 0.0], atol=1e-12)
    np.testing.assert_allclose(sample.position_pelvis_in_world[:2], (left[:2] + right[:2]) / 2, atol=1e-12)


def test_rate_is_checked(hubo):
    for rate in (0.0, -100.0, float("nan"), 1e6):
        with pytest.raises(InvalidParameterError, match="rate"):
            OnlineWalker(hubo, rate=rate)


command_strategy = st.one_of(
    st.builds(StepCommand, st.sampled_from([0.7, 0.8, 0.95]), st.floats(-0.1, 0.25)),
    st.builds(lambda d, a: StepCommand(d, side=a), st.sampled_from([0.8, 0.95]), st.floats(-0.06, 0.06)),
    st.builds(lambda d, t: StepCommand(d, turn=t), st.sampled_from([0.8, 0.95]), st.floats(-0.2, 0.2)),
    st.just("stop"),
)


@pytest.mark.parametrize("generator", ["polynomial", "hyperbolic"])
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.integers(0, 400), command_strategy), min_size=3, max_size=12))
def test_commands_at_any_tick_keep_the_motion_continuous(hubo, generator, actions):
    """Commands queued, replaced or stopped at random ticks: positions never jump between ticks."""
    rate = 200.0
    walker = OnlineWalker(hubo, rate=rate, generator=generator)
    previous = None
    largest = 0.0
    for wait, action in actions:
        for _ in range(wait):
            sample = walker.tick()
            rows = np.concatenate([sample.position_pelvis_in_world, sample.position_left_ankle_in_world,
                                   sample.position_right_ankle_in_world])
            if previous is not None:
                largest = max(largest, float(np.abs(rows - previous).max()))
            previous = rows
        queued = walker.queued
        try:
            walker.stop() if action == "stop" else walker.command(action, wait=True)
        except ZmpwalkError:
            assert walker.queued == queued  # a rejected command changes nothing
    assert largest < 2.0 / rate  # [m] less than 2 m/s between two ticks: no jump anywhere


@pytest.mark.parametrize(("joints", "command", "error"), [
    (True, StepCommand(duration=1.0, forward=0.3, foot_lift=0.15), "right_ankle_pitch"),
])
def test_a_command_whose_stop_is_infeasible_is_rejected_by_command_not_by_a_later_tick(joints, command, error):
    walker = OnlineWalker(load_robot("hubo"), rate=100, joints=joints)
    with pytest.raises(ZmpwalkError, match=f"closing step this command would end with.*{error}"):
        walker.command(command, wait=True)
    assert not walker.walking and walker.queued is None  # unchanged
    for _ in range(300):  # and it goes on standing, and walking when asked
        walker.tick()
    walker.command(StepCommand(duration=0.8, forward=0.1), wait=True)
    for _ in range(600):
        walker.tick()
    assert not walker.walking  # stopped by itself with the stop planned at command()


def test_samples_do_not_alias_the_walkers_buffers():
    walker = OnlineWalker(load_robot("hubo"), rate=100, joints=True)
    first = walker.tick()  # standing: every standing tick reads the same row
    expected = first.position_pelvis_in_world.copy(), first.joint_angles.copy()
    first.position_pelvis_in_world[:] = 99.0
    first.joint_angles[:] = 99.0
    first.zmp_in_world[:] = 99.0
    second = walker.tick()
    assert np.array_equal(second.position_pelvis_in_world, expected[0])
    assert np.array_equal(second.joint_angles, expected[1])
    assert np.all(second.zmp_in_world != 99.0)


# --------------------------------------------------------------------- hostile command sequences

_HOSTILE_NUMBERS = st.sampled_from([
    None, math.nan, math.inf, -math.inf, 10**400, 1e300, -1e-300, 800.0, 0.0, True, "0.8",
    np.float32(0.5), np.int64(1), np.float64(-2.5), 1e-7, -0.0,
])
_FIELD_NAMES = ("forward", "side", "turn", "alpha", "alpha1", "beta1", "d1", "d1_recovery", "up_ratio", "sway",
                "lateral_velocity", "dsp_time", "foot_lift")
_PLAUSIBLE = {"forward": st.floats(-0.3, 0.6), "side": st.floats(-0.15, 0.15), "turn": st.floats(-0.8, 0.8)}


@st.composite
def _hostile_fields(draw: st.DrawFn) -> dict[str, object]:
    def value(plausible: st.SearchStrategy[float]) -> object:  # three times in four a plausible number
        return draw(st.one_of(plausible, plausible, plausible, _HOSTILE_NUMBERS))

    fields: dict[str, object] = {"duration": value(st.floats(0.5, 1.2))}
    for name in draw(st.lists(st.sampled_from(_FIELD_NAMES), max_size=3, unique=True)):
        fields[name] = value(_PLAUSIBLE.get(name, st.floats(0.0, 1.0)))
    if draw(st.booleans()):
        fields["stop"] = draw(st.sampled_from([True, False, 1, None]))
    return fields


@pytest.mark.parametrize("joints", [False, True])
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(actions=st.lists(st.tuples(st.integers(0, 150), _hostile_fields()), min_size=1, max_size=8))
def test_hostile_commands_are_rejected_by_command_never_by_tick(hubo, joints, actions):
    """Random commands, hostile values and None included: every error is a ZmpwalkError naming a parameter,
    raised when the command is made or given, never by a tick; a rejection changes nothing (the walk equals
    that of a walker given only the accepted commands, sample for sample)."""
    rate = 100.0
    walker = OnlineWalker(hubo, rate=rate, joints=joints)
    reference = OnlineWalker(hubo, rate=rate, joints=joints)
    for wait, fields in [*actions, (1500, None)]:  # then 15 s more: the last walk's stop included
        for _ in range(wait):
            a, b = walker.tick(), reference.tick()  # a tick never raises
            np.testing.assert_array_equal(_rows(a), _rows(b))
            if joints:
                np.testing.assert_array_equal(a.joint_angles, b.joint_angles)
        if fields is None:
            break
        try:
            command = StepCommand(**fields)  # type: ignore[arg-type]
            queued = walker.queued
            try:
                walker.command(command, wait=True)
            except ZmpwalkError as error:
                assert walker.queued == queued
                event("rejected by command()")
                raise error
        except ZmpwalkError as error:
            assert isinstance(error, InvalidParameterError) and error.parameter  # names a parameter
            assert error.parameter in str(error) and "expected" in str(error)
            continue
        event("accepted")
        reference.command(command, wait=True)
    assert not walker.walking  # every accepted walk ended standing


# --------------------------------------------------------------------- command(): the check in slices

def _sample_row(sample):
    return np.concatenate([_rows(sample), sample.joint_angles, sample.joint_velocities])


def counting_clock(monkeypatch, part: float):
    """Make the walker's budget count parts: every part of a check takes ``part`` [s] on its clock, whatever
    the machine (the pacing, and so which command is checked by when, is then the same on every run)."""
    now = [0.0]

    def clock() -> float:
        now[0] += part
        return now[0]

    monkeypatch.setattr("zmpwalk.online._clock", clock)


@pytest.mark.parametrize("rate", [100.0, 1000.0])
@pytest.mark.parametrize("generator", ["polynomial", "hyperbolic"])
def test_commands_checked_in_slices_give_the_same_walk_as_commands_checked_at_once(hubo, rate, generator,
                                                                                   monkeypatch):
    """command() (checked in parts, a few per tick) against command(wait=True) (checked at once): sample for
    sample, joint angles and rates included; the walk from standstill starts START_DELAY later, as documented.
    On a clock where a part takes a fifth of the budget, so that every check ends in time on any machine."""
    from zmpwalk.online import START_DELAY, work_budget

    counting_clock(monkeypatch, work_budget(rate) / 5)

    commands = [StepCommand(0.8, 0.2), StepCommand(0.7, 0.1, turn=0.1), StepCommand(0.8, side=0.05),
                StepCommand(0.95, -0.1)]
    delay = round(START_DELAY * rate)
    direct, sliced = (OnlineWalker(hubo, rate=rate, joints=True, generator=generator) for _ in range(2))
    sliced.command(commands[0])
    direct_rows, sliced_rows = [], []
    for _ in range(delay):  # both stand still meanwhile
        direct_rows.append(_sample_row(direct.tick()))
        sliced_rows.append(_sample_row(sliced.tick()))
    direct.command(commands[0], wait=True)
    pending = commands[1:]
    for tick in range(round(9.0 * rate)):
        if pending and direct.queued is None and tick % 7 == 3:  # a command soon after each step starts
            direct.command(pending[0], wait=True)
            sliced.command(pending.pop(0))
        direct_rows.append(_sample_row(direct.tick()))
        sliced_rows.append(_sample_row(sliced.tick()))
    np.testing.assert_array_equal(np.array(sliced_rows), np.array(direct_rows))
    assert not direct.walking and not sliced.walking and sliced.rejection is None


@pytest.mark.parametrize("rate", [100.0, 1000.0])
@pytest.mark.parametrize("generator", ["polynomial", "hyperbolic"])
def test_commands_checked_in_parts_walk_the_batch_pattern(hubo, rate, generator, monkeypatch):
    """The walks do not change with the slicing: the first command given with wait (so that the walk starts at
    once, as the batch walk does), every other with command() soon after the step before it starts, checked
    in parts over the ticks: generate()'s batch pattern of the same commands (positions, yaws, ZMP) and
    pattern_joint_trajectory's joints and rates, sample for sample."""
    from zmpwalk.kinematics import pattern_joint_trajectory
    from zmpwalk.online import work_budget

    counting_clock(monkeypatch, work_budget(rate) / 5)
    commands = [StepCommand(0.8, 0.2), StepCommand(0.7, 0.1, turn=0.1), StepCommand(0.8, side=0.05),
                StepCommand(0.95, -0.1), StepCommand(0.8, 0.15)]
    pattern = (generate if generator == "polynomial" else generate_hyperbolic)(hubo, commands, rate=rate)
    joints = pattern_joint_trajectory(pattern)
    samples = _walked_in_parts(OnlineWalker(hubo, rate=rate, joints=True, generator=generator), commands,
                               len(pattern.time))
    np.testing.assert_allclose([_rows(s) for s in samples], _pattern_rows(pattern), atol=TOL, rtol=0)
    np.testing.assert_allclose([s.joint_angles for s in samples], joints.angles, atol=1e-9, rtol=0)
    np.testing.assert_allclose([s.joint_velocities for s in samples], joints.velocities, atol=1e-9, rtol=0)


def _walked_in_parts(walker, commands, ticks):
    """``ticks`` samples of ``walker`` given the first command with wait (the walk starts at once, as the batch
    walk does), every other with command() once the one before is under way (checked in parts over the ticks);
    every command walked, none refused."""
    walker.command(commands[0], wait=True)
    pending, samples = list(commands[1:]), []
    for _ in range(ticks):
        if pending and walker.queued is None and walker.checking is None:
            walker.command(pending.pop(0))
        samples.append(walker.tick())
    assert not pending and walker.rejection is None and not walker.walking
    return samples


@pytest.mark.slow
def test_an_imported_robots_commands_checked_in_parts_walk_the_batch_pattern(monkeypatch):
    """An imported robot (TALOS): its check evaluates the pattern in blocks and fills the legs once over each step
    (zmpwalk.whole_body, chunk by chunk from each plan's first sample): the batch pattern's positions sample for
    sample, and its joints within the IK's tolerances (each plan's legs start from the ready posture, the batch's
    from its first sample: the same solution to 1e-8 rad; the rates to 1e-5 rad/s but where a plan's rows meet the
    next's and at the walk's end: there the base's velocity takes its offset's derivative one-sided, within a plan,
    at most 1e-3 rad/s off, two samples each)."""
    from pathlib import Path

    from zmpwalk.kinematics import pattern_joint_trajectory
    from zmpwalk.online import work_budget
    from zmpwalk.robots import load_robot

    model = Path(__file__).resolve().parents[2] / "shared" / "robots" / "pal_talos" / "scene_position.xml"
    if not model.is_file():
        pytest.skip(f"{model} is absent")
    robot, rate = load_robot(model), 500.0
    counting_clock(monkeypatch, work_budget(rate) / 5)
    commands = [StepCommand(0.9, 0.1), StepCommand(0.9, 0.05, turn=0.15), StepCommand(0.9, side=0.05),
                StepCommand(0.9, 0.1)]
    pattern = generate(robot, commands, rate=rate)
    joints = pattern_joint_trajectory(pattern)
    samples = _walked_in_parts(OnlineWalker(robot, rate=rate, joints=True, generator="polynomial"), commands,
                               len(pattern.time))
    np.testing.assert_allclose([_rows(s) for s in samples], _pattern_rows(pattern), atol=TOL, rtol=0)
    np.testing.assert_allclose([s.joint_angles for s in samples], joints.angles, atol=1e-8, rtol=0)
    rates = np.abs(np.array([s.joint_velocities for s in samples]) - joints.velocities)
    assert rates.max() < 1e-3 and (rates > 1e-5).any(axis=1).sum() <= 2 * (len(commands) + 1)  # [rad/s]


@pytest.mark.parametrize("rate", [100.0, 1000.0])
def test_a_command_given_as_the_step_before_starts_is_checked_before_its_own_step(hubo, rate, monkeypatch):
    """A command given as the step before it starts, or from standstill, is checked before its step begins,
    in ticks whose parts fit the budget: on a clock where every part takes a fifth of the budget (the check
    ends after about a third of the step at 1 kHz, in a few ticks at 100 Hz)."""
    from zmpwalk.online import work_budget

    counting_clock(monkeypatch, work_budget(rate) / 5)
    steps = [StepCommand(0.8, 0.2), StepCommand(0.7, 0.15), StepCommand(0.7, 0.1, turn=0.1),
             StepCommand(0.8, side=0.05), StepCommand(0.95, 0.1), StepCommand(0.7, 0.2)]
    walker = OnlineWalker(hubo, rate=rate, joints=True)
    checks = 0
    for _ in range(round(12.0 * rate)):
        if steps and walker.queued is None and walker.checking is None:
            walker.command(steps.pop(0))
            checks += 1
        job = walker._job
        if job is not None:
            assert walker._index < job.start  # unfinished only before its step begins
            parts = job.parts
        walker.tick()
        if job is not None and walker._job is job:
            assert 1 <= job.parts - parts <= 5  # the budget's worth of parts, at least one
    assert checks == 6 and not steps and walker.rejection is None and not walker.walking


def test_a_command_that_fails_its_check_is_kept_as_the_rejection_and_changes_nothing(hubo):
    reference, walker = OnlineWalker(hubo, rate=1000, joints=True), OnlineWalker(hubo, rate=1000, joints=True)
    reference.command(StepCommand(0.8, 0.1), wait=True)
    walker.command(StepCommand(0.8, 0.1), wait=True)
    for tick in range(4000):
        if tick == 100:
            walker.command(StepCommand(1.0, 0.3, foot_lift=0.15))  # its stop leaves the ankle pitch range
            assert walker.checking is not None
        np.testing.assert_array_equal(_sample_row(walker.tick()), _sample_row(reference.tick()))
    error = walker.rejection
    assert isinstance(error, InfeasibleCommandError) and error.parameter == "forward"
    assert "closing step" in str(error) and "ankle_pitch" in str(error) and error.largest["forward"] < 0.3
    assert walker.checking is None and not walker.walking


def _step_under_way(walker):
    """Tick until the walker's first step is under way; the index of the tick its step ends at."""
    while walker.queued is not None or walker._current is None:
        walker.tick()
    current = walker._current
    return current.first_index + len(current.rows)


@pytest.mark.parametrize("rate", [100.0, 1000.0])
@pytest.mark.parametrize("joints", [False, True])
def test_a_command_given_in_the_last_tick_of_a_step_follows_the_closing_stop(hubo, rate, joints, monkeypatch):
    """The rule for a check not complete when its step would begin (module docstring): the walker takes the
    closing stop of the step under way, no tick runs the rest of the check (each tick runs its budget's worth
    of parts), and the command walks after the stop, exactly as the same command given right after the
    stop's first tick: sample for sample, joints included."""
    from zmpwalk.online import work_budget

    counting_clock(monkeypatch, work_budget(rate) / 3)  # three parts a tick
    late, reference = (OnlineWalker(hubo, rate=rate, joints=joints) for _ in range(2))
    for walker in (late, reference):
        walker.command(StepCommand(0.8, 0.1), wait=True)
    end = _step_under_way(late)
    assert _step_under_way(reference) == end
    while late._index < end - 1:
        late.tick()
        reference.tick()
    command = StepCommand(0.8, 0.15)
    late.command(command)  # in the last tick of the step
    row = _sample_row if joints else _rows
    rows = [row(late.tick())]
    assert late._current is None or not late._current.command.stop  # the step still under way
    rows_reference = [row(reference.tick())]
    parts = 0
    for tick in range(round(8.0 * rate)):
        job = late._job
        rows.append(row(late.tick()))
        rows_reference.append(row(reference.tick()))
        if tick == 0:
            assert late._current.command.stop and late.checking == command  # the closing stop; still checking
            reference.command(command)  # right after the stop's first tick
        if job is not None and late._job is job:
            assert job.parts - parts <= 3  # no tick finishes a check at once
        parts = late._job.parts if late._job is not None else 0
    np.testing.assert_array_equal(np.array(rows), np.array(rows_reference))
    assert late.rejection is None and not late.walking and late.checking is None
    assert np.abs(rows[-1][:3] - rows[0][:3]).max() > 0.1  # it walked the 0.15 m step after the stop


def test_a_command_checked_late_after_a_queued_one_follows_the_queued_step(hubo, monkeypatch):
    """A queued command walks when its step comes even while a later command is still under check (the
    walk takes what was checked); the later command follows it, a step later."""
    counting_clock(monkeypatch, 20e-6)
    walker = OnlineWalker(hubo, rate=1000, joints=True)
    walker.command(StepCommand(0.8, 0.1), wait=True)
    end = _step_under_way(walker)
    walker.command(StepCommand(0.7, 0.05), wait=True)  # queued
    while walker._index < end - 3:
        walker.tick()
    walker.command(StepCommand(0.8, 0.2))  # too late for this step: checked while the queued one walks
    for _ in range(4):
        walker.tick()
    assert walker._current.command == StepCommand(0.7, 0.05) and walker.checking == StepCommand(0.8, 0.2)
    while walker.checking is not None:
        walker.tick()
    assert walker.queued == StepCommand(0.8, 0.2) and walker.rejection is None
    while walker.queued is not None:
        walker.tick()
    assert walker._current.command == StepCommand(0.8, 0.2)


@pytest.mark.parametrize("rate", [100.0, 250.0])
def test_a_walk_from_standstill_not_checked_by_its_start_starts_later(hubo, rate, monkeypatch):
    """On a machine too slow for the budget (every part spends it: one part a tick), the walk from standstill
    whose check is not done by its start is checked again with time for one part a tick, and walks."""
    from zmpwalk.online import work_budget

    counting_clock(monkeypatch, 2 * work_budget(rate))
    walker = OnlineWalker(hubo, rate=rate, joints=True)
    walker.command(StepCommand(0.8, 0.1))
    first = walker._job
    started = None
    for tick in range(round(30 * rate)):
        job = walker._job
        before = job.parts if job is not None else 0
        walker.tick()
        if job is not None and walker._job is job:
            assert job.parts - before == 1  # one part a tick
        if started is None and walker._current is not None:
            started = tick
    assert walker._job is None and walker.rejection is None and not walker.walking
    assert started is not None and started > first.start  # later than START_DELAY after the command


def test_stop_while_walking_takes_the_stop_planned_with_the_step(hubo):
    walker = OnlineWalker(hubo, rate=200)
    walker.command(StepCommand(0.8, 0.2), wait=True)
    for _ in range(300):
        walker.tick()
    walker.command(StepCommand(0.8, 0.2), wait=True)
    walker.stop()  # replaces the queued step with the stop of the step under way
    assert walker.queued is not None and walker.queued.stop
    for _ in range(2000):
        sample = walker.tick()
    assert not walker.walking
    np.testing.assert_allclose(sample.position_left_ankle_in_world[0], sample.position_right_ankle_in_world[0],
                               atol=1e-12)  # feet side by side


@pytest.mark.parametrize("generator", ["polynomial", "hyperbolic"])
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(actions=st.lists(st.tuples(st.integers(0, 150), _hostile_fields(), st.booleans()), min_size=1, max_size=8))
def test_hostile_commands_never_make_a_tick_raise(hubo, generator, actions):
    """command() and command(wait=True) mixed at random ticks with hostile values: no tick raises, every
    rejection kept in walker.rejection names a parameter, the motion stays continuous, and every walk ends
    standing."""
    rate = 100.0
    walker = OnlineWalker(hubo, rate=rate, joints=True, generator=generator)
    previous, largest = None, 0.0
    for ticks, fields, checked_in_ticks in [*actions, (1500, None, False)]:
        for _ in range(ticks):
            sample = walker.tick()
            rows = np.concatenate([sample.position_pelvis_in_world, sample.position_left_ankle_in_world,
                                   sample.position_right_ankle_in_world])  # positions (the cubic's ZMP jumps)
            if previous is not None:
                largest = max(largest, float(np.abs(rows - previous).max()))
            previous = rows
            error = walker.rejection
            if error is not None:
                assert isinstance(error, InvalidParameterError) and error.parameter in str(error)
        if fields is None:
            break
        try:
            command = StepCommand(**fields)  # type: ignore[arg-type]
            walker.command(command, wait=not checked_in_ticks)
        except ZmpwalkError as error:
            assert isinstance(error, InvalidParameterError) and error.parameter
    assert largest < hubo.max_foot_speed / rate  # [m] nothing moves faster than the swing foot's limit: no jump
    assert not walker.walking and walker.checking is None


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_online_samples_with_joints_equal_the_batch_path_on_random_walks(hubo, seed):
    """Positions, ZMP, joint angles and joint rates of OnlineWalker (commands given as each step
    starts, checked at once) against generate + pattern_joint_trajectory of the same commands: 1e-9."""
    from zmpwalk.kinematics import pattern_joint_trajectory

    rng = np.random.default_rng(seed)
    commands = []
    for _ in range(6):
        mode = rng.integers(3)
        duration = float(rng.choice([0.7, 0.8, 0.95]))
        if mode == 0:
            commands.append(StepCommand(duration, float(rng.uniform(-0.1, 0.25))))
        elif mode == 1:
            commands.append(StepCommand(duration, side=float(rng.uniform(-0.06, 0.06))))
        else:
            commands.append(StepCommand(duration, float(rng.uniform(0.0, 0.1)), turn=float(rng.uniform(-0.2, 0.2))))
    rate = 500.0
    pattern = generate(hubo, commands, rate=rate)
    joints = pattern_joint_trajectory(pattern)
    walker = OnlineWalker(hubo, rate=rate, joints=True)
    pending, samples = list(commands), []
    for _ in range(len(pattern.time)):
        if pending and walker.queued is None:
            walker.command(pending.pop(0), wait=True)
        samples.append(walker.tick())
    np.testing.assert_allclose([_rows(s) for s in samples], _pattern_rows(pattern), atol=1e-9, rtol=0)
    np.testing.assert_allclose([s.joint_angles for s in samples], joints.angles, atol=1e-9, rtol=0)
    np.testing.assert_allclose([s.joint_velocities for s in samples], joints.velocities, atol=1e-9, rtol=0)


def _pose(sample):
    """Pelvis and both ankles: position and yaw [m, rad]."""
    return np.concatenate([sample.position_pelvis_in_world, [sample.yaw_pelvis_in_world],
                           sample.position_left_ankle_in_world, [sample.yaw_left_foot_in_world],
                           sample.position_right_ankle_in_world, [sample.yaw_right_foot_in_world]])


def _stopping(hubo, rate, generator, steps, stop_at):
    """A walker that walked ``steps`` and was asked to stop ``stop_at`` of the way into the last (None: it
    stops by itself), ticked until its stop (closing step and settle) is under way; the stop's plan. Its budget
    runs on a clock that counts parts (1 us a reading: about 50-100 parts a tick, every check ends well within
    START_DELAY), so that when a walk starts does not depend on how busy the machine is."""
    walker = OnlineWalker(hubo, rate=rate, generator=generator, clock=CountingClock(1e-6))
    for step in steps:
        walker.command(step, wait=True)
        while walker.queued is not None:
            walker.tick()
    if stop_at is not None:
        for _ in range(int(stop_at * steps[-1].duration * rate)):
            walker.tick()
        walker.stop()
    while walker._current is None or not walker._current.command.stop:
        walker.tick()
    return walker, walker._current


def _walk_commanded_at(hubo, setup, delay, wait):
    """The walk ``command`` given ``delay`` of the way from the first tick of the stop (its closing step, then
    the settle) to 1 s after its end (None: at its first tick of standing still): every tick's pose from the
    tick the walk starts on (the rule of the module docstring), and the poses between the end of the settle
    and that tick."""
    from zmpwalk.online import START_DELAY

    rate, generator, steps, stop_at, command = setup
    walker, stop = _stopping(hubo, rate, generator, steps, stop_at)
    rest = stop.first_index + len(stop.rows)  # the first tick of standing still
    given = rest if delay is None else stop.first_index + int(delay * (rest + rate - stop.first_index))
    while walker._index < given:
        walker.tick()
    walker.command(command, wait=wait)
    start = max(rest, given + (0 if wait else math.ceil(START_DELAY * rate - 1e-9)))
    before, after = [], []
    while len(after) < 8 * command.duration * rate:  # the walk (at most 7 step times) and standing after it
        index = walker._index
        pose = _pose(walker.tick())
        if index >= start:
            after.append(pose)
        elif index >= rest:
            before.append(pose)
    assert not walker.walking
    return np.array(before), np.array(after)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.sampled_from([100.0, 250.0]), st.sampled_from(["polynomial", "hyperbolic"]),
       st.lists(st.builds(StepCommand, st.floats(0.7, 0.95), st.floats(0.0, 0.2), turn=st.floats(-0.1, 0.1)),
                min_size=1, max_size=3),
       st.one_of(st.none(), st.floats(0.0, 0.9)),
       st.builds(StepCommand, st.floats(0.7, 0.95), st.floats(-0.1, 0.2), turn=st.floats(-0.1, 0.1)),
       st.floats(0.0, 1.0), st.booleans())
def test_a_walk_after_a_stop_is_the_same_whenever_in_the_settle_it_is_commanded(
        hubo, rate, generator, steps, stop_at, command, delay, wait):
    """A command given at any tick of a stop (its closing step and settle), or after it: the walk starts from the
    standing state on the tick the rule gives (the first at or after the end of the settle and START_DELAY
    after the command, without the delay with wait), and from there its pelvis and feet are those of the
    same command given with wait at the first tick of standing still, to 1e-9 m, sample for sample (before
    the issue's fix: up to 8.6 mm apart, 49 of 49 random walkers at 100 Hz)."""
    setup = (rate, generator, steps, stop_at, command)
    _, reference = _walk_commanded_at(hubo, setup, None, True)
    standing, walk = _walk_commanded_at(hubo, setup, delay, wait)
    assert np.abs(reference[1] - reference[0]).max() > 1e-9  # it starts moving at once
    np.testing.assert_allclose(walk, reference, atol=1e-9, rtol=0)
    if len(standing):  # standing still until it starts, where the walk starts
        np.testing.assert_allclose(standing, np.broadcast_to(reference[0], standing.shape), atol=1e-9, rtol=0)


class _Watch:
    """What became of each command given to a walker: queued, walked (its step under way), or replaced by a later
    command or stop() before it walked (the walker's rule: a later command replaces one not yet walking)."""

    def __init__(self, walker):
        self.walker = walker
        self.given: list[StepCommand] = []
        self.queued: dict[int, int] = {}  # id of a command -> the index of the last action when it was queued
        self.walked: set[int] = set()
        self.rejected: set[int] = set()
        self.actions = 0

    def give(self, command, stop=False):
        self.actions += 1
        if stop:
            self.walker.stop()
        else:
            self.given.append(command)
            self.walker.command(command)

    def tick(self):
        walker = self.walker
        job, pending = walker._job, walker._pending
        sample = walker.tick()  # never raises
        if walker.queued is not None:
            self.queued.setdefault(id(walker.queued), self.actions)
        if walker._current is not None:
            self.walked.add(id(walker._current.command))
        if job is not None and walker._job is None and walker._pending is pending:  # the check refused it
            self.rejected.add(id(job.command))
            assert isinstance(walker._rejection.error, ZmpwalkError)
        return job, sample

    def replaced(self, command):
        """Whether a later command or stop() came after ``command`` was queued (or given)."""
        return self.queued.get(id(command), self.given.index(command) + 1) < self.actions


@pytest.mark.parametrize("joints", [False, True])
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rate=st.sampled_from([100.0, 250.0, 1000.0]), part=st.sampled_from([0.05, 0.3, 1.0, 3.0]),
       actions=st.lists(st.tuples(st.one_of(st.floats(0.0, 1.0), st.floats(0.95, 1.0)), command_strategy),
                        min_size=1, max_size=8))
def test_a_check_not_complete_when_its_step_begins_never_finishes_in_a_tick(hubo, joints, rate, part, actions,
                                                                             monkeypatch):
    """Commands at random ticks of random steps (late ones too: in the last ticks of a step), a part costing
    5 % to 3 times the tick's budget: every tick runs at most its budget's worth of parts (at least one; a check
    behind its pace, CATCH_UP budgets' worth), a check not complete when its step would begin goes on after it while
    the walk takes what was checked (the queued command or the closing stop), and every command queued walks unless a
    later one replaced it."""
    from dataclasses import replace

    from zmpwalk.online import CATCH_UP, work_budget

    counting_clock(monkeypatch, part * work_budget(rate))
    most = int(CATCH_UP / part) + 1  # parts a tick may run: up to the (caught-up) budget's end, at least one
    walker = OnlineWalker(hubo, rate=rate, joints=joints)
    watch = _Watch(walker)
    for fraction, action in [*actions, (None, None)]:
        current = walker._current  # the action at ``fraction`` of what is left of the step under way
        left = current.first_index + len(current.rows) - walker._index if current is not None else 0.9 * rate
        ticks = round(3.0 * rate) if fraction is None else int(fraction * left)
        for _ in range(ticks):
            queued, current, job = walker._pending, walker._current, walker._job
            parts = job.parts if job is not None else 0
            watch.tick()
            if job is not None and walker._job is job:  # still under check: at most its budget's worth of parts
                assert 1 <= job.parts - parts <= most
            if job is not None and walker._index > job.start and walker._job is not None \
                    and walker._job.command is job.command:  # its step was to begin: it waits
                event("a check not complete when its step was to begin")
                assert walker._current is queued or walker._current is (current.closing if current else None) \
                    or walker._current is None
        if action is None:
            break
        watch.give(replace(action) if action != "stop" else None, stop=action == "stop")
    for _ in range(round(40 * rate)):  # until every check ended and the walk stopped
        watch.tick()
        if walker.checking is None and not walker.walking:
            break
    assert walker.checking is None and not walker.walking
    for command in watch.given:
        if watch.replaced(command) or id(command) in watch.rejected:
            continue
        assert id(command) in watch.walked, command  # queued (or the last given) and not replaced: it walked


@pytest.mark.parametrize("rate", [100.0, 1000.0])
def test_the_tick_budget_can_be_given(hubo, rate, monkeypatch):
    """OnlineWalker(budget=...) sets the time a tick spends on a check: on a clock where a part takes 10 us, a
    tick runs at least budget / 10 us parts where it has them and at most CATCH_UP times that (a check behind its
    pace: at 100 Hz a step has few ticks), fewer with a smaller budget, and the check still ends; a budget that is
    not a positive time below the control period is refused."""
    from zmpwalk.online import CATCH_UP

    counting_clock(monkeypatch, 10e-6)
    for budget, least in ((20e-6, 2), (60e-6, 6)):
        walker = OnlineWalker(hubo, rate=rate, joints=True, budget=budget)
        walker.command(StepCommand(0.8, 0.1))
        largest = 0
        while walker.checking is not None:
            before = walker._job.parts
            job = walker._job
            walker.tick()
            if walker._job is job:
                largest = max(largest, job.parts - before)
        assert least <= largest <= CATCH_UP * least and walker.queued == StepCommand(0.8, 0.1)
        assert largest == least or rate == 100.0  # at 1 kHz the budget's pace suffices
    for budget in (0.0, -1e-5, math.nan, math.inf, 1.0 / rate, True, "5e-5"):
        with pytest.raises(InvalidParameterError, match="budget"):
            OnlineWalker(hubo, rate=rate, budget=budget)  # type: ignore[arg-type]
