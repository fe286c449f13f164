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
from zmpwalk.online import OnlineWalker
from zmpwalk.robots.model import RobotModel
from zmpwalk.sample import WalkingSample

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
    [N] then torque [N m] about the ankle, in the foot frame, (6,) each; zero on a swinging sole.

    In Python floats: a few microseconds a tick, where numpy's calls on 3-vectors take about 50."""
    gravity, mass = robot.gravity, robot.mass
    com, zmp = sample.position_pelvis_in_world, sample.zmp_in_world
    zmp_x, zmp_y = float(zmp[0]), float(zmp[1])
    scale = gravity / robot.pendulum_length
    force = (mass * (scale * (float(com[0]) - zmp_x)), mass * (scale * (float(com[1]) - zmp_y)), mass * gravity)
    left, right = sample.position_left_ankle_in_world, sample.position_right_ankle_in_world
    ankles = ((float(left[0]), float(left[1]), float(left[2])), (float(right[0]), float(right[1]), float(right[2])))
    yaws = (sample.yaw_left_foot_in_world, sample.yaw_right_foot_in_world)
    span_x, span_y = ankles[1][0] - ankles[0][0], ankles[1][1] - ankles[0][1]
    if sample.support == "left":
        shares = (1.0, 0.0)
    elif sample.support == "right":
        shares = (0.0, 1.0)
    else:
        along = (zmp_x - ankles[0][0]) * span_x + (zmp_y - ankles[0][1]) * span_y
        ratio = min(max(along / max(span_x * span_x + span_y * span_y, 1e-12), 0.0), 1.0)
        shares = (1.0 - ratio, ratio)
    base_x, base_y = ankles[0][0] + span_x * shares[1], ankles[0][1] + span_y * shares[1]
    wrenches = []
    for yaw, share in zip(yaws, shares, strict=True):
        if share == 0.0:
            wrenches.append(np.zeros(6))
            continue
        # the centre of pressure on the sole, less the ankle [m], and this sole's share of the force [N]
        r_x, r_y, r_z = zmp_x - base_x, zmp_y - base_y, -robot.ankle_height
        f_x, f_y, f_z = share * force[0], share * force[1], share * force[2]
        t_x, t_y, t_z = r_y * f_z - r_z * f_y, r_z * f_x - r_x * f_z, r_x * f_y - r_y * f_x  # about the ankle
        c, s = math.cos(yaw), math.sin(yaw)  # world -> foot frame: turned by -yaw about z
        wrenches.append(np.array([c * f_x + s * f_y, c * f_y - s * f_x, f_z, c * t_x + s * t_y, c * t_y - s * t_x,
                                  t_z]))
    return wrenches[0], wrenches[1]
