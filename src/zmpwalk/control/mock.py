"""A plant without a simulator, for tests and dry runs: the joints read back as commanded, the soles carry what
the linear inverted pendulum of the walker's sample puts on them.

:class:`MockPlant` measures, for the last :class:`~zmpwalk.control.plant.JointTargets` applied:

* the joint encoders: the commanded angles (perfect servos);
* each sole's wrench: the pendulum's ground force ``m (c'' + g)``, with ``c'' = (g / l)(c - p)`` from the sample's
  CoM point ``c`` and ZMP ``p`` (the cart-table model, ``l`` the robot's pendulum length), on the stance sole in
  single support and split between the soles by where the ZMP lies between the ankles in double support, each
  share's centre of pressure keeping the total at the ZMP (as :func:`zmpwalk.sim.plant.static_feedforward` splits
  it); expressed about each ankle in its foot frame (feet flat, turned by their planned yaw);
* the torso upright and still (attitude and rate 0), its heading the pattern's.

Before the first :meth:`MockPlant.apply` it stands in the ready posture, its weight shared by the soles.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement
from zmpwalk.control.plant import JointTargets
from zmpwalk.errors import InvalidParameterError
from zmpwalk.online import OnlineWalker, WalkingSample
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]


class MockPlant:
    """A :class:`~zmpwalk.control.plant.Plant` that follows its targets exactly (see the module docstring).

    Args:
        robot: The robot (mass, pendulum length, ankle height).
        rate: Control rate [Hz]: :meth:`step` advances the clock by one period.

    Raises:
        InvalidParameterError: A rate that is not a positive finite number.
    """

    def __init__(self, robot: RobotModel, rate: float = 1000.0) -> None:
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (math.isfinite(rate) and rate > 0):
            raise InvalidParameterError("rate", rate, "a control rate > 0 Hz")
        self.robot = robot
        self.rate = float(rate)
        self._ticks = 0
        standing = OnlineWalker(robot, self.rate, joints=True).tick()  # the ready posture the walker starts in
        if standing.joint_angles is None:  # pragma: no cover - made with joints
            raise InvalidParameterError("joints", None, "the walker's joint angles")
        self._angles = standing.joint_angles
        self._sample: WalkingSample = standing
        self.applied = 0  # targets applied so far

    @property
    def time(self) -> float:
        """[s] of the next :meth:`measure`."""
        return self._ticks / self.rate

    def apply(self, targets: JointTargets) -> None:
        """Take the targets: their angles are read back, their sample gives the soles' load."""
        self._angles = np.array(targets.angles, dtype=np.float64)
        self._sample = targets.sample
        self.applied += 1

    def step(self) -> None:
        """One control period."""
        self._ticks += 1

    def measure(self) -> BalanceMeasurement:
        """The encoders as commanded, the pendulum's sole wrenches, an upright still torso."""
        left, right = sole_wrenches(self.robot, self._sample)
        return BalanceMeasurement(wrench_left=left, wrench_right=right, attitude=np.zeros(2), rate=np.zeros(3),
                                  joint_angles=self._angles.copy(), yaw=self._sample.yaw_pelvis_in_world)


def sole_wrenches(robot: RobotModel, sample: WalkingSample) -> tuple[Array, Array]:
    """The ground's wrench on each sole for the linear inverted pendulum of ``sample`` (module docstring): force
    [N] then torque [N m] about the ankle, in the foot frame, (6,) each; zero on a swinging sole."""
    gravity, mass = robot.gravity, robot.mass
    com, zmp = sample.position_pelvis_in_world, sample.zmp_in_world
    acceleration = gravity / robot.pendulum_length * (com[:2] - zmp)
    force = mass * np.array([acceleration[0], acceleration[1], gravity])
    ankles = (sample.position_left_ankle_in_world, sample.position_right_ankle_in_world)
    yaws = (sample.yaw_left_foot_in_world, sample.yaw_right_foot_in_world)
    if sample.support == "left":
        shares = (1.0, 0.0)
    elif sample.support == "right":
        shares = (0.0, 1.0)
    else:
        span = ankles[1][:2] - ankles[0][:2]
        ratio = float(np.clip((zmp - ankles[0][:2]) @ span / max(float(span @ span), 1e-12), 0.0, 1.0))
        shares = (1.0 - ratio, ratio)
    base_point = ankles[0][:2] + (ankles[1][:2] - ankles[0][:2]) * shares[1]
    wrenches = []
    for ankle, yaw, share in zip(ankles, yaws, shares, strict=True):
        if share == 0.0:
            wrenches.append(np.zeros(6))
            continue
        cop = np.array([*(ankle[:2] + zmp - base_point), ankle[2] - robot.ankle_height])  # on the sole [m]
        share_force = share * force
        torque = np.cross(cop - ankle, share_force)  # about the ankle, in world
        c, s = math.cos(yaw), math.sin(yaw)
        to_foot = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
        wrenches.append(np.concatenate([to_foot @ share_force, to_foot @ torque]))
    return wrenches[0], wrenches[1]
