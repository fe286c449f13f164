"""The walking pattern at one control tick: what :class:`~zmpwalk.online.OnlineWalker` gives a control loop and
:class:`~zmpwalk.control.WalkingController` corrects."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


@dataclass(slots=True)  # not frozen: a frozen dataclass's __init__ costs 1 us more, a third of a tick
class WalkingSample:
    """The pattern at one control tick, in world (SI).

    A new object every tick, its arrays copies of the walker's row: changing it changes nothing in the walker.

    Attributes:
        time: [s].
        support: ``"double"``, ``"left"`` or ``"right"``.
        position_pelvis_in_world: Pelvis centre [m], shape (3,).
        yaw_pelvis_in_world: [rad].
        position_left_ankle_in_world, position_right_ankle_in_world: [m], shape (3,).
        yaw_left_foot_in_world, yaw_right_foot_in_world: [rad].
        zmp_in_world: Cart-table ZMP [m], shape (2,).
        joint_angles: The 12 leg joint angles [rad] in the order of
            :data:`zmpwalk.kinematics.JOINT_COLUMNS`, or None unless the walker was made with ``joints=True``.
        joint_velocities: Their rates [rad/s], or None.
    """

    time: float
    support: str
    position_pelvis_in_world: Array
    yaw_pelvis_in_world: float
    position_left_ankle_in_world: Array
    yaw_left_foot_in_world: float
    position_right_ankle_in_world: Array
    yaw_right_foot_in_world: float
    zmp_in_world: Array
    joint_angles: Array | None = None
    joint_velocities: Array | None = None
