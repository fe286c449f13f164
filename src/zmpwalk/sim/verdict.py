"""Does the simulated walk pass? Every criterion with its figure, its limit and pass or fail.

A walk passes when all of these hold (the limits are module constants, stated in docs/simulation.md):

1. **No fall** (the fall criterion of :mod:`zmpwalk.sim.measure`): shown as the time walked of the run's length.
2. **It ends standing still**, over the final hold of at least :data:`MIN_HOLD` after the last step:
   both soles loaded (the less loaded one carries at least :data:`LOADED_SHARE` of the weight), the base's
   horizontal speed at most :data:`STILL_SPEED`, the torso's roll and pitch settled (their spread at most
   :data:`SETTLED_ATTITUDE`). A negative sole force means the sole was off the floor: its ankle sensor then
   carries the foot hanging from the leg (the foot's weight and inertia), which reads as a pull.
3. **The feet end where the plan puts them**: each ankle within :data:`FEET_DISTANCE` and
   :data:`FEET_YAW` of its planned final pose.
4. **The CoP stays inside the loaded soles** (margin at least :data:`COP_MARGIN`) except at touchdown
   transients: the :data:`TOUCHDOWN_WINDOW` after a sole touches the floor (carries more than
   :data:`CONTACT_FRACTION` of the weight) or becomes loaded is not judged. (The other sole's force-torque
   reading swings with the impact before the landing sole counts as loaded: TALOS's carrying sole read a CoP
   30 mm outside itself at the first millisecond of the other's touchdown, at 101 N on the landing sole.)
5. **The plan keeps its ZMP inside the soles**: the pattern's least cart-table ZMP margin at least
   :data:`PLAN_ZMP_MARGIN` (what ``zmpwalk plan`` calls inside the support polygon).
6. **The joints stay within their actuators' limits**: the largest held (:data:`~zmpwalk.sim.actuators.IMPACT_WINDOW`)
   |torque| of a leg joint over its model's actuator limit, and with a motor file each motor's use of its
   torque-speed envelope and of its rated torque (:mod:`zmpwalk.sim.motors`), at most :data:`ACTUATOR_LIMIT`.
   A simulated actuator gives at most its model's limit (MuJoCo clamps it), so a held peak at that limit
   (100 %) is a saturated actuator: the walk was carried within the limit, with nothing to spare, and passes
   with a warning, as does anything from :data:`ACTUATOR_WARNING` on (amber, never green). A motor file's
   envelope or rating is not enforced by the simulation: a use beyond it (over 100 %) fails. Where the model
   gives no limit and no motor file is given it is not measured (shown so, never green).

Margins read the same way everywhere: positive inside, negative outside.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING

import numpy as np

from zmpwalk.sim.actuators import IMPACT_WINDOW, ActuatorRow, actuator_table, planned_over_limit
from zmpwalk.sim.contact import CONTACT_FRACTION, LOADED_FRACTION
from zmpwalk.sim.motors import Motor, MotorFit, motor_fits

if TYPE_CHECKING:
    from zmpwalk.sim.result import SimulationResult

MIN_HOLD = 2.0  # [s]
LOADED_SHARE = LOADED_FRACTION  # [-] of the weight on the less loaded sole
STILL_SPEED = 0.05  # [m/s]
SETTLED_ATTITUDE = 0.01  # [rad]
SETTLE = 0.5  # [s] standing before a judged walk (simulate, report, demo, sweep, tune)
HOLD = 2.0  # [s] standing after a judged walk: the verdict judges how the walk ends over this time
FEET_DISTANCE = 0.02  # [m]
FEET_YAW = math.radians(2.0)  # [rad]
COP_MARGIN = -0.005  # [m]: 5 mm of the sensors' CoP beyond an edge is the foot's own inertia at its limit
TOUCHDOWN_WINDOW = 0.05  # [s]
PLAN_ZMP_MARGIN = 0.0  # [m] the plan's cart-table ZMP on the edge of its support polygon at worst
ACTUATOR_LIMIT = 1.0  # [-] of an actuator's limit: a held peak (or a motor's use) must stay at most at it
ACTUATOR_WARNING = 0.9  # [-] of an actuator's limit: from here a passing walk is shown amber
SATURATION_TOL = 1e-6  # [-] a clamped actuator reads its limit to rounding

PASS, WARN, FAIL, SKIP = "PASS", "WARN", "FAIL", "SKIP"  # a criterion's state; SKIP: not measured


@dataclass(frozen=True)
class Criterion:
    """One criterion of the verdict.

    Attributes:
        name: Short name (``"no fall"``, ``"feet where planned"``, ...).
        figure: The measured value (nan where it cannot be measured, e.g. after a fall).
        limit: The limit it is held to.
        unit: Unit of both (``"fraction"``: of an actuator's limit, shown in %).
        passed: Whether it holds (a criterion that is not measured fails only when that is a failure, e.g. a fall).
        rule: How it is judged, in words.
        sense: How the figure must compare with the limit: ``"at least"``, ``"at most"`` or ``"below"``.
        warning: Passed, but in its warning band (shown amber, never green).
        note: What the figure means where it needs words (which joint; a negative sole force).
        shown: Figure and limit in words where a number beside a limit would mislead (``"walked 12.3 s of
            12.3 s"``); empty: ``figure (limit: sense limit)``.
    """

    name: str
    figure: float
    limit: float
    unit: str
    passed: bool
    rule: str
    sense: str = "at least"
    warning: bool = False
    note: str = ""
    shown: str = ""

    @property
    def state(self) -> str:
        """:data:`FAIL`, :data:`SKIP` (passed, not measured), :data:`WARN` or :data:`PASS`."""
        if not self.passed:
            return FAIL
        if not math.isfinite(self.figure):
            return SKIP
        return WARN if self.warning else PASS

    def text(self) -> str:
        """Figure and limit (and the note), as every display shows them."""
        figure = self.shown or f"{_show(self.figure, self.unit)} (limit: {self.sense} {_show(self.limit, self.unit)})"
        return f"{figure}; {self.note}" if self.note else figure


@dataclass(frozen=True)
class Verdict:
    """All criteria of one walk; :attr:`passed` only if every one passed.

    Attributes:
        criteria: The criteria.
        warnings: What else a reader must know of the walk (the plan asking more than an actuator gives, a
            motor that does not fit): printed by the console and shown on the page (:func:`walk_warnings`).
    """

    criteria: tuple[Criterion, ...]
    warnings: tuple[str, ...] = ()

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.criteria)

    @property
    def failed(self) -> list[str]:
        """Names of the criteria that failed."""
        return [c.name for c in self.criteria if not c.passed]

    def named(self, state: str) -> list[str]:
        """Names of the criteria in ``state``."""
        return [c.name for c in self.criteria if c.state == state]

    @property
    def state(self) -> str:
        """FAIL if a criterion failed; WARN if one is in its warning band or there are warnings; PASS otherwise
        (see :attr:`complete`: whether every criterion was measured)."""
        states = {c.state for c in self.criteria}
        if FAIL in states:
            return FAIL
        return WARN if WARN in states or self.warnings else PASS

    @property
    def complete(self) -> bool:
        """Every criterion measured (none :data:`SKIP`)."""
        return not self.named(SKIP)

    @property
    def clean(self) -> bool:
        """Every criterion passed with its figure and nothing to warn of: the only outcome shown green."""
        return self.state == PASS and self.complete

    def outcome(self) -> str:
        """The walk's outcome in words (the page's headline and the console's ``verdict:`` line)."""
        if self.state == FAIL:
            return "fails: " + ", ".join(self.failed)
        if self.clean:
            return "passes every criterion"
        parts = [f"warning: {', '.join(self.named(WARN))}"] if self.named(WARN) else []
        if self.warnings:
            parts.append(f"{len(self.warnings)} warning{'s' if len(self.warnings) > 1 else ''} below")
        if self.named(SKIP):
            parts.append(f"not measured: {', '.join(self.named(SKIP))}")
        measured = len(self.criteria) - len(self.named(SKIP))
        return f"passes the {measured} criteria measured ({'; '.join(parts)})"

    def as_dict(self) -> dict[str, object]:
        """As JSON takes it: a figure or limit that is not measured is None (null), not NaN."""
        def finite(value: float) -> float | None:
            return value if math.isfinite(value) else None

        return {"passed": self.passed, "state": self.state, "complete": self.complete, "outcome": self.outcome(),
                "criteria": [{**asdict(c), "figure": finite(c.figure), "limit": finite(c.limit), "state": c.state,
                              "text": c.text()} for c in self.criteria],
                "warnings": list(self.warnings)}

    def lines(self) -> list[str]:
        """One line per criterion: ``PASS|WARN|FAIL|SKIP name: figure (limit: ...); note (rule)``."""
        return [f"{c.state} {c.name}: {c.text()} ({c.rule})" for c in self.criteria]


def _show(value: float, unit: str) -> str:
    if not math.isfinite(value):
        return "not measured"
    if unit == "m":
        return f"{value * 1e3:.1f} mm"
    if unit == "rad":
        return f"{value:.4f} rad"
    if unit == "fraction":
        return f"{value * 100:.1f} %"
    return f"{value:.3g} {unit}".strip()


def walk_verdict(result: SimulationResult, hold: float, motors: Sequence[Motor] | None = None) -> Verdict:
    """Judge a simulated walk (see the module docstring).

    Args:
        result: The simulation.
        hold: How long the last pose was held after the walk [s] (:func:`zmpwalk.sim.run.simulate`).
        motors: The motors of a motor file (:func:`zmpwalk.sim.motors.load_motors`), judged with the model's
            actuator limits; None: the model's limits alone.
    """
    rows = actuator_table(result)
    fits = motor_fits(result, list(motors)) if motors else []
    criteria = [_no_fall(result), *_the_end(result, hold)]
    fell = result.fell
    criteria += [
        Criterion("feet where planned", result.final_feet_error, FEET_DISTANCE, "m",
                  not fell and result.final_feet_error <= FEET_DISTANCE,
                  "largest horizontal distance of a final ankle from its planned place", "at most"),
        Criterion("feet turned as planned", result.final_feet_yaw_error, FEET_YAW, "rad",
                  not fell and result.final_feet_yaw_error <= FEET_YAW, "largest yaw error of a final foot",
                  "at most"),
    ]
    criteria.append(cop_inside(result))
    criteria += [_plan_zmp(result), actuator_criterion(rows, fits)]
    return Verdict(tuple(criteria), tuple(walk_warnings(rows, fits)))


def cop_inside(result: SimulationResult) -> Criterion:
    """The measured CoP's least margin inside the loaded soles (:func:`cop_margin_outside_touchdowns`); a walk that
    fell fails it, and a margin within its limit then says that the fall failed it."""
    margin = cop_margin_outside_touchdowns(result)
    within = margin >= COP_MARGIN
    return Criterion("CoP inside the loaded soles", margin, COP_MARGIN, "m", not result.fell and within,
                     f"least CoP margin (positive inside) of the sensors' CoP, the {TOUCHDOWN_WINDOW * 1e3:g} ms "
                     "after each touchdown not judged",
                     note="fails with the fall: measured until it" if result.fell and within else "")


def _no_fall(result: SimulationResult) -> Criterion:
    """Time walked against the run's length, both from the run's first sample (the settle included)."""
    start = float(result.time[0]) if len(result.time) else 0.0
    end = float(result.time[-1]) if len(result.time) else math.nan
    planned = result.planned_end if math.isfinite(result.planned_end) else end
    walked = (result.fall_time if result.fall_time is not None else end) - start
    length = planned - start
    shown = (f"fell after {walked:.2f} s of {length:.2f} s" if result.fell else
             f"walked {walked:.2f} s of {length:.2f} s")
    return Criterion("no fall", walked, length, "s", not result.fell,
                     "time walked (standing before and after included) without the torso touching the ground, "
                     "tilting over 0.6 rad or sinking below 60 % of its height", "at least", shown=shown)


def _the_end(result: SimulationResult, hold: float) -> list[Criterion]:
    """Both soles loaded, standing still and the torso settled over the final hold."""
    loaded_force = LOADED_SHARE * result.robot.mass * result.robot.gravity
    enough = hold >= MIN_HOLD - 1e-9 and not result.fell
    force = result.end_min_sole_force if enough else math.nan
    lifted = ("negative: a sole was off the floor (its ankle sensor carries the foot hanging from the leg, "
              "its weight and inertia, which reads as a pull)" if force < 0 else "")
    return [
        Criterion("both soles loaded at the end", force, loaded_force, "N", enough and force >= loaded_force,
                  f"least normal force of either sole over the last {MIN_HOLD:g} s", "at least", note=lifted),
        Criterion("standing still at the end", result.end_max_speed if enough else math.nan, STILL_SPEED, "m/s",
                  enough and result.end_max_speed <= STILL_SPEED,
                  f"largest horizontal speed of the base over the last {MIN_HOLD:g} s", "at most"),
        Criterion("torso settled at the end", result.end_attitude_range if enough else math.nan, SETTLED_ATTITUDE,
                  "rad", enough and result.end_attitude_range <= SETTLED_ATTITUDE,
                  f"spread of torso roll and pitch over the last {MIN_HOLD:g} s", "at most"),
    ]


def _plan_zmp(result: SimulationResult) -> Criterion:
    margin = result.plan_zmp_margin
    measured = math.isfinite(margin)
    return Criterion("the plan keeps its ZMP inside the soles", margin, PLAN_ZMP_MARGIN, "m",
                     not measured or margin >= PLAN_ZMP_MARGIN,
                     "least margin (positive inside) of the pattern's cart-table ZMP to its support polygon, over "
                     "the whole pattern", "at least",
                     shown="" if measured else "not measured: the result carries no plan's margin")


def actuator_criterion(rows: list[ActuatorRow], fits: list[MotorFit]) -> Criterion:
    """The largest use of an actuator's limit: held torque over the model's limit, a motor's envelope and rating."""
    uses = [(r.peak_torque / r.torque_limit, f"{r.joint} held {r.peak_torque:.3g} of {r.torque_limit:.3g} N m")
            for r in rows if math.isfinite(r.torque_limit) and r.torque_limit > 0]
    for f in fits:
        uses.append((f.peak_use, f"{f.joint}: held peak on the torque-speed envelope of its motor {f.motor!r}"))
        uses.append((f.rms_use, f"{f.joint}: RMS torque on the rated torque of its motor {f.motor!r}"))
    rule = (f"largest |torque| held {IMPACT_WINDOW * 1e3:g} ms over its actuator's limit in the model"
            + (", and each motor's use of its torque-speed envelope and rated torque" if fits else
               "; speed not judged: the model gives no speed limit, a motor file (--motors) does"))
    if not uses:
        return Criterion("the joints stay within their actuators' limits", math.nan, ACTUATOR_LIMIT, "fraction",
                         True, rule, "at most",
                         shown="not measured: the model's actuators have no torque limit (a motor file, --motors, "
                         "gives limits)")
    worst = max(uses, key=lambda use: use[0])
    figure = worst[0]
    passed = figure <= ACTUATOR_LIMIT + SATURATION_TOL
    near = sorted((use for use in uses if use[0] >= ACTUATOR_WARNING), key=lambda use: -use[0])
    note = "; ".join(f"{text} ({share * 100:.0f} %{', saturated' if share >= ACTUATOR_LIMIT - SATURATION_TOL else ''})"
                     for share, text in near) or worst[1]
    return Criterion("the joints stay within their actuators' limits", figure, ACTUATOR_LIMIT, "fraction", passed,
                     rule + f"; amber from {ACTUATOR_WARNING * 100:g} % (100 %: saturated)", "at most",
                     warning=passed and figure >= ACTUATOR_WARNING, note=note)


def walk_warnings(rows: list[ActuatorRow], fits: list[MotorFit]) -> list[str]:
    """What the console prints as warnings of a walk, and the page shows: the joints whose plan (an ideal
    robot's inverse dynamics) needs more than the actuator gives, and the motors that do not fit."""
    warnings = []
    over = planned_over_limit(rows)
    if over:
        warnings.append("the plan itself needs more than the actuators give (ideal robot, inverse dynamics): "
                        + ", ".join(f"{r.joint} {r.planned_torque:.3g} of {r.torque_limit:.3g} N m" for r in over))
    warnings += [f"motor {f.motor!r} at {f.joint}: RMS {f.rms_use * 100:.0f} % of rated, held peak "
                 f"{f.peak_use * 100:.0f} % of the envelope: {f.verdict}" for f in fits if not f.fits]
    return warnings


def controller_words(balance: bool, controller: bool = False) -> str:
    """What ran in the simulation's loop, in words (the console's and the page's summary): ``controller``, the
    walking controller a robot's loop runs (walker, stabilizer, feedforward; commands given mid-walk)."""
    if balance and controller:
        return ("the walking controller, as a robot's loop runs it: the online walker (commands given mid-walk), "
                "the stabilizer (DCM, ankle, force and attitude loops) and the feedforward, at 1 kHz")
    if balance:
        return "the walking pattern with the stabilizer in the loop (DCM, ankle, force and attitude loops)"
    return "the walking pattern alone, open loop (--balance off: no stabilizer, as the papers walk it)"


def cop_margin_outside_touchdowns(result: SimulationResult) -> float:
    """Least CoP margin [m] over the samples not within :data:`TOUCHDOWN_WINDOW` after a sole touched the floor
    or became loaded.

    The robot is set on the floor at the first sample: a sole loaded there has just touched down too.
    """
    weight = result.robot.mass * result.robot.gravity
    forces = np.column_stack([result.force_left, result.force_right])
    touchdown = np.zeros(len(result.time), dtype=bool)
    window = max(1, round(TOUCHDOWN_WINDOW / max(float(np.median(np.diff(result.time))), 1e-6)))
    for fraction in (CONTACT_FRACTION, LOADED_FRACTION):
        over = forces > fraction * weight
        for foot in range(2):
            became = np.concatenate([[True], ~over[:-1, foot]])  # nothing touches before the first sample
            for start in np.flatnonzero(over[:, foot] & became):
                touchdown[start:start + window] = True
    judged = result.cop_margin[~touchdown]
    judged = judged[np.isfinite(judged)]
    return float(judged.min()) if len(judged) else math.nan
