"""Capture steps in the batch walk: the references re-made from the stabilizer's estimate after a push.

A :class:`CaptureReplanner` is the ``tail`` of :func:`zmpwalk.sim.closed_loop.closed_loop`: at a tick where the
stabilizer's DCM error passed the trigger in a single support it plans a capture step
(:func:`zmpwalk.capture.capture_step`) from the measured DCM, and gives the references of the rest of the walk
from the next tick on: what the stabilizer tracks, the ZMP, the joint references and the controls with their
feedforward (:mod:`zmpwalk.sim.references`). It keeps the capture steps taken, in order.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import Stabilizer
from zmpwalk.capture import CapturePlan, CaptureSettings, capture_step
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Side, Support
from zmpwalk.sim.plant import Plant
from zmpwalk.sim.references import CONTROL_RATE, rows_at, servo_controls, tracked_references

Array = NDArray[np.float64]


class CaptureReplanner:
    """Plans capture steps during a walk and re-makes its references (see the module docstring).

    Attributes:
        captures: The capture steps planned, in order: each one's figures and its pattern.
    """

    def __init__(self, robot: RobotModel, pattern: WalkingPattern, time: Array, plant: Plant, feedforward: bool,
                 settings: CaptureSettings, planned_torques: Array | None) -> None:
        """The replanner of ``pattern``'s walk on ``robot``, sampled at ``time`` [s] (n,) (the walk's ticks);
        ``planned_torques`` (n, 12) [N m], where the feedforward runs, is re-made with the references."""
        self.robot, self.pattern, self.time, self.plant = robot, pattern, time, plant
        self.feedforward, self.settings, self.planned_torques = feedforward, settings, planned_torques
        self.captures: list[tuple[CapturePlan, WalkingPattern]] = []

    def __call__(self, k: int, stabilizer: Stabilizer, stance_support: int) -> dict[str, NDArray[np.generic]]:
        """The references from tick ``k + 1`` on, re-made for a capture step planned from the stabilizer's
        estimate at tick ``k`` (its DCM error; the swinging foot's landing correction handed over), in the single
        support ``stance_support`` (1 left, 2 right)."""
        time = self.time
        source, touchdown = self.pattern, None
        if self.captures:  # a capture step under way is re-planned from its own plan, landing no later than needed
            source, touchdown = self.captures[-1][1], self.captures[-1][0].time + self.captures[-1][0].swing_time
        at = np.array([np.clip(time[k + 1], source.time[0], source.time[-1])])

        def sample(values: Array) -> Array:
            return np.asarray(rows_at(at, source.time, values)[0], dtype=np.float64)

        position_com, velocity_com = sample(source.position_pelvis_in_world), sample(source.velocity_pelvis_in_world)
        dcm = position_com[:2] + velocity_com[:2] / stabilizer.omega + stabilizer.state.dcm_error
        stance_side = Side.LEFT if stance_support == Support.LEFT else Side.RIGHT
        stance, swing = stance_side.label, stance_side.other.label
        ankles = [sample(a) for a in (source.position_left_ankle_in_world, source.position_right_ankle_in_world)]
        rates = [sample(v) for v in (source.velocity_left_ankle_in_world, source.velocity_right_ankle_in_world)]
        ankles[0 if swing == "left" else 1][:2] += stabilizer.landing_correction(swing)
        yaws = (float(np.interp(at[0], source.time, source.yaw_left_foot_in_world)),
                float(np.interp(at[0], source.time, source.yaw_right_foot_in_world)))
        tail, plan = capture_step(
            self.robot, time=float(time[k + 1]), rate=CONTROL_RATE, end=float(time[-1]), stance=stance,
            position_com_in_world=position_com, dcm_in_world=dcm,
            yaw_pelvis_in_world=float(np.interp(at[0], source.time, source.yaw_pelvis_in_world)),
            ankles_in_world=(ankles[0], ankles[1]), ankle_velocities_in_world=(rates[0], rates[1]), foot_yaws=yaws,
            settings=self.settings, touchdown=touchdown)
        stabilizer.hand_over_landing(swing)  # the capture's swing starts where the correction aimed it
        self.captures.append((plan, tail))
        return self._references(k, tail)

    def _references(self, k: int, tail: WalkingPattern) -> dict[str, NDArray[np.generic]]:
        """The references of the capture pattern ``tail`` from tick ``k + 1`` on (the planned torques re-made)."""
        tail_time = np.clip(self.time[k + 1:], tail.time[0], tail.time[-1])
        zmp = rows_at(tail_time, tail.time, tail.zmp_in_world)
        tail_reference, tail_control, torques = servo_controls(
            self.plant, tail, pattern_joint_trajectory(tail, check_limits=False), tail_time, zmp, self.feedforward)
        if self.planned_torques is not None and torques is not None:
            self.planned_torques[k + 1:] = torques
        return {**tracked_references(tail, tail_time), "zmp": zmp, "reference": tail_reference,
                "control": tail_control}
