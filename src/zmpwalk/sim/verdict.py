"""Does the simulated walk pass? Every criterion with its figure, its limit and pass or fail.

A walk passes when all of these hold (the limits are module constants, stated in docs/simulation.md):

1. **No fall** (the fall criterion of :mod:`zmpwalk.sim.run`).
2. **It ends standing still**, over the final hold of at least :data:`MIN_HOLD` after the last step:
   both soles loaded (the less loaded one carries at least :data:`LOADED_SHARE` of the weight), the base's
   horizontal speed at most :data:`STILL_SPEED`, the torso's roll and pitch settled (their spread at most
   :data:`SETTLED_ATTITUDE`).
3. **The feet end where the plan puts them**: each ankle within :data:`FEET_DISTANCE` and
   :data:`FEET_YAW` of its planned final pose.
4. **The CoP stays inside the loaded soles** (margin at least :data:`COP_MARGIN`) except at touchdown
   transients: the :data:`TOUCHDOWN_WINDOW` after a sole touches the floor (carries more than
   :data:`CONTACT_FRACTION` of the weight) or becomes loaded is not judged. (The other sole's force-torque
   reading swings with the impact before the landing sole counts as loaded: TALOS's carrying sole read a CoP
   30 mm outside itself at the first millisecond of the other's touchdown, at 101 N on the landing sole.)
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from zmpwalk.sim.run import LOADED_FRACTION, SimulationResult

MIN_HOLD = 2.0  # [s]
LOADED_SHARE = LOADED_FRACTION  # [-] of the weight on the less loaded sole
STILL_SPEED = 0.05  # [m/s]
SETTLED_ATTITUDE = 0.01  # [rad]
SETTLE = 0.5  # [s] standing before a judged walk (simulate, report, demo, sweep, tune)
HOLD = 2.0  # [s] standing after it: the verdict judges how the walk ends over this time
FEET_DISTANCE = 0.02  # [m]
FEET_YAW = math.radians(2.0)  # [rad]
COP_MARGIN = -0.005  # [m]: 5 mm of the sensors' CoP beyond an edge is the foot's own inertia at its limit
TOUCHDOWN_WINDOW = 0.05  # [s]
CONTACT_FRACTION = 0.01  # [-] of the weight: a sole carrying more touches the floor


@dataclass(frozen=True)
class Criterion:
    """One criterion of the verdict.

    Attributes:
        name: Short name (``"no fall"``, ``"feet where planned"``, ...).
        figure: The measured value (nan where it cannot be measured, e.g. after a fall).
        limit: The limit it is held to.
        unit: Unit of both.
        passed: Whether it holds.
        rule: How it is judged, in words.
    """

    name: str
    figure: float
    limit: float
    unit: str
    passed: bool
    rule: str


@dataclass(frozen=True)
class Verdict:
    """All criteria of one walk; :attr:`passed` only if every one passed."""

    criteria: tuple[Criterion, ...]

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.criteria)

    @property
    def failed(self) -> list[str]:
        """Names of the criteria that failed."""
        return [c.name for c in self.criteria if not c.passed]

    def as_dict(self) -> dict[str, object]:
        return {"passed": self.passed, "criteria": [asdict(c) for c in self.criteria]}

    def lines(self) -> list[str]:
        """One line per criterion: ``PASS|FAIL name: figure (limit)``."""
        return [f"{'PASS' if c.passed else 'FAIL'} {c.name}: {_show(c.figure, c.unit)} "
                f"(limit {_show(c.limit, c.unit)}; {c.rule})" for c in self.criteria]


def _show(value: float, unit: str) -> str:
    if not math.isfinite(value):
        return "not measured"
    if unit == "m":
        return f"{value * 1e3:.1f} mm"
    if unit == "rad":
        return f"{value:.4f} rad"
    return f"{value:.3g} {unit}".strip()


def walk_verdict(result: SimulationResult, hold: float) -> Verdict:
    """Judge a simulated walk (see the module docstring).

    Args:
        result: The simulation.
        hold: How long the last pose was held after the walk [s] (:func:`zmpwalk.sim.run.simulate`).
    """
    loaded_force = LOADED_SHARE * result.robot.mass * result.robot.gravity
    fell = result.fell
    enough = hold >= MIN_HOLD - 1e-9 and not fell
    end = float(result.time[-1]) if len(result.time) else math.nan
    criteria = [
        Criterion("no fall", result.fall_time if result.fall_time is not None else end, end, "s", not fell,
                  "time walked without the torso touching the ground, tilting over 0.6 rad or sinking below 60 % "
                  "of its height"),
        Criterion("both soles loaded at the end", result.end_min_sole_force if enough else math.nan,
                  loaded_force, "N", enough and result.end_min_sole_force >= loaded_force,
                  f"least normal force of either sole over the last {MIN_HOLD:g} s"),
        Criterion("standing still at the end", result.end_max_speed if enough else math.nan, STILL_SPEED, "m/s",
                  enough and result.end_max_speed <= STILL_SPEED,
                  f"largest horizontal speed of the base over the last {MIN_HOLD:g} s"),
        Criterion("torso settled at the end", result.end_attitude_range if enough else math.nan, SETTLED_ATTITUDE,
                  "rad", enough and result.end_attitude_range <= SETTLED_ATTITUDE,
                  f"spread of torso roll and pitch over the last {MIN_HOLD:g} s"),
        Criterion("feet where planned", result.final_feet_error, FEET_DISTANCE, "m",
                  not fell and result.final_feet_error <= FEET_DISTANCE,
                  "largest horizontal distance of a final ankle from its planned place"),
        Criterion("feet turned as planned", result.final_feet_yaw_error, FEET_YAW, "rad",
                  not fell and result.final_feet_yaw_error <= FEET_YAW, "largest yaw error of a final foot"),
    ]
    margin = cop_margin_outside_touchdowns(result)
    criteria.append(Criterion("CoP inside the loaded soles", margin, COP_MARGIN, "m",
                              not fell and margin >= COP_MARGIN,
                              f"least CoP margin, {TOUCHDOWN_WINDOW * 1e3:g} ms after each touchdown not judged"))
    return Verdict(tuple(criteria))


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
