"""Walk a joint trajectory in MuJoCo and measure what a builder needs: does it walk, and which motors.

:func:`simulate` drives the joint servos of the generated model with a joint
trajectory (linearly interpolated to the 1 kHz servo rate, as HUBO's servo
controllers do between the main computer's references) and measures, at every
millisecond: the torso's position and attitude, the contact forces of each
sole and their centres of pressure (the paper's foot force sensors), the
joint angles, velocities and actuator torques, and the mechanical power.

**Fall criterion**: the torso touches the ground, or tilts more than
:data:`FALL_TILT` from upright, or its centre drops below
:data:`FALL_HEIGHT_FRACTION` of the pelvis height. The run stops
:data:`AFTER_FALL` seconds after a fall.

The measurements come from MuJoCo sensors, as on the robot: a force-torque
sensor at each ankle (the centre of pressure of a sole is computed from it,
as HUBO's foot sensors do, so it includes the small inertia of the foot; a
sole is counted as loaded, and its CoP measured, above
:data:`LOADED_FRACTION` of the weight), the actuator torques, the joint
encoders, the torso pose, the torso gyro. Open loop, the whole walk runs in C
with :func:`mujoco.rollout.rollout`.

**Plants and balance**: the plant is the robot's own MJCF or URDF where it has
one, else the box model of its robot file (:mod:`zmpwalk.sim.plant`). With a
:class:`~zmpwalk.balance.Stabilizer` the walk is stepped tick by tick and the
stabilizer gets the sensor values only (with optional latency and noise); the
model-based feedforward of :mod:`zmpwalk.sim.plant` is on then, and for every
robot's own model (docs/balance.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
from mujoco import rollout
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement, Stabilizer
from zmpwalk.capture import CapturePlan, CaptureSettings, capture_step
from zmpwalk.errors import InfeasiblePatternError, InvalidParameterError, UnreachableError
from zmpwalk.files import atomic_output
from zmpwalk.kinematics import JOINT_COLUMNS, JointTrajectory, check_sole_roll, pattern_joint_trajectory
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.mjcf import contact_mapping
from zmpwalk.sim.plant import (
    Plant,
    build_plant,
    damping_feedforward,
    plant_qpos,
    servo_offsets,
    servo_torques,
    set_initial_state,
)
from zmpwalk.sim.soles import (
    SensorSlices,
    foot_slip,
    rotation_from_quaternion,
    rpy_from_quaternion,
    sole_measurements,
)

Array = NDArray[np.float64]

CONTROL_RATE = 1000.0  # [Hz] servo reference rate and measurement rate
FALL_TILT = 0.6  # [rad]
FALL_HEIGHT_FRACTION = 0.6  # [-] of the pelvis height
AFTER_FALL = 0.3  # [s] simulated after a fall
SETTLE = 1.0  # [s] default settle phase of a robot's own model
HOLD = 2.0  # [s] default hold after the walk of a robot's own model
CAPTURE_INTERVAL = 0.02  # [s] least time between two capture steps planned in one single support
NOSLIP_ITERATIONS = 5  # MuJoCo noslip iterations on a tilted floor (Disturbances.apply: no creep of loaded soles)


@dataclass
class SimulationResult:
    """Measurements of one simulated walk, in world (SI), one row per millisecond.

    Attributes:
        robot: The robot.
        time: [s], (n,).
        torso_position: Pelvis centre [m], (n, 3).
        torso_rpy: Torso roll, pitch, yaw [rad], (n, 3).
        fell: Whether it fell (see the module docstring for the criterion).
        fall_time: When [s], or None.
        distance: Horizontal distance of the pelvis from start to end [m].
        average_speed: ``distance`` over the walk's duration [m/s].
        foot_slip: Largest horizontal slide of a loaded sole [m].
        cop_left, cop_right, cop: Centres of pressure [m], (n, 2); NaN where the sole is unloaded.
        force_left, force_right: Normal force on each sole [N], (n,).
        reference_zmp: The pattern's ZMP [m], (n, 2).
        cop_margin: Signed distance of the CoP to the polygon of the loaded soles [m], (n,).
        joint_names: The 12 joint column names.
        joint_angles, joint_velocities, joint_torques, joint_power: (n, 12) [rad], [rad/s], [N m], [W].
        mass_scale: Multiplier of all masses.
        ankle_positions: Left and right ankle positions in world [m], (n, 2, 3).
        planned_torques: The leg joint torques the plan needs on an ideal robot (inverse dynamics of the
            planned motion with the planned ground reaction, what the feedforward sends) [N m], (n, 12); None
            where the feedforward did not run.
        balance: The stabilizer's log per sample (``zmp_desired``, ``com_offset``, ``ankle_offsets``,
            ``height_difference``, ``pelvis_turn``), or None open loop.
        final_feet_error: Largest horizontal distance of a simulated ankle from its planned final place [m]
            (nan after a fall).
        final_feet_yaw_error: Largest yaw error of a foot at the end [rad].
        end_min_sole_force: Smallest normal force on either sole over the final hold [N] (both loaded: > 0).
        end_max_speed: Largest horizontal speed of the base over the final hold [m/s].
        end_attitude_range: Largest spread of torso roll or pitch over the final hold [rad].
        captures: The capture steps taken (``simulate``'s ``capture``), in order; empty when the pattern was
            played to its end.
        plan_zmp_margin: The simulated pattern's least cart-table ZMP margin to its support polygon [m] (> 0
            inside; :meth:`WalkingPattern.min_zmp_margin`).
        planned_end: When the run was to end, the final hold included [s] (``time[-1]`` unless it fell).
    """

    robot: RobotModel
    time: Array
    torso_position: Array
    torso_rpy: Array
    fell: bool
    fall_time: float | None
    distance: float
    average_speed: float
    foot_slip: float
    cop_left: Array
    cop_right: Array
    cop: Array
    force_left: Array
    force_right: Array
    reference_zmp: Array
    cop_margin: Array
    joint_angles: Array
    joint_velocities: Array
    joint_torques: Array
    joint_power: Array
    mass_scale: float = 1.0
    joint_names: tuple[str, ...] = field(default=JOINT_COLUMNS)
    balance: dict[str, Array] | None = None
    ankle_positions: Array | None = None  # [m] (n, 2, 3)
    planned_torques: Array | None = None  # [N m] (n, 12)
    final_feet_error: float = math.nan  # [m]
    final_feet_yaw_error: float = math.nan  # [rad]
    end_min_sole_force: float = math.nan  # [N]
    end_max_speed: float = math.nan  # [m/s]
    end_attitude_range: float = math.nan  # [rad]
    captures: list[CapturePlan] = field(default_factory=list)
    plan_zmp_margin: float = math.nan  # [m]
    planned_end: float = math.nan  # [s]

    @property
    def cop_error(self) -> Array:
        """CoP minus the reference ZMP [m], (n, 2); NaN where no sole is loaded."""
        return self.cop - self.reference_zmp

    def cop_error_stats(self) -> tuple[float, float]:
        """RMS and largest length of the CoP error [m] over the loaded samples."""
        error = np.linalg.norm(self.cop_error, axis=1)
        error = error[np.isfinite(error)]
        if len(error) == 0:
            return math.nan, math.nan
        return float(np.sqrt(np.mean(error**2))), float(error.max())


def simulate(
    robot: RobotModel,
    joints: JointTrajectory,
    pattern: WalkingPattern,
    *,
    mass_scale: float = 1.0,
    settle: float | None = None,
    hold: float | None = None,
    feedforward: bool | None = None,
    stabilizer: Stabilizer | None = None,
    latency: float = 0.0,
    noise: SensorNoise | None = None,
    progress: Callable[[float], None] | None = None,
    disturbances: Disturbances | None = None,
    capture: CaptureSettings | None = None,
) -> SimulationResult:
    """Simulate ``joints`` (made from ``pattern``) on ``robot`` and measure the walk.

    Args:
        robot: A robot file with ``[bodies]``, ``[servos]``, ``[contact]``.
        joints: The 12 joint angles over time (:func:`zmpwalk.kinematics.pattern_joint_trajectory`).
        pattern: The pattern they come from: initial pose and reference ZMP.
        mass_scale: Multiply every mass and inertia, and the servo gains with them
            (:func:`zmpwalk.sim.mjcf.robot_mjcf`; box models only).
        settle: Time the first pose is held before the walk [s] (the robot settles onto its soles; default
            :data:`SETTLE` for a robot's own model, 0 for the box models, which start at rest on their soles).
            Standing still, its reference ZMP is the CoM's ground point, not the walk's first ZMP.
        hold: Time the last pose is held after the walk [s] (does it end standing still?; default :data:`HOLD`
            for a robot's own model, 0 for the box models).
        feedforward: Add the feedforwards of :func:`zmpwalk.sim.plant.static_feedforward` (gravity and the
            planned ground reaction) and :func:`zmpwalk.sim.plant.damping_feedforward` (servo damping) to
            the servo references (default: on for a robot's own model and whenever a stabilizer runs; off
            for the box models open loop, whose stiff servos the papers' results were measured with).
        stabilizer: Close the loop with this :class:`~zmpwalk.balance.Stabilizer` (the same code as on the
            robot, fed with the simulated sensors only); None walks open loop.
        latency: Delay of every measurement the stabilizer gets [s] (0 to 0.1).
        noise: Gaussian noise on the measurements (seeded; :class:`SensorNoise`).
        progress: Called with the fraction done [0, 1] now and then while a closed loop runs.
        disturbances: A push, a floor tilt or a mass error of the plant (:class:`Disturbances`); the pattern,
            the feedforward and the stabilizer keep the nominal robot.
        capture: With a stabilizer: once its DCM error passes ``capture.trigger`` in a single support, the
            rest of the walk is replaced by a capture step planned from its estimate
            (:func:`zmpwalk.capture.capture_step`; the joint references and the feedforward re-made for it),
            re-planned while its swing lasts whenever the error passes the trigger again (a push still acting),
            at most every :data:`CAPTURE_INTERVAL`; the result's ``captures`` lists them, and the walk's end (final
            feet, the reference ZMP) is the last one's. None (default): the pattern is played to its end.

    Returns:
        The measurements. The same input gives the same result.

    Raises:
        InvalidParameterError: Mismatched inputs or a robot without simulation data.
        JointLimitError: A five-joint leg's sole would roll beyond its bound (``sole_roll`` set:
            :func:`zmpwalk.kinematics.check_sole_roll`; the walk needs an ankle roll the leg does not have).
    """
    if len(joints.time) != len(pattern.time) or len(pattern.time) < 2:
        raise InvalidParameterError("joints", len(joints.time), f"{len(pattern.time)} samples, as the pattern")
    if not (0.01 <= mass_scale <= 100):
        raise InvalidParameterError("mass_scale", mass_scale, "a value in [0.01, 100]")
    imported = robot.plant is not None
    settle = (SETTLE if imported else 0.0) if settle is None else settle
    hold = (HOLD if imported else 0.0) if hold is None else hold
    if not 0.0 <= settle <= 10.0:
        raise InvalidParameterError("settle", settle, "a time in [0, 10] s")
    if not 0.0 <= hold <= 60.0:
        raise InvalidParameterError("hold", hold, "a time in [0, 60] s")
    if not 0.0 <= latency <= 0.1:
        raise InvalidParameterError("latency", latency, "a delay in [0, 0.1] s")
    if capture is not None and stabilizer is None:
        raise InvalidParameterError("capture", capture, "None without a stabilizer (its DCM estimate triggers it)")
    if capture is not None and pattern.position_com_in_world is not None:
        raise InvalidParameterError("capture", capture, "None for a multibody-corrected pattern (a capture step "
                                    "plans the pattern's CoM point)")
    if stabilizer is not None and stabilizer.com_reference != pattern.com_point:
        raise InvalidParameterError("stabilizer.com_reference", stabilizer.com_reference,
                                    f"{pattern.com_point}: the CoM point this pattern gives")
    check_sole_roll(joints.time, joints.angles, robot)  # a five-joint leg's sole roll within its bound
    plant = build_plant(robot, mass_scale)
    if feedforward is None:
        feedforward = plant.imported or stabilizer is not None
    model = plant.model
    data = mujoco.MjData(model)
    if plant.imported:
        penetration = 0.0
    else:
        penetration = contact_mapping(RobotModel(**{**vars(robot), "mass": robot.link_mass * mass_scale})).penetration
    weight = float(model.body_subtreemass[1]) * robot.gravity
    steps_per_tick = max(1, round(1.0 / (CONTROL_RATE * float(model.opt.timestep))))
    # References at the control rate, linearly interpolated; the first pose held for `settle` before, the last
    # for `hold` after. Times are those of the pattern (the settle phase runs at negative times).
    settle_ticks = round(settle * CONTROL_RATE)
    time = np.arange(-settle_ticks, math.floor((pattern.time[-1] + hold) * CONTROL_RATE + 1e-9) + 1) / CONTROL_RATE
    pattern_time = np.clip(time, pattern.time[0], pattern.time[-1])
    zmp_ref = _rows_at(pattern_time, pattern.time, pattern.zmp_in_world)
    # Standing still before the walk the ZMP is under the CoM (c'' = 0 in p = c - c'' l / g, Eqs. 1-2); the
    # pattern's first sample is already the walk's (a start stage that accelerates, the start transient of
    # Lim et al. whose ZMP jumps), which neither the feedforward nor the stabilizer may hold during the settle.
    zmp_ref[time < pattern.time[0]] = pattern.position_com_point_in_world[0, :2]
    reference, control, planned_torques = _controls(plant, pattern, joints, pattern_time, zmp_ref, feedforward)
    base_planned = (pattern.position_pelvis_in_world if joints.position_base_in_world is None
                    else joints.position_base_in_world)
    set_initial_state(plant, data, base_planned[0], float(pattern.yaw_pelvis_in_world[0]), reference[0], penetration)
    sensors = SensorSlices(model)
    n = len(time)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    captures: list[tuple[CapturePlan, WalkingPattern]] = []

    def capture_tail(k: int, stabilizer: Stabilizer, stance_support: int) -> dict[str, NDArray[np.generic]]:
        """The references from tick ``k + 1`` on, re-made for a capture step planned from the stabilizer's
        estimate at tick ``k`` (its DCM error; the swinging foot's landing correction handed over), in the single
        support ``stance_support`` (1 left, 2 right)."""
        source, touchdown = pattern, None
        if captures:  # a capture step under way is re-planned from its own plan, landing no later than needed
            source, touchdown = captures[-1][1], captures[-1][0].time + captures[-1][0].swing_time
        at = np.array([np.clip(time[k + 1], source.time[0], source.time[-1])])

        def sample(values: Array) -> Array:
            return np.asarray(_rows_at(at, source.time, values)[0], dtype=np.float64)

        position_com, velocity_com = sample(source.position_pelvis_in_world), sample(source.velocity_pelvis_in_world)
        dcm = position_com[:2] + velocity_com[:2] / stabilizer.omega + stabilizer.state.dcm_error
        stance = "left" if stance_support == 1 else "right"
        swing = "right" if stance == "left" else "left"
        ankles = [sample(a) for a in (source.position_left_ankle_in_world, source.position_right_ankle_in_world)]
        rates = [sample(v) for v in (source.velocity_left_ankle_in_world, source.velocity_right_ankle_in_world)]
        ankles[0 if swing == "left" else 1][:2] += stabilizer.landing_correction(swing)
        yaws = (float(np.interp(at[0], source.time, source.yaw_left_foot_in_world)),
                float(np.interp(at[0], source.time, source.yaw_right_foot_in_world)))
        tail, plan = capture_step(
            robot, time=float(time[k + 1]), rate=CONTROL_RATE, end=float(time[-1]), stance=stance,
            position_com_in_world=position_com, dcm_in_world=dcm,
            yaw_pelvis_in_world=float(np.interp(at[0], source.time, source.yaw_pelvis_in_world)),
            ankles_in_world=(ankles[0], ankles[1]), ankle_velocities_in_world=(rates[0], rates[1]), foot_yaws=yaws,
            settings=capture, touchdown=touchdown)
        stabilizer.hand_over_landing(swing)  # the capture's swing starts where the correction aimed it
        captures.append((plan, tail))
        tail_time = np.clip(time[k + 1:], tail.time[0], tail.time[-1])
        zmp = _rows_at(tail_time, tail.time, tail.zmp_in_world)
        tail_reference, tail_control, torques = _controls(
            plant, tail, pattern_joint_trajectory(tail, check_limits=False), tail_time, zmp, feedforward)
        if planned_torques is not None and torques is not None:
            planned_torques[k + 1:] = torques
        return {**_tracked(tail, tail_time), "zmp": zmp, "reference": tail_reference, "control": tail_control}

    if disturbances is not None:  # the world changes after the controller's model is made
        disturbances.apply(model)
    balance_log: dict[str, Array] | None = None
    if stabilizer is None and (disturbances is None or disturbances.push_time is None):
        _, readings = rollout.rollout(model, data, state[None], np.repeat(control, steps_per_tick, axis=0)[None])
        readings = readings[0, steps_per_tick - 1::steps_per_tick]
    else:
        readings, balance_log = _closed_loop(model, data, plant, stabilizer, pattern, pattern_time, reference,
                                             control, zmp_ref, steps_per_tick, sensors, latency, noise, progress,
                                             disturbances, time,
                                             None if capture is None else (capture.trigger, capture_tail))
    # --- measurements
    pelvis = sensors.take(readings, "pelvis_pos")
    rpy = rpy_from_quaternion(sensors.take(readings, "pelvis_quat"))
    touch = sensors.take(readings, "torso_touch")[:, 0] if "torso_touch" in sensors.slices else np.zeros(n)
    tilt = np.arccos(np.clip(np.cos(rpy[:, 0]) * np.cos(rpy[:, 1]), -1, 1))
    fallen = (touch > 0) | (tilt > FALL_TILT) | (pelvis[:, 2] < FALL_HEIGHT_FRACTION * robot.pelvis_height)
    fall_index = int(np.argmax(fallen)) if fallen.any() else None
    end = n if fall_index is None else min(n, fall_index + int(AFTER_FALL * CONTROL_RATE) + 1)
    planned_end = float(time[-1])
    readings, time, zmp_ref = readings[:end], time[:end], zmp_ref[:end]
    pelvis, rpy = pelvis[:end], rpy[:end]
    names_q = [f"{c}_q" for c in JOINT_COLUMNS]
    angles = sensors.columns(readings, names_q)
    velocities = sensors.columns(readings, [f"{c}_qd" for c in JOINT_COLUMNS])
    torque = sensors.columns(readings, [f"{c}_tau" for c in JOINT_COLUMNS])
    soles = sole_measurements(robot, sensors, readings, weight)
    forces, loaded, cop_feet, cop_total, margin, ankles = (soles.forces, soles.loaded, soles.cop_feet, soles.cop,
                                                           soles.margin, soles.ankles)
    slip = foot_slip(loaded, ankles)
    distance = float(np.linalg.norm(pelvis[-1, :2] - pelvis[0, :2]))
    # How the walk ends: the feet against the plan, and the last `hold` seconds (standing still?).
    feet_error = feet_yaw_error = math.nan
    end_force = end_speed = end_attitude = math.nan
    final = captures[-1][1] if captures else pattern  # after a capture step the walk ends as it planned
    if fall_index is None:
        planned = (final.position_left_ankle_in_world[-1], final.position_right_ankle_in_world[-1])
        planned_yaw = (final.yaw_left_foot_in_world[-1], final.yaw_right_foot_in_world[-1])
        feet_error = max(float(np.linalg.norm(ankles[-1, f] - planned[f][:2])) for f in range(2))
        yaws = [rpy_from_quaternion(sensors.take(readings[-1:], f"{label}_ankle_quat"))[0, 2]
                for label in ("left", "right")]
        feet_yaw_error = max(abs(float((yaws[f] - planned_yaw[f] + math.pi) % (2 * math.pi) - math.pi))
                             for f in range(2))
        window = time > time[-1] - max(hold, 1.0 / CONTROL_RATE)
        end_force = float(forces[window].min())
        speed = np.linalg.norm(np.gradient(pelvis[:, :2], time, axis=0), axis=1)
        end_speed = float(speed[window].max())
        end_attitude = float(np.ptp(rpy[window, :2], axis=0).max())
    return SimulationResult(
        robot=robot, time=time, torso_position=pelvis, torso_rpy=rpy,
        fell=fall_index is not None, fall_time=None if fall_index is None else float(time[fall_index]),
        distance=distance, average_speed=distance / float(pattern.time[-1]), foot_slip=slip,
        cop_left=cop_feet[:, 0], cop_right=cop_feet[:, 1], cop=cop_total, force_left=forces[:, 0],
        force_right=forces[:, 1], reference_zmp=zmp_ref, cop_margin=margin, joint_angles=angles,
        joint_velocities=velocities, joint_torques=torque, joint_power=torque * velocities, mass_scale=mass_scale,
        final_feet_error=feet_error, final_feet_yaw_error=feet_yaw_error, end_min_sole_force=end_force,
        end_max_speed=end_speed, end_attitude_range=end_attitude,
        balance=None if balance_log is None else {k: v[:end] for k, v in balance_log.items()},
        ankle_positions=np.stack([sensors.take(readings, f"{label}_ankle_pos") for label in ("left", "right")], axis=1),
        planned_torques=None if planned_torques is None else planned_torques[:end],
        captures=[plan for plan, _ in captures], plan_zmp_margin=pattern.min_zmp_margin()[0],
        planned_end=planned_end,
    )


@dataclass(frozen=True)
class Disturbances:
    """What the world does to the robot that the plan does not know.

    Attributes:
        push_time: When a push on the torso (base) starts [s], or None.
        push_impulse: Its impulse in world [N s], (x, y, z); applied as a constant force over ``push_duration``.
        push_duration: [s].
        floor_tilt: Roll and pitch of the floor [rad] (the floor's rotation ``Rx(roll) Ry(pitch)`` from level:
            pitch > 0 runs downhill ahead, roll > 0 raises the left side);
            simulated by turning gravity in the floor's frame; the IMU reads attitude against gravity.
        mass_error: The plant's masses and inertias are ``1 + mass_error`` times the model's [-].
    """

    push_time: float | None = None  # [s]
    push_impulse: tuple[float, float, float] = (0.0, 0.0, 0.0)  # [N s]
    push_duration: float = 0.1  # [s]
    floor_tilt: tuple[float, float] = (0.0, 0.0)  # [rad]
    mass_error: float = 0.0  # [-]

    def __post_init__(self) -> None:
        if not -0.5 < self.mass_error < 1.0:
            raise InvalidParameterError("mass_error", self.mass_error, "a fraction in (-0.5, 1)")
        if len(self.floor_tilt) != 2 or max(abs(a) for a in self.floor_tilt) > 0.3:
            raise InvalidParameterError("floor_tilt", self.floor_tilt, "(roll, pitch) within 0.3 rad")
        if not 0.001 <= self.push_duration <= 1.0:
            raise InvalidParameterError("push_duration", self.push_duration, "a time in [0.001, 1] s")
        if len(self.push_impulse) != 3 or not all(math.isfinite(v) and abs(v) <= 1000.0 for v in self.push_impulse):
            raise InvalidParameterError("push_impulse", self.push_impulse, "three components within 1000 N s")

    @property
    def floor_rotation(self) -> Array:
        """The floor's rotation from level, ``Rx(roll) Ry(pitch)``."""
        roll, pitch = self.floor_tilt
        cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
        rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
        ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
        return np.asarray(rx @ ry, dtype=np.float64)

    def apply(self, model: mujoco.MjModel) -> None:
        """Tilt gravity and scale the masses of ``model`` (in place; MuJoCo's derived constants recomputed).

        On a tilted floor gravity pulls along the floor at every loaded sole, all the time. MuJoCo's soft
        contacts let a sole creep under such a lasting tangential force although it is far inside the
        friction cone (TALOS on 2 degrees of pitch: its stance ankle moved 2.3-3.9 mm while loaded, against
        0.1-1.2 mm on a level floor, and the leg odometry, which cannot see it, was 22 mm off after ten
        steps); a real sole does not. The noslip solver (:data:`NOSLIP_ITERATIONS`) removes that creep, so it
        runs on a tilted floor (on TALOS it costs two thirds more time per step; on a level floor, where no
        lasting tangential force acts, the odometry lost 0.3 mm over a whole walk's single supports).
        """
        gravity = float(np.linalg.norm(model.opt.gravity))
        model.opt.gravity[:] = self.floor_rotation.T @ np.array([0.0, 0.0, -gravity])
        if any(self.floor_tilt):
            model.opt.noslip_iterations = NOSLIP_ITERATIONS
        model.body_mass[:] *= 1.0 + self.mass_error
        model.body_inertia[:] *= 1.0 + self.mass_error
        mujoco.mj_setConst(model, mujoco.MjData(model))  # scratch data: mj_setConst works at qpos0

    def force_at(self, time: float) -> Array:
        """The push's force at ``time`` [N], (3,)."""
        if self.push_time is None or not self.push_time <= time < self.push_time + self.push_duration:
            return np.zeros(3)
        return np.asarray(self.push_impulse, dtype=float) / self.push_duration


@dataclass(frozen=True)
class SensorNoise:
    """Standard deviations of Gaussian noise added to the stabilizer's measurements (seeded).

    Attributes:
        force: On each force component [N].
        torque: On each torque component [N m].
        attitude: On roll and pitch [rad].
        rate: On each gyro axis [rad/s].
        encoder: On each joint angle [rad].
        seed: Of ``numpy.random.default_rng``.
    """

    force: float = 5.0  # [N]
    torque: float = 0.5  # [N m]
    attitude: float = 0.002  # [rad]
    rate: float = 0.01  # [rad/s]
    encoder: float = 0.0005  # [rad]
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("force", "torque", "attitude", "rate", "encoder"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise InvalidParameterError(f"noise.{name}", value, "a standard deviation >= 0")


class _MeasurementReader:
    """The stabilizer's inputs from one row of sensor data (:meth:`read`), with the sensors' columns found once.

    The ground's wrench on each foot is the opposite of what the ankle sensor between foot and leg reads
    (both in the foot frame); the IMU's attitude is relative to gravity (on a tilted floor, ``floor`` is the
    floor's rotation from level).
    """

    def __init__(self, sensors: SensorSlices, floor: Array | None = None) -> None:
        def columns(*names: str) -> NDArray[np.intp]:
            return np.concatenate([np.arange(sensors.slices[n].start, sensors.slices[n].stop) for n in names])

        self._left = columns("left_force", "left_torque")
        self._right = columns("right_force", "right_torque")
        self._quaternion = sensors.slices["pelvis_quat"]
        self._gyro = sensors.slices["pelvis_gyro"]
        self._joints = columns(*(f"{c}_q" for c in JOINT_COLUMNS))
        self._floor = None if floor is None or np.allclose(floor, np.eye(3)) else floor

    def read(self, row: Array) -> BalanceMeasurement:
        """The measurement of one row of ``sensordata``."""
        w, x, y, z = row[self._quaternion].tolist()
        if self._floor is None:
            roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
            pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
            yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        else:
            level = self._floor @ rotation_from_quaternion(row[None, self._quaternion])[0]
            roll, pitch = math.atan2(level[2, 1], level[2, 2]), math.asin(max(-1.0, min(1.0, -level[2, 0])))
            yaw = math.atan2(level[1, 0], level[0, 0])
        return BalanceMeasurement(wrench_left=-row[self._left], wrench_right=-row[self._right],
                                  attitude=np.array([roll, pitch]), rate=row[self._gyro].copy(), yaw=yaw,
                                  joint_angles=row[self._joints])


def _rows_at(times: Array, pattern_times: Array, values: Array) -> Array:
    """Each column of ``values`` (m, k) linearly interpolated at ``times`` (n,): (n, k)."""
    return np.column_stack([np.interp(times, pattern_times, values[:, i]) for i in range(values.shape[1])])


def _tracked(pattern: WalkingPattern, times: Array) -> dict[str, NDArray[np.generic]]:
    """What the stabilizer tracks of ``pattern`` at ``times`` (n,): its CoM point ``com`` (n, 3), pelvis ``yaw``,
    ankles ``left`` and ``right`` (n, 3), foot yaws ``left_yaw`` and ``right_yaw``, and the ``support`` code (a
    time at a phase change has the phase that begins)."""
    return {"com": _rows_at(times, pattern.time, pattern.position_com_point_in_world),
            "yaw": np.interp(times, pattern.time, pattern.yaw_pelvis_in_world),
            "left": _rows_at(times, pattern.time, pattern.position_left_ankle_in_world),
            "right": _rows_at(times, pattern.time, pattern.position_right_ankle_in_world),
            "left_yaw": np.interp(times, pattern.time, pattern.yaw_left_foot_in_world),
            "right_yaw": np.interp(times, pattern.time, pattern.yaw_right_foot_in_world),
            "support": pattern.support[np.clip(np.searchsorted(pattern.time, times - 1e-9), 0,
                                               len(pattern.time) - 1)]}


def _controls(plant: Plant, pattern: WalkingPattern, joints: JointTrajectory, pattern_time: Array, zmp_ref: Array,
              feedforward: bool) -> tuple[Array, Array, Array | None]:
    """The leg joint references (n, 12) at ``pattern_time`` (n,), the controls (n, nu) with the feedforwards of
    the planned motion where ``feedforward`` (gravity, ground reaction and servo damping, docs/balance.md), and
    the planned leg torques (n, 12) [N m] or None."""
    reference = _rows_at(pattern_time, joints.time, joints.angles)
    control = np.repeat(plant.ctrl_hold[None, :], len(pattern_time), axis=0)
    control[:, plant.leg_actuators] = reference
    if not feedforward:
        return reference, control, None
    base_planned = (pattern.position_pelvis_in_world if joints.position_base_in_world is None
                    else joints.position_base_in_world)
    base_path = _rows_at(pattern_time, pattern.time, base_planned)
    yaw_path = np.interp(pattern_time, pattern.time, pattern.yaw_pelvis_in_world)
    planned_ankles = [_rows_at(pattern_time, pattern.time, a)
                      for a in (pattern.position_left_ankle_in_world, pattern.position_right_ankle_in_world)]
    qpos_path = plant_qpos(plant, base_path, yaw_path, reference)
    rates = _rows_at(pattern_time, joints.time, joints.velocities)
    control[:, plant.leg_actuators] += damping_feedforward(plant, rates)
    index = np.clip(np.searchsorted(pattern.time, pattern_time), 0, len(pattern.time) - 1)
    needed = servo_torques(plant, qpos_path, zmp_ref, pattern.support[index], (planned_ankles[0], planned_ankles[1]))
    control += servo_offsets(plant, needed)
    return reference, control, needed[:, plant.leg_actuators]


def _closed_loop(model: mujoco.MjModel, data: mujoco.MjData, plant: Plant, stabilizer: Stabilizer | None,
                 pattern: WalkingPattern, pattern_time: Array, reference: Array, control: Array, zmp_ref: Array,
                 steps_per_tick: int, sensors: SensorSlices, latency: float, noise: SensorNoise | None,
                 progress: Callable[[float], None] | None = None, disturbances: Disturbances | None = None,
                 time: Array | None = None,
                 capture: tuple[float, Callable[[int, Stabilizer, int], dict[str, NDArray[np.generic]]]] | None = None,
                 ) -> tuple[Array, dict[str, Array]]:
    """Step the model tick by tick (the stabilizer in the loop where given, pushes applied); sensor rows
    (n, nsensordata) and the stabilizer's log. With ``capture = (trigger, tail)``: whenever the stabilizer's DCM
    error passes ``trigger`` [m] in a single support (at most every :data:`CAPTURE_INTERVAL`), ``tail`` re-makes
    the references from the next tick on (:func:`_tracked`'s, the ZMP, the joint references and the controls)."""
    n = len(pattern_time)
    time = pattern_time if time is None else time
    tracked = _tracked(pattern, pattern_time)
    com, yaw, support = tracked["com"], tracked["yaw"], tracked["support"]
    ankles, foot_yaws = (tracked["left"], tracked["right"]), (tracked["left_yaw"], tracked["right_yaw"])
    offsets = control[:, plant.leg_actuators] - reference  # the feedforward's share of the leg controls
    readings = np.empty((n, model.nsensordata))
    delay = round(latency * CONTROL_RATE)
    rng = np.random.default_rng(noise.seed) if noise else None
    log = {"zmp_desired": np.empty((n, 2)), "com_offset": np.empty((n, 2)), "ankle_offsets": np.empty((n, 4)),
           "height_difference": np.empty(n), "pelvis_turn": np.empty((n, 2))}
    mujoco.mj_forward(model, data)
    current = data.sensordata.copy()
    reader = _MeasurementReader(sensors, None if disturbances is None else disturbances.floor_rotation)
    push_body = int(model.site_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "pelvis")])
    if stabilizer is not None:
        stabilizer.reset()
    last_capture = -n
    for k in range(n):
        if progress is not None and k % 500 == 0:
            progress(k / n)
        if disturbances is not None:
            data.xfrc_applied[push_body, :3] = disturbances.force_at(float(time[k]))
        if stabilizer is None:
            data.ctrl[:] = control[k]
            for _ in range(steps_per_tick):
                mujoco.mj_step(model, data)
            readings[k] = data.sensordata
            if not np.all(np.isfinite(data.qpos)):
                readings[k + 1:] = readings[k]
                break
            continue
        row = current if k - 1 - delay < 0 else readings[k - 1 - delay]
        measurement = reader.read(row)
        if rng is not None and noise is not None:
            measurement.wrench_left += rng.normal(0, [noise.force] * 3 + [noise.torque] * 3)
            measurement.wrench_right += rng.normal(0, [noise.force] * 3 + [noise.torque] * 3)
            measurement.attitude = measurement.attitude + rng.normal(0, noise.attitude, 2)
            measurement.rate = measurement.rate + rng.normal(0, noise.rate, 3)
            measurement.joint_angles = measurement.joint_angles + rng.normal(0, noise.encoder, 12)
        angles = stabilizer.update(
            support=int(support[k]), position_com_in_world=com[k], yaw_pelvis_in_world=float(yaw[k]),
            zmp_in_world=zmp_ref[k], ankles_in_world=(ankles[0][k], ankles[1][k]),
            foot_yaws=(float(foot_yaws[0][k]), float(foot_yaws[1][k])), joint_angles=reference[k],
            measurement=measurement)
        data.ctrl[:] = control[k]
        data.ctrl[plant.leg_actuators] = angles + offsets[k]
        for _ in range(steps_per_tick):
            mujoco.mj_step(model, data)
        readings[k] = data.sensordata
        state = stabilizer.state
        log["zmp_desired"][k] = state.zmp_desired
        log["com_offset"][k] = state.com_offset
        log["ankle_offsets"][k] = state.ankle_offsets.ravel()
        log["height_difference"][k] = state.height_difference
        log["pelvis_turn"][k] = state.pelvis_turn
        if (capture is not None and k + 1 < n and support[k] != 0 and support[k + 1] == support[k]
                and k - last_capture >= CAPTURE_INTERVAL * CONTROL_RATE
                and math.hypot(float(state.dcm_error[0]), float(state.dcm_error[1])) > capture[0]):
            last_capture = k
            try:
                tail = capture[1](k, stabilizer, int(support[k]))
            except (UnreachableError, InfeasiblePatternError):
                pass  # no capture step fits: the plan goes on as it was
            else:
                for key, values in tracked.items():
                    values[k + 1:] = tail[key]
                zmp_ref[k + 1:], reference[k + 1:], control[k + 1:] = tail["zmp"], tail["reference"], tail["control"]
                offsets[k + 1:] = control[k + 1:, plant.leg_actuators] - reference[k + 1:]
        if not np.all(np.isfinite(data.qpos)):
            readings[k + 1:] = readings[k]
            break
    return readings, log


def write_result_csv(result: SimulationResult, path: Path) -> None:
    """The simulation's time series as CSV, one row per millisecond, SI units in the column names' meaning
    (m, rad, N, N m, W): torso pose, CoP and reference ZMP, sole forces, CoP margin, each joint's angle,
    torque and power."""
    columns: dict[str, np.ndarray] = {
        "t": result.time,
        "torso_x": result.torso_position[:, 0], "torso_y": result.torso_position[:, 1],
        "torso_z": result.torso_position[:, 2], "torso_roll": result.torso_rpy[:, 0],
        "torso_pitch": result.torso_rpy[:, 1], "torso_yaw": result.torso_rpy[:, 2],
        "cop_x": result.cop[:, 0], "cop_y": result.cop[:, 1],
        "zmp_ref_x": result.reference_zmp[:, 0], "zmp_ref_y": result.reference_zmp[:, 1],
        "force_left": result.force_left, "force_right": result.force_right, "cop_margin": result.cop_margin,
    }
    for i, name in enumerate(result.joint_names):
        columns[f"{name}_q"] = result.joint_angles[:, i]
        columns[f"{name}_tau"] = result.joint_torques[:, i]
        columns[f"{name}_power"] = result.joint_power[:, i]
    with atomic_output(path) as temporary:
        np.savetxt(temporary, np.column_stack(list(columns.values())), delimiter=",", header=",".join(columns),
                   comments="", fmt="%.9g")
