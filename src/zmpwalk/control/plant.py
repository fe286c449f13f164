"""What a :class:`~zmpwalk.control.controller.WalkingController` exchanges with the robot: :class:`JointTargets` out,
a :class:`~zmpwalk.balance.BalanceMeasurement` in, through a :class:`Plant`.

A plant is whatever carries out the targets and measures: a real robot's driver, the MuJoCo model
(:class:`zmpwalk.sim.loop.MujocoPlant`) or a mock (:class:`zmpwalk.control.mock.MockPlant`). The loop a robot
runs, one control period per pass::

    measurement = plant.measure()
    targets = controller.update(measurement)
    plant.apply(targets)
    plant.step()            # a simulator advances; a robot's driver waits for the next period
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement
from zmpwalk.sample import WalkingSample

Array = NDArray[np.float64]


@dataclass(slots=True)
class JointTargets:
    """The 12 leg joints' targets of one control tick, as low-level humanoid interfaces take them (q, dq, tau_ff).

    A servo that takes all three runs ``tau = kp (q - q_measured) + kv (dq - dq_measured) + tau_ff``; one that takes
    only angles gets :attr:`angles` (and sags by the torque it carries over its stiffness).

    Attributes:
        time: The tick's time [s] (the walker's clock, from the controller's start).
        angles: Joint angles [rad], (12,), in the walker's column order (:data:`zmpwalk.kinematics.JOINT_COLUMNS`:
            left hip yaw, roll, pitch, knee, ankle pitch, roll, then the right leg): the pattern's, corrected by
            the stabilizer.
        velocities: Joint rates [rad/s], (12,): the pattern's (the stabilizer's corrections are slow offsets).
        torques: Feedforward torques [N m], (12,): the planned motion's by inverse dynamics where the controller
            has a feedforward (:class:`zmpwalk.control.controller.Feedforward`), else None.
        sample: The walker's sample the targets come from (the pattern: pelvis, feet, ZMP, support).
        corrected: Whether the stabilizer corrected the angles this tick (False: balance off, or a fault, kept in
            :attr:`WalkingController.fault`).
    """

    time: float  # [s]
    angles: Array  # [rad] (12,)
    velocities: Array  # [rad/s] (12,)
    torques: Array | None  # [N m] (12,)
    sample: WalkingSample
    corrected: bool = True


class Plant(Protocol):
    """A robot (or a model of one) that a controller drives at its control rate.

    Attributes:
        time: The plant's clock [s]: the time of the next :meth:`measure`.
    """

    @property
    def time(self) -> float:
        """[s]."""
        ...

    def measure(self) -> BalanceMeasurement:
        """What the robot measures now: each sole's wrench, the torso's attitude and rate, the joint encoders."""
        ...

    def apply(self, targets: JointTargets) -> None:
        """Send the leg joints' targets to the servos (they act until the next :meth:`apply`)."""
        ...

    def step(self) -> None:
        """Advance by one control period (a simulator integrates; a robot's driver waits for the next period)."""
        ...
