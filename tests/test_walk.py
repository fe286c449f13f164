"""One walk from spec to verdict: :func:`zmpwalk.walk.run_walk`, the walk ``zmpwalk simulate`` runs."""

from __future__ import annotations

import json

import numpy as np
import pytest

from zmpwalk import InvalidParameterError, StepCommand, WalkSpec, load_robot, pattern_joint_trajectory, run_walk
from zmpwalk.capture import CaptureSettings
from zmpwalk.cli import main
from zmpwalk.cli.printing import json_safe
from zmpwalk.patterns import generator
from zmpwalk.scenarios import load_scenario_with_labels
from zmpwalk.sim.verdict import controller_words
from zmpwalk.walk import STAGES, planned_walk


@pytest.fixture(scope="module")
def hubo():
    return load_robot("hubo")


@pytest.mark.slow
def test_a_hubo_scenario_walks_as_the_command_line_walks_it(hubo, capsys) -> None:
    assert main(["simulate", "--scenario", "fig10", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    commands, labels = load_scenario_with_labels("fig10")
    outcome = run_walk(WalkSpec(hubo, commands, labels, source="scenario fig10"))
    assert json_safe(outcome.verdict.as_dict()) == printed["verdict"]
    assert outcome.verdict.passed
    rms, largest = outcome.result.cop_error_stats()
    assert (outcome.result.distance, rms, largest) == (printed["distance"], printed["cop_error_rms"],
                                                       printed["cop_error_max"])
    assert json_safe([vars(row) for row in outcome.rows]) == printed["actuators"]
    assert outcome.pattern.generator == printed["generator"] == hubo.default_generator
    assert list(outcome.warnings) == printed["warnings"]
    assert set(outcome.seconds) == set(STAGES) and outcome.wall_time > 0


@pytest.mark.slow
def test_balance_chooses_the_stabilizer_or_the_open_loop(hubo) -> None:
    commands, labels = load_scenario_with_labels("fig10")
    stages: list[tuple[str, int, int]] = []
    closed = run_walk(WalkSpec(hubo, commands, labels), progress=lambda *stage: stages.append(stage))
    open_loop = run_walk(WalkSpec(hubo, commands, labels, balance=False))
    assert closed.result.balance is not None and open_loop.result.balance is None
    assert (closed.controller, open_loop.controller) == (controller_words(True, True), controller_words(False))
    assert closed.verdict.passed
    rms_closed, _ = closed.result.cop_error_stats()
    rms_open, _ = open_loop.result.cop_error_stats()
    assert rms_closed < rms_open  # the stabilizer brings the CoP to the reference ZMP
    walked = [stage for stage in stages if stage[2] == len(STAGES)]
    assert walked == [("pattern", 0, 4), ("joints", 1, 4), ("simulation", 2, 4), ("measures", 4, 4)]
    assert any(stage[0] == "simulation" and stage[2] == 100 for stage in stages)


def test_the_planned_walk_is_the_generator_s_pattern_and_its_joints(hubo) -> None:
    commands = [StepCommand(0.9, 0.1)] * 2
    planned = planned_walk(WalkSpec(hubo, commands, generator="preview"))
    pattern = generator("preview")(hubo, commands, rate=1000.0)
    np.testing.assert_array_equal(planned.pattern.zmp_in_world, pattern.zmp_in_world)
    np.testing.assert_array_equal(planned.joints.angles, pattern_joint_trajectory(pattern).angles)
    assert planned.correction is None


@pytest.mark.parametrize(("fields", "parameter"), [
    ({"commands": ()}, "commands"),
    ({"generator": "lipm"}, "generator"),
    ({"generator": "preview", "pelvis": "quintic"}, "pelvis"),
    ({"pelvis": "septic"}, "pelvis"),
    ({"balance": False, "capture": CaptureSettings()}, "capture"),
    ({"zmp_correction": True, "capture": CaptureSettings()}, "capture"),
    ({"paper_steps": 2}, "paper_steps"),
    ({"commands": (), "paper_steps": -1}, "paper_steps"),
    ({"latency": 0.5}, "latency"),
    ({"mass_scale": 0.0}, "mass_scale"),
    ({"settle": -1.0}, "settle"),
    ({"hold": 61.0}, "hold"),
    ({"settle": "1"}, "settle"),
    ({"mass_scale": None}, "mass_scale"),
])
def test_a_spec_no_walk_can_follow_names_its_field(hubo, fields, parameter) -> None:
    chosen = {"commands": [StepCommand(0.9, 0.1)], **fields}
    with pytest.raises(InvalidParameterError) as raised:
        WalkSpec(hubo, **chosen)
    assert raised.value.parameter == parameter
    assert parameter in str(raised.value)


def test_a_spec_is_frozen_and_keeps_its_commands_as_given(hubo) -> None:
    commands = [StepCommand(0.9, 0.1)]
    spec = WalkSpec(hubo, commands, ["first"])
    commands.append(StepCommand(0.9, 0.1))
    assert spec.commands == (StepCommand(0.9, 0.1),) and spec.labels == ("first",)
    assert spec.generator_name == hubo.default_generator
    with pytest.raises(AttributeError):
        spec.balance = False  # type: ignore[misc]


def test_a_fall_is_judged_against_the_walk_the_plan_lasts(hubo) -> None:
    """Through the controller the run is sized for the longest walk its commands might take (three times each step,
    and more); a fall is judged against the plan's length, as long as the same walk unpushed, which stands."""
    from zmpwalk.sim.disturbances import Disturbances

    commands = [StepCommand(duration=0.95, forward=0.2)] * 4  # [s], [m]
    push = Disturbances(push_time=1.5, push_impulse=(-60.0, 0.0, 0.0))  # [s], [N s]: backward, mid-walk
    pushed, walked = (run_walk(WalkSpec(hubo, commands, disturbances=d)) for d in (push, None))
    assert pushed.result.fell and not walked.result.fell
    fall, stand = (next(c for c in w.verdict.criteria if c.name == "no fall") for w in (pushed, walked))
    assert fall.limit == pytest.approx(stand.limit, abs=2e-3)  # [s] one tick, 10.01 s
    assert stand.limit == pytest.approx(walked.pattern.time[-1] + walked.spec.hold - walked.result.time[0], abs=2e-3)
    assert f"of {stand.limit:.2f} s" in fall.shown
