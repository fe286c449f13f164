"""A robot imported from its own MJCF or URDF: derived values against MuJoCo's own numbers, IK on every sample,
the simulation of the real model, and one clear error for each bad model."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError
from zmpwalk.kinematics import pattern_joint_trajectory, rot_z
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots import load_robot
from zmpwalk.robots.tree import base_mount, root_from_base

ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
TALOS = ROBOTS / "pal_talos" / "scene_position.xml"
T1 = ROBOTS / "booster_t1" / "scene.xml"
needs_robots = pytest.mark.skipif(not TALOS.is_file() or not T1.is_file(), reason="../shared/robots is absent")


def body_position(model: mujoco.MjModel, name: str) -> np.ndarray:
    """Body origin relative to its parent chain at qpos0, summed to the base (no rotations in these models)."""
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
    total = np.zeros(3)
    while model.body_parentid[body] != 0 and model.body_jntnum[body] >= 0:
        if model.body_parentid[body] == 0 or model.jnt_type[model.body_jntadr[body]] == mujoco.mjtJoint.mjJNT_FREE:
            break
        total += model.body_pos[body]
        body = model.body_parentid[body]
    return total


@needs_robots
def test_talos_derived_values_match_mujoco() -> None:
    robot = load_robot(TALOS)
    model = mujoco.MjModel.from_xml_path(str(TALOS))
    hip = body_position(model, "leg_left_1_link")  # the hip axes meet at this body's origin
    assert (robot.hip_x, robot.hip_spacing / 2, -robot.hip_drop) == pytest.approx(tuple(hip), abs=1e-9)
    assert robot.thigh_length == pytest.approx(float(-model.body_pos[model.body("leg_left_4_link").id][2]), abs=1e-9)
    assert robot.shank_length == pytest.approx(float(-model.body_pos[model.body("leg_left_5_link").id][2]), abs=1e-9)
    # The sole box: size .1 .06 .006 at (-0.005, 0, -0.1) below the ankle.
    assert robot.ankle_height == pytest.approx(0.106, abs=1e-9)
    assert (robot.foot_length, robot.foot_width) == pytest.approx((0.2, 0.12), abs=1e-9)
    assert robot.sole_center_x == pytest.approx(-0.005, abs=1e-9)
    assert robot.mass == pytest.approx(float(model.body_subtreemass[model.body("base_link").id]), rel=1e-12)
    for side in ("left", "right"):
        joint = model.joint(f"leg_{side}_4_joint")
        assert robot.limits_of(f"{side}_knee") == pytest.approx(tuple(joint.range), abs=1e-12)
    assert robot.limits_of("left_hip_yaw") != robot.limits_of("right_hip_yaw")  # per side: mirrored ranges
    assert robot.legs is not None and all(leg.closed_form for leg in robot.legs)
    assert robot.plant is not None and robot.plant.joints[3].actuator is not None
    assert robot.plant.joints[3].actuator.kp == pytest.approx(1000.0)


@needs_robots
def test_ready_posture_puts_the_com_over_the_feet() -> None:
    for path in (TALOS, T1):
        robot = load_robot(path)
        pattern = generate(robot, [StepCommand(duration=1.0, forward=0.0)], rate=100.0)
        joints = pattern_joint_trajectory(pattern)
        model = mujoco.MjModel.from_xml_path(str(path))
        data = mujoco.MjData(model)
        assert robot.plant is not None and joints.position_base_in_world is not None
        data.qpos[:] = robot.plant.qpos_reference
        base = model.body(robot.plant.base_body).id  # the legs' base: here the floating base itself
        mount = base_mount(model, data.qpos, 1, base)
        data.qpos[0:3], rotation = root_from_base(mount, joints.position_base_in_world[0], np.eye(3))
        assert mount is None and rotation == pytest.approx(np.eye(3), abs=1e-12)  # T1's waist yaw: its own servo
        data.qpos[3:7] = (1, 0, 0, 0)
        for column, joint in enumerate(robot.plant.joints):
            data.qpos[model.joint(joint.name).qposadr[0]] = joints.angles[0, column]
        mujoco.mj_forward(model, data)
        com = data.subtree_com[0]
        assert com[:2] == pytest.approx(pattern.position_pelvis_in_world[0, :2], abs=1e-5)  # [m]
        assert com[2] == pytest.approx(robot.pendulum_length, abs=1e-6)


@needs_robots
def test_t1_numeric_ik_reaches_every_sample() -> None:
    robot = load_robot(T1)
    assert robot.legs is not None and not any(leg.closed_form for leg in robot.legs)
    pattern = generate(robot, [StepCommand(duration=0.8, forward=0.1)] * 10, rate=1000.0)
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    assert joints.position_base_in_world is not None
    base = joints.position_base_in_world
    yaw = pattern.yaw_pelvis_in_world
    c, s = np.cos(yaw), np.sin(yaw)
    for index, (chain, ankle, foot_yaw) in enumerate(zip(
            robot.legs, (pattern.position_left_ankle_in_world, pattern.position_right_ankle_in_world),
            (pattern.yaw_left_foot_in_world, pattern.yaw_right_foot_in_world), strict=True)):
        q = np.empty((len(yaw), 6))
        q[:, list(chain.role_order)] = joints.angles[:, 6 * index:6 * index + 6]
        position, rotation = chain.fk(q)
        rel = ankle - base
        target = np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])
        assert np.abs(position - target).max() < 1e-4  # [m]: 0.1 mm
        error = rotation @ np.swapaxes(rot_z(foot_yaw - yaw), 1, 2) - np.eye(3)
        assert np.abs(error).max() < 1e-3  # [rad]: 1 mrad


@needs_robots
def test_closed_form_and_numeric_agree_on_talos() -> None:
    robot = load_robot(TALOS)
    assert robot.legs is not None
    rng = np.random.default_rng(7)
    for chain in robot.legs:
        q = chain.reference + rng.uniform(-0.3, 0.3, (300, 6))
        position, rotation = chain.fk(q)
        closed, _ = chain.solve(position, rotation, numeric=False)
        numeric, _ = chain.solve(position, rotation, numeric=True)
        assert np.abs(closed - q).max() < 1e-9
        assert np.abs(closed - numeric).max() < 1e-6  # [rad]


@needs_robots
def test_talos_stands_on_its_own_servos_with_the_feedforward() -> None:
    from zmpwalk.sim import simulate

    robot = load_robot(TALOS)
    pattern = generate(robot, [StepCommand(duration=1.0, forward=0.0)], rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    planned_knee = joints.angles[0, 3]
    sagging = simulate(robot, joints, pattern, settle=1.0, hold=0.0, feedforward=False)
    holding = simulate(robot, joints, pattern, settle=1.0, hold=0.0, feedforward=True)
    at_start = int(np.searchsorted(holding.time, 0.0))
    assert abs(holding.joint_angles[at_start, 3] - planned_knee) < 0.01  # [rad]
    assert abs(sagging.joint_angles[at_start, 3] - planned_knee) > 0.05  # the sag the feedforward removes
    settle = holding.time < 0.0  # standing still on the starting pose
    assert np.abs(holding.torso_rpy[settle, :2]).max() < 0.02  # [rad]
    assert np.abs(sagging.torso_rpy[sagging.time < 0.0, 1]).max() > 0.05  # without it, TALOS tips backwards


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


LEG = """
<body name="{side}_hip" pos="0 {y} -0.1"><joint name="{side}_hy" axis="0 0 1"/><geom size="0.02" mass="1"/>
 <body name="{side}_hr"><joint name="{side}_hr" axis="1 0 0"/><geom size="0.02" mass="1"/>
  <body name="{side}_hp"><joint name="{side}_hp" axis="0 1 0"/><geom size="0.02" mass="1"/>
   <body name="{side}_shank" pos="0 0 -0.3"><joint name="{side}_kn" axis="0 1 0"/><geom size="0.02" mass="1"/>
    <body name="{side}_ank" pos="0 0 -0.3">{ankle}<geom size="0.02" mass="0.2" contype="0" conaffinity="0"/>
     <body name="{side}_foot"><joint name="{side}_ar" axis="1 0 0"/>
      <geom type="box" size="0.1 0.05 0.01" pos="0 0 -0.05" mass="0.5"/>{extra}
     </body>
    </body>
   </body>
  </body>
 </body>
