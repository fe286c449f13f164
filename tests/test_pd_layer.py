"""The joint PD layer of torque-driven and unactuated joints (docs/robot-import.md): the gain rule's numbers, what
drives each joint, the torque clipped at the model's limit, a motor-driven arm held at its keyframe, and a URDF
without actuators that walks."""

from __future__ import annotations

import json
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk.balance import servo_stiffness
from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError, InvalidParameterError
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots import load_robot
from zmpwalk.robots.description import PD_BANDWIDTH, PD_LOAD_STIFFNESS, PD_WEAK_ANKLE_LOAD_STIFFNESS
from zmpwalk.robots.inspect import robot_summary, robot_table, robot_toml
from zmpwalk.robots.pd import check_load_stiffness, pd_gains, pd_physics_step, rule_stiffness
from zmpwalk.sim.plant import build_plant, servo_offsets, servo_torques
from zmpwalk.sim.poses import plant_qpos, set_initial_state

LEG = """
<body name="{s}_hip" pos="0 {y} -0.1"><joint name="{s}_hy" axis="0 0 1"/><geom size="0.02" mass="1"/>
 <body name="{s}_hr"><joint name="{s}_hr" axis="1 0 0"/><geom size="0.02" mass="1"/>
  <body name="{s}_hp"><joint name="{s}_hp" axis="0 1 0"/><geom size="0.02" mass="1"/>
   <body name="{s}_shank" pos="0 0 -0.3"><joint name="{s}_kn" axis="0 1 0" range="0 2.4" {knee}/>
    <geom size="0.02" mass="1"/>
    <body name="{s}_ank" pos="0 0 -0.3"><joint name="{s}_ap" axis="0 1 0"/>
     <geom size="0.02" mass="0.2" contype="0" conaffinity="0"/>
     <body name="{s}_foot"><joint name="{s}_ar" axis="1 0 0"/>
      <geom type="box" size="0.1 0.05 0.01" pos="0 0 -0.05" mass="0.5"/>
     </body>
    </body>
   </body>
  </body>
 </body>
</body>"""

ARMATURE = 0.01  # [kg m^2] every joint's rotor inertia in the synthetic models
ARM_KEY = -1.2  # [rad] the arm's keyframe angle: raised forward, its weight pulling it down


def motor_biped(actuators: str | None = None, knee_limit: str = 'actuatorfrcrange="-35 35"') -> str:
    """A 19.4 kg biped with a 1 kg arm; every joint torque-driven (``<motor>``) unless ``actuators`` is given."""
    legs = "".join(LEG.format(s=s, y=y, knee=knee_limit) for s, y in (("l", 0.1), ("r", -0.1)))
    if actuators is None:
        actuators = '<motor name="shoulder_m" joint="shoulder" ctrlrange="-5 5"/>' + "".join(
            f'<motor name="{s}_{j}_m" joint="{s}_{j}" ctrlrange="-20 20" gear="2"/>' if j == "hp" else
            f'<motor name="{s}_{j}_m" joint="{s}_{j}" ctrlrange="-40 40"/>'
            for s in ("l", "r") for j in ("hy", "hr", "hp", "kn", "ap", "ar"))
    return f"""<mujoco><compiler angle="radian"/><default><joint armature="{ARMATURE}" damping="0.1"/></default>
<worldbody><geom type="plane" size="5 5 .1"/>
<body name="base" pos="0 0 0.8"><freejoint/><geom type="box" size="0.1 0.15 0.1" mass="10"/>
 <body name="arm" pos="0 0.2 0.05"><joint name="shoulder" axis="0 1 0" range="-3 3"/>
  <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="1" contype="0" conaffinity="0"/></body>
{legs}</body></worldbody>
<actuator>{actuators}</actuator>
<keyframe><key name="ready" qpos="0 0 0.8 1 0 0 0 {ARM_KEY}{' 0' * 12}"/></keyframe></mujoco>"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_rule_bandwidth_load_and_step_bound() -> None:
    kp, kv = pd_gains(2.0, 10.0)  # heavy and lightly loaded: the bandwidth term
    assert kp == pytest.approx(2.0 * (2 * math.pi * 4.0) ** 2, rel=1e-12)  # 1263.3 N m/rad
    assert kp == pytest.approx(1263.309, abs=1e-3)
    assert kv == pytest.approx(2.0 * math.sqrt(kp * 2.0), rel=1e-12)  # critical on its own inertia
    kp, kv = pd_gains(0.01, 100.0)  # light and loaded: kappa W
    assert kp == pytest.approx(400.0, rel=1e-12) and kv == pytest.approx(2 * math.sqrt(4.0), rel=1e-12)
    kp, kv = pd_gains(1e-4, 1000.0, timestep=0.001)  # a light link would be stiffer than the step allows
    assert kp == pytest.approx(1e-4 * (0.5 / 0.001) ** 2, rel=1e-12)  # 25 N m/rad: sqrt(kp / I) dt = 0.5
    assert kv * 0.001 / 1e-4 == pytest.approx(1.0, rel=1e-12)  # kv dt / I = 2 zeta beta, half the bound 2
    with pytest.raises(InvalidParameterError, match="inertia"):
        pd_gains(0.0, 1.0)


def test_the_physics_step_shortens_where_the_bound_holds_a_leg_joint_below_the_rule() -> None:
    """``pd_physics_step``: the longest of 1, 1/2, 1/4 of the step at which every leg joint's bound
    ``I (0.5 / dt)^2`` reaches the stiffness it needs. A URDF's ankle roll (0.0004 kg m^2, no rotor; ``4 m g l`` =
    940 N m/rad): 100 at 1 ms, 400 at 0.5 ms, 1600 at 0.25 ms; TALOS's ankle roll (0.0104 kg m^2, 3299.2): 2600 at 1
    ms, 10400 at 0.5 ms; a robot file's ``kp`` is the stiffness needed."""
    needed = rule_stiffness(0.0004, 235.0)
    assert needed == pytest.approx(940.0, rel=1e-12)  # [N m/rad] kappa W
    assert pd_physics_step([(0.0004, needed)], 0.001) == pytest.approx(0.00025, abs=1e-15)  # [s]
    assert pd_gains(0.0004, 235.0, 0.00025)[0] == pytest.approx(needed, rel=1e-12)  # the rule's, not the bound
    assert pd_gains(0.0004, 235.0, 0.001)[0] == pytest.approx(100.0, rel=1e-12)  # [N m/rad] the bound at 1 ms
    talos = (0.0104, rule_stiffness(0.0104, 824.8))  # [kg m^2], [N m/rad]
    assert pd_physics_step([talos, (0.1, 3299.2)], 0.001) == pytest.approx(0.0005, abs=1e-15)
    assert pd_physics_step([(0.1, 3299.2), (0.0253, 3299.2)], 0.001) == pytest.approx(0.001, abs=1e-15)  # TALOS knee
    assert pd_physics_step([(0.0004, 380.0)], 0.001) == pytest.approx(0.0005, abs=1e-15)  # 400 >= 380
    assert pd_physics_step([(0.0004, 300.0)], 0.0005) == pytest.approx(0.0005, abs=1e-15)  # 400 >= 300
    assert pd_physics_step([(1e-7, 940.0)], 0.001) == pytest.approx(0.00025, abs=1e-15)  # none fits: the least


