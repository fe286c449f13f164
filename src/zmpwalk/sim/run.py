"""Walk a joint trajectory in MuJoCo and measure what a builder needs: does it walk, and which motors.

:func:`simulate` drives the joint servos of the generated model with a joint
trajectory (linearly interpolated to the 1 kHz servo rate, as HUBO's servo
controllers do between the main computer's references: :mod:`zmpwalk.sim.references`) and measures, at every
millisecond: the torso's position and attitude, the contact forces of each
sole and their centres of pressure (the paper's foot force sensors), the
joint angles, velocities and actuator torques, and the mechanical power.

**Fall criterion**: the torso touches the ground, or tilts more than
:data:`~zmpwalk.sim.measure.FALL_TILT` from upright, or its centre drops below
:data:`~zmpwalk.sim.measure.FALL_HEIGHT_FRACTION` of the pelvis height. The run stops
:data:`~zmpwalk.sim.measure.AFTER_FALL` seconds after a fall.

The measurements come from MuJoCo sensors, as on the robot: a force-torque
sensor at each ankle (the centre of pressure of a sole is computed from it,
as HUBO's foot sensors do, so it includes the small inertia of the foot; a
sole is counted as loaded, and its CoP measured, above
:data:`~zmpwalk.sim.contact.LOADED_FRACTION` of the weight), the actuator torques, the joint
encoders, the torso pose, the torso gyro. Open loop, the whole walk runs in C
with :func:`mujoco.rollout.rollout`.

**Plants and balance**: the plant is the robot's own MJCF or URDF where it has
one, else the box model of its robot file (:mod:`zmpwalk.sim.plant`). With a
:class:`~zmpwalk.balance.Stabilizer` the walk is stepped tick by tick (:mod:`zmpwalk.sim.closed_loop`) and the
stabilizer gets the sensor values only (with optional latency and noise); the
model-based feedforward of :mod:`zmpwalk.sim.plant` is on then, and for every
robot's own model (docs/balance.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np
from mujoco import rollout
from numpy.typing import NDArray

from zmpwalk.balance import Stabilizer
from zmpwalk.capture import CAPTURE_INTERVAL, CaptureSettings
from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JointTrajectory, check_sole_roll
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.closed_loop import closed_loop
from zmpwalk.sim.disturbances import NOSLIP_ITERATIONS, Disturbances, SensorNoise
from zmpwalk.sim.disturbances import _MeasurementReader as _MeasurementReader
from zmpwalk.sim.measure import AFTER_FALL, FALL_HEIGHT_FRACTION, FALL_TILT, measure_walk
from zmpwalk.sim.mjcf import contact_mapping
from zmpwalk.sim.plant import Plant, build_plant
from zmpwalk.sim.poses import set_initial_state
from zmpwalk.sim.ranges import check_range
from zmpwalk.sim.references import CONTROL_RATE, rows_at, servo_controls
from zmpwalk.sim.replan import CaptureReplanner
from zmpwalk.sim.result import SimulationResult, write_result_csv
from zmpwalk.sim.soles import SensorSlices

Array = NDArray[np.float64]

OWN_MODEL_SETTLE = 1.0  # [s] settle phase of a robot's own model where simulate is given none
OWN_MODEL_HOLD = 2.0  # [s] hold after the walk of a robot's own model where simulate is given none


def simulate(robot: RobotModel, joints: JointTrajectory, pattern: WalkingPattern, *, mass_scale: float = 1.0,
             settle: float | None = None, hold: float | None = None, feedforward: bool | None = None,
             stabilizer: Stabilizer | None = None, latency: float = 0.0, noise: SensorNoise | None = None,
             progress: Callable[[float], None] | None = None, disturbances: Disturbances | None = None,
             capture: CaptureSettings | None = None) -> SimulationResult:
    """Simulate ``joints`` (made from ``pattern``) on ``robot`` and measure the walk.

    Args:
        robot: A robot file with ``[bodies]``, ``[servos]``, ``[contact]``.
        joints: The 12 joint angles over time (:func:`zmpwalk.kinematics.pattern_joint_trajectory`).
        pattern: The pattern they come from: initial pose and reference ZMP.
        mass_scale: Multiply every mass and inertia, and the servo gains with them
            (:func:`zmpwalk.sim.mjcf.robot_mjcf`; box models only).
        settle: Time the first pose is held before the walk [s] (the robot settles onto its soles; default
            :data:`OWN_MODEL_SETTLE` for a robot's own model, 0 for the box models, which start at rest on their
            soles). Standing still, its reference ZMP is the CoM's ground point, not the walk's first ZMP.
        hold: Time the last pose is held after the walk [s] (does it end standing still?; default
            :data:`OWN_MODEL_HOLD` for a robot's own model, 0 for the box models).
        feedforward: Add the feedforwards of :func:`zmpwalk.sim.plant.static_feedforward` (gravity and the
            planned ground reaction) and :func:`zmpwalk.sim.plant.damping_feedforward` (servo damping) to
            the servo references (default: on for a robot's own model and whenever a stabilizer runs; off
            for the box models open loop, whose stiff servos the papers' results were measured with).
        stabilizer: Close the loop with this :class:`~zmpwalk.balance.Stabilizer` (the same code as on the
            robot, fed with the simulated sensors only); None walks open loop.
        latency: Delay of every measurement the stabilizer gets [s] (0 to 0.1).
        noise: Gaussian noise on the measurements (seeded; :class:`~zmpwalk.sim.disturbances.SensorNoise`).
        progress: Called with the fraction done [0, 1] now and then while a closed loop runs.
        disturbances: A push, a floor tilt or a mass error of the plant
            (:class:`~zmpwalk.sim.disturbances.Disturbances`); the pattern, the feedforward and the stabilizer keep
            the nominal robot.
        capture: With a stabilizer: once its DCM error passes ``capture.trigger`` in a single support, the
            rest of the walk is replaced by a capture step planned from its estimate
            (:func:`zmpwalk.capture.capture_step`; the joint references and the feedforward re-made for it),
            re-planned while its swing lasts whenever the error passes the trigger again (a push still acting),
            at most every :data:`~zmpwalk.capture.CAPTURE_INTERVAL`; the result's ``captures`` lists them,
            and the walk's end (final feet, the reference ZMP) is the last one's. None (default): the pattern is
            played to its end.

    Returns:
        The measurements. The same input gives the same result.

    Raises:
        InvalidParameterError: Mismatched inputs or a robot without simulation data.
        JointLimitError: A five-joint leg's sole would roll beyond its bound (``sole_roll`` set:
            :func:`zmpwalk.kinematics.check_sole_roll`; the walk needs an ankle roll the leg does not have).
    """
    settle, hold = _checked_inputs(robot, joints, pattern, mass_scale, settle, hold, latency, stabilizer, capture)
    plant = build_plant(robot, mass_scale)
    feedforward = (plant.imported or stabilizer is not None) if feedforward is None else feedforward
    data = mujoco.MjData(plant.model)
    weight = float(plant.model.body_subtreemass[1]) * robot.gravity
    time, pattern_time, zmp_ref = _walk_times(pattern, settle, hold)
    reference, control, planned_torques = servo_controls(plant, pattern, joints, pattern_time, zmp_ref, feedforward)
    state = _initial_state(robot, plant, data, pattern, joints, reference[0], mass_scale)
    replanner = (None if capture is None
                 else CaptureReplanner(robot, pattern, time, plant, feedforward, capture, planned_torques))
    if disturbances is not None:  # the world changes after the controller's model is made
        disturbances.apply(plant.model)
    readings, balance_log = _walk(plant, data, state, stabilizer, pattern, time, pattern_time, reference, control,
                                  zmp_ref, latency, noise, progress, disturbances, replanner)
    captures = [] if replanner is None else replanner.captures
    final = captures[-1][1] if captures else pattern  # after a capture step the walk ends as it planned
    return measure_walk(robot, SensorSlices(plant.model), readings, time, zmp_ref, weight, pattern, final, hold,
                        mass_scale=mass_scale, balance_log=balance_log, planned_torques=planned_torques,
                        captures=[plan for plan, _ in captures])


def _checked_inputs(robot: RobotModel, joints: JointTrajectory, pattern: WalkingPattern, mass_scale: float,
                    settle: float | None, hold: float | None, latency: float, stabilizer: Stabilizer | None,
                    capture: CaptureSettings | None) -> tuple[float, float]:
    """The settle and hold [s] of the walk (:func:`_settle_and_hold`), once every input of :func:`simulate` is
    checked (the raises of :func:`simulate`)."""
    if len(joints.time) != len(pattern.time) or len(pattern.time) < 2:
        raise InvalidParameterError("joints", len(joints.time), f"{len(pattern.time)} samples, as the pattern")
    check_range("mass_scale", mass_scale)
    settle, hold = _settle_and_hold(robot, settle, hold)
    check_range("latency", latency)
    if capture is not None and stabilizer is None:
        raise InvalidParameterError("capture", capture, "None without a stabilizer (its DCM estimate triggers it)")
    if capture is not None and pattern.position_com_in_world is not None:
        raise InvalidParameterError("capture", capture, "None for a multibody-corrected pattern (a capture step "
                                    "plans the pattern's CoM point)")
    if stabilizer is not None and stabilizer.com_reference != pattern.com_point:
        raise InvalidParameterError("stabilizer.com_reference", stabilizer.com_reference,
                                    f"{pattern.com_point}: the CoM point this pattern gives")
    check_sole_roll(joints.time, joints.angles, robot)  # a five-joint leg's sole roll within its bound
    return settle, hold


def _settle_and_hold(robot: RobotModel, settle: float | None, hold: float | None) -> tuple[float, float]:
    """The settle before and the hold after the walk [s]: those given, else :data:`OWN_MODEL_SETTLE` and
    :data:`OWN_MODEL_HOLD` for a robot's own model and 0 for the box models (which start at rest on their soles)."""
    imported = robot.own_model
    settle = (OWN_MODEL_SETTLE if imported else 0.0) if settle is None else settle
    hold = (OWN_MODEL_HOLD if imported else 0.0) if hold is None else hold
    return check_range("settle", settle), check_range("hold", hold)


def _walk_times(pattern: WalkingPattern, settle: float, hold: float) -> tuple[Array, Array, Array]:
    """The ticks of the walk [s] (n,), the pattern's time at each (n,) and the reference ZMP [m] (n, 2).

    References run at the control rate, linearly interpolated; the first pose held for ``settle`` before, the last
    for ``hold`` after. Times are those of the pattern (the settle phase runs at negative times).
    """
    settle_ticks = round(settle * CONTROL_RATE)
    time = np.arange(-settle_ticks, math.floor((pattern.time[-1] + hold) * CONTROL_RATE + 1e-9) + 1) / CONTROL_RATE
    pattern_time = np.clip(time, pattern.time[0], pattern.time[-1])
    zmp_ref = rows_at(pattern_time, pattern.time, pattern.zmp_in_world)
    # Standing still before the walk the ZMP is under the CoM (c'' = 0 in p = c - c'' l / g, Eqs. 1-2); the
    # pattern's first sample is already the walk's (a start stage that accelerates, the start transient of
    # Lim et al. whose ZMP jumps), which neither the feedforward nor the stabilizer may hold during the settle.
    zmp_ref[time < pattern.time[0]] = pattern.position_com_point_in_world[0, :2]
    return time, pattern_time, zmp_ref


def _initial_state(robot: RobotModel, plant: Plant, data: mujoco.MjData, pattern: WalkingPattern,
                   joints: JointTrajectory, angles: Array, mass_scale: float) -> Array:
    """Pose ``data`` at the walk's start (the planned base, the joint references ``angles``, a box model's soles
    at their static penetration) and return its full physics state."""
    if plant.imported:
        penetration = 0.0
    else:
        penetration = contact_mapping(RobotModel(**{**vars(robot), "mass": robot.link_mass * mass_scale})).penetration
    base_planned = (pattern.position_pelvis_in_world if joints.position_base_in_world is None
                    else joints.position_base_in_world)
    set_initial_state(plant, data, base_planned[0], float(pattern.yaw_pelvis_in_world[0]), angles, penetration)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(plant.model, spec))
    mujoco.mj_getState(plant.model, data, state, spec)
    return state


