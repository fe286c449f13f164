"""Leg kinematics: hip positions and the reach check (inverse kinematics comes with the leg model)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import UnreachableError
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]


def hip_positions_in_world(
    position_pelvis_in_world: Array, yaw_pelvis_in_world: Array, robot: RobotModel
) -> tuple[Array, Array]:
    """Left and right hip joint centres in world [m], each (n, 3)."""
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    half = robot.hip_spacing / 2
    offset_left = np.column_stack([-s * half, c * half, np.full_like(c, -robot.hip_drop)])
    offset_right = offset_left * np.array([-1.0, -1.0, 1.0])
    return position_pelvis_in_world + offset_left, position_pelvis_in_world + offset_right


def leg_reach_excess(
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    position_left_ankle_in_world: Array,
    position_right_ankle_in_world: Array,
    robot: RobotModel,
) -> tuple[Array, Array]:
    """Hip-to-ankle distance minus the leg's reach at its least knee bend [m], left and right, each (n,).

    Positive values are out of reach.
    """
    hip_left, hip_right = hip_positions_in_world(position_pelvis_in_world, yaw_pelvis_in_world, robot)
    reach = robot.max_leg_reach
    return (np.linalg.norm(position_left_ankle_in_world - hip_left, axis=1) - reach,
            np.linalg.norm(position_right_ankle_in_world - hip_right, axis=1) - reach)


def check_leg_reach(
    time: Array,
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    position_left_ankle_in_world: Array,
    position_right_ankle_in_world: Array,
    robot: RobotModel,
) -> None:
    """Raise if a hip-to-ankle distance exceeds the leg's reach at its least knee bend.

    Raises:
        UnreachableError: Names the leg, the first time it is out of reach and
            the largest excess [m]; ``error.sample`` is the first sample index.
    """
    excesses = leg_reach_excess(position_pelvis_in_world, yaw_pelvis_in_world, position_left_ankle_in_world,
                                position_right_ankle_in_world, robot)
    firsts = [int(np.argmax(e > 0)) if np.any(e > 0) else len(time) for e in excesses]
    if min(firsts) == len(time):
        return
    side = 0 if firsts[0] <= firsts[1] else 1
    first = firsts[side]
    excess = excesses[side]
    error = UnreachableError(
        ("left", "right")[side], float(time[first]), float(excess.max()),
        f"hip-to-ankle distance up to {float(excess.max()) + robot.max_leg_reach:.3f} m, "
        f"reach {robot.max_leg_reach:.3f} m",
    )
    error.sample = first
    raise error