def test_motor_legs_get_the_rule_gains_and_their_limits(tmp_path: Path) -> None:
    robot = load_robot(write(tmp_path, "motor.xml", motor_biped()))
    assert robot.plant is not None and robot.legs is not None
    weight_moment = robot.mass * robot.gravity * robot.pendulum_length
    assert robot.mass == pytest.approx(20.4, abs=1e-9)
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "motor.xml"))
    data = mujoco.MjData(model)
    data.qpos[:] = robot.plant.qpos_reference
    for chain in robot.legs:  # the ready posture
        for name, angle in zip(chain.joint_names, chain.reference, strict=True):
            data.qpos[model.joint(name).qposadr[0]] = angle
    mujoco.mj_kinematics(model, data)
    joints = {joint.name: joint for joint in robot.plant.joints}
    # the ankle roll carries the foot only: a 0.5 kg box 0.2 x 0.1 x 0.02 m, 0.05 m below the axis
    foot = 0.5 / 12 * (0.1 ** 2 + 0.02 ** 2) + 0.5 * 0.05 ** 2
    ankle_roll = joints["l_ar"].actuator
    assert ankle_roll is not None and ankle_roll.inertia == pytest.approx(ARMATURE + foot, rel=1e-9)
    # the knee: the shank and ankle spheres and the foot box about the knee axis (parallel axes at the posture)
    axis, anchor = data.xaxis[model.joint("l_kn").id], data.xanchor[model.joint("l_kn").id]
    knee = ARMATURE
    box_foot = 0.5 / 12 * np.array([0.1 ** 2 + 0.02 ** 2, 0.2 ** 2 + 0.02 ** 2, 0.2 ** 2 + 0.1 ** 2])
    for body, own in (("l_shank", np.full(3, 0.4 * 1.0 * 0.02 ** 2)), ("l_ank", np.full(3, 0.4 * 0.2 * 0.02 ** 2)),
                      ("l_foot", box_foot)):
        lever = data.xipos[model.body(body).id] - anchor
        local = data.ximat[model.body(body).id].reshape(3, 3).T @ axis  # the axis in the body's frame
        knee += float(own @ local ** 2) + float(model.body(body).mass[0]) * float(
            np.sum((lever - axis * (axis @ lever)) ** 2))
    knee_actuator = joints["l_kn"].actuator
    assert knee_actuator is not None and knee_actuator.inertia == pytest.approx(knee, rel=1e-6)
    for joint in robot.plant.joints:
        actuator = joint.actuator
        assert actuator is not None and actuator.kind == "motor" and actuator.pd_layer and actuator.servo
        assert actuator.label == "torque motor + PD"
        expected = max(actuator.inertia * PD_BANDWIDTH ** 2, PD_LOAD_STIFFNESS * weight_moment)
        assert actuator.kp == pytest.approx(expected, rel=1e-12)
        assert actuator.kv == pytest.approx(2 * math.sqrt(actuator.kp * actuator.inertia), rel=1e-12)
    assert weight_moment == pytest.approx(119.755, abs=1e-3)  # [N m]: 20.4 kg x 9.81 m/s^2 x 0.5984 m
    assert ankle_roll.kp == pytest.approx(479.020, abs=1e-3)  # [N m/rad]: 4 m g l, the load term (every leg joint)
    assert ankle_roll.kv == pytest.approx(4.731, abs=1e-3)  # [N m s/rad]: 2 sqrt(479.0 x 0.01168)
    limits = {joint.name[2:]: joint.actuator.force_limit for joint in robot.plant.joints if joint.actuator}
    assert limits == {"hy": 40.0, "hr": 40.0, "hp": 40.0, "kn": 35.0, "ap": 40.0, "ar": 40.0}  # gear 2 x 20; 35
    stiffness = servo_stiffness(robot)  # the stabilizer sees the layer's gains
    assert stiffness is not None and stiffness == pytest.approx([j.actuator.kp for j in robot.plant.joints])
    summary = robot_summary(robot)["joints"]
    assert [j["actuator"]["kp"] for j in summary] == pytest.approx(list(stiffness), rel=1e-12)
    assert {j["actuator"]["drive"] for j in summary} == {"torque motor + PD"}


