"""Automatic tuning of the shape factors (zmpwalk.tune): margins, reproducibility, resuming, the schedule file."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from zmpwalk import StepCommand, generate, load_robot
from zmpwalk.cli import main
from zmpwalk.errors import ZmpwalkError
from zmpwalk.schedule import Schedule
from zmpwalk.tune import Condition, conditions_of, hubo_schedule_data, margins, row_values, schedule_toml, tune

pytestmark = pytest.mark.slow  # every test here runs Optuna studies and MuJoCo walks

SLOW_ROW = Condition("forward", 0.7, 0.2)  # Table 2's 0.7 s row: its ZMP leaves the sole with the paper's values


def test_the_grid_is_the_paper_tables():
    grid = conditions_of(hubo_schedule_data())
    assert len(grid) == 18 and grid[0] == Condition("forward", 0.95, 0.0) and grid[-1] == Condition("side", 0.7, 0.07)
    assert row_values(hubo_schedule_data(), SLOW_ROW) == {"sway": 0.032, "alpha": 1.6, "up_ratio": 0.425}


def test_the_cheap_criterion_is_the_whole_walks_margin(hubo):
    """The margins of the paper's 0.7 s row over a walk of its steps from standstill to standstill."""
    cart, multibody = margins(hubo, hubo_schedule_data(), SLOW_ROW, steps=10)
    pattern = generate(hubo, [StepCommand(0.7, 0.2)] * 10, rate=1000.0, schedule=Schedule.paper())
    assert cart == pytest.approx(-0.0127, abs=5e-4)  # [m] as docs/zmp-margins.md, steady walking
    assert cart == pytest.approx(pattern.min_zmp_margin()[0], abs=1e-12)
    assert multibody < 0.0 and not math.isnan(multibody)


def test_tuning_a_row_puts_both_zmps_inside_and_walks_and_the_same_seed_gives_the_same_row(tmp_path):
    """The 0.7 s stride-0 row (the start and stop of every 0.7 s walk) first, then the 0.2 m row with it."""
    rows = [Condition("forward", 0.7, 0.0), SLOW_ROW]
    first = tune("hubo", trials=12, seed=3, workers=1, conditions=rows, steps=6)
    second = tune("hubo", trials=12, seed=3, workers=1, conditions=rows, steps=6)
    result = first.results[1]
    assert [r.values for r in first.results] == [r.values for r in second.results]  # reproducible
    assert result.cart_margin > 0.0 and result.multibody_margin > 0.0  # [m] both inside the sole
    assert result.table_cart_margin < 0.0  # [m] where the paper's values were outside
    assert result.walks and result.trials == 12
    # the written file is a schedule zmpwalk reads, with the tuned row in it
    path = tmp_path / "tuned.toml"
    path.write_text(schedule_toml(first, "hubo"), encoding="utf-8")
    schedule = Schedule.from_file(path)
    parameters, _ = schedule.stage_parameters(StepCommand(0.7, 0.2), load_robot("hubo"))
    assert parameters.sway == pytest.approx(result.values["sway"], rel=1e-5)
    assert parameters.alpha == pytest.approx(result.values["alpha"], rel=1e-5)


def test_tuning_on_a_local_dask_cluster_gives_the_rows_of_one_process():
    pytest.importorskip("dask.distributed")
    rows = [Condition("forward", 0.7, 0.0), SLOW_ROW]
    on_dask = tune("hubo", trials=4, seed=5, workers=2, conditions=rows, steps=4, scheduler="local")
    inline = tune("hubo", trials=4, seed=5, workers=1, conditions=rows, steps=4)
    assert [r.values for r in on_dask.results] == [r.values for r in inline.results]  # seeded per row


def test_a_stored_study_resumes_where_it_stopped(tmp_path):
    storage = tmp_path / "tune.db"
    tune("hubo", trials=4, workers=1, conditions=[SLOW_ROW], steps=4, storage=storage)
    resumed = tune("hubo", trials=7, workers=1, conditions=[SLOW_ROW], steps=4, storage=storage)
    assert resumed.results[0].trials == 7  # 4 kept, 3 more


def test_a_new_study_file_is_shared_by_parallel_workers(tmp_path):
    """Two worker processes starting on a new SQLite file (each used to make its tables: "table studies already
    exists"); the rows are those of one process."""
    rows = [Condition("forward", 0.7, 0.0), Condition("forward", 0.8, 0.0)]  # one pass: both at once
    stored = tune("hubo", trials=3, seed=5, workers=2, conditions=rows, steps=4, storage=tmp_path / "new.db")
    inline = tune("hubo", trials=3, seed=5, workers=1, conditions=rows, steps=4)
    assert [r.values for r in stored.results] == [r.values for r in inline.results]


def test_bad_tuning_input_is_one_clear_error(tmp_path, capsys):
    with pytest.raises(ZmpwalkError, match="trials = 0"):
        tune("hubo", trials=0)
    with pytest.raises(ZmpwalkError, match="condition"):
        tune("hubo", conditions=[Condition("forward", 0.6, 0.2)])
    assert main(["tune", "--robot", "hubo", "--out", str(tmp_path / "t.toml"), "--workers", "0"]) == 2
    assert "--workers = 0" in capsys.readouterr().err


def test_without_optuna_tuning_says_how_to_get_it(monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_optuna(name, *args, **kwargs):
        if name == "optuna" or name.startswith("optuna."):
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_optuna)
    with pytest.raises(ZmpwalkError, match=r"pip install 'zmpwalk\[tune\]'"):
        tune("hubo", trials=1)