</body>"""


def biped(legs: str) -> str:
    return f"""<mujoco><worldbody><geom type="plane" size="5 5 .1"/>
<body name="base" pos="0 0 0.8"><freejoint/><geom type="box" size="0.1 0.15 0.1" mass="10"/>{legs}</body>
</worldbody></mujoco>"""


def leg(side: str, y: float, ankle: str = '<joint name="{s}_ap" axis="0 1 0"/>', extra: str = "") -> str:
    return LEG.format(side=side, y=y, ankle=ankle.format(s=side), extra=extra)


def test_a_small_mjcf_biped_imports(tmp_path: Path) -> None:
    robot = load_robot(write(tmp_path, "ok.xml", biped(leg("l", 0.1) + leg("r", -0.1))))
    assert robot.hip_spacing == pytest.approx(0.2)
    assert robot.thigh_length == pytest.approx(0.3) and robot.shank_length == pytest.approx(0.3)
    assert robot.ankle_height == pytest.approx(0.06)
    assert robot.legs is not None and all(chain.closed_form for chain in robot.legs)


@pytest.mark.parametrize(("name", "text", "words"), [
    ("nolegs.xml", biped(""), "no legs"),
    ("five.xml", biped(leg("l", 0.1, ankle="") + leg("r", -0.1, ankle="")), "5 joints"),
    ("nobase.xml", "<mujoco><worldbody><body><geom size='0.1'/></body></worldbody></mujoco>", "no floating base"),
    ("ambiguous.xml", biped(leg("l", 0.1, extra='<body name="l_toe" pos="0.12 0 0"><joint axis="0 1 0"/>'
                                                  '<geom type="box" size="0.02 0.05 0.01" pos="0 0 -0.05"/></body>')
                            + leg("r", -0.1)), "give the feet"),
    ("mesh.xml", "<mujoco><asset><mesh name='m' file='missing.stl'/></asset><worldbody><body><freejoint/>"
                 "<geom type='mesh' mesh='m'/></body></worldbody></mujoco>", "missing.stl"),
])
def test_bad_models_give_one_clear_error(tmp_path: Path, name: str, text: str, words: str) -> None:
    with pytest.raises(FileFormatError, match=words):
        load_robot(write(tmp_path, name, text))


def test_missing_model_file_and_unresolved_package(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match="no such file"):
        load_robot(tmp_path / "absent.xml")
    urdf = write(tmp_path, "r.urdf", """<robot name="r"><link name="base"><visual><geometry>