def test_each_joint_says_what_drives_it(tmp_path: Path) -> None:
    actuators = ('<position name="l_hy_p" joint="l_hy" kp="300" kv="5"/><motor name="l_kn_m" joint="l_kn" '
                 'ctrlrange="-40 40"/><position name="r_hy_p" joint="r_hy" kp="300" kv="5"/>'
                 '<motor name="r_kn_m" joint="r_kn" ctrlrange="-40 40"/>'
                 + "".join(f'<position name="{s}_{j}_p" joint="{s}_{j}" kp="400"/>'
                           for s in ("l", "r") for j in ("hr", "hp")))
    robot = load_robot(write(tmp_path, "mixed.xml", motor_biped(actuators, knee_limit="")))
    assert robot.plant is not None
    kinds = {j.name[2:]: (j.actuator.kind, j.actuator.pd_layer, j.actuator.label)
             for j in robot.plant.joints if j.actuator is not None}
    assert kinds == {"hy": ("position", False, "position servo"), "hr": ("position", False, "position servo"),
                     "hp": ("position", False, "position servo"), "kn": ("motor", True, "torque motor + PD"),
                     "ap": ("none", True, "PD (no actuator)"), "ar": ("none", True, "PD (no actuator)")}
    hip_yaw = robot.plant.joints[0].actuator
    assert hip_yaw is not None and (hip_yaw.kp, hip_yaw.kv) == (300.0, 5.0)  # the model's own servo, unchanged
    assert "shoulder" not in dict(robot.plant.pd_joints)  # an unactuated arm in a model with actuators: passive
    plant = build_plant(robot)
    model = plant.model
    for column, joint in enumerate(robot.plant.joints):
        actuator = int(plant.leg_actuators[column])
        assert joint.actuator is not None and model.actuator(actuator).name == joint.actuator.name
        assert model.actuator_gainprm[actuator, 0] == pytest.approx(joint.actuator.kp, rel=1e-12)
        assert model.actuator_biasprm[actuator, 1:3] == pytest.approx([-joint.actuator.kp, -joint.actuator.kv])
    assert model.actuator("zmpwalk_pd_l_ap").forcelimited == 0  # no limit in the model: none added
    assert model.actuator("l_kn_m").forcerange == pytest.approx([-40.0, 40.0])
    knee = model.actuator("l_kn_m").id  # its keyframe control was a torque; now the reference angle
    assert plant.ctrl_hold[knee] == pytest.approx(robot.plant.qpos_reference[model.joint("l_kn").qposadr[0]])
    velocity = write(tmp_path, "velocity.xml", motor_biped(actuators.replace(
        '<motor name="l_kn_m" joint="l_kn" ctrlrange="-40 40"/>', '<velocity name="l_kn_v" joint="l_kn" kv="5"/>'),
        knee_limit=""))
    with pytest.raises(InvalidParameterError, match="left_knee actuator = 'general'"):
        build_plant(load_robot(velocity))


