"""Tables 2-3 of Park et al. (2008) as data, and the interpolation between conditions."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from zmpwalk import StepCommand, generate
from zmpwalk.robots.model import schedule_scale
from zmpwalk.schedule import Schedule

TOL = 1e-12


@pytest.mark.parametrize("duration, stride, sway, alpha, u", [
    (0.95, 0.10, 0.038, 1.85, 0.47), (0.95, 0.30, 0.038, 1.85, 0.47),
    (0.80, 0.10, 0.035, 1.70, 0.47), (0.80, 0.25, 0.035, 1.60, 0.47),
    (0.70, 0.10, 0.032, 1.70, 0.425), (0.70, 0.25, 0.032, 1.55, 0.425),
])
def test_table2_printed_values(hubo, schedule, duration, stride, sway, alpha, u):
    first, second = schedule.stage_parameters(StepCommand(duration, stride), hubo)
    assert (first.sway, first.alpha, first.up_ratio) == pytest.approx((sway, alpha, u), abs=TOL)
    assert (first.d1, first.alpha1, first.beta1) == pytest.approx((0.2, 1.0, 1.0), abs=TOL)
    assert first.source == "table" and second == first


def test_table2_on_the_spot_u_at_07s(hubo, schedule):
    first, _ = schedule.stage_parameters(StepCommand(0.7, 0.0), hubo)
    assert first.up_ratio == pytest.approx(0.5, abs=TOL) and first.sway == pytest.approx(0.032, abs=TOL)


@pytest.mark.parametrize("duration, side, sway, alpha1, beta1, d1_open, d1_recovery", [
    (0.95, 0.05, 0.038, 0.87, 0.87, 0.25, 0.20),
    (0.95, 0.07, 0.038, 0.85, 0.85, 0.25, 0.20),
    (0.80, 0.05, 0.035, 0.80, 0.80, 0.22, 0.18),
    (0.80, 0.07, 0.035, 0.80, 0.78, 0.23, 0.16),
    (0.70, 0.05, 0.0315, 0.80, 0.80, 0.25, 0.12),
])
def test_table3_printed_values(hubo, schedule, duration, side, sway, alpha1, beta1, d1_open, d1_recovery):
    first, second = schedule.stage_parameters(StepCommand(duration, side=side), hubo)
    assert (first.sway, first.alpha1, first.beta1, first.d1) == pytest.approx((sway, alpha1, beta1, d1_open), abs=TOL)
    assert (second.alpha1, second.beta1, second.d1) == pytest.approx((alpha1, beta1, d1_recovery), abs=TOL)


def test_interpolation_between_strides_and_step_times(hubo, schedule):
    mid_stride, _ = schedule.stage_parameters(StepCommand(0.8, 0.15), hubo)
    assert mid_stride.alpha == pytest.approx((1.7 + 1.6) / 2, abs=TOL)
    assert mid_stride.source == "interpolated"
    mid_time, _ = schedule.stage_parameters(StepCommand(0.75, 0.2), hubo)
    assert mid_time.sway == pytest.approx((0.035 + 0.032) / 2, abs=TOL)
    assert mid_time.up_ratio == pytest.approx((0.47 + 0.425) / 2, abs=TOL)
    # alpha is 'x' at stride 0: the nearest defined row is used
    near_zero, _ = schedule.stage_parameters(StepCommand(0.95, 0.05), hubo)
    assert near_zero.alpha == pytest.approx(1.85, abs=TOL)


def test_small_side_steps_interpolate_towards_stepping_on_the_spot(hubo, schedule):
    first, _ = schedule.stage_parameters(StepCommand(0.95, side=0.025), hubo)
    assert first.alpha1 == pytest.approx((1.0 + 0.87) / 2, abs=TOL)
    assert first.d1 == pytest.approx((0.2 + 0.25) / 2, abs=TOL)


def test_outside_the_tables_is_held_and_marked_extrapolated(hubo, schedule):
    fast, _ = schedule.stage_parameters(StepCommand(0.6, 0.2), hubo)
    assert fast.source == "extrapolated" and fast.sway == pytest.approx(0.032, abs=TOL)
    long, _ = schedule.stage_parameters(StepCommand(0.8, 0.35), hubo)
    assert long.source == "extrapolated" and long.alpha == pytest.approx(1.6, abs=TOL)


def test_overrides_replace_scheduled_values(hubo, schedule):
    first, second = schedule.stage_parameters(
        StepCommand(0.95, side=0.05, alpha1=1.1, d1=0.3, d1_recovery=0.1, sway=0.04), hubo)
    assert (first.alpha1, first.d1, first.sway) == pytest.approx((1.1, 0.3, 0.04), abs=TOL)
    assert (second.d1, second.sway, second.alpha1) == pytest.approx((0.1, 0.04, 1.1), abs=TOL)
    assert first.source.endswith("+override")


def test_a_turn_table_is_looked_up_like_table_3(hubo):
    """Exact rows, interpolation towards stepping on the spot below the smallest turn, a curved step's two
    stages, and the columns checked."""
    from zmpwalk.errors import FileFormatError
    from zmpwalk.schedule import TURN_COLUMNS
    from zmpwalk.tune import hubo_schedule_data

    data = hubo_schedule_data()
    data["turn"] = {"columns": list(TURN_COLUMNS), "rows": [[0.8, 0.2, 0.05, 0.4, 1.1, 0.9, 0.3, 0.1]]}
    schedule = Schedule(data)
    first, second = schedule.stage_parameters(StepCommand(0.8, turn=-0.2), hubo)
    assert (first.sway, first.up_ratio, first.alpha1, first.beta1, first.d1, second.d1) == pytest.approx(
        (0.05, 0.4, 1.1, 0.9, 0.3, 0.1), abs=1e-12)
    half, _ = schedule.stage_parameters(StepCommand(0.8, turn=0.1), hubo)
    spot, _ = Schedule.hubo().stage_parameters(StepCommand(0.8), hubo)
    assert half.sway == pytest.approx(0.5 * (0.05 + spot.sway), abs=1e-12)  # halfway to the on-spot row
    curved, _ = schedule.stage_parameters(StepCommand(0.8, 0.1, turn=0.2), hubo)
    straight, _ = schedule.stage_parameters(StepCommand(0.8, 0.1), hubo)
    assert curved.alpha == straight.alpha and curved.sway == pytest.approx(0.05, abs=1e-12)
    data["turn"]["columns"] = ["duration", "turn", "up_ratio", "sway", "alpha1", "beta1", "d1_open", "d1_recovery"]
    with pytest.raises(FileFormatError, match=r"\[turn\] columns"):
        Schedule(data)


def test_table_2_may_carry_v_y_and_the_double_support_time(hubo):
    """Optional columns of the forward table: looked up like the others, for side steps and turns too (their
    stride's row); without them the robot's values."""
    from zmpwalk.tune import hubo_schedule_data, with_timing_columns

    data = with_timing_columns(hubo_schedule_data(), hubo)
    plain, _ = Schedule.hubo().stage_parameters(StepCommand(0.8, 0.1), hubo)
    same, _ = Schedule(data).stage_parameters(StepCommand(0.8, 0.1), hubo)
    assert (same.lateral_velocity, same.dsp_time) == (plain.lateral_velocity, plain.dsp_time) == (
        hubo.lateral_velocity, hubo.dsp_time)
    columns = data["forward"]["columns"]
    for row in data["forward"]["rows"]:
        if row[0] == 0.8:
            row[columns.index("dsp_time")] = 0.15 if row[1] == 0.0 else 0.12
            row[columns.index("lateral_velocity")] = 0.14
    schedule = Schedule(data)
    forward, _ = schedule.stage_parameters(StepCommand(0.8, 0.1), hubo)
    side, recovery = schedule.stage_parameters(StepCommand(0.8, side=0.05), hubo)
    assert (forward.dsp_time, forward.lateral_velocity) == pytest.approx((0.12, 0.14), abs=1e-12)
    assert (side.dsp_time, recovery.dsp_time) == pytest.approx((0.15, 0.15), abs=1e-12)  # the stride-0 row


@pytest.mark.parametrize("pendulum_factor, leg_factor", [(1.47, 1.175), (0.9, 0.85), (2.0, 1.0)])
def test_a_scaled_robot_walks_hubos_pattern_scaled_in_time_by_the_pendulum_and_in_length_by_the_legs(
        hubo, pendulum_factor, leg_factor):
    """The derivation of robots.model.schedule_scale: the cart-table model is linear in length, so a robot of
    pendulum l and leg L walks HUBO's forward pelvis, feet and ZMP times L / L_HUBO at the times sqrt(l / l_HUBO)
    (any length factor works; only the time is fixed by the pendulum)."""
    s_t = math.sqrt(pendulum_factor)
    robot = replace(hubo, pendulum_length=hubo.pendulum_length * pendulum_factor,
                    thigh_length=hubo.thigh_length * leg_factor, shank_length=hubo.shank_length * leg_factor,
                    pelvis_height=hubo.pelvis_height * leg_factor, hip_drop=hubo.hip_drop * leg_factor,
                    ankle_height=hubo.ankle_height * leg_factor, dsp_time=hubo.dsp_time * s_t,
                    foot_lift=hubo.foot_lift * leg_factor,
                    schedule_scale=schedule_scale(hubo.pendulum_length * pendulum_factor,
                                                  (hubo.thigh_length + hubo.shank_length) * leg_factor,
                                                  hubo.hip_spacing))
    assert robot.schedule_scale == pytest.approx((s_t, leg_factor, 1.0), abs=1e-12)
    commands = [StepCommand(0.8, 0.15), StepCommand(0.7, 0.25), StepCommand(0.95, 0.1)]
    # quintic pelvis curves: the ZMP is continuous, so a sample on a stage boundary (where rounding may put it
    # in either stage) compares too
    reference = generate(hubo, commands, rate=100.0, pelvis="quintic")
    scaled = generate(robot, [StepCommand(c.duration * s_t, c.forward * leg_factor) for c in commands],
                      rate=100.0 / s_t, pelvis="quintic")  # the same samples in the dimensionless time
    assert len(scaled.time) == len(reference.time)
    assert scaled.time == pytest.approx(reference.time * s_t, abs=1e-9)
    for name in ("position_pelvis_in_world", "position_left_ankle_in_world", "position_right_ankle_in_world"):
        assert getattr(scaled, name)[:, 0] == pytest.approx(getattr(reference, name)[:, 0] * leg_factor, abs=1e-9)
    assert scaled.zmp_in_world[:, 0] == pytest.approx(reference.zmp_in_world[:, 0] * leg_factor, abs=1e-9)
    # sideways: the hip spacing is HUBO's, so the sway and its ZMP are HUBO's at the scaled times
    assert scaled.zmp_in_world[:, 1] == pytest.approx(reference.zmp_in_world[:, 1], abs=1e-9)


def test_the_lookups_interpolation_is_numpys_to_the_last_bit():
    """zmpwalk.schedule._interp (plain Python, for lookups of a few rows) against numpy.interp: the same floats,
    at the nodes, between them and outside, on seeded random tables of 1 to 6 rows."""
    import numpy as np

    from zmpwalk.schedule import _interp

    rng = np.random.default_rng(7)
    for _ in range(2000):
        n = int(rng.integers(1, 7))
        xp = np.sort(rng.choice(np.linspace(0.0, 0.4, 41), size=n, replace=False))
        fp = rng.uniform(-2.0, 2.0, n)
        for x in [*xp, *rng.uniform(-0.1, 0.5, 5)]:
            assert _interp(float(x), xp.tolist(), fp.tolist()) == float(np.interp(x, xp, fp))  # exactly


def test_a_table_without_alpha_serves_stride_zero_and_names_the_missing_alpha_otherwise(hubo):
    """A user's Table 2 with only stride-0 rows ('x' for alpha): stepping on the spot plans (alpha has no effect
    there, Eq. 13); a stride is one clear error naming alpha (it was numpy's 'array of sample points is empty')."""
    from zmpwalk.errors import FileFormatError

    data = {"forward": {"d1": 0.2, "alpha1": 1.0, "beta1": 1.0,
                        "columns": ["duration", "stride", "sway", "alpha", "up_ratio"],
                        "rows": [[0.8, 0.0, 0.035, math.nan, 0.47]]},
            "side": {"columns": ["duration", "side", "sway", "up_ratio", "alpha1", "beta1", "d1_open", "d1_recovery"],
                     "rows": [[0.8, 0.05, 0.035, 0.47, 0.8, 0.8, 0.22, 0.18]]}}
    schedule = Schedule(data, "mine.toml")
    on_the_spot, _ = schedule.stage_parameters(StepCommand(0.8), hubo)
    assert on_the_spot.sway == pytest.approx(0.035, abs=TOL)
    with pytest.raises(FileFormatError, match=r"mine\.toml.*alpha.*0\.8 s"):
        schedule.stage_parameters(StepCommand(0.8, 0.1), hubo)
    given, _ = schedule.stage_parameters(StepCommand(0.8, 0.1, alpha=1.5), hubo)  # the command's own alpha
    assert given.alpha == pytest.approx(1.5, abs=TOL)


def test_the_default_schedule_is_the_papers_tables_with_a_v_y_column():
    """The two built-in files agree cell by cell in every printed value; the default adds Table 2's
    lateral_velocity column (0.1 m at 0.95 and 0.8 s, 0.09 m at 0.7 s: tests/test_tables.py derives it)."""
    from zmpwalk.files import read_toml
    from zmpwalk.schedule import SCHEDULE_FILES, schedule_path

    assert set(SCHEDULE_FILES) == {"default", "paper"}
    default, paper = (read_toml(schedule_path(name)) for name in ("default", "paper"))
    assert default["side"] == paper["side"]
    forward, printed = default["forward"], paper["forward"]
    assert {k: v for k, v in forward.items() if k not in ("columns", "rows")} == {
        k: v for k, v in printed.items() if k not in ("columns", "rows")}
    assert forward["columns"] == [*printed["columns"], "lateral_velocity"]
    for row, printed_row in zip(forward["rows"], printed["rows"], strict=True):
        assert row[:-1] == pytest.approx(printed_row, nan_ok=True, abs=0.0)
        assert row[-1] == {0.95: 0.1, 0.8: 0.1, 0.7: 0.09}[row[0]]


def test_named_schedules_and_the_robots_v_y(hubo):
    """Schedule.hubo() is the default, Schedule.paper() the printed tables (every step takes the robot's V_y),
    each read once; an unknown name is an error naming the parameter and what is allowed."""
    from zmpwalk.errors import InvalidParameterError

    assert Schedule.hubo() is Schedule.named("default") and Schedule.paper() is Schedule.named("paper")
    for duration, expected in ((0.95, 0.1), (0.8, 0.1), (0.75, 0.095), (0.7, 0.09)):
        default, _ = Schedule.hubo().stage_parameters(StepCommand(duration, 0.2), hubo)
        paper, _ = Schedule.paper().stage_parameters(StepCommand(duration, 0.2), hubo)
        assert default.lateral_velocity == pytest.approx(expected, abs=1e-12)
        assert paper.lateral_velocity == hubo.lateral_velocity == 0.1
        assert (default.sway, default.alpha, default.up_ratio) == (paper.sway, paper.alpha, paper.up_ratio)
    side, recovery = Schedule.hubo().stage_parameters(StepCommand(0.7, side=0.05), hubo)
    assert side.lateral_velocity == recovery.lateral_velocity == pytest.approx(0.09, abs=1e-12)  # the stride-0 row
    override, _ = Schedule.hubo().stage_parameters(StepCommand(0.7, 0.2, lateral_velocity=0.08), hubo)
    assert override.lateral_velocity == 0.08 and override.source == "table+override"
    with pytest.raises(InvalidParameterError, match=r"schedule = 'tuned' is not allowed; expected one of default, "
                                                    r"paper or a schedule file"):
        Schedule.named("tuned")


def test_the_schedule_option_takes_a_name_or_a_file(tmp_path, capsys):
    """--schedule paper reproduces the printed tables' margins, --schedule default (or none) the default's, a
    file is read, and anything else is one usage error (exit 2) naming the option and the names."""
    import json

    from zmpwalk.cli import main
    from zmpwalk.schedule import schedule_path

    margins = {}
    for option in ([], ["--schedule", "default"], ["--schedule", "paper"],
                   ["--schedule", str(schedule_path("paper"))]):
        assert main(["plan", "--scenario", "fig27", "--json", "--allow-outside", *option]) == 0
        margins[" ".join(option[1:]) or "none"] = json.loads(capsys.readouterr().out)["min_zmp_margin"]
    assert margins["none"] == margins["default"] == pytest.approx(0.0170, abs=0.5e-3)  # [m]
    assert margins["paper"] == margins[str(schedule_path("paper"))] == pytest.approx(-0.0127, abs=0.5e-3)
    assert main(["tables", "--schedule", "paper", "--steps", "2", "--json"]) == 0
    rows = {(r["mode"], r["duration"], r["stride"]): r["min_margin"] for r in json.loads(capsys.readouterr().out)}
    assert rows[("forward", 0.7, 0.2)] < 0.0 < rows[("forward", 0.8, 0.2)]
    assert main(["plan", "--scenario", "fig27", "--schedule", str(tmp_path / "nope")]) == 2
    assert "--schedule" in capsys.readouterr().err


def test_a_lookup_interpolates_each_columns_defined_cells_as_numpy_does():
    """The prepared blocks (each step time's rows as columns, NaN cells left out, built once) give every column
    numpy.interp over its defined cells at every tabulated step time, side steps with the on-the-spot row in front:
    the values the planner reads, to the last bit."""
    schedule = Schedule.hubo()
    rng = np.random.default_rng(5)
    for grid, prepend in ((schedule._forward, None), (schedule._side, schedule.on_spot_row)):
        for tabulated in grid.durations:
            rows = grid.by_duration[tabulated]
            if prepend is not None:
                rows = [prepend(tabulated), *rows]
            table = np.array(rows)
            for key in rng.uniform(table[:, grid.key_index].min(), table[:, grid.key_index].max(), 20):
                row, _ = grid.lookup(tabulated, float(key), prepend)
                for index, name in enumerate(grid.columns):
                    defined = ~np.isnan(table[:, index])
                    expected = float(np.interp(key, table[defined, grid.key_index], table[defined, index])) \
                        if defined.any() else math.nan
                    assert row[name] == expected or (math.isnan(row[name]) and math.isnan(expected))
