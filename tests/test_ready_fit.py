"""The ready posture fitted to a walk's strides (zmpwalk.ready_fit): an imported robot whose own posture refuses a
walk for its legs walks it from the nearest hip-to-ankle stretch that plans it whole."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from test_import import biped, leg, write
from zmpwalk import load_robot
from zmpwalk.commands import StepCommand
from zmpwalk.errors import (
    FileFormatError,
    InfeasibleCommandError,
    InfeasiblePatternError,
    InvalidParameterError,
    UnreachableError,
    ZmpwalkError,
)
from zmpwalk.joint_limits import JointLimitError
from zmpwalk.ready_fit import STRETCHES, fit_ready_posture, legs_refuse, stretches_to_try
from zmpwalk.robots.model import RobotModel
from zmpwalk.robots.posture import READY_STRETCH
from zmpwalk.walk import WalkSpec, checked_walk, planned_walk, run_walk

LONG = [StepCommand(duration=0.8, forward=0.315)] * 3  # [s], [m]: beyond the 0.3 + 0.3 m legs' reach from 0.92


@pytest.fixture(scope="module")
def free_biped(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write(tmp_path_factory.mktemp("fit"), "free.xml", biped(leg("l", 0.1) + leg("r", -0.1)))


def hip_to_ankle(robot: object) -> float:
    """The left leg's hip-centre-to-ankle distance in the ready posture [m]."""
    chain = robot.legs[0]  # type: ignore[attr-defined]
    ankle, _ = chain.fk(chain.reference[None])
    return float(np.linalg.norm(ankle[0] - chain.hip))


def test_stretches_are_tried_nearest_first() -> None:
    assert list(STRETCHES) == pytest.approx([0.8, 0.82, 0.84, 0.86, 0.88, 0.9, 0.92, 0.94, 0.96], abs=1e-12)
    assert stretches_to_try(0.92) == pytest.approx([0.94, 0.9, 0.96, 0.88, 0.86, 0.84, 0.82, 0.8], abs=1e-12)
    assert stretches_to_try(0.864)[:3] == pytest.approx([0.88, 0.84, 0.9], abs=1e-12)  # 0.86: within 0.005


def test_only_the_legs_refusals_start_the_search() -> None:
    unreachable = UnreachableError("left", 1.0, 0.004)
    assert legs_refuse(unreachable)
    assert legs_refuse(JointLimitError("left_knee", 2.1, 1.0, (0.0, 2.0)))
    assert not legs_refuse(JointLimitError("left_ankle_roll", 0.1, 1.0, (-0.03, 0.03), sole_roll=0.1))
    assert legs_refuse(InfeasibleCommandError("forward", 0.3, {"forward": 0.2}, unreachable))
    zmp = InfeasiblePatternError("the ZMP leaves the soles")
    assert not legs_refuse(InfeasibleCommandError("forward", 0.3, {}, zmp))
    assert not legs_refuse(zmp)


def test_a_stride_beyond_reach_walks_from_the_nearest_stretch_that_plans_it(free_biped: Path) -> None:
    robot = load_robot(free_biped)
    assert robot.plant is not None and robot.plant.ready_stretch == pytest.approx(READY_STRETCH, abs=1e-12)
    assert hip_to_ankle(robot) == pytest.approx(READY_STRETCH * 0.6, abs=1e-9)  # [m]
    spec = WalkSpec(robot, LONG)
    with pytest.raises(UnreachableError, match="left ankle out of reach"):
        planned_walk(spec)
    fitted = fit_ready_posture(spec, lambda stretch: load_robot(free_biped, ready_stretch=stretch))
    assert fitted.stretch == pytest.approx(0.9, abs=1e-12) and fitted.own_stretch == pytest.approx(READY_STRETCH)
    assert "forward = 0.315 is not allowed" in fitted.refusal and "hips 0.90 of the straight leg" in fitted.words()
    assert hip_to_ankle(fitted.spec.robot) == pytest.approx(0.9 * 0.6, abs=1e-9)  # [m]
    assert fitted.spec.robot.pelvis_height < robot.pelvis_height - 0.01  # [m] crouched lower
    for nearer in (0.94,):  # the one nearer the robot's 0.92 tried first
        with pytest.raises(ZmpwalkError):
            planned_walk(WalkSpec(load_robot(free_biped, ready_stretch=nearer), LONG, check_limits=True))
    outcome = run_walk(fitted.spec, planned=fitted.planned)
    assert outcome.verdict.passed, outcome.verdict


