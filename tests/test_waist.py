"""Legs below a waist: a model whose floating root is the torso, the legs hanging from a pelvis under waist joints
(ToddlerBot's class). Below a waist that no actuator of its own drives (tied to its motor by a tendon), the legs'
base is the pelvis: the import's frame, the plant's sensors and the pose the plan gives, the root placed from it;
below a servo-held waist, the floating torso (zmpwalk.robots.tree)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk.online import OnlineWalker
from zmpwalk.robots import load_robot
from zmpwalk.robots.inspect import robot_table
from zmpwalk.robots.tree import base_mount, root_from_base
from zmpwalk.sim.mujoco_plant import MujocoPlant
from zmpwalk.sim.plant import build_plant
from zmpwalk.sim.poses import set_base_pose

TORSO_MASS = 8.0  # [kg]
TORSO_COM = (0.02, 0.0, 0.25)  # [m] in the pelvis frame at the reference pose
WAIST = (0.0, 0.0, 0.12)  # [m] the waist joints' place in the pelvis frame


def _inertia(mass: float, x: float, y: float, z: float) -> str:
    return f"{mass / 12 * (y * y + z * z):.6g} {mass / 12 * (x * x + z * z):.6g} {mass / 12 * (x * x + y * y):.6g}"


def _legs() -> str:
    """Two six-joint legs (hip yaw, roll, pitch, knee, ankle pitch, roll), 0.2 m apart, torque motors."""
    spec = (("hip_yaw", "0 0 1", 0.5, "0 0 0", "0.001 0.001 0.001", "-0.8 0.8", "0 {y} -0.1"),
            ("hip_roll", "1 0 0", 0.5, "0 0 0", "0.001 0.001 0.001", "-0.6 0.6", "0 0 0"),
            ("hip_pitch", "0 1 0", 1.5, "0 0 -0.15", _inertia(1.5, 0.06, 0.06, 0.3), "-1.6 1.0", "0 0 0"),
            ("knee", "0 1 0", 1.0, "0 0 -0.15", _inertia(1.0, 0.05, 0.05, 0.3), "0 2.4", "0 0 -0.3"),
            ("ankle_pitch", "0 1 0", 0.1, "0 0 0", "0.0001 0.0001 0.0001", "-1.0 1.0", "0 0 -0.3"),
            ("ankle_roll", "1 0 0", 0.8, "0.02 0 -0.05", _inertia(0.8, 0.22, 0.14, 0.02), "-0.5 0.5", "0 0 0"))
    legs = ""
    for side, y in (("l", 0.1), ("r", -0.1)):
        inner = '<geom type="box" size="0.11 0.07 0.01" pos="0.02 0 -0.05" mass="0"/>'
        for name, axis, mass, com, inertia, limits, pos in reversed(spec):
            inner = (f'<body name="{side}_{name}_link" pos="{pos.format(y=y)}"><joint name="{side}_{name}" '
                     f'axis="{axis}" range="{limits}"/><inertial pos="{com}" mass="{mass}" diaginertia="{inertia}"/>'
                     f"{inner}</body>")
        legs += inner
    return legs


def _motors(named: bool = True) -> str:
    joints = [f"{side}_{name}" for side in "lr"
              for name in ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")]
    return "".join(f'<motor {f"name={joint!r} " if named else ""}joint="{joint}" ctrlrange="-80 80"/>'
                   for joint in joints)


def waisted_biped(slack: float = 0.0, waist_roll: float = 0.0, servo: bool = False) -> str:
    """A 19.6 kg biped whose floating root is an 8 kg torso on a waist (yaw, then roll) above the pelvis the legs
    hang from (torque motors). The waist roll is driven through a gear joint on the pelvis (``waist_act``, a
    position servo), coupled by a tendon that leaves it ``slack`` [rad] either way, as ToddlerBot's; the keyframe
    rolls the waist by ``waist_roll`` [rad]. With ``servo`` the waist roll has a position servo of its own instead
    of the tendon."""
    wx, wy, wz = WAIST
    tx, ty, tz = TORSO_COM
    limited = f'limited="true" range="{-slack - 1e-6} {slack + 1e-6}"'
    coupling = ('<tendon><fixed name="waist_coupling" ' + limited + '><joint joint="waist_roll" coef="1"/>'
                '<joint joint="waist_act" coef="-1"/></fixed></tendon>')
    own = '<position joint="waist_roll" kp="400" kv="20"/>' if servo else ""
    return f"""<mujoco model="waisted"><compiler angle="radian"/>
