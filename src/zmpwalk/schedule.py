"""Parameter scheduling: Tables 2 and 3 of Park et al. (2008) and interpolation between them.

The paper tunes the shape factors for a few (step time, stride) conditions and
names the scheduling of untested conditions as future work. zmpwalk looks a
step up as follows:

1. Within one tabulated step time, each value is interpolated linearly in the
   stride between the neighbouring rows. ``alpha`` is undefined ('x') at
   stride 0 because it multiplies the stride; there the nearest defined row
   is used.
2. Between two tabulated step times, the two results are interpolated
   linearly in the step time.
3. Side steps use Table 3. Below the smallest tabulated side step (5 cm) the
   values are interpolated towards stepping on the spot, whose values are
   Table 2's stride-0 row with ``alpha1 = beta1 = 1`` and ``d1`` of Table 2.
   Turns (without a side step, with or without a stride) use the optional
   ``[turn]`` table, keyed by the turn of one step [rad] and with Table 3's
   columns, in the same way (towards stepping on the spot below its smallest
   turn). The paper has no turn table: without one a turn takes Table 2's row
   and ``alpha1``, ``beta1``, ``d1`` for both its stages (``zmpwalk tune``
   writes a ``[turn]`` table).
   Table 2 may carry two more columns, ``lateral_velocity`` (``V_y`` [m per
   unit ``2 t_bar``]) and ``dsp_time`` (``d`` [s]), looked up like the others
   and used by every step of that step time and stride (side steps and turns:
   their stride's row); without them both are the robot's (``zmpwalk tune
   --timing`` writes them).
4. Outside the tabulated range (a step time below 0.7 s or above 0.95 s, a
   stride beyond the longest row) the nearest edge value is held and the
   lookup is marked ``extrapolated``; the pattern reports it per step. ``V_y``
   is the exception below the shortest tabulated step time: held, the sway's
   crossing acceleration ``(4 alpha1 V_y - 6 beta1 S_y) / tau^2`` would grow as
   ``1 / T^2``; instead ``4 alpha1 V_y - 6 beta1 S_y`` shrinks with ``T^2``, so
   the cart-table ZMP where the sway crosses the middle stays where the
   shortest row puts it (:func:`held_crossing_velocity`).
5. Any value given in the :class:`~zmpwalk.commands.StepCommand` replaces the
   scheduled one.
6. Another robot walks the tables at the dynamically similar condition
   (:func:`~zmpwalk.robots.model.schedule_scale`): the cart-table
   model ``x'' = (g / l)(x - p)`` is the same equation for every ``l`` in the
   dimensionless time ``t / sqrt(l / g)`` and is linear in length, so a step
   time ``T`` is looked up at ``T / sqrt(l / l_HUBO)``, a stride at
   ``f / (L / L_HUBO)`` with ``L`` the leg length (the legs sweep HUBO's
   angles), and a side step and the sway ``S_y`` scale with the hip spacing
   (the lateral distance the sway must cover). HUBO's own factors are 1.

Named schedules (:data:`SCHEDULE_FILES`): ``default`` (:meth:`Schedule.hubo`), Tables 2-3 with Table 2's
``lateral_velocity`` column (``V_y`` per step time, chosen with :func:`sway_crossing_zmp`: 0.1 m at 0.95 and
0.8 s, 0.09 m at 0.7 s), and ``paper`` (:meth:`Schedule.paper`), Tables 2-3 as printed, where every step takes
the robot's ``V_y``.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError, InvalidParameterError
from zmpwalk.files import read_toml
from zmpwalk.robots.model import RobotModel


@dataclass(frozen=True)
class ShapeParameters:
    """Parameters and shape factors of one stage (one swing) of the HUBO pattern.

    Attributes:
        alpha: Pelvis X velocity factor of Eq. 13 [-].
        alpha1: Multiplier of ``V_y`` at the step change (Eq. 20) [-].
        beta1: Multiplier of ``S_y`` at mid-step (Eq. 20) [-].
        d1: Staying ratio of Eq. 18 [-].
        up_ratio: ``u`` of Fig. 12, lift time over swing time [-].
        sway: ``S_y`` of Eq. 20 [m].
        lateral_velocity: ``V_y`` of Eq. 20 [m per unit ``2 t_bar``].
        dsp_time: Double-support time ``d`` of Eq. 11 [s].
        foot_lift: Swing apex height [m].
        source: ``"table"``, ``"interpolated"``, ``"extrapolated"``; with
            ``"+override"`` when the command replaced a value.
    """

    alpha: float  # [-]
    alpha1: float  # [-]
    beta1: float  # [-]
    d1: float  # [-]
    up_ratio: float  # [-]
    sway: float  # [m]
    lateral_velocity: float  # [m per unit 2*t_bar]
    dsp_time: float  # [s]
    foot_lift: float  # [m]
    source: str = "table"


class _Grid:
    """Rows of one table, grouped by step time, for 2-D piecewise-linear lookup (plain Python on a few rows: a
    lookup is tens of microseconds, inside a planner that works in slices)."""

    def __init__(self, rows: list[list[float]], columns: list[str], key: str, source: str) -> None:
        data = np.asarray(rows, dtype=float)
        if data.ndim != 2 or data.shape[1] != len(columns):
            raise FileFormatError(source, f"every row needs {len(columns)} values: {', '.join(columns)}")
        self.columns = columns
        self.durations: list[float] = np.unique(data[:, 0]).tolist()
        self.by_duration: dict[float, list[list[float]]] = {}
        key_index = columns.index(key)
        for duration in self.durations:
            block = data[data[:, 0] == duration]
            self.by_duration[duration] = block[np.argsort(block[:, key_index])].tolist()
        self.key_index = key_index
        self._prepared: dict[tuple[float, object], _Block] = {}  # by (step time, prepend): the rows as columns

    def lookup(
        self, duration: float, key: float, prepend: Callable[[float], list[float]] | None = None
    ) -> tuple[dict[str, float], str]:
        """Interpolated row at (duration, key), and how it was obtained."""
        source = "table"
        durations = self.durations
        exact = [d for d in durations if abs(d - duration) <= EXACT]
        if exact:
            pairs = [(exact[0], 1.0)]
        elif duration <= durations[0] or duration >= durations[-1]:
            nearest = durations[0] if duration <= durations[0] else durations[-1]
            source = "extrapolated"
            pairs = [(nearest, 1.0)]
        else:
            upper = bisect.bisect_left(durations, duration)
            t_low, t_high = durations[upper - 1], durations[upper]
            weight = (duration - t_low) / (t_high - t_low)
            pairs = [(t_low, 1.0 - weight), (t_high, weight)]
            source = "interpolated"
        result = dict.fromkeys(self.columns, 0.0)
        for tabulated, weight in pairs:
            row, row_source = _interpolate_rows(self._block(tabulated, prepend), key)
            if row_source != "table" and source != "extrapolated":
                source = row_source
            for index, name in enumerate(self.columns):
                result[name] += weight * row[index]
        return result, source

    def _block(self, tabulated: float, prepend: Callable[[float], list[float]] | None) -> _Block:
        """The rows of step time ``tabulated`` (after ``prepend``'s row, where given), column by column: prepared
        once (a schedule is not modified after reading, so neither is a row ``prepend`` makes from it)."""
        cached = self._prepared.get((tabulated, prepend))
        if cached is None:
            block = self.by_duration[tabulated]
            if prepend is not None:
                block = [prepend(tabulated), *block]
            cached = self._prepared[(tabulated, prepend)] = _Block.of(block, self.key_index)
        return cached


EXACT = 1e-12  # [s] or table units: a query this close to a tabulated value is that value


@dataclass(frozen=True)
class _Block:
    """One step time's rows (sorted by the key), as the interpolation reads them: the keys, and for each column the
    keys and values of its defined cells (NaN cells, 'x', skipped)."""

    keys: list[float]
    columns: list[tuple[list[float], list[float]]]

    @classmethod
    def of(cls, block: list[list[float]], key_index: int) -> _Block:
        columns = []
        for column in range(len(block[0])):
            defined = [(row[key_index], row[column]) for row in block if not math.isnan(row[column])]
            columns.append(([k for k, _ in defined], [v for _, v in defined]))
        return cls([row[key_index] for row in block], columns)


def _interpolate_rows(block: _Block, key: float) -> tuple[list[float], str]:
    """Linear interpolation along ``key`` in one step time's rows, column by column (each over its defined cells)."""
    keys = block.keys
    source = "table"
    if key < keys[0] - EXACT or key > keys[-1] + EXACT:
        source = "extrapolated"
    elif not any(abs(k - key) <= EXACT + 1e-5 * abs(key) for k in keys):
        source = "interpolated"
    return [_interp(key, xp, fp) for xp, fp in block.columns], source


def _interp(x: float, xp: list[float], fp: list[float]) -> float:
    """``numpy.interp(x, xp, fp)`` for one ``x`` and increasing ``xp``, operation for operation (the same
    floating-point result): the end values outside, ``slope (x - xp[j]) + fp[j]`` inside; NaN where the
    column has no value at all."""
    if not xp:
        return math.nan
    if x >= xp[-1]:
        return fp[-1]
    if x < xp[0]:
        return fp[0]
    j = bisect.bisect_right(xp, x) - 1
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    value = slope * (x - xp[j]) + fp[j]
    if math.isnan(value):  # as numpy: try from the other end
        value = slope * (x - xp[j + 1]) + fp[j + 1]
        if math.isnan(value) and fp[j] == fp[j + 1]:
            value = fp[j]
    return value


# the [turn] table's columns: Table 3's, keyed by the turn of one step [rad]
TURN_COLUMNS = ["duration", "turn", "sway", "up_ratio", "alpha1", "beta1", "d1_open", "d1_recovery"]


class Schedule:
    """Shape parameters for any (step time, stride, side step, turn) from tuned tables.

    Args:
        data: The parsed schedule file (see ``data/schedule_hubo.toml``).
        source: Name of the file, for error messages.
    """

    def __init__(self, data: dict[str, Any], source: str = "<schedule>") -> None:
        self._source = source
        try:
            forward = data["forward"]
            side = data["side"]
            self._forward = _Grid(forward["rows"], forward["columns"], "stride", source)
            self._side = _Grid(side["rows"], side["columns"], "side", source)
            turn = data.get("turn")
            turn_columns = None if turn is None else list(turn["columns"])
            self._turn = None if turn is None or turn_columns != TURN_COLUMNS else \
                _Grid(turn["rows"], turn["columns"], "turn", source)
            self._forward_d1 = float(forward["d1"])
            self._forward_alpha1 = float(forward["alpha1"])
            self._forward_beta1 = float(forward["beta1"])
        except (KeyError, TypeError, ValueError) as error:
            raise FileFormatError(source, f"malformed schedule: {error}") from None
        if turn_columns is not None and turn_columns != TURN_COLUMNS:
            raise FileFormatError(source, f"[turn] columns must be {TURN_COLUMNS}, not {turn_columns}")
        self._cache: dict[tuple[object, ...], tuple[ShapeParameters, ShapeParameters]] = {}

    def conditions(self) -> list[tuple[str, float, float]]:
        """The tabulated conditions: ``("forward", step time [s], stride [m])``, ``("side", ..., side step [m])``
        and, where the schedule has a turn table, ``("turn", ..., turn [rad])``."""
        result = []
        grids = [("forward", self._forward), ("side", self._side)]
        if self._turn is not None:
            grids.append(("turn", self._turn))
        for mode, grid in grids:
            for duration in sorted(grid.by_duration, reverse=True):
                for row in grid.by_duration[duration]:
                    result.append((mode, float(duration), float(row[grid.key_index])))
        return result

    def on_spot_row(self, duration: float) -> list[float]:
        """Stepping on the spot as a Table 3 (or turn table) row, side step (turn) 0, at a tabulated step time."""
        on_spot, _ = self._forward.lookup(duration, 0.0)
        return [duration, 0.0, on_spot["sway"], on_spot["up_ratio"], self._forward_alpha1,
                self._forward_beta1, self._forward_d1, self._forward_d1]

    @classmethod
    def from_file(cls, path: Path) -> Schedule:
        """Read a schedule file (TOML)."""
        return cls(read_toml(path), str(path))

    @classmethod
    def hubo(cls) -> Schedule:
        """HUBO's default schedule: Tables 2 and 3 of Park et al. (2008) with ``V_y`` per step time
        (``data/schedule_hubo_default.toml``; read once, a schedule is not modified after reading)."""
        return cls.named("default")

    @classmethod
    def paper(cls) -> Schedule:
        """Tables 2 and 3 of Park et al. (2008) as printed (``data/schedule_hubo.toml``): ``V_y`` is the robot's."""
        return cls.named("paper")

    @classmethod
    def named(cls, name: str) -> Schedule:
        """A built-in schedule by name (:data:`SCHEDULE_FILES`), read once.

        Raises:
            InvalidParameterError: An unknown name.
        """
        if name not in SCHEDULE_FILES:
            raise InvalidParameterError("schedule", name, f"one of {', '.join(SCHEDULE_FILES)} or a schedule file")
        return _named_schedule(name)

    def stage_parameters(
        self, command: StepCommand, robot: RobotModel
    ) -> tuple[ShapeParameters, ShapeParameters]:
        """Parameters of the open-stance (or only) stage and of the recovery stage.

        Overrides in ``command`` replace the scheduled values; the robot gives
        the values the tables do not hold (``d``, foot lift, ``V_y``).
        """
        key = (command, robot.lateral_velocity, robot.dsp_time, robot.foot_lift, robot.schedule_scale,
               robot.pendulum_length, robot.gravity)  # l and g: V_y below the tables (held_crossing_velocity)
        cached = self._cache.get(key)
        if cached is None:
            if len(self._cache) > 4096:
                self._cache.clear()
            cached = self._cache[key] = self._stage_parameters(command, robot)
        return cached

    def _stage_parameters(
        self, command: StepCommand, robot: RobotModel
    ) -> tuple[ShapeParameters, ShapeParameters]:
        # The tables' robot (HUBO) walks this robot's step at the dynamically similar condition:
        # step time / sqrt(l / l_HUBO), stride / (L / L_HUBO), side step and sway with the hip spacing
        # (robots.model.schedule_scale).
        time_scale, stride_scale, lateral_scale = robot.schedule_scale
        duration = command.duration / time_scale
        stride = abs(command.forward) / stride_scale
        row, source = self._forward.lookup(duration, stride)
        alpha = row["alpha"]
        if math.isnan(alpha):  # no row near this step time gives alpha: only stride-0 rows ('x'), where it is moot
            if stride > 0.0 and command.alpha is None:
                raise FileFormatError(self._source, f"Table 2 gives no alpha near step time {duration:g} s (only "
                                      f"stride-0 rows, 'x'); a stride of {command.forward:g} m needs a row with one")
            alpha = 1.0  # Eq. 13: v1 = alpha f / T is 0 at stride 0 whatever alpha
        sway = row["sway"] * lateral_scale
        up_ratio = row["up_ratio"]
        open_alpha1 = recovery_alpha1 = self._forward_alpha1
        open_beta1 = recovery_beta1 = self._forward_beta1
        open_d1 = recovery_d1 = self._forward_d1
        two_stage: tuple[dict[str, float], str] | None = None
        if command.side != 0.0:
            two_stage = self._side.lookup(duration, abs(command.side) / lateral_scale, self.on_spot_row)
        elif command.turn != 0.0 and self._turn is not None:  # a turn is an angle: the same for every robot
            two_stage = self._turn.lookup(duration, abs(command.turn), self.on_spot_row)
        if two_stage is not None:
            side_row, side_source = two_stage
            sway = side_row["sway"] * lateral_scale
            up_ratio = side_row["up_ratio"]
            open_alpha1, open_beta1 = side_row["alpha1"], side_row["beta1"]
            open_d1, recovery_d1 = side_row["d1_open"], side_row["d1_recovery"]
            recovery_alpha1, recovery_beta1 = open_alpha1, open_beta1
            source = _worse(source, side_source)
        # V_y and d: Table 2's row where the forward table carries them (table units), else the robot's
        lateral_velocity = row["lateral_velocity"] * lateral_scale if "lateral_velocity" in row \
            else robot.lateral_velocity
        shortest = self._forward.durations[0]
        if duration < shortest - EXACT:  # below the tables: the crossing's ZMP held, not V_y (module docstring)
            lateral_velocity = held_crossing_velocity(
                lateral_velocity, sway, open_alpha1, open_beta1, duration / shortest,
                (1.0 - open_d1) * command.duration / 2.0, robot.pendulum_length, robot.gravity)
        dsp_time = row["dsp_time"] * time_scale if "dsp_time" in row else robot.dsp_time
        common = {
            "alpha": alpha, "up_ratio": up_ratio, "sway": sway,
            "lateral_velocity": lateral_velocity, "dsp_time": dsp_time,
            "foot_lift": robot.foot_lift,
        }
        first = ShapeParameters(alpha1=open_alpha1, beta1=open_beta1, d1=open_d1, source=source, **common)
        second = ShapeParameters(
            alpha1=recovery_alpha1, beta1=recovery_beta1, d1=recovery_d1, source=source, **common
        )
        overrides = {
            name: getattr(command, name)
            for name in ("alpha", "up_ratio", "sway", "lateral_velocity", "dsp_time", "foot_lift",
                         "alpha1", "beta1", "d1")
            if getattr(command, name) is not None
        }
        if overrides:
            first = replace(first, source=first.source + "+override", **overrides)
            # d1 is per stage (Table 3's superscripts): the recovery stage takes d1_recovery instead.
            second_overrides = {k: v for k, v in overrides.items() if k != "d1" or not command.is_two_stage}
            second = replace(second, source=second.source + "+override", **second_overrides)
        if command.d1_recovery is not None:
            second = replace(second, d1=command.d1_recovery, source=second.source.split("+")[0] + "+override")
        return first, second


def _worse(first: str, second: str) -> str:
    order = ("table", "interpolated", "extrapolated")
    return order[max(order.index(first), order.index(second))]


# the built-in schedules by name: --schedule NAME, Schedule.named(NAME)
SCHEDULE_FILES = {"default": "schedule_hubo_default.toml", "paper": "schedule_hubo.toml"}


def schedule_path(name_or_file: str | Path) -> Path:
    """The file of a built-in schedule's name (:data:`SCHEDULE_FILES`), or the path given (a file named like a
    built-in schedule is given as ``./paper``)."""
    if isinstance(name_or_file, str) and name_or_file in SCHEDULE_FILES:
        return Path(str(resources.files("zmpwalk") / "data" / SCHEDULE_FILES[name_or_file]))
    return Path(name_or_file)


@lru_cache(maxsize=len(SCHEDULE_FILES))
def _named_schedule(name: str) -> Schedule:
    return Schedule.from_file(schedule_path(name))


SWAY_RULE = (1.5, 3.0)  # [-] alpha1 V_y / (beta1 S_y) strictly between: sway cubics without inflection (Eq. 20)


def sway_crossing_zmp(lateral_velocity: float, sway: float, alpha1: float, beta1: float, back_time: float,
                      pendulum_length: float, gravity: float) -> float:
    """Distance [m] of the cart-table ZMP from the middle of the stance where the sway crosses it (Eqs. 1-2, 20).

    The returning sway cubic of Eq. 20 runs, in units of its own time ``tau = back_time`` (``(1 - d1) T / 2``,
    Eq. 18), from ``-beta1 S_y`` at rest to the middle at the slope ``alpha1 V_y``. A cubic Hermite curve's
    second derivative at its end is ``6 p0 + 2 m0 - 6 p1 + 4 m1``, here ``4 alpha1 V_y - 6 beta1 S_y`` per unit
    time squared; the pelvis is then at the middle, so the ZMP ``p = y - (l / g) y''`` (Eqs. 1-2) lies
    ``(l / g) (4 alpha1 V_y - 6 beta1 S_y) / tau^2`` from it, on the side of the foot the sway leaves (the next
    stage's outgoing cubic starts with the opposite acceleration: as far on the other side when the two
    stages share their parameters). Positive when ``alpha1 V_y > 1.5 beta1 S_y``.

    Args:
        lateral_velocity: ``V_y`` [m per unit ``2 t_bar``].
        sway: ``S_y`` [m].
        alpha1: Eq. 20's multiplier of ``V_y`` [-].
        beta1: Eq. 20's multiplier of ``S_y`` [-].
        back_time: ``tau``, the returning cubic's length [s].
        pendulum_length: ``l`` [m].
        gravity: ``g`` [m/s^2].
    """
    return pendulum_length / gravity * (4.0 * alpha1 * lateral_velocity - 6.0 * beta1 * sway) / back_time**2


def crossing_velocity(offset: float, sway: float, alpha1: float, beta1: float, back_time: float,
                      pendulum_length: float, gravity: float) -> float:
    """The ``V_y`` [m per unit ``2 t_bar``] that puts the crossing's ZMP ``offset`` [m] from the middle:
    :func:`sway_crossing_zmp` solved for ``V_y``, ``(6 beta1 S_y + (g / l) offset tau^2) / (4 alpha1)``
    (arguments as there)."""
    return (6.0 * beta1 * sway + gravity / pendulum_length * offset * back_time**2) / (4.0 * alpha1)


def held_crossing_velocity(lateral_velocity: float, sway: float, alpha1: float, beta1: float, time_ratio: float,
                           back_time: float, pendulum_length: float, gravity: float) -> float:
    """``V_y`` [m per unit ``2 t_bar``] of a step ``time_ratio`` (< 1) times as long as the shortest tabulated
    step: lowered to hold the crossing's ZMP (:func:`sway_crossing_zmp`) where ``lateral_velocity`` puts it at
    that step, but not below the ``V_y`` where the sway's turn-around takes over as the farther ZMP.

    With ``d1`` held, ``tau`` is proportional to the step time, so the crossing's offset stays when
    ``4 alpha1 V_y - 6 beta1 S_y`` shrinks with ``time_ratio^2``:
    ``V_y' = (6 beta1 S_y + (4 alpha1 V_y - 6 beta1 S_y) time_ratio^2) / (4 alpha1)``. Lowering ``V_y`` moves the
    other end of the sway outwards: where the outgoing cubic (0 at slope ``alpha1 V_y`` to ``beta1 S_y`` at rest)
    turns into the stay, its second derivative is ``2 alpha1 V_y - 6 beta1 S_y``, so the ZMP there is
    ``beta1 S_y + (l / g) (6 beta1 S_y - 2 alpha1 V_y) / tau^2`` from the middle. The two are equal at
    ``alpha1 V_y = beta1 S_y (2 + tau^2 g / (6 l))``; below it the turn-around is the farther, and ``V_y`` is not
    lowered past it. ``V_y`` is never raised.

    Args:
        lateral_velocity: ``V_y`` at the shortest tabulated step time [m per unit ``2 t_bar``].
        sway: ``S_y`` [m].
        alpha1: Eq. 20's multiplier of ``V_y`` [-].
        beta1: Eq. 20's multiplier of ``S_y`` [-].
        time_ratio: The step time over the shortest tabulated one [-].
        back_time: ``tau`` of the short step, ``(1 - d1) T / 2`` [s].
        pendulum_length: ``l`` [m].
        gravity: ``g`` [m/s^2].
    """
    excess = 4.0 * alpha1 * lateral_velocity - 6.0 * beta1 * sway  # [m] per unit time squared
    held = (6.0 * beta1 * sway + excess * time_ratio**2) / (4.0 * alpha1)
    balance = beta1 * sway * (2.0 + back_time**2 * gravity / (6.0 * pendulum_length)) / alpha1
    return min(lateral_velocity, max(held, balance))