def test_a_walk_the_robot_walks_keeps_its_posture(free_biped: Path) -> None:
    robot = load_robot(free_biped)
    fitted = fit_ready_posture(WalkSpec(robot, [StepCommand(duration=0.8, forward=0.1)] * 2),
                               lambda stretch: pytest.fail("no other posture is tried"))
    assert fitted.stretch is None and fitted.spec.robot is robot and fitted.words() == ""


def test_no_stretch_fits_gives_the_robots_own_refusal(free_biped: Path) -> None:
    robot = load_robot(free_biped)
    steps = [StepCommand(duration=2.0, forward=0.4)] * 3  # [s], [m]
    with pytest.raises(InfeasibleCommandError) as own:
        planned_walk(WalkSpec(robot, steps))
    for stretch in STRETCHES:
        with pytest.raises(ZmpwalkError):
            planned_walk(WalkSpec(load_robot(free_biped, ready_stretch=stretch), steps, check_limits=True))
    with pytest.raises(InfeasibleCommandError) as error:
        fit_ready_posture(WalkSpec(robot, steps), lambda stretch: load_robot(free_biped, ready_stretch=stretch))
    assert str(error.value) == str(own.value)


def test_a_robot_file_that_sets_its_posture_keeps_it(free_biped: Path, tmp_path: Path) -> None:
    path = write(tmp_path, "robot.toml", f'[model]\nfile = "{free_biped}"\n[posture]\nready_stretch = 0.92\n')
    robot = load_robot(path)
    assert robot.plant is not None and robot.plant.posture_set_by == "ready_stretch"
    fitted = fit_ready_posture(WalkSpec(robot, LONG), lambda stretch: pytest.fail("the file's posture is kept"))
    assert fitted.planned is None and fitted.stretch is None and fitted.spec.robot is robot  # planned by run_walk
    with pytest.raises(InfeasibleCommandError, match=r"at most 0\.31"):
        checked_walk(fitted.spec)
    with pytest.raises(InvalidParameterError, match=r"ready_stretch = 0.9 .*sets the ready posture"):
        load_robot(path, ready_stretch=0.9)
    low = write(tmp_path, "low.toml", f'[model]\nfile = "{free_biped}"\n[posture]\nready_stretch = 0.85\n')
    lower = load_robot(low)
    assert hip_to_ankle(lower) == pytest.approx(0.85 * 0.6, abs=1e-9)  # [m]


@pytest.mark.parametrize("value", [0.5, 1.0, 1.2, math.nan, -0.9])
def test_a_stretch_out_of_range_is_refused_naming_it(free_biped: Path, tmp_path: Path, value: float) -> None:
    with pytest.raises(InvalidParameterError, match=r"ready_stretch = .* above 0.5 and below 1.0"):
        load_robot(free_biped, ready_stretch=value)
    path = write(tmp_path, "bad.toml", f'[model]\nfile = "{free_biped}"\n[posture]\nready_stretch = {value}\n')
    with pytest.raises(FileFormatError, match=r"\[posture\] ready_stretch"):
        load_robot(path)


NARROW_ANKLE = '<joint name="{s}_ap" axis="0 1 0" range="-25 25"/>'  # [deg] MJCF's default unit: +-0.4363 rad


