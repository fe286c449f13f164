"""The MuJoCo model of a robot as a :class:`~zmpwalk.control.plant.Plant`, and the feedforward a controller computes
from it tick by tick.

:class:`MujocoPlant` wraps what :mod:`zmpwalk.sim.plant` and :mod:`zmpwalk.sim.run` do for a whole pattern into the
calls of a control loop: ``measure()`` reads the model's sensors as the robot's (the ground's wrench on each sole at
the ankle in the foot frame, the torso IMU, the joint encoders), ``apply(targets)`` drives the leg servos with the
angles, rates and feedforward torques of :class:`~zmpwalk.control.plant.JointTargets`, ``step()`` integrates one
control period. :class:`ModelFeedforward` is the inverse dynamics of :func:`zmpwalk.sim.plant.static_feedforward`
for one sample at a time (:class:`zmpwalk.control.controller.Feedforward`).
"""

from __future__ import annotations

import copy
import dataclasses
import math

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement
from zmpwalk.control.plant import JointTargets
from zmpwalk.errors import InvalidParameterError
from zmpwalk.robots.model import RobotModel
from zmpwalk.robots.pd import is_position_servo
from zmpwalk.sample import WalkingSample
from zmpwalk.sim.disturbances import NOSLIP_ITERATIONS, SensorNoise
from zmpwalk.sim.integrator import diverged, divergence_counters
from zmpwalk.sim.mjcf import contact_mapping
from zmpwalk.sim.plant import Plant as SimPlant
from zmpwalk.sim.plant import build_plant, passive_torques, static_feedforward
from zmpwalk.sim.poses import set_base_pose, set_initial_state
from zmpwalk.sim.ranges import check_range
from zmpwalk.sim.run import FALL_HEIGHT_FRACTION, FALL_TILT, Disturbances, _MeasurementReader
from zmpwalk.sim.soles import SensorSlices

Array = NDArray[np.float64]

_STEPS_IN_ONE_CALL = "nstep" in (mujoco.mj_step.__doc__ or "")  # mj_step(m, d, nstep): the steps of a tick in one call


