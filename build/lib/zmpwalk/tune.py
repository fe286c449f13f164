"""Automatic tuning of the HUBO pattern's shape factors per robot: the paper's future work.

For every condition of a grid (step time and stride, side step or turn; the paper's Tables 2-3 by default,
and a turn table of :data:`TURN_GRID` that the paper does not have) :func:`tune` searches the shape factors
of that table row within :data:`FORWARD_RANGES` and :data:`SIDE_RANGES` (turns: the side table's columns;
table units, those of the HUBO tables; another robot walks them at its dynamically similar condition,
:mod:`zmpwalk.schedule`) to maximise the stability score:

1. **Cheap, every candidate**: the smallest margin, over every 1 kHz sample of a walk of ``steps`` steps
   of the condition from standstill to standstill, of the cart-table ZMP (Eqs. 1-2) and of the
   multibody ZMP (Eq. 3 of Lim et al., every link of the robot file's ``[bodies]``; robots without
   them: the cart-table ZMP only) inside the support polygon [m]. The score is that margin, capped at
   :data:`MARGIN_CAP` (more is no safer, and the cap leaves the choice among safe candidates to the
   simulation).
2. **Simulation, the best few**: the :data:`SIMULATED` best candidates (and the table's own values) walk
   the same steps in MuJoCo (the robot's own model or its box model, the stabilizer as ``simulate``
   defaults). A candidate passes when it does not fall and its CoP stays inside the loaded soles
   (the verdict's criterion); among those that pass, the best cheap score wins, then the smaller
   torso attitude (the paper's "attitude": largest roll or pitch during the walk), then the smaller
   peak torque.

Every walk starts and ends with the stepping-on-the-spot row of its step time (the start stage and the
closing step), so those rows are tuned first, and the others then with them in place: two passes.

The optimiser is Optuna's TPE sampler: a handful of bounded, continuous parameters, a noisy-free but
non-smooth objective (a minimum over samples), a few dozen evaluations per condition; TPE needs no
gradient and handles the flat, capped regions, and Optuna gives seeded, reproducible studies that an
SQLite storage makes resumable. Conditions run in parallel on a process pool, one per core.
"""

from __future__ import annotations

import copy
import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError, ZmpwalkError
from zmpwalk.files import read_toml
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots import loaded_robot
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import TURN_COLUMNS, Schedule
from zmpwalk.sweep import in_pool

FORWARD_RANGES = {"sway": (0.02, 0.06), "alpha": (1.0, 2.2), "up_ratio": (0.3, 0.6)}  # [m], [-], [-]
SIDE_RANGES = {"sway": (0.02, 0.06), "up_ratio": (0.3, 0.6), "alpha1": (0.6, 1.2), "beta1": (0.6, 1.2),
               "d1_open": (0.1, 0.4), "d1_recovery": (0.05, 0.35)}  # [m], then [-]
# V_y and d (table units) where the forward table carries them: tune(..., timing=True) adds the columns
TIMING_RANGES = {"lateral_velocity": (0.05, 0.2), "dsp_time": (0.05, 0.2)}  # [m per unit 2 t_bar], [s]
# turn rows where the schedule has none: step times of Tables 2-3 x turns of one step [rad] (7.5 and 15 degrees)
TURN_GRID = ((0.95, 0.13), (0.95, 0.26), (0.80, 0.13), (0.80, 0.26), (0.70, 0.13), (0.70, 0.26))
MARGIN_CAP = 0.03  # [m] margins beyond this score the same
SIMULATED = 3  # best candidates of each condition that walk in MuJoCo
RATE = 1000.0  # [Hz]


@dataclass(frozen=True)
class Condition:
    """One row of the tables: ``mode`` ``"forward"``, ``"side"`` or ``"turn"``, step time [s], and the row's
    key: stride or side step [m], or turn [rad]."""

    mode: str
    duration: float  # [s]
    stride: float  # [m] stride or side step, [rad] turn

    @property
    def name(self) -> str:
        return f"{self.mode} {self.duration:.2f} s {self.stride:.2f} {'rad' if self.mode == 'turn' else 'm'}"


