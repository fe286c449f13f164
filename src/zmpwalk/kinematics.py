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
        UnreachableError: Names the leg, the first time and the excess [m].
    """
    hip_left, hip_right = hip_positions_in_world(position_pelvis_in_world, yaw_pelvis_in_world, robot)
    reach = robot.max_leg_reach
    for leg, hip, ankle in (("left", hip_left, position_left_ankle_in_world),
                            ("right", hip_right, position_right_ankle_in_world)):
        excess = np.linalg.norm(ankle - hip, axis=1) - reach
        if np.any(excess > 0):
            worst = int(np.argmax(excess))
            raise UnreachableError(
                leg, float(time[worst]), float(excess[worst]),
                f"hip-to-ankle {float(excess[worst] + reach):.3f} m > reach {reach:.3f} m",
            )