def test_turn_rows_are_added_to_a_grid_without_them_and_tuned_into_the_file(tmp_path):
    """The paper has no turn table: tune adds TURN_GRID's rows, starting from what a turn takes without one,
    tunes the 0.7 s row (outside the sole with those values) inside, and writes a [turn] table that is read."""
    from zmpwalk.tune import TURN_GRID, with_turn_table

    data = with_turn_table(hubo_schedule_data())
    turns = [c for c in conditions_of(data) if c.mode == "turn"]
    assert [(c.duration, c.stride) for c in turns] == list(TURN_GRID)
    hubo = load_robot("hubo")
    before, _ = Schedule(data).stage_parameters(StepCommand(0.7, turn=0.13), hubo)
    without, _ = Schedule.hubo().stage_parameters(StepCommand(0.7, turn=0.13), hubo)
    assert (before.sway, before.up_ratio, before.alpha1, before.d1) == pytest.approx(
        (without.sway, without.up_ratio, without.alpha1, without.d1), abs=1e-12)  # nothing changes by adding it
    rows = [Condition("forward", 0.7, 0.0), Condition("turn", 0.7, 0.13)]
    tuned = tune("hubo", trials=30, seed=2, workers=1, conditions=rows, steps=6)
    result = tuned.results[1]
    assert result.table_cart_margin < 0.0 < result.cart_margin and result.walks  # [m]
    path = tmp_path / "tuned.toml"
    path.write_text(schedule_toml(tuned, "hubo"), encoding="utf-8")
    first, second = Schedule.from_file(path).stage_parameters(StepCommand(0.7, turn=0.13), hubo)
    assert first.sway == pytest.approx(result.values["sway"], rel=1e-5)
    assert (first.d1, second.d1) == pytest.approx((result.values["d1_open"], result.values["d1_recovery"]), rel=1e-5)


def test_timing_tunes_v_y_and_the_double_support_time_within_their_ranges(tmp_path):
    from zmpwalk.tune import TIMING_RANGES

    result = tune("hubo", trials=4, seed=1, workers=1, conditions=[Condition("forward", 0.8, 0.0)], steps=4,
                  timing=True)
    values = result.results[0].values
    for name, (low, high) in TIMING_RANGES.items():
        assert low <= values[name] <= high
    path = tmp_path / "timed.toml"
    path.write_text(schedule_toml(result, "hubo"), encoding="utf-8")
    parameters, _ = Schedule.from_file(path).stage_parameters(StepCommand(0.8), load_robot("hubo"))
    assert (parameters.dsp_time, parameters.lateral_velocity) == pytest.approx(
        (values["dsp_time"], values["lateral_velocity"]), rel=1e-5)


def test_the_cli_reports_each_tuned_condition_on_a_log(tmp_path, capsys):
    """Written to a file (not a terminal), the progress is one line per condition, not a redrawn bar."""
    schedule = tmp_path / "small.toml"
    schedule.write_text('''[forward]
d1 = 0.2
alpha1 = 1
beta1 = 1
columns = ["duration", "stride", "sway", "alpha", "up_ratio"]
rows = [[0.8, 0.0, 0.035, nan, 0.47]]

[side]
columns = ["duration", "side", "sway", "up_ratio", "alpha1", "beta1", "d1_open", "d1_recovery"]
rows = [[0.8, 0.05, 0.035, 0.47, 0.8, 0.8, 0.22, 0.18]]

[turn]
columns = ["duration", "turn", "sway", "up_ratio", "alpha1", "beta1", "d1_open", "d1_recovery"]
rows = [[0.8, 0.13, 0.035, 0.47, 1.0, 1.0, 0.2, 0.2]]
''', encoding="utf-8")
    main(["tune", "--robot", "hubo", "--schedule", str(schedule), "--out", str(tmp_path / "t.toml"),
          "--trials", "1", "--steps", "2", "--workers", "1"])
    err = capsys.readouterr().err
    assert [line for line in err.splitlines() if "conditions tuned" in line][-1].startswith("3/3 conditions tuned")
    assert "\r" not in err


ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.skipif(not (ROBOTS / "booster_t1" / "scene.xml").is_file(), reason="../shared/robots is absent")
def test_booster_t1s_tuned_tables_plan_its_forward_walks_inside_the_soles_where_hubos_do_not():
    """examples/schedule_t1_tuned.toml (zmpwalk tune on T1's own model): every forward row of the grid plans
    10 steps with the ZMP inside T1's 100 mm soles at every 1 kHz sample (its file says +3.4 to +8.4 mm);
    HUBO's tables, scaled, leave them (-8.6 mm at 0.95 s)."""
    robot = load_robot(ROBOTS / "booster_t1" / "scene.xml")
    tuned = Schedule.from_file(EXAMPLES / "schedule_t1_tuned.toml")
    time_scale, stride_scale, _ = robot.schedule_scale
    for duration, stride in ((0.95, 0.1), (0.8, 0.2), (0.7, 0.2)):
        commands = [StepCommand(duration=duration * time_scale, forward=stride * stride_scale)] * 10
        margin = float(generate(robot, commands, rate=1000.0, schedule=tuned).zmp_margin().min())
        assert margin > 0.003, (duration, stride, margin)  # [m]
    hubo = generate(robot, [StepCommand(duration=0.95 * time_scale, forward=0.1 * stride_scale)] * 10, rate=1000.0)
    assert float(hubo.zmp_margin().min()) < -0.005  # [m]