def test_the_pd_torque_is_clipped_at_the_limit(tmp_path: Path) -> None:
    robot = load_robot(write(tmp_path, "motor.xml", motor_biped()))
    plant = build_plant(robot)
    model, data = plant.model, mujoco.MjData(plant.model)
    assert robot.legs is not None and robot.plant is not None
    angles = np.concatenate([chain.reference[list(chain.role_order)] for chain in robot.legs])
    set_initial_state(plant, data, np.array([0.0, 0.0, robot.pelvis_height]), 0.0, angles)
    knee = int(plant.leg_actuators[3])
    limit = robot.plant.joints[3].actuator.force_limit if robot.plant.joints[3].actuator else math.inf
    assert limit == 35.0  # the joint's actuatorfrcrange, below the motor's 40 N m
    mujoco.mj_forward(model, data)
    q, qd = data.qpos[plant.leg_qpos[3]], data.qvel[model.jnt_dofadr[model.joint("l_kn").id]]
    expected = model.actuator_gainprm[knee, 0] * (data.ctrl[knee] - q) + model.actuator_biasprm[knee, 2] * qd
    assert data.actuator_force[knee] == pytest.approx(expected, abs=1e-9)  # the PD law below the limit
    data.ctrl[knee] += 1.0  # a 1 rad step: 236 N m wanted
    forces = []
    for _ in range(300):
        mujoco.mj_step(model, data)
        forces.append(abs(float(data.actuator_force[knee])))
        assert abs(data.qfrc_actuator[model.jnt_dofadr[model.joint("l_kn").id]]) <= limit + 1e-9
    assert max(forces) == pytest.approx(limit, abs=1e-9)  # held at the limit, never past it
    assert sum(f > limit - 1e-9 for f in forces) > 10


