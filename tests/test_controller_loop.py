"""The whole controller in a robot's loop on the mock plant: commands at random times, 1 Hz to 1 kHz, hostile
ones among them, with the stabilizer and without.

No test here asserts a timing: ``bench/bench_control_loop.py`` measures the ticks (its controller
configurations). These check what the loop relies on whatever the timing of commands and however long each part
of the walker's check takes: no ``update()`` raises, every tick's targets are 12 finite angles and rates, every
refusal is a ZmpwalkError naming a parameter, and after ``stop()`` the walk ends standing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, given, seed, settings
from hypothesis import strategies as st

from command_strategies import HOSTILE_STEPS, ORDINARY_STEPS, parts_clock
from zmpwalk import InvalidParameterError, StepCommand, ZmpwalkError
from zmpwalk.control import MockPlant, WalkingController
from zmpwalk.online import work_budget

VELOCITIES = st.one_of(
    st.tuples(st.floats(-0.1, 0.25), st.floats(-0.05, 0.05), st.floats(-0.2, 0.2)),  # ordinary
    st.tuples(st.floats(-3.0, 3.0), st.floats(-1.0, 1.0), st.floats(-2.0, 2.0)),  # mostly beyond reach
    st.sampled_from([(math.nan, 0.0, 0.0), (math.inf, 0.0, 0.0), (0.0, 0.0, 0.0)]),  # refused at the call; a stop
)
ACTION = st.one_of(
    st.tuples(st.just("step"), ORDINARY_STEPS), st.tuples(st.just("step"), ORDINARY_STEPS),
    st.tuples(st.just("step"), HOSTILE_STEPS), st.tuples(st.just("velocity"), VELOCITIES),
    st.tuples(st.just("stop"), st.none()),
)
END_SECONDS = 8.0  # [s] after the closing stop(): the step under way, the closing step and the settle end in it




def _act(controller: WalkingController, kind: str, value: object) -> None:
    """Give one action as an operator's loop does: a refusal at the call is caught (and named)."""
    try:
        if kind == "stop":
            controller.stop()
        elif kind == "velocity":
            controller.set_velocity(*value)  # type: ignore[misc]
        else:
            controller.command(StepCommand(**value))  # type: ignore[arg-type]
    except InvalidParameterError as error:
        assert error.parameter and error.parameter in str(error)
        event("refused at the call")


def _tick(controller: WalkingController, plant: MockPlant) -> None:
    """One pass of the robot's loop; its targets are 12 finite angles and rates."""
    targets = controller.update(plant.measure())  # never raises
    assert targets.angles.shape == targets.velocities.shape == (12,)
    assert np.isfinite(targets.angles).all() and np.isfinite(targets.velocities).all()
    plant.apply(targets)
    plant.step()


@pytest.mark.parametrize("balance", [True, False])
@seed(20261202)
@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(rate=st.sampled_from([1.0, 10.0, 100.0, 100.0, 333.0, 1000.0, 1000.0]),
       part=st.sampled_from([0.02, 0.3, 1.0, 4.0]),
       actions=st.lists(st.tuples(st.floats(0.001, 1.5), ACTION), min_size=1, max_size=8))
def test_the_controller_takes_commands_at_random_times_and_no_update_raises(hubo, balance, rate, part, actions,
                                                                            monkeypatch):
    """Step commands, velocities and stop() (hostile ones among them) given 1 ms to 1.5 s apart (up to 1 kHz),
    at control rates of 1 Hz (without the stabilizer) to 1 kHz, on a machine where every part of the walker's
    check costs 2 % to 4 times the tick's budget: no update raises, the targets stay finite, every refusal
    names a parameter, the stabilizer has no fault on the mock plant, and after a last stop() the walk ends
    standing."""
    assume(rate >= 10.0 or not balance)  # the stabilizer runs at 10 Hz and more
    parts_clock(monkeypatch, part * work_budget(rate))
    controller = WalkingController(hubo, rate, balance=balance)
    plant = MockPlant(hubo, rate)
    walked = False
    for wait, (kind, value) in [*actions, (0.0, ("stop", None))]:
        for _ in range(max(round(wait * rate), 1)):
            _tick(controller, plant)
            walked = walked or controller.walker.current is not None
            if controller.rejected is not None:
                event("refused by the check")
        _act(controller, kind, value)
    event("walked" if walked else "stood")
    for _ in range(round(END_SECONDS * rate)):
        _tick(controller, plant)
        if not controller.walker.walking and controller.walker.checking is None:
            break
    assert not controller.walker.walking and controller.walker.checking is None
    assert controller.faults == 0
    error = controller.rejection  # names the largest stride that fits, where that is the cause
    assert error is None or (isinstance(error, ZmpwalkError) and error.parameter and error.parameter in str(error))
