"""The ready posture fitted to a walk's strides.

An imported robot stands ready with its hips at the keyframe's hip-to-ankle distance, at most
:data:`~zmpwalk.robots.posture.READY_STRETCH` (0.92) of the straight leg. Its legs reach farther fore and aft
crouched lower (a flat foot ``x`` ahead of the hip at hip-to-ankle height ``h`` needs ``sqrt(h^2 + x^2)`` within the
leg's reach), and bend their ankles and knees less standing taller. A long stride on a short leg (ToddlerBot, OP3:
10 cm on legs of 0.20-0.22 m) leaves the reach from 0.92; a keyframe crouched deep for a narrow ankle range
(Berkeley Humanoid's ankle pitch stops at -0.524 rad) leaves that range. Where the robot's own posture refuses a
walk for its legs (out of reach, a joint out of range), :func:`fit_ready_posture` plans the walk again from the
stretches of :data:`STRETCHES`, nearest the robot's first, and walks from the first that plans it whole.

Only the legs' refusals start the search: a ZMP outside the soles, a step too fast for the foot speed limit or a
five-joint leg's sole roll are other parameters' (their errors name them), and a robot file that sets its posture
(``[posture] pelvis_height`` or ``ready_stretch``) keeps it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace

import numpy as np

from zmpwalk.errors import InfeasibleCommandError, UnreachableError, ZmpwalkError
from zmpwalk.joint_limits import JointLimitError, check_joint_limits
from zmpwalk.robots.model import RobotModel
from zmpwalk.walk import PlannedWalk, WalkSpec, checked_walk, planned_walk

STRETCHES = tuple(float(s) for s in np.round(np.arange(0.80, 0.961, 0.02), 2))  # [-] the stretches tried
SAME_STRETCH = 0.005  # [-] a stretch this close to the robot's own is not tried again


@dataclass(frozen=True)
class FittedWalk:
    """A walk planned from the ready posture that fits it.

    Attributes:
        spec: The walk, its robot standing at ``stretch`` (the spec given where the robot's own posture fits).
        planned: Its pattern and joints; None for a robot whose posture is not fitted (a box model, a robot file
            that sets it): not planned here.
        stretch: The ready posture's hip-to-ankle distance over the straight leg [-] it walks from, or None: the
            robot's own.
        own_stretch: The robot's own [-] (0 for a box model).
        refusal: Why the robot's own posture does not walk it (the planner's error), or empty.
    """

    spec: WalkSpec
    planned: PlannedWalk | None
    stretch: float | None = None  # [-]
    own_stretch: float = 0.0  # [-]
    refusal: str = ""

    def words(self) -> str:
        """One line for the user: the posture the walk starts from, and why; empty where it is the robot's own."""
        if self.stretch is None:
            return ""
        return (f"ready posture: hips {self.stretch:.2f} of the straight leg above the ankles (pelvis "
                f"{self.spec.robot.pelvis_height:.4f} m), not the robot's {self.own_stretch:.3f}, which refuses "
                f"this walk: {self.refusal}")

    @contextmanager
    def walking(self, say: bool = True) -> Iterator[None]:
        """Around the walk from :attr:`spec`: the posture fitted is printed first (``say``), and an error of the
        walk says it walked from it (nothing of either where the posture is the robot's own)."""
        if self.stretch is not None and say:
            print(self.words(), flush=True)  # before the walk, which may fail
        try:
            yield
        except ZmpwalkError as error:
            if self.stretch is None:
                raise
            raise error.in_context(f"walking from a ready posture of hips {self.stretch:.2f} of the straight leg "
                                   f"(the robot's {self.own_stretch:.3f} refuses this walk)") from None


def legs_refuse(error: ZmpwalkError) -> bool:
    """Whether ``error`` is the legs' refusal a ready posture can change: a leg out of reach or a joint of the model
    out of its range, raised as such or as the cause of an :class:`~zmpwalk.errors.InfeasibleCommandError`."""
    cause = error.cause if isinstance(error, InfeasibleCommandError) else error
    if isinstance(cause, JointLimitError):
        return cause.sole_roll is None
    return isinstance(cause, UnreachableError)


def stretches_to_try(own: float) -> list[float]:
    """:data:`STRETCHES` nearest ``own`` first (the taller of two as near), less those within :data:`SAME_STRETCH`."""
    return sorted((s for s in STRETCHES if abs(s - own) > SAME_STRETCH), key=lambda s: (abs(s - own), -s))


def fit_ready_posture(spec: WalkSpec, reload: Callable[[float], RobotModel]) -> FittedWalk:
    """Plan ``spec``; where the robot's own ready posture refuses it for its legs, plan it from the nearest
    stretch that walks it whole (see the module docstring).

    The own posture's plan is held to the joint ranges too (the walking controller's check refuses a command that
    leaves them, whatever ``spec.check_limits``); where no stretch does better, that plan is returned as it was
    (``check_limits`` off: the verdict, or the controller's refusal, names the joint).

    Args:
        spec: The walk.
        reload: The same robot standing at a stretch [-] (``load_robot(..., ready_stretch=stretch)``).

    Returns:
        The walk as planned, from the robot's posture or the one fitted; ``spec`` unplanned for a box model or a
        robot file that sets its posture.

    Raises:
        ZmpwalkError: The robot's own posture's refusal, where no stretch plans the walk (or the refusal is not
            the legs').
    """
    plant = spec.robot.plant
    if plant is None or plant.posture_set_by:
        return FittedWalk(spec, None)
    try:
        planned = checked_walk(spec)
    except ZmpwalkError as error:
        if not legs_refuse(error):
            raise
        fitted = walk_from_other_posture(spec, reload, error)
        if fitted is None:
            raise
        return fitted
    try:
        check_joint_limits(planned.joints.time, planned.joints.angles, spec.robot)
    except JointLimitError as error:
        if not legs_refuse(error):
            return FittedWalk(spec, planned)
        return walk_from_other_posture(spec, reload, error) or FittedWalk(spec, planned)
    return FittedWalk(spec, planned)


def fit_ready_posture_of(robot: str, spec: WalkSpec) -> FittedWalk:
    """:func:`fit_ready_posture` for a robot given as ``--robot`` takes it (a name, robot file or model path: a
    sweep's or an export's workers load it themselves), reloaded at each stretch tried."""
    from zmpwalk.robots import load_robot

    return fit_ready_posture(spec, lambda stretch: load_robot(robot, ready_stretch=stretch))


def walk_from_other_posture(spec: WalkSpec, reload: Callable[[float], RobotModel],
                            refusal: ZmpwalkError) -> FittedWalk | None:
    """``spec``'s walk planned from the first of :func:`stretches_to_try` that plans it with every joint in its range
    (``refusal``: the robot's own posture's, which the result quotes), or None."""
    own = spec.robot.plant.ready_stretch if spec.robot.plant is not None else 0.0
    for stretch in stretches_to_try(own):
        try:  # a leg may not reach that posture at all (FileFormatError), or the walk from it
            candidate = replace(spec, robot=reload(stretch))
            planned = planned_walk(replace(candidate, check_limits=True))
        except ZmpwalkError:
            continue
        return FittedWalk(candidate, planned, stretch, own, _first_line(refusal))
    return None


def _first_line(error: ZmpwalkError) -> str:
    """The refusal's first line (the message of a five-joint leg's, say, runs on)."""
    return str(error).splitlines()[0]