@dataclass
class ConditionResult:
    """The tuned row of one condition and how it scored.

    Attributes:
        condition: The condition.
        values: The tuned values of the row's tuned columns (table units).
        table: The same columns as the starting schedule has them.
        cart_margin, multibody_margin: Smallest ZMP margins of the tuned row [m] (multibody: nan where
            the robot has no link masses).
        table_cart_margin, table_multibody_margin: The same for the table's values [m].
        walks: The tuned row walked its steps in MuJoCo without falling and with the CoP inside the soles.
        attitude: Largest torso roll or pitch during that walk [rad].
        peak_torque: Largest held joint torque of that walk [N m].
        trials: Candidates evaluated.
        seconds: Wall-clock time of the condition [s].
    """

    condition: Condition
    values: dict[str, float]
    table: dict[str, float]
    cart_margin: float  # [m]
    multibody_margin: float  # [m]
    table_cart_margin: float  # [m]
    table_multibody_margin: float  # [m]
    walks: bool
    attitude: float  # [rad]
    peak_torque: float  # [N m]
    trials: int
    seconds: float  # [s]
    table_walks: bool = False


@dataclass
class TuneResult:
    """A tuned schedule: its data (the schedule file's tables) and every condition's result."""

    data: dict[str, Any]
    results: list[ConditionResult] = field(default_factory=list)

    def schedule(self) -> Schedule:
        return Schedule(self.data, "<tuned>")


def _optuna() -> Any:
    try:
        import optuna
    except ImportError:
        raise ZmpwalkError("tuning needs Optuna: pip install 'zmpwalk[tune]' (or pip install optuna)") from None
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna


def hubo_schedule_data() -> dict[str, Any]:
    """The parsed schedule file of Tables 2-3 (a fresh copy)."""
    from importlib import resources

    return read_toml(Path(str(resources.files("zmpwalk") / "data" / "schedule_hubo.toml")))


MODE_KEYS = (("forward", "stride"), ("side", "side"), ("turn", "turn"))  # each table and its key column


def with_turn_table(data: dict[str, Any]) -> dict[str, Any]:
    """``data`` with a turn table of :data:`TURN_GRID` where it has none, each row holding what a turn takes
    without one (Table 2's stride-0 row, and its ``alpha1``, ``beta1``, ``d1`` for both stages)."""
    if "turn" in data:
        return data
    out = copy.deepcopy(data)
    schedule = Schedule(data, "<schedule>")
    rows = []
    for duration, turn in TURN_GRID:
        on_spot = schedule.on_spot_row(duration)  # [duration, 0, sway, up_ratio, alpha1, beta1, d1, d1]
        rows.append([duration, turn, *(float(v) for v in on_spot[2:])])
    out["turn"] = {"columns": list(TURN_COLUMNS), "rows": rows}
    return out


def conditions_of(data: dict[str, Any]) -> list[Condition]:
    """Every row of a schedule's tables as a condition, in the file's order."""
    result = []
    for mode, key in MODE_KEYS:
        if mode not in data:
            continue
        table = data[mode]
        columns = table["columns"]
        for row in table["rows"]:
            result.append(Condition(mode, float(row[columns.index("duration")]), float(row[columns.index(key)])))
    return result


def _row_index(data: dict[str, Any], condition: Condition) -> int:
    table = data.get(condition.mode, {"columns": [condition.mode], "rows": []})
    columns = table["columns"]
    key = columns.index(dict(MODE_KEYS)[condition.mode])
    for index, row in enumerate(table["rows"]):
        if abs(row[columns.index("duration")] - condition.duration) < 1e-9 and abs(row[key] - condition.stride) < 1e-9:
            return index
    raise InvalidParameterError("condition", condition.name, "a row of the schedule's tables")


def tuned_columns(condition: Condition, data: dict[str, Any] | None = None) -> dict[str, tuple[float, float]]:
    """The columns searched for a condition and their ranges (``alpha`` is undefined at stride 0; ``V_y`` and
    ``d`` where ``data``'s forward table carries them)."""
    if condition.mode in ("side", "turn"):
        return dict(SIDE_RANGES)
    ranges = dict(FORWARD_RANGES)
    if condition.stride == 0.0:
        del ranges["alpha"]
    if data is not None:
        ranges.update({name: span for name, span in TIMING_RANGES.items() if name in data["forward"]["columns"]})
    return ranges