def _walk(plant: Plant, data: mujoco.MjData, state: Array, stabilizer: Stabilizer | None, pattern: WalkingPattern,
          time: Array, pattern_time: Array, reference: Array, control: Array, zmp_ref: Array, latency: float,
          noise: SensorNoise | None, progress: Callable[[float], None] | None, disturbances: Disturbances | None,
          replanner: CaptureReplanner | None) -> tuple[Array, dict[str, Array] | None]:
    """The sensor rows of the walk (n, nsensordata) and the stabilizer's log (None open loop): in one
    :func:`mujoco.rollout.rollout` from ``state`` where nothing acts within the walk (no stabilizer, no push), else
    tick by tick (:func:`~zmpwalk.sim.closed_loop.closed_loop`)."""
    model = plant.model
    steps_per_tick = max(1, round(1.0 / (CONTROL_RATE * float(model.opt.timestep))))
    if stabilizer is None and (disturbances is None or disturbances.push_time is None):
        _, readings = rollout.rollout(model, data, state[None], np.repeat(control, steps_per_tick, axis=0)[None])
        return readings[0, steps_per_tick - 1::steps_per_tick], None
    return closed_loop(model, data, plant, stabilizer, pattern, pattern_time, reference, control, zmp_ref,
                       steps_per_tick, SensorSlices(model), latency, noise, progress, disturbances, time,
                       None if replanner is None else (replanner.settings.trigger, replanner))


__all__ = [
    "AFTER_FALL",
    "CAPTURE_INTERVAL",
    "CONTROL_RATE",
    "FALL_HEIGHT_FRACTION",
    "FALL_TILT",
    "NOSLIP_ITERATIONS",
    "OWN_MODEL_HOLD",
    "OWN_MODEL_SETTLE",
    "Disturbances",
    "SensorNoise",
    "SimulationResult",
    "simulate",
    "write_result_csv",
]
