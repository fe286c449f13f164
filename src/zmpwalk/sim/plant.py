"""The plant of a simulation: the robot's own MJCF or URDF model, or the box model of a robot file.

:func:`build_plant` gives one :class:`Plant` either way, so :func:`zmpwalk.sim.run.simulate` never asks
which it runs. For an imported robot (:mod:`zmpwalk.robots.imported`) the plant is the builder's own
model, unmodified in its meshes, masses, inertias, contacts and actuators, with:

* a floor where the file has none (a plane at z = 0, MuJoCo's default contact);
* sensors added where zmpwalk measures, as on the robot: a force-torque sensor at each ankle point
  (a site in the foot body, axes of the foot frame), the pose of the base and of each ankle, and each
  leg joint's angle, rate and actuator torque (``jointactuatorfrc``);
* a time step of at most :data:`MAX_TIMESTEP` (the 1 kHz servo period of the references);
* the leg joints' actuators driven by the joint trajectory, every other actuator holding the
  reference pose (the keyframe's controls).

The leg actuators must be position servos (MuJoCo ``<position>`` or an equivalent ``general``):
zmpwalk sends joint angles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.robots.imported import collision_points, load_model_spec, rigid_bodies
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]

MAX_TIMESTEP = 0.001  # [s]


@dataclass
class Plant:
    """A compiled model with zmpwalk's sensors, and how the 12 joint columns map onto it.

    Attributes:
        model: The MuJoCo model.
        leg_actuators: Actuator index of each joint column (left leg then right, role order), (12,).
        leg_qpos: ``qpos`` address of each joint column, (12,).
        ctrl_hold: Controls of the reference pose (the other actuators keep them), (nu,).
        qpos_hold: The reference pose, (nq,).
        base_offset: The pattern's pelvis point in the base frame (the CoM offset) [m], (3,).
        imported: True for the robot's own model, False for the box model.
    """

    model: mujoco.MjModel
    leg_actuators: NDArray[np.intp]
    leg_qpos: NDArray[np.intp]
    ctrl_hold: Array
    qpos_hold: Array
    base_offset: Array
    imported: bool


def build_plant(robot: RobotModel, mass_scale: float = 1.0) -> Plant:
    """The plant of ``robot`` (see the module docstring).

    Raises:
        InvalidParameterError: A leg joint without a position actuator, or a mass scale on an imported
            model (its masses are the builder's).
    """
    if robot.plant is None:
        from zmpwalk.sim.mjcf import robot_mjcf

        model = mujoco.MjModel.from_xml_string(robot_mjcf(robot, mass_scale))
        qpos = model.qpos0.copy()
        return Plant(model, np.arange(12), np.arange(7, 19), np.zeros(model.nu), qpos, np.zeros(3), False)
    if mass_scale != 1.0:
        raise InvalidParameterError("mass_scale", mass_scale, "1 for a robot imported from its model (its "
                                    "masses are the model's)")
    plant = robot.plant
    spec = load_model_spec(plant.path, plant.package_paths)
    model = spec.compile()
    if model.opt.timestep > MAX_TIMESTEP:
        spec.option.timestep = MAX_TIMESTEP
    if not any(g.type == mujoco.mjtGeom.mjGEOM_PLANE for g in spec.worldbody.geoms):
        spec.worldbody.add_geom(name="zmpwalk_floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0, 0, 0.05])
    # Zero pose of the legs, base at the origin: where the ankle points sit in the foot bodies.
    data = mujoco.MjData(model)
    joint_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint.name) for joint in plant.joints]
    qpos = np.array(plant.qpos_reference)
    zero = qpos.copy()
    for j in joint_ids:
        zero[model.jnt_qposadr[j]] = 0.0
    base = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, plant.base_body)
    base_adr = int(model.jnt_qposadr[model.body_jntadr[base]])
    zero[base_adr:base_adr + 7] = (0, 0, 0, 1, 0, 0, 0)
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
        mujoco.mju_mat2Quat(quaternion, rotation.T.flatten())  # site axes = pelvis axes at the zero pose
        spec.body(foot).add_site(name=f"{label}_ankle", pos=position, quat=quaternion, size=[0.005, 0.005, 0.005])
    sensors = [("pelvis_pos", mujoco.mjtSensor.mjSENS_FRAMEPOS, "pelvis"),
               ("pelvis_quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT, "pelvis")]
    for label in ("left", "right"):
        sensors += [(f"{label}_force", mujoco.mjtSensor.mjSENS_FORCE, f"{label}_ankle"),
                    (f"{label}_torque", mujoco.mjtSensor.mjSENS_TORQUE, f"{label}_ankle"),
                    (f"{label}_ankle_pos", mujoco.mjtSensor.mjSENS_FRAMEPOS, f"{label}_ankle"),
                    (f"{label}_ankle_quat", mujoco.mjtSensor.mjSENS_FRAMEQUAT, f"{label}_ankle")]
    for name, kind, site in sensors:
        sensor = spec.add_sensor(name=name, type=kind, objname=site)
        sensor.objtype = mujoco.mjtObj.mjOBJ_SITE
    for column, joint in zip(JOINT_COLUMNS, plant.joints, strict=True):
        for suffix, kind in (("q", mujoco.mjtSensor.mjSENS_JOINTPOS), ("qd", mujoco.mjtSensor.mjSENS_JOINTVEL),
                             ("tau", mujoco.mjtSensor.mjSENS_JOINTACTFRC)):
            sensor = spec.add_sensor(name=f"{column}_{suffix}", type=kind, objname=joint.name)
            sensor.objtype = mujoco.mjtObj.mjOBJ_JOINT
    model = spec.compile()
    actuators = []
    for column, joint in zip(JOINT_COLUMNS, plant.joints, strict=True):
        if joint.actuator is None or joint.actuator.kind != "position":
            kind = "none" if joint.actuator is None else joint.actuator.kind
            raise InvalidParameterError(f"{column} actuator", kind, "a position servo (MuJoCo <position>): "
                                        "zmpwalk drives the leg joints with joint angles")
        actuators.append(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, joint.actuator.name))
    leg_qpos = np.array([model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.name)]
                         for j in plant.joints])
    offset = np.array([robot.com_offset[0], robot.com_offset[1], 0.0])
    return Plant(model, np.array(actuators), leg_qpos, np.array(plant.ctrl_reference), qpos, offset, True)


def set_initial_state(plant: Plant, data: mujoco.MjData, position_pelvis: Array, yaw: float, angles: Array,
                      penetration: float = 0.0) -> None:
    """Stand the plant in the first pose at rest: the pattern's pelvis point and yaw, the leg angles (12,)
    [rad], the other joints at the reference pose, the lowest sole ``penetration`` [m] into the ground."""
    model = plant.model
    data.qpos[:] = plant.qpos_hold
    c, s = math.cos(yaw), math.sin(yaw)
    offset = plant.base_offset
    data.qpos[0:3] = position_pelvis - np.array([c * offset[0] - s * offset[1], s * offset[0] + c * offset[1], 0.0])
    data.qpos[3:7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    data.qpos[plant.leg_qpos] = angles
    data.qvel[:] = 0.0
    data.ctrl[:] = plant.ctrl_hold
    data.ctrl[plant.leg_actuators] = angles
    mujoco.mj_kinematics(model, data)
    soles = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{s}_ankle") for s in ("left", "right")]
    if plant.imported:
        bottom = min(float(collision_points(model, data, rigid_bodies(model, int(model.site_bodyid[site])))[:, 2]
                           .min()) for site in soles)
    else:
        geoms = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, f"{s}_sole") for s in ("left", "right")]
        bottom = min(float(data.geom_xpos[g][2] - model.geom_size[g][2]) for g in geoms)
    data.qpos[2] += -bottom - penetration
    mujoco.mj_forward(model, data)
