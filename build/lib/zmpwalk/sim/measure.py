"""What a simulated walk measured: its sensor rows turned into a :class:`~zmpwalk.sim.result.SimulationResult`.

**Fall criterion**: the torso touches the ground, or tilts more than :data:`FALL_TILT` from upright, or its centre
drops below :data:`FALL_HEIGHT_FRACTION` of the pelvis height. The run is kept until :data:`AFTER_FALL` seconds
after a fall.

How the walk ends (standing, without a fall): the feet against their planned final places, and over the final
hold the least sole force, the base's largest speed and the torso's attitude spread.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from zmpwalk.capture import CapturePlan
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.references import CONTROL_RATE
from zmpwalk.sim.result import SimulationResult
from zmpwalk.sim.soles import SensorSlices, SoleMeasurements, foot_slip, rpy_from_quaternion, sole_measurements

Array = NDArray[np.float64]

FALL_TILT = 0.6  # [rad]
FALL_HEIGHT_FRACTION = 0.6  # [-] of the pelvis height
AFTER_FALL = 0.3  # [s] simulated after a fall


def measure_walk(robot: RobotModel, sensors: SensorSlices, readings: Array, time: Array, zmp_ref: Array,
                 weight: float, pattern: WalkingPattern, final: WalkingPattern, hold: float, *, mass_scale: float,
                 balance_log: dict[str, Array] | None, planned_torques: Array | None,
                 captures: list[CapturePlan]) -> SimulationResult:
    """The result of a walk from its sensor rows (one per tick at ``time`` [s]), cut :data:`AFTER_FALL` after a fall.

    Args:
        robot: The robot.
        sensors: The columns of the sensor rows.
        readings: The sensor rows, (n, nsensordata).
        time: [s], (n,).
        zmp_ref: The reference ZMP [m], (n, 2).
        weight: The plant's weight [N].
        pattern: The pattern walked (its ZMP margin and duration).
        final: The pattern whose end the walk ends at (after a capture step, the last one's).
        hold: The final hold [s] over which the end is judged.
        mass_scale: Multiplier of all masses.
        balance_log: The stabilizer's log, or None.
        planned_torques: The feedforward's planned leg torques [N m], (n, 12), or None.
        captures: The capture steps taken, in order.
    """
    pelvis = sensors.take(readings, "pelvis_pos")
    rpy = rpy_from_quaternion(sensors.take(readings, "pelvis_quat"))
    fall_index = _fall_index(robot, sensors, readings, pelvis, rpy)
    n = len(time)
    end = n if fall_index is None else min(n, fall_index + int(AFTER_FALL * CONTROL_RATE) + 1)
    planned_end = float(time[-1])
    readings, time, zmp_ref = readings[:end], time[:end], zmp_ref[:end]
    pelvis, rpy = pelvis[:end], rpy[:end]
    angles = sensors.columns(readings, [f"{c}_q" for c in JOINT_COLUMNS])
    velocities = sensors.columns(readings, [f"{c}_qd" for c in JOINT_COLUMNS])
    torque = sensors.columns(readings, [f"{c}_tau" for c in JOINT_COLUMNS])
    soles = sole_measurements(robot, sensors, readings, weight)
    distance = float(np.linalg.norm(pelvis[-1, :2] - pelvis[0, :2]))
    ending = (math.nan,) * 5 if fall_index is not None else _end_figures(sensors, readings, time, pelvis, rpy,
                                                                         soles, final, hold)
    return SimulationResult(
        robot=robot, time=time, torso_position=pelvis, torso_rpy=rpy,
        fell=fall_index is not None, fall_time=None if fall_index is None else float(time[fall_index]),
        distance=distance, average_speed=distance / float(pattern.time[-1]),
        foot_slip=foot_slip(soles.loaded, soles.ankles),
        cop_left=soles.cop_feet[:, 0], cop_right=soles.cop_feet[:, 1], cop=soles.cop, force_left=soles.forces[:, 0],
        force_right=soles.forces[:, 1], reference_zmp=zmp_ref, cop_margin=soles.margin, joint_angles=angles,
        joint_velocities=velocities, joint_torques=torque, joint_power=torque * velocities, mass_scale=mass_scale,
        final_feet_error=ending[0], final_feet_yaw_error=ending[1], end_min_sole_force=ending[2],
        end_max_speed=ending[3], end_attitude_range=ending[4],
        balance=None if balance_log is None else {k: v[:end] for k, v in balance_log.items()},
        ankle_positions=np.stack([sensors.take(readings, f"{label}_ankle_pos") for label in ("left", "right")], axis=1),
        planned_torques=None if planned_torques is None else planned_torques[:end],
        captures=captures, plan_zmp_margin=pattern.min_zmp_margin()[0], planned_end=planned_end,
    )


def _fall_index(robot: RobotModel, sensors: SensorSlices, readings: Array, pelvis: Array, rpy: Array) -> int | None:
    """The first row at which the robot has fallen (the module docstring's criterion), or None."""
    touch = (sensors.take(readings, "torso_touch")[:, 0] if "torso_touch" in sensors.slices
             else np.zeros(len(readings)))
    tilt = np.arccos(np.clip(np.cos(rpy[:, 0]) * np.cos(rpy[:, 1]), -1, 1))
    fallen = (touch > 0) | (tilt > FALL_TILT) | (pelvis[:, 2] < FALL_HEIGHT_FRACTION * robot.pelvis_height)
    return int(np.argmax(fallen)) if fallen.any() else None


def _end_figures(sensors: SensorSlices, readings: Array, time: Array, pelvis: Array, rpy: Array,
                 soles: SoleMeasurements, final: WalkingPattern,
                 hold: float) -> tuple[float, float, float, float, float]:
    """How the walk ends: the feet against ``final``'s last poses (largest distance [m] and yaw error [rad]), and
    over the last ``hold``: the least sole force [N], the base's largest speed [m/s] and the torso's attitude
    spread [rad]."""
    ankles = soles.ankles
    planned = (final.position_left_ankle_in_world[-1], final.position_right_ankle_in_world[-1])
    planned_yaw = (final.yaw_left_foot_in_world[-1], final.yaw_right_foot_in_world[-1])
    feet_error = max(float(np.linalg.norm(ankles[-1, f] - planned[f][:2])) for f in range(2))
    yaws = [rpy_from_quaternion(sensors.take(readings[-1:], f"{label}_ankle_quat"))[0, 2]
            for label in ("left", "right")]
    feet_yaw_error = max(abs(float((yaws[f] - planned_yaw[f] + math.pi) % (2 * math.pi) - math.pi))
                         for f in range(2))
    window = time > time[-1] - max(hold, 1.0 / CONTROL_RATE)
    end_force = float(soles.forces[window].min())
    speed = np.linalg.norm(np.gradient(pelvis[:, :2], time, axis=0), axis=1)
    end_speed = float(speed[window].max())
    end_attitude = float(np.ptp(rpy[window, :2], axis=0).max())
    return feet_error, feet_yaw_error, end_force, end_speed, end_attitude
