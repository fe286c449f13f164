"""Rejections that point at the right fix: the stride before the step time, limits in the user's directions,
one way of numbering the steps."""

from __future__ import annotations

import re

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from zmpwalk import (
    InfeasibleCommandError,
    InvalidParameterError,
    OnlineWalker,
    StepCommand,
    UnreachableError,
    ZmpwalkError,
    generate,
)
from zmpwalk.patterns.polynomial import STEP_TIME_PROBES, STRIDE_FIELDS, names_stride, plan_walk

RATE = 100.0  # [Hz]


def _rejection(hubo, command, joints=False):
    """The error of ``command`` given with wait to a standing walker (None: accepted)."""
    walker = OnlineWalker(hubo, rate=RATE, joints=joints)
    try:
        walker.command(command, wait=True)
    except ZmpwalkError as error:
        assert not walker.walking and walker.queued is None  # a rejection changes nothing
        return error
    return None


def _fits_at_some_step_time(hubo, command, durations):
    for duration in durations:
        try:
            candidate = StepCommand(duration, command.forward, command.side, command.turn)
        except InvalidParameterError:
            continue
        if _rejection(hubo, candidate) is None:
            return duration
    return None


def test_a_side_step_beyond_reach_at_any_step_time_names_the_side_step_not_the_step_time(hubo):
    """1.55 m to the left at 0.56 s: the swing is too fast for 0.56 s, but no step time brings it within the
    legs' reach (before: 'a step time >= 0.718 s'). Named: the side step, with the largest that fits at 0.56 s."""
    command = StepCommand(0.56, side=1.55)
    assert _fits_at_some_step_time(hubo, command, [0.56, 0.72, 0.8, 1.0, 1.5, 2.0, 3.0, 5.0]) is None
    error = _rejection(hubo, command)
    assert isinstance(error, InfeasibleCommandError) and error.parameter == "side" and error.value == 1.55
    assert error.every_step_time and error.step_time is None
    assert isinstance(error.cause, UnreachableError)
    largest = error.largest["side"]
    assert set(error.largest) == {"side"} and 0.3 < largest < 0.45  # [m] signed SI, to the left
    assert "duration" not in str(error) and "at any step time" in str(error)
    assert f"at most {largest:.3f} m to the left (side = {largest:.3f} m)" in str(error)
    assert _rejection(hubo, StepCommand(0.56, side=largest)) is None  # the named stride is taken at 0.56 s
    assert _rejection(hubo, StepCommand(0.56, side=largest * 1.02)) is not None  # within 2 %


def test_the_same_rule_when_the_rejection_is_read_from_a_walker_in_a_control_loop(hubo):
    walker = OnlineWalker(hubo, rate=RATE)
    walker.command(StepCommand(0.56, side=1.55))
    for _ in range(100):
        walker.tick()
    error = walker.rejection
    assert isinstance(error, InfeasibleCommandError) and error.parameter == "side" and error.every_step_time
    assert walker.rejection is error and not walker.walking  # searched once, kept


def test_a_stride_that_fits_at_a_longer_step_time_is_still_told_to_take_it(hubo):
    """0.3 m at 0.3 s: the swing is too fast, a longer step time fits: the step time is named."""
    error = _rejection(hubo, StepCommand(0.3, 0.3))
    assert isinstance(error, InvalidParameterError) and not isinstance(error, InfeasibleCommandError)
    assert error.parameter == "duration" and "a step time >= 0.3" in str(error)
    shortest = float(re.search(r"a step time >= (\d\.\d+) s", str(error)).group(1))
    assert _rejection(hubo, StepCommand(shortest + 0.001, 0.3)) is None


def test_where_no_step_in_place_fits_at_the_step_time_the_largest_stride_names_a_step_time_that_does(hubo):
    """1.55 m at 0.15 s: not even a step in place swings fast enough at 0.15 s; the stride fits at no step
    time; the largest side step is given at the nearest step time where one fits (0.3 s), and fits there."""
    error = _rejection(hubo, StepCommand(0.15, side=1.55))
    assert isinstance(error, InfeasibleCommandError) and error.parameter == "side" and error.every_step_time
    assert error.step_time == pytest.approx(0.3, abs=1e-12)
    largest = error.largest["side"]
    assert f"at most {largest:.3f} m to the left (side = {largest:.3f} m) at a step time of 0.300 s" in str(error)
    assert _rejection(hubo, StepCommand(0.3, side=largest)) is None


@pytest.mark.parametrize(("command", "joints", "words"), [
    (StepCommand(0.8, -0.9), False, [r"at most (0\.4\d\d) m backward \(forward = -\1 m\)"]),
    (StepCommand(0.8, 0.9), False, [r"at most (0\.4\d\d) m forward \(forward = \1 m\)"]),
    (StepCommand(0.8, side=-0.9), False, [r"at most (0\.3\d\d) m to the right \(side = -\1 m\)"]),
    (StepCommand(0.8, side=0.9), False, [r"at most (0\.3\d\d) m to the left \(side = \1 m\)"]),
    (StepCommand(0.8, 0.3, side=-0.2, turn=-0.9), True,
     [r"at most (0\.\d{3}) m forward, (0\.\d{3}) m to the right and (0\.\d{3}) rad clockwise "
      r"\(forward = \1 m, side = -\2 m, turn = -\3 rad\)"]),
])
def test_limits_are_stated_in_the_users_directions(hubo, command, joints, words):
    """Negative forward is backward, negative side to the right (y is left), negative turn clockwise; the
    fields follow as they are written; ``largest`` keeps the signed SI values."""
    error = _rejection(hubo, command, joints)
    assert isinstance(error, InfeasibleCommandError)
    for pattern in words:
        match = re.search(pattern, str(error))
        assert match, str(error)
    for name, value in error.largest.items():
        assert value * getattr(command, name) > 0  # same direction, signed
        assert f"{name} = {value:.3f} " in str(error)
    assert "at most forward =" not in str(error) and "at most side =" not in str(error)