<mesh filename="package://nowhere_pkg/meshes/base.stl"/></geometry></visual></link></robot>""")
    with pytest.raises(FileFormatError, match="package://nowhere_pkg"):
        load_robot(urdf)


def test_cli_robot_inspects_and_writes_a_loadable_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.cli import main

    model = write(tmp_path, "ok.xml", biped(leg("l", 0.1) + leg("r", -0.1)))
    assert main(["robot", str(model), "--write", str(tmp_path / "ok.toml")]) == 0
    assert "left_knee" in capsys.readouterr().out
    robot = load_robot(tmp_path / "ok.toml")
    assert robot.hip_spacing == pytest.approx(0.2)
    assert main(["robot", str(tmp_path / "five.xml")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_a_model_robot_file_carries_tuned_stabilizer_gains(tmp_path: Path) -> None:
    """A robot file naming its own model may carry [stabilizer], as a box model's file does."""
    from zmpwalk.balance import Stabilizer
    from zmpwalk.cli import main

    write(tmp_path, "ok.xml", biped(leg("l", 0.1) + leg("r", -0.1)))
    assert main(["robot", str(tmp_path / "ok.xml"), "--write", str(tmp_path / "ok.toml")]) == 0
    plain = load_robot(tmp_path / "ok.toml")
    assert plain.stabilizer_gains == ()
    with (tmp_path / "ok.toml").open("a", encoding="utf-8") as handle:
        handle.write("\n[stabilizer]\ncom_stiffness = 3.0\ntouchdown_speed = 0.2\n")
    tuned = load_robot(tmp_path / "ok.toml")
    assert dict(tuned.stabilizer_gains) == {"com_stiffness": 3.0, "touchdown_speed": 0.2}
    gains = Stabilizer(tuned, 1000.0).gains
    assert gains.com_stiffness == 3.0 and gains.touchdown_speed == 0.2 and gains.dcm == 3.0  # [1/s^2], [m/s], [1/s]
    with (tmp_path / "ok.toml").open("a", encoding="utf-8") as handle:
        handle.write("dcm_gain = 2.0\n")
    with pytest.raises(FileFormatError, match="dcm_gain"):
        load_robot(tmp_path / "ok.toml")