def _ankle_sites(model: mujoco.MjModel) -> tuple[int, int]:
    """The ids of the left and right ankle sites."""
    left, right = (mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_ankle") for s in ("left", "right"))
    return int(left), int(right)


def _held_angles(plant: SimPlant) -> Array:
    """The 12 leg joint columns [rad] at the reference pose (a five-joint leg's virtual ankle roll at 0)."""
    angles = np.zeros(12)
    angles[plant.leg_columns] = plant.qpos_hold[plant.leg_qpos]
    return angles


def _base_position(plant: SimPlant, data: mujoco.MjData, sample: WalkingSample, angles: Array,
                   sites: tuple[int, int]) -> Array:
    """The base origin [m] (3,) of a sample's pose: the pelvis point on a box model; on a robot's own model, where
    the leg angles put the ankles at the sample's (on average; the walker's pelvis point is its whole-body CoM),
    the base upright at the sample's yaw."""
    if not plant.imported:
        return np.array(sample.position_pelvis_in_world, dtype=np.float64)
    data.qpos[:] = plant.qpos_hold
    set_base_pose(plant, data.qpos, np.zeros(3), sample.yaw_pelvis_in_world)
    data.qpos[plant.leg_qpos] = angles[plant.leg_columns]
    mujoco.mj_kinematics(plant.model, data)
    planned = (sample.position_left_ankle_in_world, sample.position_right_ankle_in_world)
    return np.asarray(sum(p - data.site_xpos[s] for p, s in zip(planned, sites, strict=True)) / 2, dtype=np.float64)


class ModelFeedforward:
    """The joint torques of each tick's planned motion by inverse dynamics of a MuJoCo model (a
    :class:`~zmpwalk.control.controller.Feedforward`).

    As :func:`zmpwalk.sim.plant.static_feedforward` for a whole pattern, ``tau = M(q) q'' + C(q, q') + g(q) +
    tau_passive(q') - sum_feet J^T w``, for one sample (:func:`~zmpwalk.sim.plant.passive_torques`: the joints' own
    damping and friction in the model): ``q`` its pose (the base upright at the pelvis yaw), ``q'`` the base's rate by
    a backward difference over one tick and the legs' planned rates, ``q''`` their backward difference; ``w`` the
    ground wrench ``m (c'' + g)`` at the planned ZMP, ``c'' = (g / z_c)(c - p)`` of the model's CoM, on the stance
    sole, split by the ZMP's place between the soles in double support. Bounded work per tick: one forward
    kinematics, one recursive Newton-Euler pass and two site Jacobians.

    Args:
        plant: The model (its nominal masses: what the controller knows of the robot).
        rate: Control rate [Hz]; :meth:`torques` is called once per tick, in order.

    Attributes:
        servo_torques: The last tick's torque at every position servo [N m], (nu,) (0 at other actuators).
    """

    def __init__(self, plant: SimPlant, rate: float) -> None:
        model = plant.model
        self.plant = plant
        self.dt = 1.0 / float(rate)
        self._data = mujoco.MjData(model)
        self._scratch = mujoco.MjData(model)
        self._servos = np.array([a for a in range(model.nu) if is_position_servo(model, a)], dtype=np.intp)
        self._dofs = np.array([model.jnt_dofadr[model.actuator_trnid[a][0]] for a in self._servos], dtype=np.intp)
        self._leg_dofs = np.array([model.jnt_dofadr[model.actuator_trnid[a][0]] for a in plant.leg_actuators],
                                  dtype=np.intp)
        self._sites = _ankle_sites(model)
        self._mass = float(np.sum(model.body_mass))
        self._gravity = -float(model.opt.gravity[2])
        self._qpos = plant.qpos_hold.copy()
        self._previous_qpos: Array | None = None
        self._qvel, self._previous_qvel = np.zeros(model.nv), np.zeros(model.nv)
        self._tau = np.zeros(model.nv)
        self._passive = bool(model.dof_damping.any() or model.dof_frictionloss.any())
        self._feet = tuple(int(model.site_bodyid[site]) for site in self._sites)  # the ankle sites' bodies
        self._reaction, self._force, self._point = np.zeros(model.nv), np.zeros(3), np.zeros(3)
        self._no_torque = np.zeros(3)
        self.servo_torques = np.zeros(model.nu)
        self.rate = float(rate)
        # per-tick work on views found once: MjData's attributes build a new view at every read
        self._data_qpos, self._data_qvel, self._data_qacc = self._data.qpos, self._data.qvel, self._data.qacc
        self._subtree_com = self._data.subtree_com
        columns, addresses = plant.leg_columns, plant.leg_qpos
        contiguous = len(columns) == 12 and (np.diff(addresses) == 1).all() and (columns == np.arange(12)).all()
        self._leg_slice = slice(int(addresses[0]), int(addresses[0]) + 12) if contiguous else None

    def torques(self, sample: WalkingSample) -> Array:
        """The leg joints' torques [N m], (12,), in the walker's column order, for this tick's ``sample``."""
        plant, model, data = self.plant, self.plant.model, self._data
        angles = sample.joint_angles if sample.joint_angles is not None else _held_angles(plant)
        qpos = self._qpos
        yaw = sample.yaw_pelvis_in_world
        base = (_base_position(plant, self._scratch, sample, angles, self._sites) if plant.imported
                else sample.position_pelvis_in_world)  # the box model's base is the pelvis point
        set_base_pose(plant, qpos, base, yaw)  # the root placed from it (below a waist, through the held waist)
        if self._leg_slice is not None:
            qpos[self._leg_slice] = angles
        else:
            qpos[plant.leg_qpos] = angles[plant.leg_columns]
        qvel, previous_qvel = self._qvel, self._previous_qvel
        previous_qvel[:] = qvel
        if self._previous_qpos is None:
            self._previous_qpos = qpos.copy()
        mujoco.mj_differentiatePos(model, qvel, self.dt, self._previous_qpos, qpos)
        if sample.joint_velocities is not None:
            qvel[self._leg_dofs] = sample.joint_velocities
        self._previous_qpos[:] = qpos
        self._data_qpos[:] = qpos
        self._data_qvel[:] = qvel
        np.subtract(qvel, previous_qvel, out=self._data_qacc)
        self._data_qacc *= self.rate
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_comVel(model, data)
        mujoco.mj_rne(model, data, 1, self._tau)
        if self._passive:
            self._tau += passive_torques(model, qvel)  # the joints' own damping and friction, which the motion meets
        self._subtract_reaction(sample)
        self.servo_torques[self._servos] = self._tau[self._dofs]
        leg: Array = self.servo_torques[self.plant.leg_actuators]  # a new array
        return leg

    def _subtract_reaction(self, sample: WalkingSample) -> None:
        """Take the planned ground wrench's share of each sole off the torques: ``tau -= J_p^T f``, the share's force
        ``f`` at its CoP ``p`` on the floor (MuJoCo's ``mj_applyFT``; scalar arithmetic: numpy's cross product of two
        3-vectors costs 30 us)."""
        data, gravity = self._data, self._gravity
        zx, zy = sample.zmp_in_world[:2].tolist()
        cx, cy, cz = self._subtree_com[0].tolist()
        scale = self._mass * gravity / max(cz, 1e-6)  # cart-table: m c'' = m (g / z)(c - p)
        fx, fy, fz = scale * (cx - zx), scale * (cy - zy), self._mass * gravity
        lx, ly = sample.position_left_ankle_in_world[:2].tolist()
        rx, ry = sample.position_right_ankle_in_world[:2].tolist()
        if sample.support == "left":
            ratio = 0.0
        elif sample.support == "right":
            ratio = 1.0
        else:
            sx, sy = rx - lx, ry - ly
            ratio = min(max(((zx - lx) * sx + (zy - ly) * sy) / max(sx * sx + sy * sy, 1e-12), 0.0), 1.0)
        bx, by = lx + (rx - lx) * ratio, ly + (ry - ly) * ratio  # the ZMP's foot of the line between the ankles
        reaction, force, point = self._reaction, self._force, self._point
        reaction.fill(0.0)
        for body, share, ax, ay in ((self._feet[0], 1.0 - ratio, lx, ly), (self._feet[1], ratio, rx, ry)):
            if share == 0.0:
                continue
            force[0], force[1], force[2] = share * fx, share * fy, share * fz
            point[0], point[1] = ax + zx - bx, ay + zy - by  # this sole's CoP, keeping the total at the ZMP
            mujoco.mj_applyFT(self.plant.model, data, force, self._no_torque, point, body, reaction)
        self._tau -= reaction

class MujocoPlant:
    """The MuJoCo model of a robot as a :class:`~zmpwalk.control.plant.Plant`: its sensors read as the robot's
    (:class:`~zmpwalk.balance.BalanceMeasurement`), its leg servos driven as a humanoid's low-level interface
    drives them (``q, dq, tau_ff``: control ``u = q + (kv / kp) dq + tau_ff / (kp gear^2)`` of a position servo
    ``kp (u - q) - kv q'``, docs/balance.md), every other actuator holding the reference pose.

    Args:
        robot: The robot (its own MJCF or URDF, else its robot file's box model).
        rate: Control rate [Hz]: a whole number of the model's time steps per period.
        mass_scale: Multiply the box model's masses (:func:`zmpwalk.sim.plant.build_plant`).
        disturbances: A push, a floor tilt or a mass error (:class:`~zmpwalk.sim.run.Disturbances`); the
            :meth:`feedforward` keeps the nominal model.
        latency: Every measurement is the sensors' reading this long before [s] (a whole number of control
            periods, 0 to 0.1 s; before the walk's first readings, the first), as the batch walk's
            (:func:`zmpwalk.sim.run.simulate`).
        noise: Gaussian noise added to every measurement (:class:`~zmpwalk.sim.disturbances.SensorNoise`, its
            seed's generator drawn once per :meth:`measure`); None: none.
        time_origin: Where :attr:`time` is 0 [s] after :meth:`stand` (a walk's start: a push's time then counts
            from there, as on the batch walk's clock; whole control periods).
        noslip: Run MuJoCo's noslip solver (:data:`~zmpwalk.sim.disturbances.NOSLIP_ITERATIONS` iterations): a
            loaded sole then holds where it stands instead of creeping under a lasting tangential force inside
            the friction cone, as MuJoCo's soft contacts let it (as on a tilted floor, where it always runs).

    Raises:
        InvalidParameterError: A rate whose period is not a whole number of time steps, or as
            :func:`~zmpwalk.sim.plant.build_plant`.
    """

    def __init__(self, robot: RobotModel, rate: float = 1000.0, *, mass_scale: float = 1.0,
                 disturbances: Disturbances | None = None, latency: float = 0.0, noise: SensorNoise | None = None,
                 noslip: bool = False, time_origin: float = 0.0) -> None:
        check_range("latency", latency)
        if noise is not None and not isinstance(noise, SensorNoise):
            raise InvalidParameterError("noise", noise, "a SensorNoise, or None")
        plant = build_plant(robot, mass_scale)
        model = plant.model
        if noslip:
            model.opt.noslip_iterations = NOSLIP_ITERATIONS
        steps = 1.0 / (float(rate) * float(model.opt.timestep))
        if not (math.isfinite(steps) and steps >= 1.0 - 1e-9 and abs(steps - round(steps)) < 1e-6):
            raise InvalidParameterError("rate", rate, f"a rate whose period is a whole number of the model's "
                                        f"{model.opt.timestep:g} s time steps (at most {1 / model.opt.timestep:g} Hz)")
        self.robot, self.plant, self.rate = robot, plant, float(rate)
        self.steps_per_tick = round(steps)
        self._nominal = dataclasses.replace(plant, model=copy.deepcopy(model))
        self.disturbances = disturbances
        if disturbances is not None:
            disturbances.apply(model)
        self.model, self.data = model, mujoco.MjData(model)
        self.sensors = SensorSlices(model)
        self._reader = _MeasurementReader(self.sensors, None if disturbances is None else disturbances.floor_rotation)
        servos = plant.leg_actuators
        kp, gear = model.actuator_gainprm[servos, 0], model.actuator_gear[servos, 0]
        driven = kp * gear**2 != 0.0  # a five-joint leg's virtual ankle roll has an actuator of gain and gear 0
        self._damping_ratio = np.divide(-model.actuator_biasprm[servos, 2], kp, out=np.zeros(len(servos)),
                                        where=driven)  # [s]
        self._compliance = np.divide(1.0, kp * gear**2, out=np.zeros(len(servos)), where=driven)  # [rad/(N m)]
        self._ctrl = plant.ctrl_hold.copy()
        self._push_body = int(model.site_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "pelvis")])
        self._pelvis, self._quaternion = self.sensors.slices["pelvis_pos"], self.sensors.slices["pelvis_quat"]
        self._touch = self.sensors.slices.get("torso_touch")
        self._penetration = 0.0 if plant.imported else contact_mapping(
            RobotModel(**{**vars(robot), "mass": robot.link_mass * mass_scale})).penetration
        self.weight = float(model.body_subtreemass[1]) * robot.gravity  # [N]
        self._upright_least, self._least_height = math.cos(FALL_TILT), FALL_HEIGHT_FRACTION * robot.pelvis_height
        self._ticks = 0
        self._diverged = divergence_counters(self.data)
        self._origin = round(time_origin * self.rate)  # [ticks]
        self._delay = round(latency * self.rate)
        if abs(self._delay - latency * self.rate) > 1e-6:
            raise InvalidParameterError("latency", latency, f"a whole number of control periods ({1 / self.rate:g} s)")
        self._past = np.empty((self._delay + 1, model.nsensordata))  # ring of the last readings, oldest first read
        self._noise = noise
        self._rng = np.random.default_rng(noise.seed) if noise is not None else None
        # views found once (MjData's attributes build a new view at every read) and a buffer for apply()
        self.sensordata = self.data.sensordata  # [various] the sensors' row, updated by every step
        self._qpos, self._data_ctrl = self.data.qpos, self.data.ctrl
        self._leg = np.zeros(len(plant.leg_actuators))

    @property
    def time(self) -> float:
        """[s] since :meth:`stand`, less ``time_origin``."""
        return (self._ticks - self._origin) / self.rate

    def feedforward(self) -> ModelFeedforward:
        """A :class:`ModelFeedforward` on this plant's nominal model (before its disturbances)."""
        return ModelFeedforward(self._nominal, self.rate)

    def stand(self, sample: WalkingSample) -> None:
        """Stand the robot at rest in ``sample``'s pose (a walker's standing sample, with joint angles), its lowest
        sole on the floor; the other servos hold the reference pose with its static torque."""
        if sample.joint_angles is None:
            raise InvalidParameterError("sample.joint_angles", None, "the 12 angles (a walker with joints=True)")
        plant = self.plant
        base = _base_position(plant, mujoco.MjData(plant.model), sample, sample.joint_angles,
                              _ankle_sites(plant.model))
        set_initial_state(plant, self.data, base, sample.yaw_pelvis_in_world, sample.joint_angles, self._penetration)
        others = np.setdiff1d(np.arange(self.model.nu), plant.leg_actuators)
        self._ctrl[:] = plant.ctrl_hold
        if len(others):
            qpos = self.data.qpos.copy()[None, :]
            ankles = (sample.position_left_ankle_in_world[None, :], sample.position_right_ankle_in_world[None, :])
            offsets = static_feedforward(self._nominal, qpos, sample.zmp_in_world[None, :], np.zeros(1, dtype=int),
                                         ankles, self.rate, dynamic=False)[0]
            self._ctrl[others] += offsets[others]
        self._ctrl[plant.leg_actuators] = sample.joint_angles
        self.data.ctrl[:] = self._ctrl
        self._ticks = 0
        if self._delay:
            self._past[:] = self.data.sensordata  # set_initial_state ran mj_forward

    def measure(self) -> BalanceMeasurement:
        """The sensors (``latency`` ago; now without one): each sole's wrench (the ground's, at the ankle, foot
        frame), the IMU, the encoders; with ``noise`` added."""
        if self._delay == 0:
            measurement = self._reader.read(self.sensordata)
        else:
            measurement = self._reader.read(self._past[(self._ticks + 1) % (self._delay + 1)])  # after tick t - delay
        if self._noise is not None and self._rng is not None:
            self._noise.add_to(measurement, self._rng)
        return measurement

    def apply(self, targets: JointTargets) -> None:
        """Drive the leg servos with the targets (the control of the class docstring)."""
        leg = self._leg
        np.multiply(self._damping_ratio, targets.velocities, out=leg)
        leg += targets.angles
        if targets.torques is not None:
            leg += targets.torques * self._compliance
        self._ctrl[self.plant.leg_actuators] = leg
        self._data_ctrl[:] = self._ctrl

    def step(self) -> None:
        """Integrate one control period (a push acting where :attr:`disturbances` has one)."""
        if self.disturbances is not None:
            self.data.xfrc_applied[self._push_body, :3] = self.disturbances.force_at(self.time)
        if _STEPS_IN_ONE_CALL:
            mujoco.mj_step(self.model, self.data, self.steps_per_tick)
        else:  # pragma: no cover - MuJoCo before nstep
            for _ in range(self.steps_per_tick):
                mujoco.mj_step(self.model, self.data)
        self._ticks += 1
        if self._diverged[0].number or self._diverged[1].number or self._diverged[2].number:
            error = diverged(self.model, self._diverged, self.time)
            if error is not None:
                raise error
        if self._delay:
            self._past[self._ticks % (self._delay + 1)] = self.sensordata

    def fallen(self) -> bool:
        """The fall criterion of :mod:`zmpwalk.sim.run` now (the torso touching the floor, tilted over
        :data:`~zmpwalk.sim.run.FALL_TILT` or sunk below :data:`~zmpwalk.sim.run.FALL_HEIGHT_FRACTION` of the pelvis
        height), or a state that is no longer finite (scalar reads: this runs every tick)."""
        row = self.sensordata
        x, y = float(row[self._quaternion.start + 1]), float(row[self._quaternion.start + 2])
        upright = 1.0 - 2.0 * (x * x + y * y)  # cos(tilt): the torso's z axis against the vertical
        touched = self._touch is not None and row[self._touch.start] > 0
        return bool(touched or upright < self._upright_least or row[self._pelvis.start + 2] < self._least_height
                    or not math.isfinite(sum(self._qpos.tolist())))  # a sum of Python floats: no numpy reduction
