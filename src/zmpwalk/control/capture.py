"""Capture steps in the walking controller: a pushed walk becomes one capture step and a stop, tick by tick.

:class:`CapturePolicy` is what :class:`~zmpwalk.control.WalkingController` asks after each stabilizer tick: in a
single support, at least :data:`~zmpwalk.capture.CAPTURE_INTERVAL` after the last plan, with the
stabilizer's DCM error beyond :attr:`CaptureSettings.trigger`, it plans the rest of the walk as one capture step
and a stop (:func:`zmpwalk.capture.capture_step`, Eqs. of the capture point: the swinging foot lands where the
measured DCM can come to rest) from the tick's planned state and the measured DCM: ``xi = c + c' / omega +
dcm_error``, the swinging ankle aimed where the stabilizer's landing correction put it. The
:class:`CaptureMotion` (that pattern and its joint angles) then replaces the walker's samples from the next tick
on; a later trigger in the capture's own single support re-plans from it, landing no later than the capture under
way needs. The walker stands where the capture leaves the feet from the plan on
(:meth:`~zmpwalk.online.OnlineWalker.stand_at`); the capture's last pose blends into the walker's standing one
over :data:`BLEND` (the capture's pattern has not quite come to rest); a step given before the push or during the
capture is given to the walker after it and walks on from there. Where the walker's standing pose cannot reach
those feet, the controller holds the capture's last pose (:attr:`WalkingController.stranded`).

As the batch walk's (:class:`zmpwalk.sim.replan.CaptureReplanner`), the plan is made inside the tick that
triggers it (4-6 ms of CPU on a 2-core machine): a capture is not yet bounded work.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement, Stabilizer
from zmpwalk.capture import CAPTURE_INTERVAL, CapturePlan, CaptureSettings, capture_step, capture_wanted
from zmpwalk.footsteps import Pose2D, Stance
from zmpwalk.kinematics import JointTrajectory, pattern_joint_trajectory
from zmpwalk.online import WalkingSample
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import SUPPORT_LABELS

Array = NDArray[np.float64]

BLEND = 0.5  # [s] after a capture's pattern, its rest pose blends into the walker's standing pose over this
REST = 2.0  # [s] a capture pattern lasts at least this long (the batch walk's: to the end of its run)


def _mix(a: Array | None, b: Array | None, share: float) -> Array:
    """``(1 - share) a + share b``."""
    return np.asarray((1.0 - share) * np.asarray(a) + share * np.asarray(b), dtype=np.float64)

@dataclass(frozen=True)
class CaptureMotion:
    """A capture step's pattern and joint angles, played one sample per tick from ``first`` on.

    Attributes:
        plan: The capture's figures.
        pattern: The rest of the walk: the capture step and the stop.
        joints: Its joint angles and rates.
        first: The controller tick of its first sample.
        rate: Control rate [Hz].
    """

    plan: CapturePlan
    pattern: WalkingPattern
    joints: JointTrajectory
    first: int
    rate: float  # [Hz]

    def sample(self, tick: int, standing: WalkingSample | None) -> WalkingSample:
        """The sample of controller tick ``tick``: the pattern's; after its end, a linear blend over
        :data:`BLEND` from its last sample to the walker's ``standing`` one (its pose at rest over the same feet:
        the capture's pelvis point, :data:`REST` after the plan, is still 0.2 mm from its rest on HUBO, and the
        legs' angles differ by as much), or its last sample held where there is none (the walker cannot stand
        there)."""
        i = tick - self.first
        if i < len(self.pattern.time) or standing is None:
            return self._row(min(max(i, 0), len(self.pattern.time) - 1))
        share = min((i - len(self.pattern.time) + 1) / (BLEND * self.rate), 1.0)
        last = self._row(len(self.pattern.time) - 1)
        return WalkingSample(
            time=standing.time, support="double",
            position_pelvis_in_world=_mix(last.position_pelvis_in_world, standing.position_pelvis_in_world, share),
            yaw_pelvis_in_world=standing.yaw_pelvis_in_world,
            position_left_ankle_in_world=standing.position_left_ankle_in_world,
            yaw_left_foot_in_world=standing.yaw_left_foot_in_world,
            position_right_ankle_in_world=standing.position_right_ankle_in_world,
            yaw_right_foot_in_world=standing.yaw_right_foot_in_world,
            zmp_in_world=_mix(last.zmp_in_world, standing.zmp_in_world, share),
            joint_angles=_mix(last.joint_angles, standing.joint_angles, share),
            joint_velocities=(standing.joint_angles - last.joint_angles) / BLEND if share < 1.0  # type: ignore[operator]
            else np.zeros(12))

    def ended(self, tick: int) -> bool:
        """Whether the pattern has ended by controller tick ``tick`` (the robot at rest on both feet)."""
        return tick - self.first >= len(self.pattern.time) - 1

    def done(self, tick: int) -> bool:
        """Whether the pattern and the blend after it have ended by controller tick ``tick``."""
        return tick - self.first >= len(self.pattern.time) - 1 + BLEND * self.rate

    def _row(self, i: int) -> WalkingSample:
        """The pattern's sample ``i``."""
        p = self.pattern
        return WalkingSample(
            time=float(p.time[i]), support=SUPPORT_LABELS[int(p.support[i])],
            position_pelvis_in_world=p.position_pelvis_in_world[i].copy(),
            yaw_pelvis_in_world=float(p.yaw_pelvis_in_world[i]),
            position_left_ankle_in_world=p.position_left_ankle_in_world[i].copy(),
            yaw_left_foot_in_world=float(p.yaw_left_foot_in_world[i]),
            position_right_ankle_in_world=p.position_right_ankle_in_world[i].copy(),
            yaw_right_foot_in_world=float(p.yaw_right_foot_in_world[i]),
            zmp_in_world=p.zmp_in_world[i].copy(),
            joint_angles=self.joints.angles[i].copy(), joint_velocities=self.joints.velocities[i].copy())

    def stance(self) -> Stance:
        """Where the capture leaves the feet."""
        p = self.pattern
        left, right = p.position_left_ankle_in_world[-1], p.position_right_ankle_in_world[-1]
        return Stance(Pose2D(float(left[0]), float(left[1]), float(p.yaw_left_foot_in_world[-1])),
                      Pose2D(float(right[0]), float(right[1]), float(p.yaw_right_foot_in_world[-1])), 0)