def with_timing_columns(data: dict[str, Any], robot: RobotModel) -> dict[str, Any]:
    """``data`` with Table 2 carrying ``V_y`` and ``d`` (the robot's, in table units) where it does not."""
    out = copy.deepcopy(data)
    table = out["forward"]
    time_scale, _, lateral_scale = robot.schedule_scale
    for name, value in (("lateral_velocity", robot.lateral_velocity / lateral_scale),
                        ("dsp_time", robot.dsp_time / time_scale)):
        if name not in table["columns"]:
            table["columns"] = [*table["columns"], name]
            table["rows"] = [[*row, value] for row in table["rows"]]
    return out


def row_values(data: dict[str, Any], condition: Condition) -> dict[str, float]:
    """The tuned columns of a condition's row as the schedule has them."""
    table = data[condition.mode]
    row = table["rows"][_row_index(data, condition)]
    return {name: float(row[table["columns"].index(name)]) for name in tuned_columns(condition, data)}


def with_row(data: dict[str, Any], condition: Condition, values: dict[str, float]) -> dict[str, Any]:
    """A copy of the schedule data with a condition's row changed."""
    out = copy.deepcopy(data)
    table = out[condition.mode]
    row = table["rows"][_row_index(out, condition)]
    for name, value in values.items():
        row[table["columns"].index(name)] = float(value)
    return out


def condition_command(robot: RobotModel, condition: Condition) -> StepCommand:
    """The step of a condition for this robot: table units through the robot's schedule scale."""
    time_scale, stride_scale, lateral_scale = robot.schedule_scale
    duration = condition.duration * time_scale
    if condition.mode == "forward":
        return StepCommand(duration, condition.stride * stride_scale)
    if condition.mode == "turn":
        return StepCommand(duration, turn=condition.stride)  # an angle: the same for every robot
    return StepCommand(duration, side=condition.stride * lateral_scale)


def condition_walk(robot: RobotModel, data: dict[str, Any], condition: Condition, steps: int) -> WalkingPattern:
    """``steps`` steps of a condition from standstill to standstill at 1 kHz with the schedule ``data``.

    Raises:
        ZmpwalkError: The walk cannot be planned.
    """
    from zmpwalk.patterns.polynomial import generate

    return generate(robot, [condition_command(robot, condition)] * steps, rate=RATE,
                    schedule=Schedule(data, "<candidate>"))


def margins(robot: RobotModel, data: dict[str, Any], condition: Condition, steps: int) -> tuple[float, float]:
    """Smallest cart-table and multibody ZMP margins [m] of ``steps`` steps of a condition at 1 kHz (multibody:
    nan without link masses; -inf where the walk cannot be planned, or, for a robot's own model, its legs
    cannot be solved along it: its base goes under the whole-body centre of mass, which the pattern's reach
    check does not see)."""
    from zmpwalk.dynamics import compare_zmp
    from zmpwalk.kinematics import pattern_joint_trajectory

    try:
        pattern = condition_walk(robot, data, condition, steps)
        if robot.own_model:
            pattern_joint_trajectory(pattern, check_limits=False)
    except ZmpwalkError:
        return -math.inf, -math.inf
    cart = float(np.nanmin(pattern.zmp_margin()))
    if not robot.links or robot.own_model:
        return cart, math.nan
    multibody = compare_zmp(pattern).multibody
    return cart, float(np.nanmin(replace(pattern, zmp_in_world=multibody).zmp_margin()))


def score_of(cart: float, multibody: float) -> float:
    """The cheap score [m]: the smaller margin, capped at :data:`MARGIN_CAP`."""
    low = cart if math.isnan(multibody) else min(cart, multibody)
    return min(low, MARGIN_CAP)