<default><joint armature="0.01" damping="0.1"/></default>
<worldbody><geom name="floor" type="plane" size="5 5 .1"/>
<body name="torso" pos="{wx} {wy} {0.7 + wz}"><freejoint/>
 <inertial pos="{tx - wx} {ty - wy} {tz - wz}" mass="{TORSO_MASS}" diaginertia="{_inertia(TORSO_MASS, .2, .3, .3)}"/>
 <body name="waist_link"><joint name="waist_yaw" axis="0 0 1" range="-1 1"/>
  <inertial pos="0 0 0" mass="0.05" diaginertia="0.0001 0.0001 0.0001"/>
  <body name="pelvis" pos="{-wx} {-wy} {-wz}"><joint name="waist_roll" axis="1 0 0" pos="{wx} {wy} {wz}" range="-1 1"/>
   <inertial pos="0 0 0" mass="2" diaginertia="0.02 0.02 0.02"/>
   <body name="waist_gear"><joint name="waist_act" axis="0 1 0" range="-3 3"/>
    <inertial pos="0 0 0" mass="0.01" diaginertia="0.00001 0.00001 0.00001"/></body>
   {_legs()}
  </body>
 </body>
</body></worldbody>
{"" if servo else coupling}
<actuator>{_motors()}<position joint="waist_act" kp="400" kv="10"/><position joint="waist_yaw" kp="400" kv="20"/>{own}
</actuator>
<keyframe><key name="home" qpos="{wx} {wy} {0.7 + wz} 1 0 0 0 0 {waist_roll} {waist_roll} {'0 ' * 12}"/></keyframe>
</mujoco>"""


def pelvis_rooted_biped(named: bool = True) -> str:
    """The same masses with the pelvis as the floating root and the torso welded above it; its motors ``named``
    or not."""
    wx, wy, wz = WAIST
    tx, ty, tz = TORSO_COM
    return f"""<mujoco model="rooted"><compiler angle="radian"/>
<default><joint armature="0.01" damping="0.1"/></default>
<worldbody><geom name="floor" type="plane" size="5 5 .1"/>
<body name="pelvis" pos="0 0 0.7"><freejoint/><inertial pos="0 0 0" mass="2" diaginertia="0.02 0.02 0.02"/>
 <body name="torso"><inertial pos="{tx} {ty} {tz}" mass="{TORSO_MASS}" diaginertia="0.1 0.1 0.1"/></body>
 <body name="waist_link" pos="{wx} {wy} {wz}"><inertial pos="0 0 0" mass="0.05" diaginertia="0.0001 0.0001 0.0001"/>
 </body>
 <body name="waist_gear"><inertial pos="0 0 0" mass="0.01" diaginertia="0.00001 0.00001 0.00001"/></body>
 {_legs()}