class CapturePolicy:
    """When and how the controller takes a capture step (module docstring).

    Args:
        robot: The robot.
        rate: Control rate [Hz].
        settings: The trigger and the capture step's limits.

    Attributes:
        captures: The capture steps planned, in order.
    """

    def __init__(self, robot: RobotModel, rate: float, settings: CaptureSettings) -> None:
        self.robot, self.rate, self.settings = robot, float(rate), settings
        self.captures: list[CapturePlan] = []
        self._last = -math.inf  # [ticks] of the last plan

    def due(self, tick: int, sample: WalkingSample, stabilizer: Stabilizer, measurement: BalanceMeasurement) -> bool:
        """Whether a capture step is planned at ``tick`` (``sample``'s, after the stabilizer's update on
        ``measurement``): :func:`~zmpwalk.capture.capture_wanted` in a single support."""
        if sample.support == "double" or tick - self._last < CAPTURE_INTERVAL * self.rate:
            return False
        swing = measurement.wrench_right if sample.support == "left" else measurement.wrench_left
        return capture_wanted(stabilizer.state.dcm_error, self.settings.trigger, float(swing[2]),
                              stabilizer.load_threshold)

    def plan(self, tick: int, sample: WalkingSample, previous: WalkingSample, stabilizer: Stabilizer,
             under_way: CaptureMotion | None) -> CaptureMotion:
        """The capture step from tick ``tick + 1`` on, from ``sample`` (``previous``: the tick before it, for the
        planned velocities) and the stabilizer's estimate; ``under_way``: the capture being played, if any.

        Raises:
            UnreachableError, InfeasiblePatternError: No capture step fits (the caller walks on as planned).
        """
        self._last = tick  # a plan that fails is tried again only after the interval, as one that succeeds
        dt = 1.0 / self.rate
        stance, swing = sample.support, "right" if sample.support == "left" else "left"
        position = sample.position_pelvis_in_world
        velocity = (position - previous.position_pelvis_in_world) / dt
        ankles = [sample.position_left_ankle_in_world, sample.position_right_ankle_in_world]
        rates = [(a - b) / dt for a, b in zip(ankles, (previous.position_left_ankle_in_world,
                                                        previous.position_right_ankle_in_world), strict=True)]
        ankles = [a + r * dt for a, r in zip(ankles, rates, strict=True)]  # at the capture's first tick
        ankles[0 if swing == "left" else 1][:2] += stabilizer.landing_correction(swing)
        position_next = position + velocity * dt
        dcm = position_next[:2] + velocity[:2] / stabilizer.omega + stabilizer.state.dcm_error
        touchdown = None if under_way is None else under_way.plan.time + under_way.plan.swing_time
        start = sample.time + dt
        pattern, plan = capture_step(
            self.robot, time=start, rate=self.rate, end=start + REST, stance=stance,
            position_com_in_world=position_next, dcm_in_world=dcm, yaw_pelvis_in_world=sample.yaw_pelvis_in_world,
            ankles_in_world=(ankles[0], ankles[1]), ankle_velocities_in_world=(rates[0], rates[1]),
            foot_yaws=(sample.yaw_left_foot_in_world, sample.yaw_right_foot_in_world), settings=self.settings,
            touchdown=touchdown)
        joints = pattern_joint_trajectory(pattern, check_limits=False)  # may raise: before any side effect
        stabilizer.hand_over_landing(swing)  # the capture's swing starts where the correction aimed it
        self.captures.append(plan)
        return CaptureMotion(plan, pattern, joints, tick + 1, self.rate)