def walk(robot: RobotModel, data: dict[str, Any], condition: Condition, steps: int) -> tuple[bool, float, float]:
    """Walk a condition in MuJoCo as every walk runs (``zmpwalk simulate``, :func:`zmpwalk.walk.run_walk`, the
    stabilizer on): (passes, largest torso roll or pitch [rad], largest held torque [N m])."""
    from zmpwalk.walk import WalkSpec, planned_walk, run_walk

    spec = WalkSpec(robot, [condition_command(robot, condition)] * steps, generator="polynomial",
                    schedule=Schedule(data, "<candidate>"), rate=RATE)
    try:
        planned = planned_walk(spec)
    except ZmpwalkError:
        return False, math.inf, math.inf
    outcome = run_walk(spec, planned=planned)
    result = outcome.result
    verdict = {c.name: c for c in outcome.verdict.criteria}
    passes = verdict["no fall"].passed and verdict["CoP inside the loaded soles"].passed
    attitude = float(np.nanmax(np.abs(result.torso_rpy[:, :2]))) if len(result.torso_rpy) else math.inf
    peak = max((row.peak_torque for row in outcome.rows), default=math.inf)
    return passes, attitude, peak


def tune_condition(robot_spec: str, data: dict[str, Any], condition: Condition, index: int, trials: int,
                   seed: int, steps: int, storage: str | None) -> ConditionResult:
    """Tune one condition (one process): the Optuna study, then the simulation of the best candidates."""
    optuna = _optuna()
    start = time.perf_counter()
    robot = loaded_robot(robot_spec)
    ranges = tuned_columns(condition, data)
    table = row_values(data, condition)
    sampler = optuna.samplers.TPESampler(seed=seed * 1009 + index)
    study = optuna.create_study(direction="maximize", sampler=sampler, storage=storage, load_if_exists=True,
                                study_name=f"{robot.name}: {condition.name}")
    if not study.trials:
        study.enqueue_trial(table)  # the table's own values are the first candidate

    def objective(trial: Any) -> float:
        values = {name: trial.suggest_float(name, low, high) for name, (low, high) in ranges.items()}
        cart, multibody = margins(robot, with_row(data, condition, values), condition, steps)
        trial.set_user_attr("cart", cart)
        trial.set_user_attr("multibody", multibody)
        return score_of(cart, multibody) if math.isfinite(cart) else -1.0

    remaining = trials - len([t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE])
    if remaining > 0:
        study.optimize(objective, n_trials=remaining)
    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    ranked = sorted(done, key=lambda t: (-t.value, t.number))[:SIMULATED]
    table_trial = done[0]
    candidates = []
    for trial in [*ranked, table_trial]:
        values = {name: float(trial.params[name]) for name in ranges}
        passes, attitude, peak = walk(robot, with_row(data, condition, values), condition, steps)
        candidates.append((trial, values, passes, attitude, peak))
    table_walks = candidates[-1][2]
    best = min(candidates, key=lambda c: (not c[2], -c[0].value, c[3], c[4], c[0].number))
    trial, values, passes, attitude, peak = best
    return ConditionResult(
        condition=condition, values=values, table=table, cart_margin=float(trial.user_attrs["cart"]),
        multibody_margin=float(trial.user_attrs["multibody"]), table_cart_margin=float(table_trial.user_attrs["cart"]),
        table_multibody_margin=float(table_trial.user_attrs["multibody"]), walks=passes, attitude=attitude,
        peak_torque=peak, trials=len(done), seconds=time.perf_counter() - start, table_walks=table_walks)