TALOS_MOTOR = ROBOTS / "pal_talos" / "scene_motor.xml"
N1 = ROBOTS / "fourier_n1" / "scene.xml"
needs_motor_robots = pytest.mark.skipif(not TALOS_MOTOR.is_file() or not N1.is_file(),
                                        reason="../shared/robots is absent")


@needs_motor_robots
def test_torque_driven_legs_get_the_pd_layer(capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.cli import main

    talos = load_robot(TALOS_MOTOR)
    assert talos.plant is not None
    talos_mgl = talos.mass * talos.gravity * talos.pendulum_length
    assert talos_mgl == pytest.approx(824.83, abs=0.01)  # [N m]
    # the ankle roll, 0.0104 kg m^2: at 1 ms the step bound (sqrt(kp / I) dt = 0.5) would hold it at 2605.7 N m/rad,
    # so the physics step halves and every leg joint has the load term
    roll = talos.plant.joints[5].actuator
    assert roll is not None and roll.inertia * (0.5 / 0.001) ** 2 == pytest.approx(2605.7, abs=0.1)
    assert talos.plant.physics_step == pytest.approx(0.0005, abs=1e-15)  # [s]
    for joint, limit in zip(talos.plant.joints, [100.0, 160.0, 160.0, 400.0, 160.0, 100.0] * 2, strict=True):
        assert joint.actuator is not None and joint.actuator.label == "torque motor + PD"
        assert joint.actuator.kp == pytest.approx(4 * talos_mgl, rel=1e-9)  # 3299.3 N m/rad: the load term
        assert joint.actuator.force_limit == limit  # [N m] the motor's ctrlrange (and the joint's actuatorfrcrange)
    assert len(talos.plant.pd_joints) == 32  # the legs, torso, head, arms and grippers: every motor
    n1 = load_robot(N1)
    assert n1.plant is not None
    hip_roll, knee = n1.plant.joints[1].actuator, n1.plant.joints[3].actuator
    assert hip_roll is not None and knee is not None
    assert hip_roll.inertia == pytest.approx(0.7884, abs=1e-4)  # [kg m^2]: 0.1676 of it the rotor's armature
    # the heaviest-swinging joint's bandwidth term, 498.0 N m/rad, is below the load term
    assert hip_roll.inertia * (2 * np.pi * 4.0) ** 2 == pytest.approx(498.0, abs=0.1)
    assert hip_roll.kp == knee.kp == pytest.approx(4 * n1.mass * n1.gravity * n1.pendulum_length, rel=1e-12)
    assert knee.kp == pytest.approx(937.71, abs=0.01) and knee.force_limit == 95.0  # [N m/rad], [N m]
    assert main(["robot", str(TALOS_MOTOR)]) == 0
    out = capsys.readouterr().out
    assert "torque motor + PD" in out and "static torques not computed" not in out
    assert "over the actuator's limit standing still: none" in out


@needs_robots
def test_position_servo_robots_keep_their_own_gains() -> None:
    for path in (TALOS, T1):
        robot = load_robot(path)
        assert robot.plant is not None and robot.plant.pd_joints == ()
        assert all(j.actuator is not None and j.actuator.kind == "position" and not j.actuator.pd_layer
                   for j in robot.plant.joints)
    talos = load_robot(TALOS)
    assert talos.plant is not None
    assert [j.actuator.kp for j in talos.plant.joints if j.actuator] == [1000.0] * 4 + [10000.0] * 2 + [1000.0] * 4 \
        + [10000.0] * 2


def test_the_default_foot_lift_keeps_the_pitch_joints_off_their_limits(tmp_path: Path) -> None:
    """HUBO's lift scaled to the leg, unless the foot raised level at the apex would bring a pitch joint within
    0.1 rad of its limit (zmpwalk.robots.imported._foot_lift), here the ankle pitch of 0.3 + 0.3 m legs in the
    sagittal plane: hip to ankle D = 2 L cos(knee / 2) at the angle beta from the vertical, the level sole's ankle
    pitch -(knee / 2 - beta); raising the foot by h shortens the vertical part of D by h."""
    from zmpwalk.robots.imported import HUBO_FOOT_LIFT, LIFT_RANGE_MARGIN

    free = load_robot(write(tmp_path, "free.xml", biped(leg("l", 0.1) + leg("r", -0.1))))
    assert free.foot_lift == pytest.approx(HUBO_FOOT_LIFT * free.schedule_scale[1], abs=1e-12)  # [m] scaled
    ankle = '<joint name="{s}_ap" axis="0 1 0" range="-30 30"/>'  # [deg] MJCF's default unit: +-0.5236 rad
    tight = load_robot(write(tmp_path, "tight.xml", biped(leg("l", 0.1, ankle) + leg("r", -0.1, ankle))))
    assert tight.legs is not None
    _, _, hip_pitch, knee, ankle_pitch, _ = tight.legs[0].reference
    assert ankle_pitch == pytest.approx(-(hip_pitch + knee), abs=1e-9)  # [rad] the sole level
    beta = knee / 2 + ankle_pitch  # [rad]
    across, vertical = 0.6 * math.cos(knee / 2) * math.sin(beta), 0.6 * math.cos(knee / 2) * math.cos(beta)  # [m]

    def ankle_at(lift: float) -> float:
        return -(math.acos(math.hypot(across, vertical - lift) / 0.6) - math.atan2(across, vertical - lift))

    bound, low, high = -math.radians(30) + LIFT_RANGE_MARGIN, 0.0, 0.05  # [rad], [m]
    for _ in range(60):
        low, high = ((low + high) / 2, high) if ankle_at((low + high) / 2) > bound else (low, (low + high) / 2)
    assert tight.foot_lift == pytest.approx(low, abs=1e-6)  # [m] 11.5 mm
    assert tight.foot_lift < 0.5 * free.foot_lift  # [m] of the scaled 40 mm


def test_a_stride_the_whole_body_legs_cannot_follow_names_its_command(tmp_path: Path,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """The pattern's own reach check (from its CoM point) passes 0.315 m strides of the 0.3 + 0.3 m biped, its legs
    placed under the whole-body CoM do not: the error is the walker's check of the command, naming its table and
    the stride that fits, not a sample's time alone (the robot file keeps the posture: without it the walk is
    walked from a lower one, tests/test_ready_fit.py)."""
    from zmpwalk.cli import main

    path = write(tmp_path, "free.xml", biped(leg("l", 0.1) + leg("r", -0.1)))
    robot = write(tmp_path, "free.toml", f'[model]\nfile = "{path}"\n[posture]\nready_stretch = 0.92\n')
    steps = write(tmp_path, "long.toml", "[[steps]]\nduration = 0.8\nforward = 0.315\nrepeat = 3\n")
    assert main(["plan", "--robot", str(robot), str(steps)]) == 0  # the pattern's check passes
    capsys.readouterr()
    assert main(["simulate", "--robot", str(robot), str(steps)]) == 2
    error = capsys.readouterr().err
    assert "long.toml: [[steps]] 1, repeat 1 of 3: forward = 0.315 is not allowed" in error
    fits = float(error.split("at most ")[1].split(" m forward")[0])
    assert 0.30 < fits < 0.315  # [m] (0.313 measured)