def test_a_joint_out_of_range_walks_from_a_taller_posture(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The 0.3 + 0.3 m biped with ankle pitches of +-25 deg: 10 cm strides take the rear ankle past its stop from
    0.92 (the batch plan, which does not check the ranges, walks it; the controller's check refuses it); from 0.90
    too; from 0.94, taller, every joint stays in its range. ``zmpwalk plan`` fits it with or without --joints."""
    import json

    from zmpwalk.cli import main
    from zmpwalk.joint_limits import check_joint_limits

    path = write(tmp_path, "narrow.xml", biped(leg("l", 0.1, NARROW_ANKLE) + leg("r", -0.1, NARROW_ANKLE)))
    robot = load_robot(path)
    steps = [StepCommand(duration=0.8, forward=0.1)] * 3  # [s], [m]
    own = checked_walk(WalkSpec(robot, steps))
    with pytest.raises(JointLimitError, match="ankle_pitch"):
        check_joint_limits(own.joints.time, own.joints.angles, robot)
    with pytest.raises(JointLimitError, match="ankle_pitch"):
        planned_walk(WalkSpec(load_robot(path, ready_stretch=0.9), steps, check_limits=True))
    fitted = fit_ready_posture(WalkSpec(robot, steps), lambda stretch: load_robot(path, ready_stretch=stretch))
    assert fitted.stretch == pytest.approx(0.94, abs=1e-12) and "ankle_pitch" in fitted.refusal
    assert fitted.planned is not None
    check_joint_limits(fitted.planned.joints.time, fitted.planned.joints.angles, fitted.spec.robot)  # raises none
    assert np.abs(fitted.planned.joints.angles[:, [4, 10]]).max() <= math.radians(25)  # [rad] the ankle pitches
    file = write(tmp_path, "steps.toml", "[[steps]]\nduration = 0.8\nforward = 0.1\nrepeat = 3\n")
    for joints in ([], ["--joints"]):
        assert main(["plan", "--robot", str(path), str(file), "--json", *joints]) == 0
        printed = json.loads(capsys.readouterr().out)
        assert printed["ready_stretch"] == pytest.approx(0.94, abs=1e-12) and printed["ready_posture_refusal"]


def test_a_written_robot_file_keeps_what_it_set_and_leaves_the_rest_derived(free_biped: Path, tmp_path: Path,
                                                                              capsys: pytest.CaptureFixture[str]
                                                                              ) -> None:
    import json

    from zmpwalk.cli import main

    derived = tmp_path / "derived.toml"
    assert main(["robot", str(free_biped), "--write", str(derived)]) == 0
    text = derived.read_text(encoding="utf-8")
    for name in ("ready_stretch", "pelvis_height", "dsp_time", "foot_lift", "lateral_velocity"):
        assert f"\n# {name} = " in text  # derived: commented out, so a walk may fit the posture
    assert load_robot(derived).plant.posture_set_by == ""  # type: ignore[union-attr]
    capsys.readouterr()
    assert main(["robot", str(free_biped), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["ready_stretch"] == pytest.approx(READY_STRETCH, abs=1e-12) and printed["posture_set_by"] is None
    for field, value in (("ready_stretch", "0.86"), ("pelvis_height", "0.53")):
        given = write(tmp_path, f"{field}.toml", f'[model]\nfile = "{free_biped}"\n[posture]\n{field} = {value}\n'
                      "[walking]\ndsp_time = 0.07\n")
        again = tmp_path / f"{field}_again.toml"
        assert main(["robot", str(given), "--write", str(again)]) == 0
        assert f"\n{field} = {value}" in again.read_text(encoding="utf-8")
        first, second = load_robot(given), load_robot(again)
        assert first.plant is not None and second.plant is not None and first.plant.posture_set_by == field
        assert second.plant.file_values == first.plant.file_values == tuple(sorted((field, "dsp_time")))
        assert second.pelvis_height == pytest.approx(first.pelvis_height, abs=1e-12)  # [m]
        assert second.plant.ready_stretch == pytest.approx(hip_to_ankle(second) / 0.6, abs=1e-9)  # as it stands
        assert second.dsp_time == pytest.approx(0.07, abs=1e-12)  # [s]
    capsys.readouterr()


def test_a_posture_set_twice_or_out_of_range_names_where(free_biped: Path, tmp_path: Path) -> None:
    both = write(tmp_path, "both.toml", f'[model]\nfile = "{free_biped}"\n[posture]\nready_stretch = 0.9\n'
                 "pelvis_height = 0.5\n")
    with pytest.raises(FileFormatError, match="both set the ready posture"):
        load_robot(both)
    plain = write(tmp_path, "plain.toml", f'[model]\nfile = "{free_biped}"\n')
    with pytest.raises(InvalidParameterError, match=r"ready_stretch = 1.2 .*above 0.5") as error:
        load_robot(plain, ready_stretch=1.2)  # the argument's value, not the file's
    assert not isinstance(error.value, FileFormatError)
    assert load_robot(plain, ready_stretch=0.9).plant.ready_stretch == pytest.approx(0.9, abs=1e-12)  # type: ignore[union-attr]


def test_a_box_model_has_no_stretch_to_fit(hubo: RobotModel) -> None:
    with pytest.raises(InvalidParameterError, match="ready_stretch"):
        load_robot("hubo", ready_stretch=0.9)
    fitted = fit_ready_posture(WalkSpec(hubo, LONG), lambda stretch: pytest.fail("a box model has no stretch"))
    assert fitted.planned is None and fitted.spec.robot is hubo


@pytest.mark.slow
def test_the_cli_walks_and_plans_from_the_fitted_posture(free_biped: Path, tmp_path: Path,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from zmpwalk.cli import main

    steps = write(tmp_path, "long.toml", "[[steps]]\nduration = 0.8\nforward = 0.315\nrepeat = 3\n")
    assert main(["plan", "--robot", str(free_biped), str(steps), "--joints", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ready_stretch"] == pytest.approx(0.9, abs=1e-12)
    assert main(["plan", "--robot", str(free_biped), str(steps), "--joints"]) == 0
    assert "ready posture: hips 0.90 of the straight leg" in capsys.readouterr().out
    assert main(["simulate", "--robot", str(free_biped), str(steps), "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["ready_stretch"] == pytest.approx(0.9, abs=1e-12)
    assert "forward = 0.315 is not allowed" in printed["ready_posture_refusal"]
    assert main(["report", "--robot", str(free_biped), str(steps), "--out", str(tmp_path / "report"),
                 "--no-animation", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["ready_stretch"] == pytest.approx(0.9, abs=1e-12)


def test_the_walk_from_a_fitted_posture_says_so_first_and_in_its_errors(hubo: RobotModel,
                                                                        capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.ready_fit import FittedWalk

    spec = WalkSpec(hubo, LONG)
    fitted = FittedWalk(spec, None, 0.88, 0.92, "left ankle out of reach")
    words = r"^walking from a ready posture of hips 0\.88 .*robot's 0\.920.*: boom$"
    with pytest.raises(ZmpwalkError, match=words), fitted.walking():
        raise ZmpwalkError("boom")
    assert capsys.readouterr().out.startswith("ready posture: hips 0.88 of the straight leg")
    with fitted.walking(say=False):
        pass
    assert capsys.readouterr().out == ""
    with pytest.raises(ZmpwalkError, match=r"^boom$"), FittedWalk(spec, None).walking():
        raise ZmpwalkError("boom")  # the robot's own posture: nothing added
    assert capsys.readouterr().out == ""


def test_an_export_walks_from_the_fitted_posture_and_records_it(free_biped: Path, tmp_path: Path) -> None:
    """``zmpwalk export`` fits the posture as ``simulate`` does: 0.315 m strides (0.39375 m/s at 0.8 s) start
    from 0.90, the record and the clip's first frame say so."""
    from zmpwalk.export.clips import Command
    from zmpwalk.export.run import export_command

    records = export_command(str(free_biped), Command(0.315 / 0.8, 0.0, 0.0, 0.8), str(tmp_path), 50.0, swings=3)
    assert records and all(r.ready_stretch == pytest.approx(0.9, abs=1e-12) for r in records)
    assert all(not r.error for r in records)
    fitted = load_robot(free_biped, ready_stretch=0.9)
    planned = next(r for r in records if r.kind == "planned" and r.span == "whole")
    first = np.loadtxt(tmp_path / planned.files["csv"], delimiter=",", skiprows=1)[0]  # time, root x y z, ...
    stood = load_robot(free_biped)
    assert first[3] == pytest.approx(fitted.pelvis_height, abs=1e-5)  # [m] the base where the fitted posture has it
    assert fitted.pelvis_height < stood.pelvis_height - 0.01  # [m] crouched below the robot's own posture


def test_an_export_of_a_command_the_controller_refuses_writes_no_clip(tmp_path: Path) -> None:
    """0.24 m strides (0.3 m/s at 0.8 s) take the +-25 deg ankles out of range from every posture: the walking
    controller refuses the first step and the robot stands; that is an error record, not a clip of standing."""
    from zmpwalk.export.clips import Command
    from zmpwalk.export.run import export_command

    path = write(tmp_path, "narrow.xml", biped(leg("l", 0.1, NARROW_ANKLE) + leg("r", -0.1, NARROW_ANKLE)))
    out = tmp_path / "out"
    out.mkdir()
    records = export_command(str(path), Command(0.3, 0.0, 0.0, 0.8), str(out), 50.0, swings=3)
    assert len(records) == 1 and not records[0].verified and records[0].frames == 0 and not records[0].files
    assert records[0].error.startswith("step 1 of 3, refused by the walking controller: forward = 0.24")
    assert "ankle_pitch" in records[0].error
    assert not any(out.iterdir())
