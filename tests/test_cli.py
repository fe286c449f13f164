"""The zmpwalk command end to end."""

from __future__ import annotations

import csv
import json
import subprocess
import sys

import pytest

from zmpwalk.cli import main
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.patterns.result import CSV_COLUMNS
from zmpwalk.scenarios import list_scenarios

SCENARIOS = ["demo", "fig10", "fig27", "fig28", "fig29", "fig30", "fig31", "turn45"]


def test_scenarios_lists_the_paper_experiments(capsys):
    assert main(["scenarios"]) == 0
    out = capsys.readouterr().out
    for name in SCENARIOS:
        assert name in out
    assert set(list_scenarios()) == set(SCENARIOS)


@pytest.mark.parametrize("name", SCENARIOS)
def test_every_scenario_plans_inside_the_polygon_with_the_exact_csv_columns(tmp_path, capsys, name):
    out = tmp_path / f"{name}.csv"
    assert main(["plan", "--scenario", name, "--out", str(out), "--rate", "100"]) == 0
    printed = capsys.readouterr().out
    assert "min ZMP margin" in printed
    assert "OUTSIDE the support polygon" not in printed
    with out.open() as handle:
        reader = csv.reader(handle)
        header = next(reader)
        rows = list(reader)
    assert tuple(header) == CSV_COLUMNS
    assert len(rows) > 100
    assert {row[1] for row in rows} <= {"double", "left", "right"}
    assert float(rows[0][0]) == 0.0 and float(rows[1][0]) == pytest.approx(0.01)


