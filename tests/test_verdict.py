"""The verdict: failing walks are red with a non-zero exit, each criterion carries its figure."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from zmpwalk.cli import EXIT_FAILED, main


def test_a_too_long_stride_at_0_4_s_on_hubo_fails_and_exits_non_zero(tmp_path: Path,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    steps = tmp_path / "fast.toml"
    steps.write_text("[[steps]]\nduration = 0.4\nforward = 0.28\nrepeat = 6\n", encoding="utf-8")
    assert main(["simulate", str(steps), "--json"]) == EXIT_FAILED
    verdict = json.loads(capsys.readouterr().out)["verdict"]
    assert verdict["passed"] is False
    by_name = {c["name"]: c for c in verdict["criteria"]}
    assert by_name["no fall"]["passed"] is False
    assert by_name["no fall"]["figure"] < by_name["no fall"]["limit"]  # fell before the end [s]


def test_the_small_biped_on_hubo_tables_fails_in_the_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Open loop the small biped falls on HUBO's fig30 tables (its pattern leaves the soles by 18 mm); the
    report shows it red and exits 3. (With the stabilizer it now walks them: docs/simulation.md.)"""
    out = tmp_path / "r"
    assert main(["report", "--robot", "mju-biped", "--scenario", "fig30", "--no-animation", "--balance", "off",
                 "--out", str(out)]) == EXIT_FAILED
    printed = capsys.readouterr().out
    assert "FAIL" in printed and "no fall" in printed
    page = (out / "index.html").read_text(encoding="utf-8")
    assert "class='good'>passes every criterion" not in page
    assert "<b class='bad'>fails: no fall" in page


def test_the_papers_walk_passes_every_criterion(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["simulate", "--paper-example", "--robot", "mju-biped", "--json"]) == 0
    verdict = json.loads(capsys.readouterr().out)["verdict"]
    assert verdict["passed"] is True
    assert len(verdict["criteria"]) == 7
    for criterion in verdict["criteria"]:
        assert criterion["figure"] is not None and criterion["passed"] is True


def test_the_cop_criterion_skips_each_touchdown_the_first_sample_included() -> None:
    """The robot is set on the floor at the first sample: its first 50 ms are a touchdown like any other."""
    import types

    import numpy as np

    from zmpwalk.robots import load_robot
    from zmpwalk.sim.verdict import TOUCHDOWN_WINDOW, cop_margin_outside_touchdowns

    robot = load_robot("hubo")
    time = np.arange(0.0, 1.0, 0.001)
    weight = robot.mass * robot.gravity
    left = np.full(len(time), weight / 2)
    right = left.copy()
    right[400:600] = 0.0  # the right foot swings from 0.4 to 0.6 s and lands again
    margin = np.full(len(time), 0.02)
    margin[:10] = -0.010  # placed on a tilted floor: 10 ms beyond a sole edge
    result = types.SimpleNamespace(robot=robot, time=time, force_left=left, force_right=right, cop_margin=margin)
    assert cop_margin_outside_touchdowns(result) == pytest.approx(0.02, abs=1e-12)  # type: ignore[arg-type]
    margin[600 + round(TOUCHDOWN_WINDOW / 0.001) + 5] = -0.007  # after the landing's window: judged
    assert cop_margin_outside_touchdowns(result) == pytest.approx(-0.007, abs=1e-12)  # type: ignore[arg-type]
    margin[600 + 3] = -0.030  # inside it: not judged
    assert cop_margin_outside_touchdowns(result) == pytest.approx(-0.007, abs=1e-12)  # type: ignore[arg-type]


def test_a_touchdown_starts_at_first_contact_not_when_the_sole_becomes_loaded() -> None:
    """The landing sole first touches with a small force (here 101 N, under the loaded share) while the carrying
    sole's sensor reads a CoP beyond its edge from the impact: that first contact millisecond is a touchdown."""
    import types

    import numpy as np

    from zmpwalk.robots import load_robot
    from zmpwalk.sim.run import LOADED_FRACTION
    from zmpwalk.sim.verdict import CONTACT_FRACTION, cop_margin_outside_touchdowns

    robot = load_robot("hubo")
    time = np.arange(0.0, 1.0, 0.001)
    weight = robot.mass * robot.gravity
    left = np.full(len(time), weight)
    right = np.zeros(len(time))
    right[:100] = weight / 2
    left[:100] = weight / 2
    touch = 500
    right[touch] = 0.5 * (CONTACT_FRACTION + LOADED_FRACTION) * weight  # touching, not yet loaded
    right[touch + 1:] = weight / 2
    left[touch + 1:] = weight / 2
    margin = np.full(len(time), 0.02)
    margin[touch] = -0.030
    result = types.SimpleNamespace(robot=robot, time=time, force_left=left, force_right=right, cop_margin=margin)
    assert cop_margin_outside_touchdowns(result) == pytest.approx(0.02, abs=1e-12)  # type: ignore[arg-type]
    margin[touch - 1] = -0.030  # before the contact: judged
    assert cop_margin_outside_touchdowns(result) == pytest.approx(-0.030, abs=1e-12)  # type: ignore[arg-type]
