"""The largest stride that fits: what a rejection of a step command names.

A command the legs cannot follow (or, with the hyperbolic pelvis, whose ZMP would leave the feet) is rejected
naming the stride field that is furthest beyond its limit, with the largest stride in the same direction that
fits from the same place, found by bisection on the stride's scale (:func:`infeasible_command`). A command
refused for its step time (or another parameter) whose stride fits at no step time is rejected for its stride
instead (:func:`step_time_rejection`): reach before step time.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import replace

from zmpwalk.commands import MAX_STRIDE, MAX_TURN, StepCommand
from zmpwalk.errors import (
    InfeasibleCommandError,
    InfeasiblePatternError,
    InvalidParameterError,
    UnreachableError,
    ZmpwalkError,
)
from zmpwalk.kinematics import JointLimitError

STRIDE_FIELDS = ("forward", "side", "turn")
STRIDE_BISECTIONS = 10  # halvings of the stride scale when looking for the largest that fits (0.1 %)
# the rejections that name the largest stride that fits: the legs, or (hyperbolic) the ZMP leaving the feet
STRIDE_CAUSES = (UnreachableError, JointLimitError, InfeasiblePatternError)
# [s] the step times at which a command rejected for its step time (or another parameter) is tried, to tell
# whether its stride fits at any: MIN_DURATION to MAX_DURATION of StepCommand, denser where robots walk
STEP_TIME_PROBES = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.95, 1.2, 1.6, 2.2, 3.0, 5.0)


def names_stride(error: ZmpwalkError) -> bool:
    """Whether ``error`` is about a command's stride: the legs or the ZMP (:data:`STRIDE_CAUSES`), or a stride
    field named (feet that would overlap, the largest stride that fits)."""
    return isinstance(error, STRIDE_CAUSES) or (
        isinstance(error, InvalidParameterError) and error.parameter in STRIDE_FIELDS)


def step_time_rejection(command: StepCommand, error: ZmpwalkError,
                        feasible: Callable[[StepCommand], object]) -> ZmpwalkError:
    """The rejection of ``command``, refused with ``error`` for its step time or another parameter than its
    stride: it names first the parameter that cannot be met at any setting of the others, reach before step time.

    When the stride fits at none of :data:`STEP_TIME_PROBES` (with the command's shape factors, and with the
    schedule's), no step time (or shape factor) would make it fit: the rejection names the stride, with the
    largest that fits (:func:`infeasible_command`, ``every_step_time``). Else (or for a command without a stride,
    or an error about the stride already) ``error`` itself. ``feasible`` raises
    :class:`~zmpwalk.errors.ZmpwalkError` for a command that does not fit from the same place.
    """
    if names_stride(error) or not any(getattr(command, name) for name in STRIDE_FIELDS):
        return error
    cause: ZmpwalkError | None = None
    for candidate in _step_time_probes(command):
        try:
            feasible(candidate)
        except ZmpwalkError as failure:
            if cause is None and names_stride(failure):
                cause = failure  # at the step time nearest the command's
            continue
        return error  # the stride fits at this step time: the step time (or the other parameter) is the fix
    if cause is None:  # no step time tried is for the stride: nothing to say of it
        return error
    return infeasible_command(command, cause, feasible, every_step_time=True)


def _step_time_probes(command: StepCommand) -> Iterator[StepCommand]:
    """``command`` at each of :data:`STEP_TIME_PROBES`, nearest its own step time first, with its shape factors
    and (where it overrides any) with the schedule's."""
    plain = StepCommand(command.duration, command.forward, command.side, command.turn)
    for duration in sorted(STEP_TIME_PROBES, key=lambda probe: abs(probe - command.duration)):
        for base in dict.fromkeys((command, plain)):
            try:
                yield replace(base, duration=duration)
            except InvalidParameterError:  # an override that does not fit this step time (dsp_time)
                continue


def infeasible_command(command: StepCommand, cause: ZmpwalkError, feasible: Callable[[StepCommand], object],
                       every_step_time: bool = False) -> InfeasibleCommandError:
    """The error for a command whose legs cannot follow it, with the largest stride that fits.

    The stride (``forward``, ``side``, ``turn`` together, so the direction is kept) is scaled by
    bisection on ``feasible``, which raises :class:`~zmpwalk.errors.ZmpwalkError` for a command
    that does not fit from the same place. ``every_step_time``: the stride fits at no step time (the
    command was refused first for its step time); where not even a step in place fits at the command's own
    step time, the largest stride is searched at the nearest of :data:`STEP_TIME_PROBES` where one does.
    """
    def fits(candidate: StepCommand, scale: float) -> bool:
        try:
            feasible(_scaled(candidate, scale))
        except ZmpwalkError:
            return False
        return True

    moving = [name for name in STRIDE_FIELDS if getattr(command, name) != 0.0]
    if not moving:
        lift = command.foot_lift if command.foot_lift is not None else "the schedule's"
        return InfeasibleCommandError("foot_lift", lift, {}, cause)
    # the field that is largest against its own limit names the error
    limits = {"forward": MAX_STRIDE, "side": MAX_STRIDE, "turn": MAX_TURN}
    name = max(moving, key=lambda n: abs(getattr(command, n)) / limits[n])
    base = command
    if every_step_time and not fits(command, 0.0):
        base = next((probe for probe in _step_time_probes(command) if fits(probe, 0.0)), command)
    step_time = base.duration if base is not command else None
    if not fits(base, 0.0):
        return InfeasibleCommandError(name, getattr(command, name), {}, cause, None, every_step_time)
    low, high = 0.0, 1.0
    for _ in range(STRIDE_BISECTIONS):
        middle = 0.5 * (low + high)
        if fits(base, middle):
            low = middle
        else:
            high = middle
    if low == 0.0:  # only the step in place fits: the stride's direction is not the cause
        return InfeasibleCommandError(name, getattr(command, name), {}, cause, None, every_step_time)
    largest = _scaled(base, low)
    return InfeasibleCommandError(name, getattr(command, name), {n: getattr(largest, n) for n in moving}, cause,
                                  step_time, every_step_time)


def largest_command(command: StepCommand, error: InfeasibleCommandError) -> StepCommand:
    """``command`` with the largest stride that fits of ``error`` (and its step time, where it names one)."""
    largest = error.largest
    return replace(command, duration=command.duration if error.step_time is None else error.step_time,
                   forward=largest.get("forward", 0.0), side=largest.get("side", 0.0), turn=largest.get("turn", 0.0))


def _scaled(command: StepCommand, scale: float) -> StepCommand:
    return replace(command, **{name: getattr(command, name) * scale for name in STRIDE_FIELDS})
