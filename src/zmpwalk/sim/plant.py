"""The plant of a simulation: the robot's own MJCF or URDF model, or the box model of a robot file.

:func:`build_plant` gives one :class:`Plant` either way, so :func:`zmpwalk.sim.run.simulate` never asks
which it runs. For an imported robot (:mod:`zmpwalk.robots.imported`) the plant is the builder's own
model, unmodified in its meshes, masses, inertias, contacts and actuators, with:

* a floor where the file has none (a plane at z = 0, MuJoCo's default contact);
* sensors added where zmpwalk measures, as on the robot: a force-torque sensor at each ankle point
  (a site in the foot body, axes of the foot frame), the pose of the base and of each ankle, and each
  leg joint's angle, rate and actuator torque (``jointactuatorfrc``);
* a time step of at most the robot's ``physics_step`` (the model's own, at most
  :data:`~zmpwalk.robots.description.PHYSICS_STEP`, the 1 kHz servo period of the references, or a half or a
  quarter of it where the PD layer needs it: :func:`zmpwalk.robots.pd.pd_physics_step`);
* the joint PD layer a humanoid's firmware runs, where the model has torque motors or no actuators
  (:func:`add_pd_layer`);
* no control range on its position servos (:func:`lift_control_ranges`): the control carries the target angle
  plus the damping and feedforward torques as angle offsets (``q, dq, tau_ff``, docs/balance.md), which a
  range copied from the joint's (``inheritrange``) would clip silently, and with them the torque a low-gain servo
  gives near the end of its range; the joint's range still bounds the motion and its force range the torque;
* the leg joints' actuators driven by the joint trajectory, every other actuator holding the
  reference pose (the keyframe's controls; the reference angle for a joint of the PD layer).

The leg joints must be driven by position servos (MuJoCo ``<position>`` or an equivalent ``general``) or by
the PD layer: zmpwalk sends joint angles.

A five-joint leg's virtual ankle roll (:mod:`zmpwalk.robots.legs`) has no joint in the model. Its joint column
keeps zmpwalk's 12-column layout through an actuator that does nothing, ``zmpwalk_virtual_LEFT_ankle_roll``
(gain, bias and gear 0 on the leg's ankle pitch: MuJoCo applies ``gear * force = 0``), and its sensors read that
actuator's length, velocity and force, all 0: the foot is rigid on the ankle pitch, as the model says, and the
angle the simulation measures there is 0 whatever the plan's residual roll. The column has no ``qpos``
(:attr:`Plant.leg_columns` lists the columns that do).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.robots.description import ModelPlant
from zmpwalk.robots.imported import load_model_spec
from zmpwalk.robots.linkages import joint_dofs, joint_id
from zmpwalk.robots.model import RobotModel
from zmpwalk.robots.pd import is_position_servo
from zmpwalk.robots.tree import Mount, base_mount, floating_base, root_from_base
from zmpwalk.sides import Support
from zmpwalk.sim.integrator import EULER_BOUND, explicit_damping_ratio
from zmpwalk.sim.sole_body import sole_bodies

LEFT_SUPPORT, RIGHT_SUPPORT = int(Support.LEFT), int(Support.RIGHT)  # plain ints: a numpy integer compares with
# an IntEnum member a hundred times slower

Array = NDArray[np.float64]

FEEDFORWARD_PERIOD = 0.005  # [s] the static feedforward is computed at this period and interpolated
FRICTION_RATE = 0.05  # [rad/s] (m/s on a slide) a joint's dry friction enters the feedforward as f tanh(q' / this)


@dataclass
class Plant:
    """A compiled model with zmpwalk's sensors, and how the 12 joint columns map onto it.

    Attributes:
        model: The MuJoCo model.
        leg_actuators: Actuator index of each joint column (left leg then right, role order), (12,) (a virtual
            column's: its actuator that does nothing).
        leg_qpos: ``qpos`` address of each joint column that is a joint of the model, (len(leg_columns),).
        leg_columns: Those columns (all 12 but a five-joint leg's virtual ankle roll).
        ctrl_hold: Controls of the reference pose (the other actuators keep them), (nu,).
        qpos_hold: The reference pose, (nq,).
        imported: True for the robot's own model, False for the box model.
        mount: Where the legs' base (the pelvis, whose pose the plan gives and the sensors read) sits on the
            floating root below a waist (:func:`~zmpwalk.robots.tree.base_mount`); None where it is the root.
        coupled_dofs: The degrees of freedom of the joints a driven joint moves through an equality
            (:attr:`~zmpwalk.robots.description.ModelPlant.coupled_joints`), (k,): placed where the equalities
            hold when the robot is stood (:func:`~zmpwalk.sim.poses.close_loops`).
    """

    model: mujoco.MjModel
    leg_actuators: NDArray[np.intp]
    leg_qpos: NDArray[np.intp]
    ctrl_hold: Array
    qpos_hold: Array
    imported: bool
    leg_columns: NDArray[np.intp] = field(default_factory=lambda: np.arange(12))
    mount: Mount | None = None
    coupled_dofs: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, dtype=np.intp))

    @cached_property
    def root_in_base(self) -> tuple[float, ...] | None:
        """The floating root's origin [m] and orientation (quaternion w, x, y, z) in the legs' base frame, from
        :attr:`mount` (``-R^T o`` and ``R^T``); None where the base is the root."""
        if self.mount is None:
            return None
        offset, rotation = self.mount
        quaternion = np.empty(4)
        mujoco.mju_mat2Quat(quaternion, np.ascontiguousarray(rotation.T).flatten())
        return (*(-rotation.T @ offset).tolist(), *quaternion.tolist())


def build_plant(robot: RobotModel, mass_scale: float = 1.0) -> Plant:
    """The plant of ``robot`` (see the module docstring).

    Raises:
        InvalidParameterError: A leg joint driven by neither a position servo nor the PD layer, or a mass scale
            on an imported model (its masses are the builder's).
    """
    if robot.plant is None:
        from zmpwalk.sim.mjcf import robot_mjcf

        model = mujoco.MjModel.from_xml_string(robot_mjcf(robot, mass_scale))
        qpos = model.qpos0.copy()
        return Plant(model, np.arange(12), np.arange(7, 19), np.zeros(model.nu), qpos, False)
    if mass_scale != 1.0:
        raise InvalidParameterError("mass_scale", mass_scale, "1 for a robot imported from its model (its "
                                    "masses are the model's)")
    plant = robot.plant
    spec = load_model_spec(plant.path, plant.package_paths)
    model = spec.compile()
    if model.opt.timestep > plant.physics_step:  # the PD layer's period (robots.pd.pd_physics_step)
        spec.option.timestep = plant.physics_step
    if not any(g.type == mujoco.mjtGeom.mjGEOM_PLANE for g in spec.worldbody.geoms):
        spec.worldbody.add_geom(name="zmpwalk_floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    for index, actuator in enumerate(spec.actuators):  # the names the robot gives them (robots.pd.element_name)
        if not actuator.name:
            actuator.name = f"#{index}"
    _release_coupled(spec, plant)
    sites = sole_bodies(spec, model, plant)
    add_pd_layer(spec, plant)
    lift_control_ranges(spec, model)
    qpos = np.array(plant.qpos_reference)
    root = floating_base(model, str(plant.path))
    mount = base_mount(model, qpos, root, mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, plant.base_body))
    _add_sites(spec, model, robot, plant, qpos, (int(model.jnt_qposadr[model.body_jntadr[root]]), mount), sites)
    virtual = _virtual_columns(robot)
    _add_sensors(spec, plant, virtual)
    model = spec.compile()
    if model.opt.integrator == mujoco.mjtIntegrator.mjINT_EULER and explicit_damping_ratio(model, qpos) >= EULER_BOUND:
        spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # the damping implicit (sim.integrator)
        model = spec.compile()
    actuators = _leg_actuators(model, plant, virtual)
    columns = np.array([i for i in range(12) if i not in virtual], dtype=np.intp)
    leg_qpos = np.array([model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, plant.joints[i].name)]
                         for i in columns])
    dofs = joint_dofs(model, [joint_id(model, name) for name in plant.coupled_joints])
    return Plant(model, np.array(actuators), leg_qpos, _held_controls(model, plant), qpos, True, columns, mount,
                 dofs)



def _add_sites(spec: mujoco.MjSpec, model: mujoco.MjModel, robot: RobotModel, plant: ModelPlant,
               qpos: Array, root: tuple[int, Mount | None], bodies: dict[str, str]) -> None:
    """Add the ``pelvis`` site at the base body's origin and an ``{left,right}_ankle`` site at each ankle point
    (axes of the sole frame), placed in the foot bodies from the zero pose of the legs with the base at the origin
    (``qpos``: the reference pose, the other joints' angles; ``root``: the floating root's ``qpos`` address and
    where the legs' base sits on it); a foot's site on the body ``bodies`` names for it, where it names one (its
    sole body, :func:`~zmpwalk.sim.sole_body.sole_bodies`, whose frame is the foot's)."""
    data = mujoco.MjData(model)
    joint_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint.name) for joint in plant.joints]
    zero = qpos.copy()
    for j in joint_ids:
        zero[model.jnt_qposadr[j]] = 0.0
    root_adr, mount = root
    position_root, rotation_root = root_from_base(mount, np.zeros(3), np.eye(3))  # the base at the origin
    zero[root_adr:root_adr + 3] = position_root
    mujoco.mju_mat2Quat(zero[root_adr + 3:root_adr + 7], rotation_root.flatten())
    data.qpos[:] = zero
    mujoco.mj_kinematics(model, data)
    if robot.legs is None:
        raise InvalidParameterError("robot", robot.name, "leg chains with its model (zmpwalk.robots.import_robot)")
    spec.body(plant.base_body).add_site(name="pelvis", pos=[0, 0, 0], size=[0.01, 0.01, 0.01])
    for label, foot, chain in zip(("left", "right"), plant.feet, robot.legs, strict=True):
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, foot)
        rotation = data.xmat[body].reshape(3, 3)
        position = rotation.T @ (chain.ankle - data.xpos[body])
        quaternion = np.empty(4)
        mujoco.mju_mat2Quat(quaternion, (rotation.T @ chain.sole_rotation).flatten())  # site axes: the sole frame
        spec.body(bodies.get(foot, foot)).add_site(name=f"{label}_ankle", pos=position, quat=quaternion,
                                                   size=[0.005, 0.005, 0.005])


def _add_sensors(spec: mujoco.MjSpec, plant: ModelPlant, virtual: set[int]) -> None:
    """Add zmpwalk's sensors: the base's pose and gyro, each ankle's force-torque and pose, each leg joint's angle,
    rate and actuator torque (a ``virtual`` column's read from its actuator that does nothing)."""
    sensors = [("pelvis_pos", mujoco.mjtSensor.mjSENS_FRAMEPOS, "pelvis"),
               ("pelvis_quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT, "pelvis"),
               ("pelvis_gyro", mujoco.mjtSensor.mjSENS_GYRO, "pelvis")]
    for label in ("left", "right"):
        sensors += [(f"{label}_force", mujoco.mjtSensor.mjSENS_FORCE, f"{label}_ankle"),
                    (f"{label}_torque", mujoco.mjtSensor.mjSENS_TORQUE, f"{label}_ankle"),
                    (f"{label}_ankle_pos", mujoco.mjtSensor.mjSENS_FRAMEPOS, f"{label}_ankle"),
                    (f"{label}_ankle_quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT, f"{label}_ankle")]
    for name, kind, site in sensors:
        sensor = spec.add_sensor(name=name, type=kind, objname=site)
        sensor.objtype = mujoco.mjtObj.mjOBJ_SITE
    for index, (column, joint) in enumerate(zip(JOINT_COLUMNS, plant.joints, strict=True)):
        if index in virtual:
            _add_virtual_actuator(spec, joint.name, plant.joints[6 * (index // 6) + 4].name, column)
            continue
        for suffix, kind in (("q", mujoco.mjtSensor.mjSENS_JOINTPOS), ("qd", mujoco.mjtSensor.mjSENS_JOINTVEL),
                             ("tau", mujoco.mjtSensor.mjSENS_JOINTACTFRC)):
            sensor = spec.add_sensor(name=f"{column}_{suffix}", type=kind, objname=joint.name)
            sensor.objtype = mujoco.mjtObj.mjOBJ_JOINT


def _release_coupled(spec: mujoco.MjSpec, plant: ModelPlant) -> None:
    """Make the model's actuators on the joints a driven joint moves through an equality do nothing (gain and bias
    0): the driven joint's loop moves them, and a hold would pull against it."""
    coupled = set(plant.coupled_joints)
    for actuator in spec.actuators:
        if actuator.trntype == mujoco.mjtTrn.mjTRN_JOINT and actuator.target in coupled:
            actuator.gainprm = np.zeros(len(actuator.gainprm))
            actuator.biasprm = np.zeros(len(actuator.biasprm))


def _leg_actuators(model: mujoco.MjModel, plant: ModelPlant, virtual: set[int]) -> list[int]:
    """The actuator index of each joint column (a ``virtual`` column's: its actuator that does nothing).

    Raises:
        InvalidParameterError: A leg joint driven by neither a position servo nor the PD layer.
    """
    actuators = []
    for index, (column, joint) in enumerate(zip(JOINT_COLUMNS, plant.joints, strict=True)):
        if index in virtual:
            actuators.append(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, joint.name))
            continue
        if joint.actuator is None or not joint.actuator.servo:
            kind = "none" if joint.actuator is None else joint.actuator.kind
            raise InvalidParameterError(f"{column} actuator", kind, "a position servo (MuJoCo <position>) or a "
                                        "torque motor (<motor>, driven by the PD layer): zmpwalk drives the leg "
                                        "joints with joint angles")
        actuators.append(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, joint.actuator.name))
    return actuators


def _virtual_columns(robot: RobotModel) -> set[int]:
    """The joint columns of five-joint legs' virtual ankle rolls (no joint of the model)."""
    return {6 * index + chain.virtual_column for index, chain in enumerate(robot.legs or ())
            if chain.virtual_column is not None}


def _add_virtual_actuator(spec: mujoco.MjSpec, name: str, ankle_pitch: str, column: str) -> None:
    """The actuator of a virtual joint column, which does nothing (gain, bias and gear 0 on the ankle pitch), and
    its sensors (its length, velocity and force: 0), named as a joint column's (module docstring)."""
    actuator = spec.add_actuator(name=name, target=ankle_pitch, trntype=mujoco.mjtTrn.mjTRN_JOINT)
    actuator.gaintype = mujoco.mjtGain.mjGAIN_FIXED
    actuator.biastype = mujoco.mjtBias.mjBIAS_NONE
    actuator.gainprm = [0.0] * 10
    actuator.biasprm = [0.0] * 10
    actuator.gear = [0.0] * 6
    actuator.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for suffix, kind in (("q", mujoco.mjtSensor.mjSENS_ACTUATORPOS), ("qd", mujoco.mjtSensor.mjSENS_ACTUATORVEL),
                         ("tau", mujoco.mjtSensor.mjSENS_ACTUATORFRC)):
        sensor = spec.add_sensor(name=f"{column}_{suffix}", type=kind, objname=name)
        sensor.objtype = mujoco.mjtObj.mjOBJ_ACTUATOR


def lift_control_ranges(spec: mujoco.MjSpec, model: mujoco.MjModel) -> None:
    """Drop the control range of every position servo of ``model`` in ``spec`` (the module docstring)."""
    for actuator, element in zip(range(model.nu), spec.actuators, strict=False):  # the model's, in its order
        if is_position_servo(model, actuator):
            element.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE


def add_pd_layer(spec: mujoco.MjSpec, plant: ModelPlant) -> None:
    r"""Run the joint PD layer of :attr:`ModelPlant.pd_joints` in ``spec``, as a humanoid's firmware runs it.

    Each joint's torque motor (or, where the joint has none, a new actuator ``zmpwalk_pd_JOINT``) becomes a
    position servo of the layer's gains, gear 1, its force clipped at the joint's torque limit:

    .. math:: \tau = \mathrm{clip}(k_p (u - q) - k_v \dot q,\ -\tau_{max},\ \tau_{max})

    MuJoCo then runs the PD law at every physics step (1 kHz, as firmware does, or 2 or 4 kHz:
    :attr:`ModelPlant.physics_step`). A control ``u = q_ref +
    tau_ff / kp`` (:func:`servo_offsets`) is the same as a feedforward torque: ``kp (q_ref + tau_ff / kp - q)
    = kp (q_ref - q) + tau_ff``. The motor's control range (a torque) is dropped: the control is an angle.
    """
    for joint, actuator in plant.pd_joints:
        if actuator.kind == "motor":
            servo = spec.actuator(actuator.name)
        else:
            servo = spec.add_actuator(name=actuator.name, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        servo.dyntype = mujoco.mjtDyn.mjDYN_NONE
        servo.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        servo.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        servo.gainprm = [actuator.kp] + [0.0] * 9
        servo.biasprm = [0.0, -actuator.kp, -actuator.kv] + [0.0] * 7
        servo.gear = [1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        servo.ctrllimited = mujoco.mjtLimited.mjLIMITED_FALSE
        limited = math.isfinite(actuator.force_limit)
        servo.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE if limited else mujoco.mjtLimited.mjLIMITED_FALSE
        if limited:
            servo.forcerange = [-actuator.force_limit, actuator.force_limit]


def _held_controls(model: mujoco.MjModel, plant: ModelPlant) -> Array:
    """Controls (nu,) that hold the reference pose: a position servo's on a joint (no integrator: an
    ``<intvelocity>``'s control is a rate), the reference angle times its gear
    (its control is the angle it holds: a keyframe without controls, or with them in another order than the
    actuators', holds the pose all the same); for a joint of the PD layer its reference angle (a motor's keyframe
    control is a torque; the actuators the layer adds come after the model's); any other actuator's, the keyframe's
    control."""
    controls = np.zeros(model.nu)
    controls[:len(plant.ctrl_reference)] = plant.ctrl_reference
    for actuator in range(len(plant.ctrl_reference)):
        if is_position_servo(model, actuator) and model.actuator_dyntype[actuator] == mujoco.mjtDyn.mjDYN_NONE:
            address = model.jnt_qposadr[model.actuator_trnid[actuator][0]]
            controls[actuator] = model.actuator_gear[actuator][0] * plant.qpos_reference[address]
    for joint, pd in plant.pd_joints:
        address = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)]
        controls[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, pd.name)] = plant.qpos_reference[address]
    return controls


def passive_torques(model: mujoco.MjModel, qvel: Array) -> Array:
    """The torques (nv,) [N m] a joint's own damping and dry friction in the model (``<joint damping>``,
    ``frictionloss``) take from a motion at rates ``qvel`` (nv,), which the actuators must add to move it so:
    ``b q' + f tanh(q' / v_f)``, the friction smoothed below :data:`FRICTION_RATE` ``v_f`` (at rest its sign is
    undefined: the feedforward of a joint held still does not push either way). The model's other passive forces
    (joint springs, gravity compensation, fluid drag) are left out."""
    return np.asarray(model.dof_damping * qvel + model.dof_frictionloss * np.tanh(qvel / FRICTION_RATE),
                      dtype=np.float64)


def static_feedforward(plant: Plant, qpos: Array, zmp: Array, support: NDArray[np.integer],
                       ankles: tuple[Array, Array], rate: float = 1000.0, dynamic: bool = True) -> Array:
    r"""Control offsets (n, nu) [rad] that make the position servos deliver the planned motion's joint torques.

    A position servo ``kp (u - q)`` that must deliver a torque ``tau`` lags by ``tau / kp`` (standing, TALOS's
    knees sag 0.09 rad and Booster T1's 0.35 rad; swinging, TALOS's 16 kg leg on 1000 N m/rad servos
    touches down 30 mm short). zmpwalk computes that torque from the model by inverse dynamics of the
    planned motion with the planned ground reaction:

    .. math:: \tau = M(q)\ddot q + C(q, \dot q) + g(q) + \tau_{passive}(\dot q) - \sum_{feet} J_{foot}^T w_{foot}

    with ``q`` the planned poses (base included), ``q', q''`` their central differences, ``tau_passive`` the
    joints' own damping and dry friction in the model (:func:`passive_torques`: Apptronik Apollo's legs have
    11-171 N m s/rad and 0.9-21 N m, which its swinging legs work against), and ``w`` each
    sole's planned wrench: the force ``m (c'' + g)`` of the pattern's CoM acceleration at the planned ZMP,
    on the stance foot in single support and split between the feet by where the ZMP lies between them in
    double support. The reference of each position actuator becomes ``u = q_ref + tau / (kp gear^2)``.
    ``dynamic=False`` keeps only gravity and the static reaction (``q' = q'' = 0``).

    Args:
        qpos: Planned poses (n, nq) (:func:`zmpwalk.sim.poses.plant_qpos`) at ``rate``.
        zmp: Planned ZMP in world [m], (n, 2).
        support: 0 double, 1 left, 2 right, (n,).
        ankles: Planned left and right ankle positions in world [m], each (n, 3).
        rate: Rows per second [Hz].
        dynamic: Include the inertial terms and the horizontal reaction.
    """
    return servo_offsets(plant, _servo_torques(plant, qpos, zmp, support, ankles, rate, dynamic))


def servo_offsets(plant: Plant, torques: Array) -> Array:
    """Control offsets (n, nu) [rad] that make each position servo deliver ``torques`` (n, nu) [N m]:
    ``tau / (kp gear^2)`` (0 at the other actuators)."""
    model = plant.model
    servos = [a for a in range(model.nu) if is_position_servo(model, a)]
    offsets = np.zeros_like(torques)
    offsets[:, servos] = torques[:, servos] / (model.actuator_gainprm[servos, 0] * model.actuator_gear[servos, 0] ** 2)
    return offsets


def planned_torques(plant: Plant, qpos: Array, zmp: Array, support: NDArray[np.integer],
                    ankles: tuple[Array, Array], rate: float = 1000.0) -> Array:
    """Leg joint torques of the planned motion by inverse dynamics [N m], (n, 12) in the leg-column order.

    The torques behind :func:`static_feedforward` (``dynamic=True``): what an ideal robot needs for the plan,
    against which the simulated motor table is checked.
    """
    return servo_torques(plant, qpos, zmp, support, ankles, rate)[:, plant.leg_actuators]


def servo_torques(plant: Plant, qpos: Array, zmp: Array, support: NDArray[np.integer],
                  ankles: tuple[Array, Array], rate: float = 1000.0, dynamic: bool = True) -> Array:
    """Joint torques of the planned motion at every position servo [N m], (n, nu) (0 at the other actuators):
    :func:`static_feedforward`'s inverse dynamics, for a caller that wants both the torques and the offsets
    (``dynamic=False``: gravity and the static reaction only)."""
    return _servo_torques(plant, qpos, zmp, support, ankles, rate, dynamic)


def _servo_torques(plant: Plant, qpos: Array, zmp: Array, support: NDArray[np.integer],
                   ankles: tuple[Array, Array], rate: float, dynamic: bool) -> Array:
    """Joint torques of the planned motion at each position servo [N m], (n, nu) (0 at other actuators);
    see :func:`static_feedforward`."""
    model = plant.model
    data = mujoco.MjData(model)
    n = len(qpos)
    result_torques = np.zeros((n, model.nu))
    position_actuators = [a for a in range(model.nu) if is_position_servo(model, a)]
    dofs = np.array([model.jnt_dofadr[model.actuator_trnid[a][0]] for a in position_actuators], dtype=int)
    sites = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_ankle") for s in ("left", "right")]
    mass = float(np.sum(model.body_mass))
    gravity = -float(model.opt.gravity[2])
    stride = max(1, round(FEEDFORWARD_PERIOD * rate))
    keys = np.unique(np.append(np.arange(0, n, stride), n - 1))
    torques = np.empty((len(keys), len(position_actuators)))
    result = np.zeros(model.nv)
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    before, after = np.zeros(model.nv), np.zeros(model.nv)
    h = stride / rate
    for row, k in enumerate(keys):
        data.qpos[:] = qpos[k]
        data.qvel[:] = 0.0
        data.qacc[:] = 0.0
        com_acceleration = np.zeros(2)
        if dynamic and stride <= k < n - stride:
            mujoco.mj_differentiatePos(model, before, h, qpos[k - stride], qpos[k])
            mujoco.mj_differentiatePos(model, after, h, qpos[k], qpos[k + stride])
            data.qvel[:] = (before + after) / 2
            data.qacc[:] = (after - before) / h
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        if dynamic:
            mujoco.mj_comVel(model, data)
        mujoco.mj_rne(model, data, 1 if dynamic else 0, result)
        tau = result + passive_torques(model, data.qvel)  # the joints' own damping and friction
        if dynamic and stride <= k < n - stride:
            # the CoM acceleration the ZMP implies (cart-table, Eqs. 1-2 of Park et al.): c'' = (g / l)(c - p)
            com = data.subtree_com[0]
            com_acceleration = gravity / max(float(com[2]), 1e-6) * (com[:2] - zmp[k])
        left, right = ankles[0][k, :2], ankles[1][k, :2]
        if support[k] == LEFT_SUPPORT:
            shares = (1.0, 0.0)
        elif support[k] == RIGHT_SUPPORT:
            shares = (0.0, 1.0)
        else:
            span = right - left
            ratio = float(np.clip((zmp[k] - left) @ span / max(float(span @ span), 1e-12), 0.0, 1.0))
            shares = (1.0 - ratio, ratio)
        base_point = left + (right - left) * shares[1]
        for site, share, ankle in zip(sites, shares, (left, right), strict=True):
            if share == 0.0:
                continue
            cop = np.append(ankle + (zmp[k] - base_point), 0.0)  # this sole's CoP, keeping the total at the ZMP
            force = share * mass * np.array([com_acceleration[0], com_acceleration[1], gravity])
            moment = np.cross(cop - data.site_xpos[site], force)
            mujoco.mj_jacSite(model, data, jacp, jacr, site)
            tau -= jacp.T @ force + jacr.T @ moment
        torques[row] = tau[dofs]
    for column, actuator in enumerate(position_actuators):
        result_torques[:, actuator] = np.interp(np.arange(n), keys, torques[:, column])
    return result_torques


def damping_feedforward(plant: Plant, velocities: Array) -> Array:
    """Control offsets (n, 12) [rad] that cancel the lag of the leg servos' damping at the planned joint rates.

    MuJoCo's position servo applies ``kp (u - q) - kv q'``: at a steady rate ``q'`` it lags by ``kv q' / kp``
    (TALOS's hip: 0.027 rad at 1 rad/s, 19 mm at the foot). With ``u = q_ref + (kv / kp) q'_ref`` it
    tracks the reference: the damping then acts on the rate error, as a PD servo with a velocity
    reference does.

    Args:
        velocities: Planned joint rates [rad/s], (n, 12) in the leg-column order.
    """
    model = plant.model
    ratio = np.array([-model.actuator_biasprm[a][2] / model.actuator_gainprm[a][0] if model.actuator_gainprm[a][0]
                      else 0.0 for a in plant.leg_actuators])  # a virtual column's actuator has no gain
    return np.asarray(velocities * ratio, dtype=np.float64)

