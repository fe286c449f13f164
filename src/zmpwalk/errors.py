"""The exception family of zmpwalk.

Every error the library raises on bad input derives from :class:`ZmpwalkError`,
so a controller can catch one type. Each message names the parameter, the
value it got and what is allowed; an object that raised keeps its state.
"""

from __future__ import annotations

import math
from collections.abc import Iterable


class ZmpwalkError(Exception):
    """Base class of every error zmpwalk raises on purpose.

    Every error survives pickling with its message and its fields, so that one raised in a worker process
    (a ``multiprocessing`` pool, a Dask worker) reaches the caller as it was raised.
    """

    def __reduce__(self) -> tuple[object, ...]:
        # Exception's own reduce calls ``cls(*args)``, which fails for a subclass whose __init__ takes other
        # arguments than its message: rebuild from the message and the fields instead.
        return _rebuild, (type(self), self.args, dict(self.__dict__))

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

    The message states the largest stride that fits in the user's own directions (``0.403 m backward``,
    ``0.200 m to the right``, ``0.350 rad clockwise``), then as the fields to write (``forward = -0.403 m``).

    Attributes:
        parameter, value, allowed: As :class:`InvalidParameterError`; ``parameter`` is the command's
            largest stride field (``forward``, ``side`` or ``turn``), or ``foot_lift`` for a step in place (its value
            the command's, or "the schedule's" where the command does not set it).
        largest: The largest stride that fits in the same direction, as ``{field: value}`` (signed, SI), or
            empty when no stride in that direction fits (the cause is then another field).
        cause: The reach, joint-range or ZMP error behind it.
        step_time: The step time [s] at which ``largest`` fits, where it is not the command's (no stride in
            this direction fits at the command's own), else None.
        every_step_time: The command's stride fits at no step time (it was rejected first for its step time or
            another parameter, which would not have made it fit).
    """

    def __init__(self, parameter: str, value: object, largest: dict[str, float], cause: ZmpwalkError,
                 step_time: float | None = None, every_step_time: bool = False) -> None:
        self.largest = largest
        self.cause = cause
        self.step_time = step_time
        self.every_step_time = every_step_time
        balance = isinstance(cause, InfeasiblePatternError)
        fitting = "that keeps the ZMP in the feet" if balance else "the legs can follow"
        where = "from here at any step time" if every_step_time else "from here"
        if largest:
            at = f" at a step time of {step_time:.3f} s" if step_time is not None else ""
            allowed = f"a stride {fitting} {where}, at most {self.stride_text(largest)}{at}; {cause}"
        elif parameter == "foot_lift":  # a step in place: no stride to shorten
            allowed = f"a step in place {fitting} {where}: a lower foot lift or another step time; {cause}"
        else:
            allowed = f"a step {fitting} {where}; no stride in this direction fits, whatever its length; {cause}"
        super().__init__(parameter, value, allowed)

    @staticmethod
    def stride_text(stride: dict[str, float]) -> str:
        """A stride in the user's directions, then as fields: ``0.403 m backward (forward = -0.403 m)``."""
        # each field's unit and the words for its positive and negative directions (docs/frames-and-units.md)
        directions = {"forward": ("m", "forward", "backward"), "side": ("m", "to the left", "to the right"),
                      "turn": ("rad", "counter-clockwise", "clockwise")}
        words, fields = [], []
        for name, amount in stride.items():
            unit, positive, negative = directions[name]
            words.append(f"{abs(amount):.3f} {unit} {positive if amount >= 0 else negative}")
            fields.append(f"{name} = {amount:.3f} {unit}")
        spoken = words[0] if len(words) == 1 else f"{', '.join(words[:-1])} and {words[-1]}"
        return f"{spoken} ({', '.join(fields)})"

    def with_largest(self, largest: dict[str, float]) -> InfeasibleCommandError:
        """The same rejection naming another largest stride (the same step time)."""
        return InfeasibleCommandError(self.parameter, self.value, largest, self.cause, self.step_time,
                                      self.every_step_time)


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


class SimulationError(ZmpwalkError, RuntimeError):
    """The physics simulation diverged: MuJoCo found a non-finite or huge position, velocity or acceleration and
    reset its state, so what the run would measure after it is not the robot's.

    Attributes:
        time: The control tick at whose end MuJoCo had found it [s], on the run's clock.
        joint: The joint of the first position or degree of freedom MuJoCo found so (a non-finite value spreads to
            every degree of freedom within a step: the first is often the floating base's, not the cause).
        quantity: ``"position"``, ``"velocity"`` or ``"acceleration"``.
    """

    def __init__(self, time: float, joint: str, quantity: str, detail: str = "") -> None:
        self.time = time
        self.joint = joint
        self.quantity = quantity
        extra = f"; {detail}" if detail else ""
        super().__init__(f"the simulation diverged by t = {time:.3f} s: MuJoCo found a non-finite or huge {quantity}, "
                         f"first at joint {joint!r}{extra}")


class InfeasiblePatternError(ZmpwalkError, ValueError):
    """A pattern's own feasibility condition does not hold (names the condition)."""


def _rebuild(kind: type[ZmpwalkError], args: tuple[object, ...], fields: dict[str, object]) -> ZmpwalkError:
    """An error of ``kind`` with the message ``args`` and the attributes ``fields`` (the inverse of pickling)."""
    error = kind.__new__(kind)
    Exception.__init__(error, *args)
    error.__dict__.update(fields)
    return error


def _show(value: object) -> str:
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) >= 10**20:
        return f"an integer of {len(str(abs(value)))} digits"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        return f"{value:g}"
    return repr(value)
