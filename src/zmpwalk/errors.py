"""The exception family of zmpwalk.

Every error the library raises on bad input derives from :class:`ZmpwalkError`,
so a controller can catch one type. Each message names the parameter, the
value it got and what is allowed; an object that raised keeps its state.
"""

from __future__ import annotations

import math
from collections.abc import Iterable


class ZmpwalkError(Exception):
    """Base class of every error zmpwalk raises on purpose."""

    def in_context(self, context: str) -> ZmpwalkError:
        """Prefix the message with where the error arose (a file, a step); returns ``self``."""
        if self.args:
            self.args = (f"{context}: {self.args[0]}", *self.args[1:])
        return self


class InvalidParameterError(ZmpwalkError, ValueError):
    """A parameter is outside its allowed range or of the wrong kind.

    Attributes:
        parameter: Name of the parameter, as the user spelled it.
        value: The rejected value.
        allowed: Human-readable description of the allowed values.
    """

    def __init__(self, parameter: str, value: object, allowed: str, context: str = "") -> None:
        self.parameter = parameter
        self.value = value
        self.allowed = allowed
        where = f"{context}: " if context else ""
        super().__init__(f"{where}{parameter} = {_show(value)} is not allowed; expected {allowed}")


class InfeasibleCommandError(InvalidParameterError):
    """A step command the robot's legs cannot follow (reach or joint range), or whose pattern would need the ZMP
    outside the feet (hyperbolic generator), named by its stride.

    Attributes:
        parameter, value, allowed: As :class:`InvalidParameterError`; ``parameter`` is the command's
            largest stride field (``forward``, ``side`` or ``turn``), or ``foot_lift`` for a step in place.
        largest: The largest stride that fits in the same direction, as ``{field: value}`` (SI), or
            empty when no stride in that direction fits (the cause is then another field).
        cause: The reach, joint-range or ZMP error behind it.
    """

    def __init__(self, parameter: str, value: object, largest: dict[str, float], cause: ZmpwalkError) -> None:
        self.largest = largest
        self.cause = cause
        balance = isinstance(cause, InfeasiblePatternError)
        fitting = "that keeps the ZMP in the feet" if balance else "the legs can follow"
        if largest:
            units = {"turn": "rad"}
            fits = ", ".join(f"{name} = {amount:.3f} {units.get(name, 'm')}" for name, amount in largest.items())
            allowed = f"a stride {fitting} from here, at most {fits} ({cause})"
        else:
            allowed = (f"a step {fitting} from here; no stride in this direction fits, whatever its length "
                       f"({cause})")
        super().__init__(parameter, value, allowed)


class UnknownNameError(ZmpwalkError, KeyError):
    """A name (robot, scenario, generator) is not one of the known ones."""

    def __init__(self, kind: str, name: str, known: Iterable[str]) -> None:
        self.kind = kind
        self.name = name
        self.known = sorted(known)
        super().__init__(f"unknown {kind} {name!r}; known: {', '.join(self.known)}")

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


class UnreachableError(ZmpwalkError, ValueError):
    """A foot target lies beyond what the leg can reach.

    Attributes:
        leg: ``"left"`` or ``"right"``.
        time: Time of the pattern at which the target is out of reach [s].
        excess: How far the target is beyond the reach [m].
    """

    def __init__(self, leg: str, time: float, excess: float, detail: str = "") -> None:
        self.leg = leg
        self.time = time
        self.excess = excess
        self.sample = -1  # index of the first sample out of reach, where the caller knows it
        self.stage = -1  # index of the stage, where the caller knows it
        extra = f" ({detail})" if detail else ""
        super().__init__(
            f"{leg} ankle out of reach from t = {time:.3f} s, by up to {excess * 1e3:.1f} mm{extra}"
        )


class FileFormatError(ZmpwalkError, ValueError):
    """An input file (steps, robot, schedule) is malformed.

    The message names the file and, where it applies, the step and the field.
    """

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        super().__init__(f"{path}: {message}")


class InfeasiblePatternError(ZmpwalkError, ValueError):
    """A pattern's own feasibility condition does not hold (names the condition)."""


def _show(value: object) -> str:
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**20:
        return f"an integer of {len(str(abs(value)))} digits"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return f"{value:g}"
    return repr(value)