def test_a_motor_driven_arm_is_held_at_its_keyframe(tmp_path: Path) -> None:
    robot = load_robot(write(tmp_path, "motor.xml", motor_biped()))
    assert robot.plant is not None
    arm = dict(robot.plant.pd_joints)["shoulder"]
    # a 1 kg, 0.3 m arm about a 0.4 m wide base: its weight moment and bandwidth term
    assert arm.kind == "motor" and arm.force_limit == 5.0
    assert arm.inertia == pytest.approx(ARMATURE + 1.0 * (0.3 ** 2 / 3 + 0.02 ** 2 / 4) + 0.0, rel=0.05)
    assert arm.kp == pytest.approx(max(arm.inertia * PD_BANDWIDTH ** 2, 2 * 1.0 * 9.81 * 0.15), rel=1e-3)
    plant = build_plant(robot)
    pattern = generate(robot, [StepCommand(duration=1.0, forward=0.0)], rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    assert joints.position_base_in_world is not None
    base, angles = joints.position_base_in_world[:1], joints.angles[:1]
    qpos = plant_qpos(plant, base, np.zeros(1), angles)
    ankles = (pattern.position_left_ankle_in_world[:1], pattern.position_right_ankle_in_world[:1])
    offsets = servo_offsets(plant, servo_torques(plant, qpos, pattern.zmp_in_world[:1], np.zeros(1, dtype=int),
                                                 ankles, dynamic=False))[0]
    address = plant.model.joint("shoulder").qposadr[0]
    sag = {}
    for label, feedforward in (("without", 0.0), ("with", 1.0)):
        data = mujoco.MjData(plant.model)
        set_initial_state(plant, data, base[0], 0.0, angles[0])
        data.ctrl[:] = plant.ctrl_hold + feedforward * offsets
        data.ctrl[plant.leg_actuators] = angles[0] + feedforward * offsets[plant.leg_actuators]
        error = []
        for _ in range(1500):  # 1.5 s standing
            mujoco.mj_step(plant.model, data)
            error.append(float(data.qpos[address] - ARM_KEY))
        sag[label] = np.abs(error[-200:]).max()
        assert np.abs(error).max() < 0.08  # [rad]
    weight = 1.0 * 9.81 * 0.15 * math.sin(-ARM_KEY)  # its gravity torque at the keyframe [N m]
    assert sag["without"] == pytest.approx(weight / arm.kp, rel=0.1)  # the PD alone sags by tau / kp
    assert sag["with"] < 0.005  # the feedforward (tau / kp in its target) holds it within 5 mrad


def test_pd_gains_from_the_robot_file(tmp_path: Path) -> None:
    model = write(tmp_path, "motor.xml", motor_biped())
    robot = load_robot(model)
    text = robot_toml(robot, tmp_path)
    assert '# "l_kn" = {kp = ' in text and '# "shoulder" = {kp = ' in text  # the rule's gains, commented out
    text = text.replace('# "l_kn" = {kp = ', '"l_kn" = {kp = 500, kv = 7} # ').replace(
        '# "r_kn" = {kp = ', '"r_kn" = {kp = 500} # ').replace('# "l_hy" = {kp = ', '"l_hy" = {kp = ')
    written = load_robot(write(tmp_path, "motor.toml", text))
    assert written.plant is not None
    gains = {j.name: (j.actuator.kp, j.actuator.kv) for j in written.plant.joints if j.actuator}
    inertia = next(j.actuator.inertia for j in written.plant.joints if j.name == "r_kn" and j.actuator)
    assert gains["l_kn"] == (500.0, 7.0)
    assert gains["r_kn"] == pytest.approx((500.0, 2 * math.sqrt(500.0 * inertia)), rel=1e-12)  # critical
    assert gains["l_hy"] == pytest.approx((robot.plant.joints[0].actuator.kp, robot.plant.joints[0].actuator.kv),
                                          rel=1e-5)  # as written, 6 digits
    with pytest.raises(FileFormatError, match=r"\[pd\] pd joint = 'nope'"):
        load_robot(write(tmp_path, "bad.toml", text.replace('"l_kn" = {kp = 500', '"nope" = {kp = 500')))
    with pytest.raises(FileFormatError, match=r"\[pd\] l_kn kp = -1"):
        load_robot(write(tmp_path, "neg.toml", text.replace('"l_kn" = {kp = 500', '"l_kn" = {kp = -1')))


def test_the_robot_files_load_stiffness_is_the_rules_kappa(tmp_path: Path) -> None:
    """``[pd] load_stiffness`` replaces the rule's kappa for the joints the file does not give: a leg joint whose
    gain is the weight term (kappa W) doubles from 4 to 8, critically damped; a named joint keeps its gains; the
    written file offers the field; a kappa of 1 or less, or not a number, is refused naming it."""
    model = write(tmp_path, "motor.xml", motor_biped())
    robot = load_robot(model)
    assert robot.plant is not None
    text = robot_toml(robot, tmp_path)
    assert "# load_stiffness = 4   # [-]" in text
    kept = text.replace('# "l_kn" = {kp = ', '"l_kn" = {kp = ')  # one joint given, the others derived
    stiffer = load_robot(write(tmp_path, "k8.toml", kept.replace("# load_stiffness = 4", "load_stiffness = 8")))
    assert stiffer.plant is not None and stiffer.plant.load_stiffness == 8.0
    before = {j.name: j.actuator for j in robot.plant.joints if j.actuator}
    after = {j.name: j.actuator for j in stiffer.plant.joints if j.actuator}
    weight = robot.mass * robot.gravity * robot.pendulum_length  # W of a leg joint [N m]
    weighted = [name for name, a in before.items() if a.kp == pytest.approx(PD_LOAD_STIFFNESS * weight, rel=1e-12)]
    assert weighted  # the synthetic legs' gains come from kappa W
    for name in weighted:
        if name == "l_kn":  # listed in the file: as written, 6 digits
            assert after[name].kp == pytest.approx(before[name].kp, rel=1e-5)
            continue
        # W from the file's robot: its written pelvis height (6 digits) moves the pendulum by a few micrometres
        assert after[name].kp == pytest.approx(8.0 * stiffer.mass * stiffer.gravity * stiffer.pendulum_length,
                                               rel=1e-12)
        assert after[name].kv == pytest.approx(2 * math.sqrt(after[name].kp * after[name].inertia), rel=1e-12)
    for bad in ("1", "0.5", '"stiff"', "nan"):
        with pytest.raises(FileFormatError, match=r"\[pd\] load_stiffness = .*a finite number > 1"):
            load_robot(write(tmp_path, "bad.toml", kept.replace("# load_stiffness = 4", f"load_stiffness = {bad}")))
    with pytest.raises(FileFormatError, match=r"pd joint = 'load_stiffness'"):  # a table: a joint of that name
        load_robot(write(tmp_path, "joint.toml", kept.replace("# load_stiffness = 4", "load_stiffness = {kp = 500}")))
    with pytest.raises(InvalidParameterError, match="load_stiffness"):  # an integer beyond a float's range
        check_load_stiffness(10 ** 400)
    assert check_load_stiffness(np.int64(8)) == 8.0
    # written again from the file's robot: kappa and the joint the file gives stay given, the others commented out
    again = robot_toml(stiffer, tmp_path)
    assert "\nload_stiffness = 8   # [-]" in again and '\n"l_kn" = {kp = ' in again and '\n# "r_kn" = {kp = ' in again
    assert load_robot(write(tmp_path, "again.toml", again)).plant == stiffer.plant


def inertial(mass: float, com: str, inertia: tuple[float, float, float]) -> str:
    return (f'<inertial><origin xyz="{com}"/><mass value="{mass}"/><inertia ixx="{inertia[0]}" iyy="{inertia[1]}" '
            f'izz="{inertia[2]}" ixy="0" ixz="0" iyz="0"/></inertial>')


def box(mass: float, x: float, y: float, z: float) -> tuple[float, float, float]:
    return mass / 12 * (y * y + z * z), mass / 12 * (x * x + z * z), mass / 12 * (x * x + y * y)


EFFORT = 60.0  # [N m] every joint's <limit effort> in the URDF


def urdf_biped(foot_mass: float = 0.6) -> str:
    """An 18.6 kg URDF biped with no actuators: a torso, 6-joint legs with masses and inertias, box feet of
    ``foot_mass`` [kg]."""
    parts = ['<robot name="urdf_biped">', f'<link name="torso">{inertial(10.0, "0 0 0.1", box(10.0, 0.2, 0.3, 0.3))}'
             "</link>"]
    for side, y in (("l", 0.1), ("r", -0.1)):
        parent = "torso"
        for name, axis, origin, lower, upper, mass, com, inertia in (
                ("hip_yaw", "0 0 1", f"0 {y} -0.1", -0.8, 0.8, 0.5, "0 0 0", (1e-3, 1e-3, 1e-3)),
                ("hip_roll", "1 0 0", "0 0 0", -0.6, 0.6, 0.5, "0 0 0", (1e-3, 1e-3, 1e-3)),
                ("hip_pitch", "0 1 0", "0 0 0", -1.6, 1.0, 1.5, "0 0 -0.15", box(1.5, 0.06, 0.06, 0.3)),
                ("knee", "0 1 0", "0 0 -0.3", 0.0, 2.4, 1.0, "0 0 -0.15", box(1.0, 0.05, 0.05, 0.3)),
                ("ankle_pitch", "0 1 0", "0 0 -0.3", -1.0, 1.0, 0.2, "0 0 0", (2e-4, 2e-4, 2e-4)),
                ("ankle_roll", "1 0 0", "0 0 0", -0.5, 0.5, foot_mass, "0.02 0 -0.05",
                 box(foot_mass, 0.22, 0.14, 0.02))):
            link = f"{side}_{name}_link"
            sole = ('<collision><origin xyz="0.02 0 -0.05"/><geometry><box size="0.22 0.14 0.02"/></geometry>'
                    "</collision>") if name == "ankle_roll" else ""
            parts += [f'<link name="{link}">{inertial(mass, com, inertia)}{sole}</link>',
                      f'<joint name="{side}_{name}" type="revolute"><parent link="{parent}"/><child link="{link}"/>'
                      f'<origin xyz="{origin}"/><axis xyz="{axis}"/><limit lower="{lower}" upper="{upper}" '
                      f'effort="{EFFORT}" velocity="10"/><dynamics damping="0.1"/></joint>']
            parent = link
    return "\n".join([*parts, "</robot>"])


def test_a_urdf_without_actuators_walks_six_steps(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.cli import main

    urdf = write(tmp_path, "biped.urdf", urdf_biped())
    robot = load_robot(urdf)
    assert robot.plant is not None and robot.mass == pytest.approx(18.6, abs=1e-9)
    for joint in robot.plant.joints:  # the effort limit arrives as the joint's actuatorfrcrange
        assert joint.actuator is not None and joint.actuator.kind == "none" and joint.actuator.pd_layer
        assert joint.actuator.force_limit == EFFORT
    steps = write(tmp_path, "steps.toml", "[[steps]]\nduration = 0.8\nforward = 0.05\nrepeat = 6\n")
    code = main(["simulate", "--robot", str(urdf), str(steps), "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["verdict"]["state"] == "PASS" and not summary["fell"]
    assert summary["final_feet_error"] < 0.02  # [m]
    assert summary["distance"] == pytest.approx(0.30, abs=0.03)  # [m]: six 5 cm steps and the closing one
    assert max(row["impact_torque"] for row in summary["actuators"]) <= EFFORT + 1e-9  # [N m]


def test_a_position_servo_s_control_range_does_not_clip_its_feedforward(tmp_path: Path) -> None:
    """Low-gain position servos whose control range is the joint's (``inheritrange``, as many humanoid models
    declare them): the plant lifts the range, so an offset that carries a feedforward torque past it is not
    clipped, while the joint's force range still bounds the torque."""
    actuators = "".join(f'<position name="{s}_{j}_p" joint="{s}_{j}" kp="20" kv="1" ctrlrange="-0.5 0.5" '
                        'forcerange="-30 30" forcelimited="true"/>'
                        for s in ("l", "r") for j in ("hy", "hr", "hp", "kn", "ap", "ar"))
    actuators += '<position name="shoulder_p" joint="shoulder" kp="20" ctrlrange="-1.3 1.3"/>'
    robot = load_robot(write(tmp_path, "servo.xml", motor_biped(actuators, knee_limit="")))
    plant = build_plant(robot)
    model, data = plant.model, mujoco.MjData(plant.model)
    assert not model.actuator_ctrllimited.any()  # every position servo's range lifted
    assert robot.legs is not None
    angles = np.concatenate([chain.reference[list(chain.role_order)] for chain in robot.legs])
    set_initial_state(plant, data, np.array([0.0, 0.0, robot.pelvis_height]), 0.0, angles)
    ankle = int(plant.leg_actuators[4])
    q = float(data.qpos[plant.leg_qpos[4]])
    data.ctrl[ankle] = q + 12.0 / 20.0  # a 12 N m feedforward on the angle: 0.6 rad, past the 0.5 rad range
    mujoco.mj_forward(model, data)
    assert data.actuator_force[ankle] == pytest.approx(12.0, abs=0.5)  # [N m] (kv q' of the settling pose)
    data.ctrl[ankle] = q + 2.0  # 40 N m wanted: the force range holds it at 30
    mujoco.mj_forward(model, data)
    assert abs(data.actuator_force[ankle]) == pytest.approx(30.0, abs=1e-9)


def test_a_position_servo_is_held_at_the_reference_angle_whatever_the_keyframe_controls(tmp_path: Path) -> None:
    """A position servo's control is the angle it holds (times its gear): the other servos hold the keyframe's
    pose even where the keyframe gives no controls (MuJoCo then reads 0) or gives them in another order."""
    legs = "".join(f'<position name="{s}_{j}_p" joint="{s}_{j}" kp="300" kv="5"/>'
                   for s in ("l", "r") for j in ("hy", "hr", "hp", "kn", "ap", "ar"))
    arm = '<position name="shoulder_p" joint="shoulder" kp="20" kv="1" gear="2"/>'
    no_controls = motor_biped(arm + legs, knee_limit="")
    shuffled = no_controls.replace(f'qpos="0 0 0.8 1 0 0 0 {ARM_KEY}{" 0" * 12}"/>',
                                   f'qpos="0 0 0.8 1 0 0 0 {ARM_KEY}{" 0" * 12}" ctrl="{" 0" * 12} {ARM_KEY}"/>')
    assert shuffled != no_controls  # the arm's angle given to the last actuator, a leg's
    for name, text in (("bare.xml", no_controls), ("shuffled.xml", shuffled)):
        plant = build_plant(load_robot(write(tmp_path, name, text)))
        model, data = plant.model, mujoco.MjData(plant.model)
        shoulder = model.actuator("shoulder_p").id
        assert plant.ctrl_hold[shoulder] == pytest.approx(2 * ARM_KEY, abs=1e-12)  # gear x angle [rad]
        data.qpos[:] = plant.qpos_hold
        data.ctrl[:] = plant.ctrl_hold
        base = model.body("base").id
        model.body_gravcomp[base] = 1.0  # the base hangs still: the arm alone
        for _ in range(500):
            data.qvel[:6] = 0.0
            data.qpos[:7] = plant.qpos_hold[:7]
            mujoco.mj_step(model, data)
        # its weight (1 kg, 0.15 m, 1.2 rad: 1.37 N m) on gear^2 kp = 80 N m/rad sags it 17 mrad, not 1.2 rad
        assert data.qpos[model.joint("shoulder").qposadr[0]] == pytest.approx(ARM_KEY, abs=0.03)


def test_the_feedforward_carries_the_joints_own_damping_and_friction(tmp_path: Path) -> None:
    """A joint's ``damping`` b and ``frictionloss`` f in the model take ``b q' + f tanh(q' / v_f)`` from a motion at
    ``q'``: the per-tick feedforward adds it to the inverse dynamics (Apptronik Apollo's legs: 11-171 N m s/rad,
    0.9-21 N m), so a swinging leg is not held back by the joints it moves."""
    from zmpwalk.online import WalkingSample
    from zmpwalk.sim.mujoco_plant import ModelFeedforward
    from zmpwalk.sim.plant import FRICTION_RATE, servo_torques

    servos = "".join(f'<position name="{s}_{j}_p" joint="{s}_{j}" kp="300" kv="5"/>'
                     for s in ("l", "r") for j in ("hy", "hr", "hp", "kn", "ap", "ar"))
    plain = motor_biped(servos, knee_limit="")
    lossy = plain.replace('damping="0.1"/>', 'damping="2.0" frictionloss="3.0"/>', 1)
    assert lossy != plain
    rates = np.array([0.0, 0.0, 0.5, 1.0, -0.5, 0.01] * 2)  # [rad/s] the legs' planned rates, column order
    torques = {}
    for name, text in (("plain", plain), ("lossy", lossy)):
        robot = load_robot(write(tmp_path, f"{name}.xml", text))
        plant = build_plant(robot)
        assert robot.legs is not None
        angles = np.concatenate([chain.reference[list(chain.role_order)] for chain in robot.legs])
        half = robot.hip_spacing / 2
        sample = WalkingSample(0.0, "double", np.array([0.0, 0.0, robot.pelvis_height]), 0.0,
                               np.array([0.0, half, robot.ankle_height]), 0.0,
                               np.array([0.0, -half, robot.ankle_height]), 0.0, np.zeros(2))
        sample.joint_angles, sample.joint_velocities = angles, rates
        torques[name] = ModelFeedforward(plant, 1000.0).torques(sample)
    expected = (2.0 - 0.1) * rates + 3.0 * np.tanh(rates / FRICTION_RATE)  # [N m] (plain: damping 0.1, no friction)
    assert torques["lossy"] - torques["plain"] == pytest.approx(expected, abs=1e-9)
    assert expected[5] == pytest.approx(1.9 * 0.01 + 3.0 * math.tanh(0.2), abs=1e-12)  # near rest the friction fades
    # the batch feedforward (static_feedforward's torques): the left knee at a steady 1 rad/s over 21 samples
    batch = {}
    for name, text in (("plain", plain), ("lossy", lossy)):
        robot = load_robot(write(tmp_path, f"{name}.xml", text))
        plant = build_plant(robot)
        assert robot.legs is not None
        qpos = np.tile(plant.qpos_hold, (21, 1))
        knee = plant.leg_qpos[3]
        qpos[:, knee] += 0.001 * np.arange(21)  # [rad] 1 rad/s at 1 kHz
        half = robot.hip_spacing / 2
        ankles = (np.tile([0.0, half, robot.ankle_height], (21, 1)), np.tile([0.0, -half, robot.ankle_height], (21, 1)))
        torques_batch = servo_torques(plant, qpos, np.zeros((21, 2)), np.zeros(21, dtype=int), ankles, 1000.0)
        batch[name] = torques_batch[10, plant.leg_actuators[3]]  # [N m] a middle sample (central differences)
    assert batch["lossy"] - batch["plain"] == pytest.approx(1.9 * 1.0 + 3.0 * math.tanh(1.0 / FRICTION_RATE),
                                                            abs=1e-9)


def test_a_urdfs_light_feet_shorten_the_physics_step_to_hold_them(tmp_path: Path,
                                                                  capsys: pytest.CaptureFixture[str]) -> None:
    """Feet of 50 g (no rotor inertia, as a URDF gives them): at 1 ms the bound would hold the ankle rolls below
    ``m g l``; the simulation runs at 0.25 ms (four steps a 1 kHz tick) and they get the rule's ``kappa W``. The
    same gains given in a robot file keep that step."""
    from zmpwalk.cli import main
    from zmpwalk.sim.plant import build_plant

    urdf = write(tmp_path, "light.urdf", urdf_biped(foot_mass=0.05))
    robot = load_robot(urdf)
    assert robot.plant is not None
    weight_moment = robot.mass * robot.gravity * robot.pendulum_length  # [N m]
    roll = next(j for j in robot.plant.joints if j.role == "ankle_roll")
    assert roll.actuator is not None and roll.actuator.inertia * (0.5 / 0.001) ** 2 < weight_moment
    assert robot.plant.model_step == pytest.approx(0.001, abs=1e-15)
    assert robot.plant.physics_step == pytest.approx(0.00025, abs=1e-15)  # [s]
    assert roll.actuator.kp == pytest.approx(4.0 * weight_moment, rel=1e-9)  # [N m/rad] the rule, not the bound
    assert build_plant(robot).model.opt.timestep == pytest.approx(0.00025, abs=1e-15)
    assert main(["robot", str(urdf)]) == 0
    assert "dt = 0.25 ms, shortened from the model's 1 ms" in capsys.readouterr().out
    gains = "".join(f'"{j.name}" = {{kp = {j.actuator.kp!r}, kv = {j.actuator.kv!r}}}\n'
                    for j in robot.plant.joints if j.actuator is not None and j.actuator.pd_layer)
    given = load_robot(write(tmp_path, "light.toml", f'[model]\nfile = "{urdf}"\n[pd]\n{gains}'))
    assert given.plant is not None and given.plant.physics_step == pytest.approx(0.00025, abs=1e-15)
    heavy = load_robot(write(tmp_path, "heavy.urdf", urdf_biped()))
    assert heavy.plant is not None and heavy.plant.physics_step == pytest.approx(0.001, abs=1e-15)
    assert main(["robot", str(write(tmp_path, "heavy2.urdf", urdf_biped()))]) == 0
    assert "dt = 1 ms;" in capsys.readouterr().out


def test_ankle_rolls_weaker_than_the_weight_at_the_sole_edge_double_the_rules_kappa(tmp_path: Path) -> None:
    """The rule's kappa is 8 where an ankle roll cannot hold the robot's weight with the CoP on the sole's side
    edge (20.4 kg x 9.81 m/s^2 x 0.05 m = 10.0 N m for the 0.1 m wide soles): ankle rolls of 8 N m double every
    leg joint's load term; 12 N m keep 4; a five-joint leg (no ankle roll) counts as none; a robot file's kappa
    still rules, and the file written from the derived robot leaves it commented out."""
    def with_ankle_rolls(limit: float) -> str:
        return motor_biped().replace('joint="l_ar" ctrlrange="-40 40"', f'joint="l_ar" ctrlrange="-{limit} {limit}"')

    weak = load_robot(write(tmp_path, "weak.xml", with_ankle_rolls(8)))
    strong = load_robot(write(tmp_path, "strong.xml", with_ankle_rolls(12)))
    assert weak.plant is not None and strong.plant is not None
    assert weak.plant.sole_edge_moment == pytest.approx(20.4 * 9.81 * 0.05, rel=1e-9)  # [N m] 10.0
    assert (weak.plant.ankle_roll_torque, strong.plant.ankle_roll_torque) == (8.0, 12.0)  # the weaker of the two
    assert (weak.plant.load_stiffness, strong.plant.load_stiffness) == (PD_WEAK_ANKLE_LOAD_STIFFNESS, 4.0)
    weight_moment = weak.mass * weak.gravity * weak.pendulum_length  # [N m]
    knee = {j.name: j.actuator for j in weak.plant.joints}["l_kn"]
    assert knee is not None and knee.kp == pytest.approx(8.0 * weight_moment, rel=1e-12)
    summary = robot_summary(weak)
    assert (summary["load_stiffness"], summary["ankle_roll_torque"]) == (8.0, 8.0)
    assert "kappa = 8 (the ankle rolls hold 8 N m, the weight at the sole's side edge 10 N m: the hips carry" \
        in robot_table(weak)
    text = robot_toml(weak, tmp_path)
    assert "\n# load_stiffness = 8   # [-]" in text  # derived, not the file's
    assert load_robot(write(tmp_path, "weak.toml", text)).plant == weak.plant
    given = load_robot(write(tmp_path, "given.toml", text.replace("# load_stiffness = 8", "load_stiffness = 4")))
    assert given.plant is not None and given.plant.load_stiffness == 4.0
    assert "kappa = 4: the robot file's (derived: 8," in robot_table(given)