</body></worldbody>
<actuator>{_motors(named)}</actuator>
</mujoco>"""


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_legs_base_is_the_pelvis_below_the_waist(tmp_path: Path) -> None:
    """The pelvis's frame is the robot's: the hips, the sole, the ready posture and the CoM offset are those of the
    same masses with the pelvis as the root (the torso's inertia about its own CoM aside, which no figure uses);
    the waist joints are held."""
    waisted = load_robot(write(tmp_path, "waisted.xml", waisted_biped()))
    rooted = load_robot(write(tmp_path, "rooted.xml", pelvis_rooted_biped()))
    assert waisted.plant is not None and waisted.plant.base_body == "pelvis" and waisted.plant.root_body == "torso"
    assert rooted.plant is not None and rooted.plant.root_body == ""
    assert "base 'pelvis' (below the floating 'torso', its waist held" in robot_table(waisted)
    assert {"waist_yaw", "waist_roll", "waist_act"} <= set(waisted.plant.held_joints)
    assert waisted.legs is not None and rooted.legs is not None
    for mine, theirs in zip(waisted.legs, rooted.legs, strict=True):
        assert mine.hip == pytest.approx(theirs.hip, abs=1e-12)  # [m]
        assert mine.reference == pytest.approx(theirs.reference, abs=1e-9)  # [rad] the ready posture
    for field in ("pelvis_height", "pendulum_length", "ankle_height", "hip_spacing"):
        assert getattr(waisted, field) == pytest.approx(getattr(rooted, field), abs=1e-9), field  # [m]
    assert waisted.com_offset == pytest.approx(rooted.com_offset, abs=1e-9)  # [m]
    assert waisted.mass == pytest.approx(rooted.mass, abs=1e-12)  # [kg]


def test_a_waist_held_by_its_own_servos_is_rigid_with_the_floating_base(tmp_path: Path) -> None:
    """Every waist joint driven by its own actuator (Booster T1's waist yaw): the floating torso stays the legs'
    base, as the arms it carries; the hips are then seen from it."""
    robot = load_robot(write(tmp_path, "servo.xml", waisted_biped(servo=True)))
    assert robot.plant is not None and robot.plant.base_body == "torso"
    assert build_plant(robot).mount is None
    assert robot.legs is not None
    assert robot.legs[0].hip == pytest.approx(np.array([0.0, 0.1, -0.1]) - np.array(WAIST), abs=1e-12)  # [m]


def test_a_model_without_actuators_keeps_its_floating_base(tmp_path: Path) -> None:
    """Without actuators (a URDF's case) the PD layer drives every joint, the waist's too, as a servo would hold
    it: the floating torso stays the legs' base."""
    text = waisted_biped()
    text = text[:text.index("<tendon>")] + text[text.index("</actuator>") + len("</actuator>"):]
    robot = load_robot(write(tmp_path, "bare.xml", text))
    assert robot.plant is not None and robot.plant.base_body == "torso" and robot.plant.root_body == ""


@pytest.mark.parametrize("waist_roll", [0.0, 0.1])
def test_the_root_is_placed_from_the_pelvis(tmp_path: Path, waist_roll: float) -> None:
    """The plant writes the root's pose that puts the pelvis where the plan puts it, upright at its yaw or turned
    by a given quaternion, with the waist rolled in the keyframe (the pelvis then turned on the root)."""
    robot = load_robot(write(tmp_path, "waisted.xml", waisted_biped(waist_roll=waist_roll)))
    plant = build_plant(robot)
    model, data = plant.model, mujoco.MjData(plant.model)
    pelvis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
    assert plant.mount is not None
    offset, rotation = plant.mount
    assert offset == pytest.approx(-rot_x(waist_roll) @ np.array(WAIST), abs=1e-12)  # [m] turned about the waist
    assert rotation == pytest.approx(rot_x(waist_roll), abs=1e-12)
    position, yaw = np.array([0.3, -0.2, 0.65]), 0.7  # [m], [rad]
    data.qpos[:] = plant.qpos_hold
    set_base_pose(plant, data.qpos, position, yaw)
    mujoco.mj_kinematics(model, data)
    assert data.xpos[pelvis] == pytest.approx(position, abs=1e-12)
    assert data.xmat[pelvis].reshape(3, 3) == pytest.approx(rot_z(yaw), abs=1e-12)
    quaternion = np.array([0.9, 0.1, -0.2, 0.3]) / np.linalg.norm([0.9, 0.1, -0.2, 0.3])
    set_base_pose(plant, data.qpos, position, 0.0, quaternion)
    mujoco.mj_kinematics(model, data)
    assert data.xquat[pelvis] == pytest.approx(quaternion, abs=1e-12)
    assert data.xpos[pelvis] == pytest.approx(position, abs=1e-12)
    root, turned = root_from_base(base_mount(model, plant.qpos_hold, 1, pelvis), position, np.eye(3))
    assert root == pytest.approx(position + np.array(WAIST), abs=1e-12)  # [m] the root's origin: the waist point
    assert turned == pytest.approx(rot_x(-waist_roll), abs=1e-12)


def test_the_plant_stands_the_pelvis_and_ankles_where_planned(tmp_path: Path) -> None:
    """Stood at the walker's first sample, the ankle sites are at the planned ankles and the pelvis sensor reads
    the pose the legs' angles put it in (the root placed from it)."""
    robot = load_robot(write(tmp_path, "waisted.xml", waisted_biped()))
    plant = MujocoPlant(robot, 1000.0)
    sample = OnlineWalker(robot, rate=1000.0, joints=True).tick()
    plant.stand(sample)
    model, data = plant.model, plant.data
    for label, planned in (("left", sample.position_left_ankle_in_world),
                           ("right", sample.position_right_ankle_in_world)):
        site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{label}_ankle")
        assert data.site_xpos[site][:2] == pytest.approx(planned[:2], abs=1e-9)  # [m]
    measured = plant.measure()
    assert measured.attitude == pytest.approx([0.0, 0.0], abs=1e-12)  # [rad] the pelvis upright
    pelvis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
    assert data.xpos[pelvis][2] == pytest.approx(robot.pelvis_height, abs=2e-3)  # [m] the soles on the floor


@pytest.mark.slow
def test_a_biped_on_a_slack_waist_walks_its_side_steps(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """ToddlerBot's waist roll is coupled to its motor with 0.03 rad of slack either way: the torso rolls within
    it, and a stabilizer that measured the torso for the pelvis leaned the legs by it (ToddlerBot fell at its
    first side steps). Measured on the pelvis, 4 side steps of 5 cm pass."""
    from zmpwalk.cli import main

    path = write(tmp_path, "slack.xml", waisted_biped(slack=0.03))
    steps = write(tmp_path, "side.toml", "[[steps]]\nduration = 0.8\nside = 0.05\nrepeat = 4\n")
    code = main(["simulate", "--robot", str(path), str(steps), "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["verdict"]["state"] == "PASS" and not summary["fell"]
    assert summary["distance"] == pytest.approx(0.2, abs=0.02)  # [m] four 5 cm steps


def rot_x(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_unnamed_motors_get_the_pd_layer(tmp_path: Path) -> None:
    """A model whose motors have no names: the plant finds each by its index (``#index``, as the robot lists it)
    and makes it the PD layer's position servo, with the gains the robot gives it."""
    robot = load_robot(write(tmp_path, "unnamed.xml", pelvis_rooted_biped(named=False)))
    assert robot.plant is not None
    plant = build_plant(robot)
    for (joint, actuator), index in zip(robot.plant.pd_joints, range(12), strict=False):
        assert actuator.name == f"#{index}" and actuator.kind == "motor"
        servo = mujoco.mj_name2id(plant.model, mujoco.mjtObj.mjOBJ_ACTUATOR, actuator.name)
        assert servo == index and plant.model.actuator_trnid[servo][0] == plant.model.joint(joint).id
        assert plant.model.actuator_gainprm[servo][0] == pytest.approx(actuator.kp, rel=1e-12)  # [N m/rad]


def geared_hip_yaw_biped() -> str:
    """The pelvis-rooted biped whose hip yaws are passive joints turned by a motor's gear on the pelvis through a
    joint equality (``hip_yaw = -0.8 drive``), as ToddlerBot's."""
    text = pelvis_rooted_biped()
    for side in "lr":
        gear = (f'<body name="{side}_gear"><joint name="{side}_hip_yaw_drive" axis="0 0 1" range="-3 3"/>'
                '<inertial pos="0 0 0" mass="0.01" diaginertia="0.00001 0.00001 0.00001"/></body>')
        text = text.replace(f'<body name="{side}_hip_yaw_link"', gear + f'<body name="{side}_hip_yaw_link"', 1)
        text = text.replace(f"<motor name='{side}_hip_yaw' joint=\"{side}_hip_yaw\" ctrlrange=\"-80 80\"/>",
                            f'<motor name="{side}_hip_yaw_drive" joint="{side}_hip_yaw_drive" ctrlrange="-80 80"/>')
    equalities = "".join(f'<joint joint1="{s}_hip_yaw" joint2="{s}_hip_yaw_drive" polycoef="0 -0.8 0 0 0"/>'
                         for s in "lr")
    return text.replace("</mujoco>", f"<equality>{equalities}</equality></mujoco>")


def test_a_hip_yaw_turned_through_a_joint_equality_is_driven_by_the_leg_alone(tmp_path: Path) -> None:
    """The gear's joint is neither held at its keyframe angle nor driven (its motor made to do nothing): the leg
    joint's PD loop turns it through the equality, with no second loop pulling against it."""
    robot = load_robot(write(tmp_path, "geared.xml", geared_hip_yaw_biped()))
    assert robot.plant is not None
    assert robot.plant.coupled_joints == ("l_hip_yaw_drive", "r_hip_yaw_drive")
    assert not {"l_hip_yaw_drive", "r_hip_yaw_drive"} & set(robot.plant.held_joints)
    driven = dict(robot.plant.pd_joints)
    assert "l_hip_yaw_drive" not in driven and driven["l_hip_yaw"].kind == "none"  # the PD layer's own servo
    plant = build_plant(robot)
    motor = mujoco.mj_name2id(plant.model, mujoco.mjtObj.mjOBJ_ACTUATOR, "l_hip_yaw_drive")
    assert motor >= 0
    assert not plant.model.actuator_gainprm[motor].any() and not plant.model.actuator_biasprm[motor].any()
    assert "moved through an equality by a joint the PD layer drives" in robot_table(robot)


@pytest.mark.slow
def test_a_biped_with_geared_hip_yaws_turns(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Three 15 degree turns on the geared hip yaws pass, the feet turned as planned."""
    from zmpwalk.cli import main

    path = write(tmp_path, "geared.xml", geared_hip_yaw_biped())
    steps = write(tmp_path, "turn.toml", "[[steps]]\nduration = 0.8\nturn = 0.2618\nrepeat = 3\n")
    code = main(["simulate", "--robot", str(path), str(steps), "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["verdict"]["state"] == "PASS"
    assert summary["final_feet_yaw_error"] < 0.01  # [rad]