def test_the_message_of_a_turn_clockwise_and_counter_clockwise():
    cause = UnreachableError("left", 1.0, 0.01)
    assert "at most 0.350 rad clockwise (turn = -0.350 rad)" in str(
        InfeasibleCommandError("turn", -0.9, {"turn": -0.35}, cause))
    assert "at most 0.350 rad counter-clockwise (turn = 0.350 rad)" in str(
        InfeasibleCommandError("turn", 0.9, {"turn": 0.35}, cause))
    assert "at most 0.200 m to the right (side = -0.200 m)" in str(
        InfeasibleCommandError("side", -0.9, {"side": -0.2}, cause))


stride_strategy = st.one_of(
    st.builds(lambda d, f: StepCommand(d, f), st.floats(0.1, 1.2), st.floats(-1.2, 1.2)),
    st.builds(lambda d, s: StepCommand(d, side=s), st.floats(0.1, 1.2), st.floats(-1.6, 1.6)),
    st.builds(lambda d, f, t: StepCommand(d, f, turn=t), st.floats(0.1, 1.2), st.floats(0.0, 0.6),
              st.floats(-0.4, 0.4)),
)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(stride_strategy)
def test_a_rejection_names_the_stride_exactly_when_no_step_time_makes_it_fit(hubo, command):
    """Any command: a rejection that names the step time leaves a step time at which the stride fits; one that
    says the stride fits at no step time is right about every step time tried; the largest stride named fits."""
    error = _rejection(hubo, command)
    event("accepted" if error is None else f"{type(error).__name__} {getattr(error, 'parameter', '')} "
          f"{'every step time' if getattr(error, 'every_step_time', False) else ''}")
    if error is None:
        return
    if not names_stride(error):  # the step time, or another parameter than the stride, named
        assert _fits_at_some_step_time(hubo, command, STEP_TIME_PROBES) is not None
    if isinstance(error, InfeasibleCommandError) and error.every_step_time:
        assert _fits_at_some_step_time(hubo, command, STEP_TIME_PROBES) is None
    if isinstance(error, InfeasibleCommandError) and error.largest:
        duration = command.duration if error.step_time is None else error.step_time
        fitting = StepCommand(duration, **{name: error.largest.get(name, 0.0) for name in STRIDE_FIELDS})
        assert _rejection(hubo, fitting) is None


def test_a_whole_walk_names_the_stride_that_fits_at_no_step_time_and_the_step(hubo):
    with pytest.raises(InfeasibleCommandError) as info:
        generate(hubo, [StepCommand(0.8, 0.1), StepCommand(0.56, side=1.55)], rate=RATE)
    error = info.value
    assert error.parameter == "side" and error.every_step_time
    assert str(error).startswith("step 2: side = 1.55 is not allowed")
    assert re.search(r"at most 0\.\d{3} m to the left \(side = 0\.\d{3} m\)", str(error))


def test_a_whole_walk_names_an_earlier_step_beyond_reach_before_a_later_steps_step_time(hubo):
    """Step 1 is out of the legs' reach, step 2 too fast for its swing: step 1 is named (before: step 2's
    step time, as the reach is checked once the whole walk is planned)."""
    with pytest.raises(InfeasibleCommandError) as info:
        plan_walk(hubo, [StepCommand(0.8, 0.9), StepCommand(0.2, 0.3)])
    assert info.value.parameter == "forward" and str(info.value).startswith("step 1: forward = 0.9")


def test_the_closing_stop_is_named_after_the_step_it_follows(hubo):
    """The stop a walk gets after its last command is not a numbered step of the user's: it is named after the
    last one (labels as a steps file gives them, or the default)."""
    from zmpwalk.patterns.planning import _Walk
    from zmpwalk.schedule import Schedule

    commands = [StepCommand(0.8, 0.1)] * 3
    walk = _Walk(hubo, Schedule.hubo(), "cubic", [*commands, StepCommand(0.8, stop=True)], None, 3)
    assert [walk.label(n) for n in (1, 3, 4)] == ["step 1", "step 3", "the closing stop after step 3"]
    walk.labels = ["walk.toml [[steps]] 1", "walk.toml [[steps]] 1", "walk.toml [[steps]] 2"]
    assert walk.label(4) == "the closing stop after walk.toml [[steps]] 2"


def test_a_step_in_place_the_legs_cannot_follow_names_the_foot_lift_it_was_given(hubo):
    """A robot whose ankle pitch stops 15 mrad past its standing angle (-0.5054 rad) cannot step in place at the
    schedule's lift: the error names the foot lift (the schedule's: the command sets none), says what helps, and
    gives the joint that leaves its range; 5 mm of lift fits."""
    import dataclasses

    robot = dataclasses.replace(hubo, joint_limits={"ankle_pitch": (-0.52, 1.0)})
    walker = OnlineWalker(robot, rate=RATE, joints=True)
    with pytest.raises(InfeasibleCommandError) as refused:
        walker.command(StepCommand(0.8), wait=True)
    error = refused.value
    assert error.parameter == "foot_lift" and error.value == "the schedule's" and not error.largest
    assert "a step in place the legs can follow from here: a lower foot lift or another step time" in str(error)
    assert "ankle_pitch" in str(error) and "None" not in str(error)
    walker.command(StepCommand(0.8, foot_lift=0.005), wait=True)
    assert walker.queued is not None or walker.walking