def test_plan_exit_status_outside_the_polygon_and_the_default_rate(tmp_path, capsys):
    # 0.7 s steps with the paper's V_y of 0.1 m leave the support polygon by 12.7 mm (docs/zmp-margins.md)
    steps = tmp_path / "fast.toml"
    steps.write_text("[[steps]]\nduration = 0.7\nforward = 0.2\nrepeat = 4\n")
    out = tmp_path / "fast.csv"
    assert main(["plan", str(steps), "--schedule", "paper", "--out", str(out)]) == 3
    assert "OUTSIDE the support polygon" in capsys.readouterr().out
    assert out.is_file()  # the pattern is written all the same; the status says it leaves the polygon
    assert main(["plan", str(steps), "--schedule", "paper", "--allow-outside"]) == 0
    capsys.readouterr()
    assert main(["plan", str(steps)]) == 0  # the default tables keep 0.7 s steps inside
    capsys.readouterr()
    assert main(["plan", "--scenario", "fig10", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["rate"] == 1000.0  # the default rate, as report's


def test_plan_without_out_writes_nothing_and_says_so(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["plan", "--scenario", "fig27", "--rate", "100"]) == 0
    assert "no CSV written (give --out FILE to write it)" in capsys.readouterr().out
    assert list(tmp_path.iterdir()) == []
    assert main(["plan", "--scenario", "fig27", "--rate", "100", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["out"] is None
    out = tmp_path / "fig27.csv"
    assert main(["plan", "--scenario", "fig27", "--rate", "100", "--out", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["out"] == str(out) and out.is_file()


def test_plan_json_and_rate(tmp_path, capsys):
    steps = tmp_path / "walk.toml"
    steps.write_text("[[steps]]\nduration = 0.8\nforward = 0.2\nrepeat = 4\n")
    assert main(["plan", str(steps), "--rate", "1000", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["rate"] == 1000.0 and summary["min_zmp_margin"] > 0
    assert summary["final_left_ankle"][0] == pytest.approx(0.8, abs=1e-9)


def test_tables_command_prints_every_condition(capsys):
    assert main(["tables", "--steps", "2"]) == 0
    out = capsys.readouterr().out
    assert out.count("| forward |") == 12 and out.count("| side |") == 6


@pytest.mark.parametrize("argv, message", [
    (["plan", "--scenario", "fig99"], "unknown scenario 'fig99'"),
    (["plan"], "give a steps file or --scenario"),
    (["plan", "--scenario", "fig28", "--rate", "0"], "rate = 0"),
    (["plan", "--scenario", "fig28", "--robot", "asimo"], "unknown robot 'asimo'"),
    (["plan", "nowhere.toml"], "nowhere.toml"),
    (["tables", "--steps", "0"], "--steps"),
    (["fly"], "invalid choice"),
    (["scenarios", "--yaml"], "unrecognized arguments"),
    (["hyperbolic", "--json"], "--paper-example"),
    (["simulate", "--scenario", "fig28", "--generator", "lipm"], "invalid choice"),
])
def test_errors_print_one_line_and_exit_non_zero(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_installed_command_runs_as_a_process(tmp_path):
    result = subprocess.run([sys.executable, "-m", "zmpwalk.cli", "plan", "--scenario", "fig99"],
                            capture_output=True, text=True, check=False)
    assert result.returncode == 2 and result.stderr.startswith("zmpwalk: error:")


def test_plan_joints_appends_the_twelve_joint_columns(tmp_path, capsys):
    out = tmp_path / "walk.csv"
    assert main(["plan", "--scenario", "fig10", "--joints", "--out", str(out)]) == 0
    with out.open() as handle:
        header = next(csv.reader(handle))
    assert tuple(header) == CSV_COLUMNS + JOINT_COLUMNS
    assert JOINT_COLUMNS[:3] == ("left_hip_yaw", "left_hip_roll", "left_hip_pitch")
    assert JOINT_COLUMNS[-1] == "right_ankle_roll"


def test_plan_with_the_hyperbolic_generator(tmp_path, capsys):
    steps = tmp_path / "walk.toml"
    steps.write_text("[[steps]]\nduration = 0.6\nforward = 0.03\nrepeat = 4\n")
    assert main(["plan", str(steps), "--generator", "hyperbolic", "--robot", "mju-biped", "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["generator"] == "hyperbolic" and summary["min_zmp_margin"] > 0


@pytest.mark.parametrize("step, message", [
    ("duration = 0", "duration = 0"),
    ("duration = -0.8", "duration = -0.8"),
    ("duration = 0.1\nforward = 0.1", "longer than the double-support time"),
    ("duration = 0.08\nforward = 0.1", "duration = 0.08 is not allowed; expected a value in [0.1, 5] s"),
    ("duration = 0.3\nforward = 0.3", "duration = 0.3 is not allowed; expected a step time >= 0.340 s"),
    ("duration = 0.8\nfoot_lift = 0.5", "foot_lift = 0.5 is not allowed; expected a swing apex in [0, 0.2"),
    ("duration = 0.5\nlateral_velocity = 1.0", "lateral_velocity = 1 is not allowed; expected a V_y in [0, 0.39"),
    ("duration = nan", "duration = nan"),
    ("duration = 0.8\nforward = 0.9", "out of reach"),
    ("duration = 0.8\nup_ratio = 1.5", "up_ratio = 1.5"),
    ("duration = 0.8\nd1 = 1.0", "d1 = 1"),
    ("duration = 0.8\nfoward = 0.1", "unknown field 'foward'"),
])
def test_bad_steps_files_exit_non_zero_with_one_line(tmp_path, capsys, step, message):
    steps = tmp_path / "walk.toml"
    steps.write_text(f"[[steps]]\nduration = 0.8\nforward = 0.1\n[[steps]]\n{step}\n")
    assert main(["plan", str(steps)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert message in err


def test_planning_errors_name_the_file_the_table_and_the_walked_step(tmp_path, capsys):
    steps = tmp_path / "walk.toml"
    steps.write_text("[[steps]]\nduration = 0.8\nforward = 0.1\nrepeat = 3\n[[steps]]\nduration = 0.8\nforward = 0.9\n")
    assert main(["plan", str(steps)]) == 2
    err = capsys.readouterr().err
    assert f"{steps}: [[steps]] 2: forward = 0.9 is not allowed" in err
    assert "at most 0.4" in err and " m forward (forward = 0.4" in err and "right ankle out of reach" in err


@pytest.mark.parametrize("argv, message", [
    (["plan", "--scenario", "fig10", "--feet", "only_one"], "--feet = 'only_one' must be two body names"),
    (["plan", "--scenario", "fig10", "--generator", "hyperbolic", "--pelvis", "quintic"],
     "--pelvis quintic applies to the polynomial generator"),
    (["simulate", "--scenario", "fig10", "--latency", "0.5"], "latency = 0.5"),
    (["simulate", "--scenario", "fig10", "--motors", "no-such-motors.toml"], "no-such-motors.toml"),
    (["robot", "no-such-robot.urdf"], "no such file"),
])
def test_new_options_reject_bad_input_in_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_a_model_robot_file_rejects_tables_it_does_not_take(tmp_path, capsys):
    robot = tmp_path / "r.toml"
    robot.write_text('[model]\nfile = "robot.xml"\n\n[limits]\nknee = [0, 2]\n', encoding="utf-8")
    assert main(["plan", "--scenario", "fig10", "--robot", str(robot)]) == 2
    assert "unknown table(s) limits in a robot file with [model]" in capsys.readouterr().err


STEPS = "[[steps]]\nduration = 0.8\nforward = 0.1\n"


@pytest.mark.parametrize("name, content, message", [
    ("utf16.toml", STEPS.encode("utf-16"), "is UTF-16 text"),
    ("latin1.toml", ("a = \"caf\u00e9\"\n" + STEPS).encode("latin-1"), "is not UTF-8 text"),
    ("binary.toml", bytes(range(256)), "is not UTF-8 text"),
    ("deep.toml", ("x = " + "[" * 5000 + "]" * 5000 + "\n").encode(), "nested too deeply"),
    ("broken.toml", b"[[steps]\nduration = 0.8\n", "not valid TOML"),
])
def test_unreadable_steps_files_are_one_line_and_write_nothing(tmp_path, capsys, name, content, message):
    path = tmp_path / name
    path.write_bytes(content)
    out = tmp_path / "out.csv"
    assert main(["plan", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err
    assert not out.exists()


def test_a_utf8_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + STEPS.encode())
    assert main(["plan", str(path), "--rate", "100"]) == 0


@pytest.mark.parametrize("target, message", [
    (".", "is a folder: give a file name to write"),
    ("missing/walk.csv", "does not exist"),
])
def test_unwritable_output_is_one_line_and_leaves_no_file(tmp_path, capsys, monkeypatch, target, message):
    monkeypatch.chdir(tmp_path)
    assert main(["plan", "--scenario", "fig10", "--out", target]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not list(tmp_path.rglob("*.csv")) and not list(tmp_path.rglob("*.part"))


def test_an_interrupted_write_leaves_no_partial_file(tmp_path):
    from zmpwalk.files import atomic_output

    target = tmp_path / "walk.csv"
    with pytest.raises(RuntimeError), atomic_output(target) as temporary:
        temporary.write_text("t,x\n0,1\n", encoding="utf-8")
        raise RuntimeError("the disk filled up")
    assert not target.exists() and list(tmp_path.iterdir()) == []


def test_a_missing_robot_file_says_no_such_file(capsys):
    assert main(["plan", "--scenario", "fig10", "--robot", "no-such-robot.toml"]) == 2
    assert "no-such-robot.toml: no such file" in capsys.readouterr().err


@pytest.mark.parametrize("command", [["sweep"], ["tune", "--out", "t.toml"]])
def test_sweep_and_tune_take_model_options_through_a_robot_file(command, capsys):
    assert main([*command, "--feet", "left_foot,right_foot"]) == 2
    assert "write a robot file" in capsys.readouterr().err


def test_version_and_help_load_neither_mujoco_nor_numba():
    """The command line imports what a command needs when it runs: --version and --help start fast."""
    for flag in ("--version", "--help"):
        code = ("import sys\nfrom zmpwalk.cli import main\ntry:\n    main([" + repr(flag) + "])\nexcept SystemExit:\n"
                "    pass\nprint(sorted(m for m in ('mujoco', 'numba') if m in sys.modules))")
        result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=True)
        assert result.stdout.strip().splitlines()[-1] == "[]", flag
