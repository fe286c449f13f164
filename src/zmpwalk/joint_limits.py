"""The joint columns of both legs and their ranges: the checks every joint trajectory goes through.

The 12 columns are the left leg then the right, each in the role order hip yaw, hip roll, hip pitch, knee, ankle
pitch, ankle roll (:data:`JOINT_COLUMNS`). An angle outside the robot's range is a :class:`JointLimitError`; a
five-joint leg's virtual ankle roll (:mod:`zmpwalk.leg_chain`) has the bound on the sole roll it may leave as its
range (:func:`zmpwalk.robots.collision.sole_roll_bound`), and leaving it is a :class:`JointLimitError` whose
``sole_roll`` is set and whose message names the missing ankle roll. :mod:`zmpwalk.kinematics` re-exports all of it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import ZmpwalkError
from zmpwalk.robots.model import JOINT_COLUMNS, JOINT_NAMES, RobotModel

Array = NDArray[np.float64]

LEG_JOINTS = JOINT_NAMES  # hip_yaw, hip_roll, hip_pitch, knee, ankle_pitch, ankle_roll


class JointLimitError(ZmpwalkError, ValueError):
    """A joint angle of a trajectory leaves the robot's joint range.

    Attributes:
        joint: Column name, e.g. ``"left_knee"``.
        angle: The angle [rad].
        time: When [s].
        limits: (lower, upper) [rad].
        sole_roll: Where ``joint`` is a five-joint leg's virtual ankle roll, the largest sole roll of the walk
            [rad] (the leg lacks an ankle roll: :func:`zmpwalk.robots.collision.sole_roll_bound`,
            :mod:`zmpwalk.robots.legs`); None for a joint of the model.
    """

    def __init__(self, joint: str, angle: float, time: float, limits: tuple[float, float],
                 sole_roll: float | None = None) -> None:
        self.joint, self.angle, self.time, self.limits = joint, angle, time, limits
        self.sole_roll = sole_roll
        if sole_roll is None:
            super().__init__(f"{joint} = {angle:.4f} rad at t = {time:.3f} s is outside its range "
                             f"[{limits[0]:.4f}, {limits[1]:.4f}] rad")
            return
        leg = joint.split("_", 1)[0]
        super().__init__(
            f"{joint}: the {leg} leg has 5 joints and no ankle roll, and the walk leaves its sole rolled up to "
            f"{sole_roll:.4f} rad (beyond [{limits[0]:.4f}, {limits[1]:.4f}] rad from t = {time:.3f} s, "
            f"{angle:+.4f} rad there; the bound keeps the rolled sole within 2 mm across its width, a sole). With "
            "five joints, a "
            "flat sole and an upright pelvis fix the hip roll, so the pelvis cannot sway over the stance sole as the "
            "pattern asks. What is missing: an ankle roll joint. A foot that rolls on its centre line (heel-to-toe "
            "capsules) may walk with its soles rolled, balanced sideways by its steps: give the robot file "
            f"(zmpwalk robot MODEL --write FILE) [walking] sole_roll_limit = {math.ceil(sole_roll * 100) / 100:g} "
            "and let zmpwalk simulate judge the walk")


_BOUNDS: dict[int, tuple[dict[str, tuple[float, float]], Array, Array]] = {}  # id(joint_limits) -> bounds


def joint_bounds(robot: RobotModel) -> tuple[Array, Array]:
    """Lower and upper ranges of the columns of :data:`JOINT_COLUMNS` [rad], each (12,) (made once per
    robot's table of limits: the online check reads them in every block of samples)."""
    limits = robot.joint_limits
    cached = _BOUNDS.get(id(limits))
    if cached is None or cached[0] is not limits:
        if len(_BOUNDS) > 64:
            _BOUNDS.clear()
        cached = (limits, np.array([robot.limits_of(column)[0] for column in JOINT_COLUMNS]),
                  np.array([robot.limits_of(column)[1] for column in JOINT_COLUMNS]))
        _BOUNDS[id(limits)] = cached
    return cached[1], cached[2]


def check_joint_limits(time: Array, angles: Array, robot: RobotModel) -> None:
    """Raise :class:`JointLimitError` for the first sample and joint outside the robot's ranges (with its
    ``sole_roll`` where that joint is a five-joint leg's virtual ankle roll)."""
    lower, upper = joint_bounds(robot)
    outside = (angles < lower) | (angles > upper)
    if np.any(outside):
        sample = int(np.argmax(outside.any(axis=1)))
        column = int(np.argmax(outside[sample]))
        limits = (float(lower[column]), float(upper[column]))
        sole_roll = float(np.abs(angles[:, column]).max()) if column in virtual_columns(robot) else None
        raise JointLimitError(JOINT_COLUMNS[column], float(angles[sample, column]), float(time[sample]), limits,
                              sole_roll)


def virtual_columns(robot: RobotModel) -> list[int]:
    """The joint columns of five-joint legs' virtual ankle rolls (:mod:`zmpwalk.leg_chain`): their angle is the
    sole roll the leg leaves; no motor turns them."""
    return [6 * index + chain.virtual_column for index, chain in enumerate(robot.legs or ())
            if chain.virtual_column is not None]


def check_sole_roll(time: Array, angles: Array, robot: RobotModel) -> None:
    """Raise :class:`JointLimitError` (``sole_roll`` set: the largest over the walk) where a five-joint leg's sole
    roll (its virtual column of ``angles``, (n, 12) [rad]) leaves its range, at the first sample outside; nothing for
    six-joint legs."""
    lower, upper = joint_bounds(robot)
    for column in virtual_columns(robot):
        roll = angles[:, column]
        outside = (roll < lower[column]) | (roll > upper[column])
        if np.any(outside):
            sample = int(np.argmax(outside))
            raise JointLimitError(JOINT_COLUMNS[column], float(roll[sample]), float(time[sample]),
                                  (float(lower[column]), float(upper[column])), float(np.abs(roll).max()))


__all__ = ["JOINT_COLUMNS", "LEG_JOINTS", "JointLimitError", "check_joint_limits", "check_sole_roll",
           "joint_bounds", "virtual_columns"]
