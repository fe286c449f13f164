"""Step commands: what the operator asks of each step, checked on construction.

A :class:`StepCommand` asks for one step of the walk:

* ``forward`` [m]: how far the swinging foot lands ahead of the supporting foot
  (the paper's ``f``; negative walks backward). N steps of L then a closing
  step of 0 bring both feet N*L ahead.
* ``side`` [m] (positive = left) and ``turn`` [rad] (positive = counter-clockwise):
  such a step has the paper's two stages, each a swing of ``duration``: the
  open stance, in which the leading foot (the one on the side of the motion)
  swings out by ``side`` and yaws by ``turn``, and the recovery, in which the
  other foot follows (Eqs. 14-17 and 21-23). N such steps move both feet by
  N*side and rotate them by N*turn. Combined with ``forward`` they give curved
  walking.
* ``stop``: a closing step (the swinging foot lands beside the other one) after
  which the robot stands still in the ready posture.

Every shape factor and parameter can be overridden per step; ``None`` takes
the value from the parameter schedule (:mod:`zmpwalk.schedule`).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, fields

from zmpwalk.errors import InvalidParameterError

MAX_TURN = math.pi / 2  # [rad] largest turn of one step
MIN_DURATION = 0.1  # [s] shortest step time: no biped shifts its weight faster; 0.001 is seconds by mistake
MAX_DURATION = 5.0  # [s] longest step time: walking steps last about a second; 800 is milliseconds by mistake
MAX_RATIO = 0.9  # [-] up_ratio in [1 - MAX_RATIO, MAX_RATIO], staying ratios at most this: both phases take time
MAX_DSP_FRACTION = 0.5  # [-] double support at most this part of the step time: the rest is the swing
MAX_STRIDE = 2.0  # [m] largest |forward| and |side| before any robot's reach is checked: 20 is centimetres
REQUIRED = ("duration", "forward", "side", "turn")  # the fields that take no None


@dataclass(frozen=True)
class StepCommand:
    """One step of the walk. See the module docstring for the meaning of each field.

    Raises:
        InvalidParameterError: A field is not finite or outside its range.
    """

    duration: float  # [s] step time T of one swing, in [0.1, 5]
    forward: float = 0.0  # [m] stride f, swing foot ahead of the supporting foot
    side: float = 0.0  # [m] side step A, positive = left
    turn: float = 0.0  # [rad] turn theta, positive = counter-clockwise
    stop: bool = False  # closing step into the ready posture
    alpha: float | None = None  # [-] shape factor of the pelvis X velocity (Eq. 13)
    alpha1: float | None = None  # [-] multiplier of V_y (Eq. 20)
    beta1: float | None = None  # [-] multiplier of S_y (Eq. 20)
    d1: float | None = None  # [-] staying ratio of Eq. 18, in [0, 0.9] (the open stance of a side or turn step)
    d1_recovery: float | None = None  # [-] staying ratio of the recovery stage of a side or turn step, in [0, 0.9]
    up_ratio: float | None = None  # [-] u of Fig. 12, lift time / swing time, in [0.1, 0.9]
    sway: float | None = None  # [m] S_y of Eq. 20, >= 0
    lateral_velocity: float | None = None  # [m per unit 2*t_bar] V_y of Eq. 20, >= 0
    dsp_time: float | None = None  # [s] double-support time d of Eq. 11, in [0, duration / 2]
    foot_lift: float | None = None  # [m] swing apex height, in [0, 1] (and below the robot's hips)

    def __post_init__(self) -> None:
        for item in fields(self):
            value = getattr(self, item.name)
            if item.name == "stop":
                if not isinstance(value, bool):
                    raise InvalidParameterError("stop", value, "true or false")
                continue
            if value is None and item.name not in REQUIRED:
                continue
            # any real number, numpy's scalars included, stored as a float
            number = math.nan
            if isinstance(value, numbers.Real) and not isinstance(value, bool):
                try:
                    number = float(value)
                except OverflowError:
                    number = math.nan
            if not math.isfinite(number):
                raise InvalidParameterError(item.name, value, "a finite number")
            object.__setattr__(self, item.name, number)
        _check("duration", self.duration, MIN_DURATION, MAX_DURATION, unit="s (seconds)")
        _check("forward", self.forward, -MAX_STRIDE, MAX_STRIDE, unit="m (metres)")
        _check("side", self.side, -MAX_STRIDE, MAX_STRIDE, unit="m (metres)")
        _check("turn", self.turn, -MAX_TURN, MAX_TURN, unit="rad")
        if self.stop:
            for name in ("forward", "side", "turn"):
                if getattr(self, name) != 0:
                    raise InvalidParameterError(name, getattr(self, name), "0 in a stop step")
        if self.alpha is not None:
            _check("alpha", self.alpha, 0.0, 10.0)
        for name in ("alpha1", "beta1"):
            if getattr(self, name) is not None:
                _check(name, getattr(self, name), 0.0, 10.0)
        for name in ("d1", "d1_recovery"):
            if getattr(self, name) is not None:
                _check(name, getattr(self, name), 0.0, MAX_RATIO)
        if self.up_ratio is not None:
            _check("up_ratio", self.up_ratio, 1.0 - MAX_RATIO, MAX_RATIO)
        for name, unit in (("sway", "m"), ("lateral_velocity", "m"), ("foot_lift", "m")):
            if getattr(self, name) is not None:
                _check(name, getattr(self, name), 0.0, 1.0, unit=unit)
        if self.dsp_time is not None:
            _check("dsp_time", self.dsp_time, 0.0, MAX_DSP_FRACTION * self.duration, unit="s (half the step time)")

    @property
    def is_two_stage(self) -> bool:
        """True for side and turn steps (open stance then recovery)."""
        return self.side != 0.0 or self.turn != 0.0

    @property
    def leading_side(self) -> int:
        """+1 when the left foot leads (side or turn to the left), -1 for the right, 0 if neither."""
        if self.side != 0.0:
            return 1 if self.side > 0 else -1
        if self.turn != 0.0:
            return 1 if self.turn > 0 else -1
        return 0


def _check(
    name: str,
    value: float,
    low: float,
    high: float,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
) -> None:
    too_low = value <= low if low_open else value < low
    too_high = value >= high if high_open else value > high
    if too_low or too_high:
        left = "(" if low_open else "["
        right = ")" if high_open else "]"
        suffix = f" {unit}" if unit else ""
        raise InvalidParameterError(name, value, f"a value in {left}{low:g}, {high:g}{right}{suffix}")