def tune(robot: str, trials: int = 40, seed: int = 0, workers: int | None = None, storage: Path | None = None,
         steps: int = 10, data: dict[str, Any] | None = None, conditions: Sequence[Condition] | None = None,
         progress: Callable[[int, int, float], None] | None = None, scheduler: str | None = None,
         timing: bool = False) -> TuneResult:
    """Tune the shape factors of every condition of a schedule for a robot.

    Args:
        robot: What ``--robot`` takes (a name, robot file or model path).
        trials: Candidates per condition (the table's values included).
        seed: Seed of the samplers: the same seed gives the same schedule.
        workers: Conditions tuned at a time (default: one per core).
        storage: An SQLite file keeping the studies: a run that stops resumes where it was.
        steps: Steps of each condition walked per candidate.
        data: The schedule to start from (default: Tables 2-3); its rows are the grid, with the turn rows of
            :data:`TURN_GRID` added where it has no turn table.
        conditions: Only these rows (default: every row).
        progress: Called with (conditions done, of, best score so far [m]).
        scheduler: Tune the conditions on a Dask cluster (its scheduler's address, or ``"local"``;
            :func:`zmpwalk.sweep.in_pool`). With ``storage``, every worker must reach the same file.
        timing: Also tune ``V_y`` and the double-support time ``d`` of Table 2's rows (within
            :data:`TIMING_RANGES`; the columns are added, starting from the robot's values).

    Raises:
        InvalidParameterError: A bad count or a condition that is not a row.
        ZmpwalkError: Optuna is missing, or the robot does not load.
    """
    _optuna()
    for name, value, low in (("trials", trials, 1), ("steps", steps, 2), ("workers", workers or 1, 1)):
        if isinstance(value, bool) or not isinstance(value, int) or value < low:
            raise InvalidParameterError(name, value, f"an integer >= {low}")
    data = with_turn_table(copy.deepcopy(data) if data is not None else hubo_schedule_data())
    grid = list(conditions) if conditions is not None else conditions_of(data)
    for condition in grid:
        _row_index(data, condition)
    model = loaded_robot(robot)
    if timing:
        data = with_timing_columns(data, model)
    url = f"sqlite:///{Path(storage).resolve()}" if storage is not None else None
    if url is not None:  # the tables made once here: workers starting together on a new file would race to
        _optuna().storages.RDBStorage(url)  # make them ("table studies already exists")
    workers = workers or os.cpu_count() or 1
    results: dict[int, ConditionResult] = {}
    best = -math.inf

    def record(index: int, result: ConditionResult) -> None:
        nonlocal best
        results[index] = result
        best = max(best, score_of(result.cart_margin, result.multibody_margin))
        if progress:
            progress(len(results), len(grid), best)

    # pass 1: the stride-0 rows, which start and stop every walk; pass 2: the others, walked with them
    first_pass = [i for i, c in enumerate(grid) if c.mode == "forward" and c.stride == 0.0]
    for indices in (first_pass, [i for i in range(len(grid)) if i not in first_pass]):
        in_pool(tune_condition, {i: (robot, data, grid[i], i, trials, seed, steps, url) for i in indices}, workers,
                record, scheduler)
        for index in indices:
            data = with_row(data, grid[index], results[index].values)
    return TuneResult(data, [results[index] for index in range(len(grid))])


def schedule_toml(result: TuneResult, robot: str) -> str:
    """The tuned schedule as a schedule file (the format of ``data/schedule_hubo.toml``), each row with its
    scores in a comment."""
    lines = [f"# Shape factors tuned by zmpwalk tune for {robot} (SI units; factors dimensionless).",
             "# Each row's comment: smallest cart-table / multibody ZMP margin over its steps at 1 kHz [mm], whether",
             "# it walked them in MuJoCo, and the table's own values' margins before tuning.", ""]
    by_row = {(r.condition.mode, r.condition.duration, r.condition.stride): r for r in result.results}
    for mode, key in MODE_KEYS:
        if mode not in result.data:
            continue
        table = result.data[mode]
        lines.append(f"[{mode}]")
        for name, value in table.items():
            if name not in ("columns", "rows"):
                lines.append(f"{name} = {_number(value)}")
        lines.append("columns = [" + ", ".join(f'"{c}"' for c in table["columns"]) + "]")
        lines.append("rows = [")
        columns = table["columns"]
        for row in table["rows"]:
            cells = ", ".join(_number(v) for v in row)
            condition = (mode, float(row[columns.index("duration")]), float(row[columns.index(key)]))
            r = by_row.get(condition)
            note = ""
            if r is not None:
                note = (f"  # {r.cart_margin * 1e3:+.1f} / {_mm(r.multibody_margin)} mm, "
                        f"{'walks' if r.walks else 'FAILS in simulation'}; table {r.table_cart_margin * 1e3:+.1f} / "
                        f"{_mm(r.table_multibody_margin)} mm")
            lines.append(f"  [{cells}],{note}")
        lines.append("]")
        lines.append("")
    return "\n".join(lines)


def _number(value: object) -> str:
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.6g}"
    return repr(value) if not isinstance(value, str) else f'"{value}"'


def _mm(value: float) -> str:
    return "n/a" if math.isnan(value) else f"{value * 1e3:+.1f}"
