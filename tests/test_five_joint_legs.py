"""Legs of five joints without an ankle roll (Unitree H1): the virtual ankle roll along the sole's
centre line, what the inverse kinematics meets and the sole roll it leaves, why a flat sole fixes the hip roll, the
stabilizer's 6 x 6 solve with the virtual joint's share dropped, the plant's do-nothing column, the bound on the sole
roll, and H1's walks refused with the ankle roll named (zmpwalk.robots.legs derives why)."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk import balance_kernel as kernel
from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError
from zmpwalk.kinematics import JOINT_COLUMNS, JointLimitError, pattern_joint_trajectory, rot_x
from zmpwalk.leg_chain import LegChain
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots import load_robot
from zmpwalk.robots.collision import SOLE_BAND, sole_roll_bound
from zmpwalk.robots.description import PD_WEAK_ANKLE_LOAD_STIFFNESS
from zmpwalk.scenarios import load_steps_file

ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
H1 = ROBOTS / "unitree_h1" / "scene.xml"
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
needs_h1 = pytest.mark.skipif(not H1.is_file(), reason="../shared/robots is absent")


def _inertia(mass: float, x: float, y: float, z: float) -> str:
    return f"{mass / 12 * (y * y + z * z):.6g} {mass / 12 * (x * x + z * z):.6g} {mass / 12 * (x * x + y * y):.6g}"


def five_joint_biped(joints: tuple[str, ...] = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch")) -> str:
    """An 18.6 kg biped, no actuators, whose legs have ``joints`` (hip yaw, roll, pitch, knee, ankle pitch: no
    ankle roll), legs 0.2 m apart, a flat 220 x 140 mm box sole on the last link, 60 mm below the ankle."""
    spec = {"hip_yaw": ("0 0 1", 0.5, "0 0 0", "0.001 0.001 0.001", "-0.8 0.8"),
            "hip_roll": ("1 0 0", 0.5, "0 0 0", "0.001 0.001 0.001", "-0.6 0.6"),
            "hip_pitch": ("0 1 0", 1.5, "0 0 -0.15", _inertia(1.5, 0.06, 0.06, 0.3), "-1.6 1.0"),
            "knee": ("0 1 0", 1.0, "0 0 -0.15", _inertia(1.0, 0.05, 0.05, 0.3), "0 2.4"),
            "ankle_pitch": ("0 1 0", 0.8, "0.02 0 -0.05", _inertia(0.8, 0.22, 0.14, 0.02), "-1.0 1.0")}
    places = {"knee": "0 0 -0.3", "ankle_pitch": "0 0 -0.3"}
    legs = ""
    for side, y in (("l", 0.1), ("r", -0.1)):
        inner = '<geom type="box" size="0.11 0.07 0.01" pos="0.02 0 -0.05" mass="0"/>'
        for index, name in reversed(list(enumerate(joints))):
            axis, mass, com, inertia, limits = spec[name]
            pos = f"0 {y} -0.1" if index == 0 else places.get(name, "0 0 0")
            inner = (f'<body name="{side}_{name}_link" pos="{pos}"><joint name="{side}_{name}" axis="{axis}" '
                     f'range="{limits}"/><inertial pos="{com}" mass="{mass}" diaginertia="{inertia}"/>{inner}</body>')
        legs += inner
    return f"""<mujoco model="five_joint"><compiler angle="radian"/>
<default><joint armature="0.01" damping="0.1" actuatorfrcrange="-60 60"/></default>
<worldbody><geom name="floor" type="plane" size="5 5 .1"/>
<body name="torso" pos="0 0 0.7"><freejoint/>
<inertial pos="0 0 0.1" mass="10" diaginertia="{_inertia(10, .2, .3, .3)}"/>
<geom type="box" size="0.1 0.15 0.15" pos="0 0 0.1" mass="0" contype="0" conaffinity="0"/>{legs}</body>
</worldbody></mujoco>"""


@pytest.fixture(scope="module")
def biped_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("five_joint") / "five.xml"
    path.write_text(five_joint_biped(), encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def h1_leg() -> LegChain:
    robot = load_robot(H1)
    assert robot.legs is not None
    return robot.legs[0]


def test_the_bound_keeps_a_rolled_sole_within_the_band() -> None:
    assert 0.06 * math.sin(sole_roll_bound(0.06)) == pytest.approx(SOLE_BAND, abs=1e-15)  # [m] W sin(phi)
    assert sole_roll_bound(0.06) == pytest.approx(0.033340, abs=1e-6)  # [rad] H1's 60 mm soles
    assert sole_roll_bound(0.14) == pytest.approx(0.014286, abs=1e-6)  # [rad] the biped's 140 mm soles


@needs_h1
def test_h1_imports_with_a_virtual_ankle_roll_on_the_sole_line() -> None:
    robot = load_robot(H1)
    assert robot.legs is not None and robot.plant is not None
    assert robot.hip_spacing == pytest.approx(2 * (0.0875 + 0.11536), abs=1e-12)  # [m] its legs' planes
    assert (robot.foot_length, robot.foot_width, robot.ankle_height) == pytest.approx((0.175, 0.06, 0.07), abs=1e-9)
    for chain, side in zip(robot.legs, (1, -1), strict=True):
        assert chain.virtual == 5 and chain.virtual_column == 5 and not chain.closed_form
        assert chain.joint_names[5] == f"zmpwalk_virtual_{chain.label}_ankle_roll"
        assert chain.axes[5] == pytest.approx([1.0, 0.0, 0.0], abs=1e-12)
        # through the sole's centre line on the floor: the ankle height below the ankle pitch's anchor
        assert chain.points[5] == pytest.approx([0.039468, side * 0.20286, -0.9742 - 0.07], abs=1e-9)
    columns = [joint.name for joint in robot.plant.joints]
    assert columns[4] == "left_ankle" and columns[5] == "zmpwalk_virtual_left_ankle_roll"
    roll = robot.plant.joints[5]
    assert roll.actuator is None and roll.limits == pytest.approx((-0.033340, 0.033340), abs=1e-6)  # [rad]
    assert robot.limits_of("right_ankle_roll") == roll.limits


@needs_h1
def test_the_real_joints_meet_the_sole_line_heading_and_pitch(h1_leg: LegChain) -> None:
    """The virtual joint turns the sole about its own x axis only: the five real joints meet the sole's centre line
    point, its heading and its pitch, and leave the sole rolled by the virtual angle (leg_chain's docstring)."""
    chain = h1_leg
    rng = np.random.default_rng(36)
    n = 200
    target_q = chain.reference + rng.uniform(-0.2, 0.2, (n, 6))
    position, rotation = chain.fk(target_q)  # reachable sole poses, each with some roll
    q, excess = chain.solve(position, rotation)
    assert np.all(excess <= 0)
    real = q.copy()
    real[:, 5] = 0.0
    reached, turned = chain.fk(real)
    line = np.array([0.0, 0.0, -0.07])  # the sole's centre line point under the ankle, in the sole frame
    assert np.abs((reached + turned @ line) - (position + rotation @ line)).max() < 1e-9  # [m]
    assert np.abs(turned[:, :, 0] - rotation[:, :, 0]).max() < 1e-9  # the sole's x axis: heading and pitch
    assert np.abs(turned @ rot_x(q[:, 5]) - rotation).max() < 1e-9  # the rest is a roll about it, by q_6
    assert chain.residual_roll(q) == pytest.approx(q[:, 5], abs=0)


@needs_h1
def test_a_flat_sole_fixes_the_hip_roll(h1_leg: LegChain) -> None:
    """Why the pelvis cannot sway over a flat sole: with the hip yaw at 0 and the sole level under an upright pelvis,
    the hip roll is 0 and the ankle stays in its leg's plane; moving the ankle s across it leaves the sole rolled by
    minus the hip roll, about s / L (zmpwalk.robots.legs)."""
    chain = h1_leg
    ready, _ = chain.fk(chain.reference[None])
    sways = np.linspace(-0.15, 0.15, 31)  # [m]
    targets = np.repeat(ready, len(sways), axis=0)
    targets[:, 1] = chain.points[5][1] - sways  # the sole line moved across, the pelvis over it by `sways`
    q, excess = chain.solve(targets, np.eye(3)[None].repeat(len(sways), axis=0))
    assert np.all(excess <= 0)
    assert np.abs(q[:, 5] + q[:, 1]).max() < 1e-9  # [rad] sole roll = -hip roll (hip yaw 0: R = R_x(q2) R_y(...))
    assert np.abs(q[:, 0]).max() < 1e-9
    flat = int(np.argmin(np.abs(sways)))
    assert abs(q[flat, 5]) < 2e-3  # [rad] the ready posture's CoM offset, 1 mm across, rolls it 1.4 mrad
    # The leg is rigid in its plane, rolled by the hip roll about its axis: the ankle, seen from that axis, is
    # R_x(q2) (0, d, -D) with d the plane's offset (115.36 mm) and D its depth in the plane.
    real = q.copy()
    real[:, 5] = 0.0
    ankle, _ = chain.fk(real)  # where the five real joints put the ankle (the sole line is where targeted)
    offset = chain.points[2][1] - chain.points[1][1]
    lateral, depth = ankle[:, 1] - chain.points[1][1], chain.points[1][2] - ankle[:, 2]
    plane_depth = np.sqrt(lateral**2 + depth**2 - offset**2)
    assert offset == pytest.approx(0.11536, abs=1e-12)
    assert np.abs(lateral - (offset * np.cos(q[:, 1]) + plane_depth * np.sin(q[:, 1]))).max() < 1e-9  # [m]
    assert np.all(np.diff(q[:, 5]) > 0)  # the further across, the more roll


@needs_h1
def test_the_stabilizer_drops_the_virtual_share(h1_leg: LegChain) -> None:
    """The kernel's 6 x 6 solve on a five-joint chain: the real joints make the correction less a twist about the
    virtual axis (balance.py, "Five-joint legs")."""
    chain = h1_leg
    table = np.zeros((2, 6, 11))
    table[0, :, 0:3], table[0, :, 3:6] = chain.axes, chain.points
    table[0, :, 10] = np.argsort(np.asarray(chain.role_order))
    columns = np.zeros(12)
    columns[:6] = chain.reference[list(chain.role_order)]
    frames = np.zeros((7, 12))
    kernel.leg_kinematics(table, 0, columns, frames)
    params = np.zeros(kernel.PARAMETERS)
    params[kernel.P_ANKLE_OFFSET:kernel.P_ANKLE_OFFSET + 3] = chain.ankle
    ankle = kernel.ankle_in_base(params, 0, frames)
    jacobian = np.zeros((6, 6))
    kernel.leg_jacobian(table, 0, frames, ankle, jacobian)
    assert jacobian == pytest.approx(chain.jacobian(chain.reference[None])[0], abs=1e-12)
    factors, swaps = jacobian.copy(), np.zeros(6)
    assert kernel.lu6(factors, swaps) > kernel.SINGULAR_PIVOT
    rng = np.random.default_rng(4)
    for _ in range(20):
        wanted = rng.normal(0.0, [0.01, 0.01, 0.01, 0.02, 0.02, 0.02])  # [m], [rad]
        change = wanted.copy()
        kernel.lu_solve6(factors, swaps, change)
        made = jacobian[:, :5] @ change[:5]  # what the five real joints do
        assert made - wanted == pytest.approx(-jacobian[:, 5] * change[5], abs=1e-12)
    assert float(jacobian[:3, 5] @ jacobian[3:, 5]) == pytest.approx(0.0, abs=1e-12)  # a pure rotation about a line


@needs_h1
def test_the_plant_column_of_the_virtual_joint_does_nothing() -> None:
    from zmpwalk.sim.plant import build_plant
    from zmpwalk.sim.poses import set_initial_state

    robot = load_robot(H1)
    assert robot.legs is not None
    plant = build_plant(robot)
    assert plant.leg_columns.tolist() == [0, 1, 2, 3, 4, 6, 7, 8, 9, 10] and len(plant.leg_qpos) == 10
    model = plant.model
    virtual = plant.leg_actuators[5]
    assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, virtual) == "zmpwalk_virtual_left_ankle_roll"
    assert np.all(model.actuator_gear[virtual] == 0) and model.actuator_gainprm[virtual][0] == 0
    angles = np.concatenate([np.asarray(c.reference)[list(c.role_order)] for c in robot.legs])
    runs = []
    for command in (0.0, 0.3):  # [rad] sent to the virtual column
        data = mujoco.MjData(model)
        set_initial_state(plant, data, np.array([0.0, 0.0, robot.pelvis_height]), 0.0, angles)
        data.ctrl[plant.leg_actuators[[5, 11]]] = command
        for _ in range(100):
            mujoco.mj_step(model, data)
        sensor = model.sensor("left_ankle_roll_q")
        assert data.sensordata[sensor.adr[0]] == 0.0  # [rad] the foot is rigid on the ankle pitch
        runs.append(data.qpos.copy())
    assert np.array_equal(runs[0], runs[1])  # bit for bit: the column moves nothing


@needs_h1
def test_h1_walks_are_refused_naming_the_ankle_roll(capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.cli import main

    robot = load_robot(H1)
    pattern = generate(robot, load_steps_file(EXAMPLES / "steps_forward_10cm.toml"), rate=200.0)
    with pytest.raises(JointLimitError, match="What is missing: an ankle roll joint") as raised:
        pattern_joint_trajectory(pattern)
    assert raised.value.sole_roll == pytest.approx(0.1095, abs=1e-3)  # [rad] the sole roll the walk needs
    assert raised.value.limits == pytest.approx((-0.03334, 0.03334), abs=1e-5)  # [rad] its bound
    joints = pattern_joint_trajectory(pattern, check_limits=False)  # the plan itself exists
    column = JOINT_COLUMNS.index(raised.value.joint)  # a virtual ankle roll column
    assert column in (5, 11)
    assert np.abs(joints.angles[:, column]).max() == pytest.approx(raised.value.sole_roll, abs=1e-12)
    code = main(["simulate", "--robot", str(H1), str(EXAMPLES / "steps_turn_15deg.toml"), "--generator", "preview"])
    assert code == 2
    assert "no ankle roll" in capsys.readouterr().err


def test_a_flat_soled_five_joint_leg_keeps_its_sole_and_rolls_the_body(biped_path: Path) -> None:
    """Measured behind the bound: a biped whose flat 140 mm soles cannot roll, walked with the check lifted, keeps
    them flat and rolls its torso by most of the sole roll the plan leaves (zmpwalk.robots.legs)."""
    import zmpwalk.sim.run as run
    from zmpwalk.balance import Stabilizer

    robot = load_robot(biped_path)
    assert robot.plant is not None and robot.plant.ankle_roll_torque == 0.0  # no ankle roll: the hips' kappa
    assert robot.plant.load_stiffness == PD_WEAK_ANKLE_LOAD_STIFFNESS
    pattern = generate(robot, [StepCommand(duration=0.8, forward=0.05)], rate=1000.0)
    with pytest.raises(JointLimitError, match="no ankle roll"):
        pattern_joint_trajectory(pattern)
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    lifted = pytest.MonkeyPatch()
    lifted.setattr(run, "check_sole_roll", lambda *args: None)
    try:
        result = run.simulate(robot, joints, pattern, stabilizer=Stabilizer(robot, 1000.0), hold=0.0)
    finally:
        lifted.undo()
    before = (result.time >= 0) & (result.time < pattern.time[np.argmax(pattern.support > 0)])  # double support
    planned = np.abs(np.interp(result.time[before], joints.time, joints.angles[:, 5])).max()
    assert planned == pytest.approx(0.084, abs=0.002)  # [rad] the sole roll the sway asks
    assert np.abs(result.torso_rpy[before, 0]).max() > 0.5 * planned  # [rad] measured 0.058: the body rolls


def test_legs_of_other_shapes_are_refused(tmp_path: Path) -> None:
    four = tmp_path / "four.xml"
    four.write_text(five_joint_biped(("hip_yaw", "hip_roll", "hip_pitch", "knee")), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"no legs: .* through 5 or 6 hinge joints"):
        load_robot(four)
    no_yaw = tmp_path / "no_yaw.xml"
    no_yaw.write_text(five_joint_biped(("hip_roll", "hip_pitch", "knee", "ankle_pitch", "hip_yaw")), encoding="utf-8")
    with pytest.raises(FileFormatError, match=r"has 5 joints: .*an ankle pitch alone"):
        load_robot(no_yaw)


@needs_h1
def test_the_feedforward_of_a_five_joint_robot_reads_its_real_columns() -> None:
    """The per-tick feedforward and the base placement take the 12 walker columns and write only the real joints
    (a five-joint leg's virtual ankle roll has no qpos): the reference pose's angles give the reference pose."""
    from zmpwalk.online import WalkingSample
    from zmpwalk.sim.mujoco_plant import ModelFeedforward
    from zmpwalk.sim.plant import build_plant

    robot = load_robot(H1)
    plant = build_plant(robot)
    feedforward = ModelFeedforward(plant, 1000.0)
    half = robot.hip_spacing / 2
    sample = WalkingSample(0.0, "double", np.array([0.0, 0.0, robot.pelvis_height]), 0.0,
                           np.array([0.0, half, robot.ankle_height]), 0.0,
                           np.array([0.0, -half, robot.ankle_height]), 0.0, np.zeros(2))
    held = ModelFeedforward(plant, 1000.0).torques(sample)  # no joint angles in the sample: the reference pose's
    angles = np.zeros(12)  # the walker's 12 columns at the reference pose, the virtual ankle rolls at 0
    angles[plant.leg_columns] = plant.qpos_hold[plant.leg_qpos]
    sample.joint_angles = angles
    given = feedforward.torques(sample)
    assert given.shape == (12,) and np.all(np.isfinite(given))
    assert given == pytest.approx(held, abs=1e-9)  # [N m] the same pose either way


def test_the_least_sway_of_a_walk_without_double_support() -> None:
    """The derivation behind docs/robot-import.md's bound on H1's step time: a periodic walk of the linear inverted
    pendulum whose ZMP switches every ``T`` between sole centres ``+-a`` (no double support) has its CoM on
    ``x(t) = a - a cosh(w (t - T/2)) / cosh(w T/2)`` about the stance sole at ``+a``, so its sway from the mid-line
    is at least ``a (1 - 1 / cosh(w T / 2))``. Checked by integrating the pendulum from that orbit's start."""
    a, length, gravity = 0.4057 / 2, 0.9512, 9.81  # [m] H1's ankles' half distance, its CoM's height
    omega = math.sqrt(gravity / length)
    for period in (0.34, 0.5, 0.8):  # [s]
        x, v = 0.0, a * omega * math.tanh(omega * period / 2)  # the orbit at the switch: mid-line, towards +a
        dt, far = 1e-5, 0.0
        for _ in range(round(period / dt)):  # semi-implicit Euler of x'' = w^2 (x - a)
            v += omega ** 2 * (x - a) * dt
            x += v * dt
            far = max(far, x)
        assert abs(x) < 1e-4 and v == pytest.approx(-a * omega * math.tanh(omega * period / 2), rel=1e-3)  # periodic
        assert far == pytest.approx(a * (1 - 1 / math.cosh(omega * period / 2)), abs=1e-5)  # [m]
    sway = a * (1 - 1 / math.cosh(omega * 0.8 / 2))
    assert sway == pytest.approx(0.0986, abs=1e-4)  # [m] at 0.8 s: a sole roll of 0.121 rad over the 0.817 m leg
    longest = 2 / omega * math.acosh(1 / (1 - sole_roll_bound(0.06) * 0.8168 / a))  # [s] the longest step it allows
    assert longest == pytest.approx(0.342, abs=1e-3)


def test_the_mujoco_plant_drives_the_virtual_column_with_nothing() -> None:
    """The virtual actuator has gain and gear 0: its column's velocity and torque terms stay 0 in the control (a
    division by its zero stiffness made them NaN and MuJoCo reset the walk at its first tick)."""
    from zmpwalk.control.plant import JointTargets
    from zmpwalk.sim.mujoco_plant import MujocoPlant

    robot = load_robot(H1)
    plant = MujocoPlant(robot, 1000.0)
    angles = np.concatenate([np.asarray(c.reference)[list(c.role_order)] for c in robot.legs or ()])
    plant.apply(JointTargets(time=0.0, angles=angles, velocities=np.full(12, 0.5), torques=np.full(12, 10.0),
                             sample=None, corrected=False))  # type: ignore[arg-type]
    control = plant.data.ctrl[plant.plant.leg_actuators]
    assert np.isfinite(control).all()
    assert control[[5, 11]].tolist() == angles[[5, 11]].tolist()  # [rad] the virtual columns' angles, nothing added
    real = [0, 1, 2, 3, 4, 6, 7, 8, 9, 10]
    assert np.all(control[real] > angles[real])  # [rad] the real joints' rate and torque terms are added


@pytest.mark.parametrize(("ankle_roll", "support", "lateral"), [(1.0, 1, True), (0.0, 0, True), (0.0, 1, False),
                                                                 (0.0, 2, False)])
def test_the_com_admittance_leaves_the_sideways_zmp_error_to_the_step_without_an_ankle_roll(
        ankle_roll: float, support: int, lateral: bool) -> None:
    """Legs without an ankle roll cannot move the CoP across the stance sole in single support: there the CoM
    admittance's ZMP term keeps only its part along the pelvis (yaw 0.5 rad here), in double support both parts."""
    from zmpwalk.stabilizer import loops
    from zmpwalk.stabilizer.layout import LOG_SIZE, ROBOT_CONSTANTS, STATE_SIZE, P, S, pack_parameters
    from zmpwalk.stabilizer_gains import StabilizerGains

    constants: dict[str, object] = {name: np.zeros(size) for name, size in ROBOT_CONSTANTS}
    params = pack_parameters(StabilizerGains(com_damping=0.0, com_stiffness=0.0), **constants)
    params[P.dt], params[P.ankle_roll] = 0.001, ankle_roll  # [s], [-]
    state, log, yaw = np.zeros(STATE_SIZE), np.zeros(LOG_SIZE), 0.5
    error = np.array([0.02, -0.01])  # [m] measured ZMP less the desired, world
    loops.com_admittance(params, state, log, True, (float(error[0]), float(error[1])), (0.0, 0.0), 0.0, 0.0,
                         support, yaw)
    rate = state[S.offset_rate:S.offset_rate + 2] / (20.0 * 0.001)  # [m] the ZMP error the offset's rate answered
    along = np.array([math.cos(yaw), math.sin(yaw)])
    expected = error if lateral else along * (error @ along)
    assert rate == pytest.approx(expected, abs=1e-15)


def test_the_stabilizer_knows_which_legs_have_an_ankle_roll() -> None:
    from zmpwalk.balance import Stabilizer
    from zmpwalk.stabilizer.layout import P

    assert Stabilizer(load_robot(H1), 1000.0)._params[P.ankle_roll] == 0.0
    assert Stabilizer(load_robot("hubo"), 1000.0)._params[P.ankle_roll] == 1.0


def _h1_file(tmp_path: Path, limit: float) -> Path:
    from zmpwalk.cli import main

    path = tmp_path / "h1.toml"
    assert main(["robot", str(H1), "--write", str(path)]) == 0
    text = path.read_text(encoding="utf-8")
    assert "# sole_roll_limit = 0.0333395   # [rad]" in text  # the written file offers the field, commented out
    path.write_text(text.replace("# sole_roll_limit = 0.0333395", f"sole_roll_limit = {limit}"), encoding="utf-8")
    return path


@needs_h1
def test_a_robot_file_raises_the_sole_roll_limit_the_refusal_names(tmp_path: Path) -> None:
    pattern = generate(load_robot(H1), load_steps_file(EXAMPLES / "steps_forward_10cm.toml"), rate=200.0)
    with pytest.raises(JointLimitError, match=r"\[walking\] sole_roll_limit = 0.11 ") as raised:
        pattern_joint_trajectory(pattern)  # the option, rounded up from the roll the walk needs
    assert raised.value.sole_roll == pytest.approx(0.1095, abs=1e-3)  # [rad]
    robot = load_robot(_h1_file(tmp_path, 0.2))
    assert robot.joint_limits["left_ankle_roll"] == (-0.2, 0.2)  # [rad] the virtual column's range
    pattern = generate(robot, load_steps_file(EXAMPLES / "steps_forward_10cm.toml"), rate=200.0)
    pattern_joint_trajectory(pattern)  # within the limit: planned
    talos = tmp_path / "talos.toml"
    talos.write_text(f'[model]\nfile = "{ROBOTS / "pal_talos" / "scene_motor.xml"}"\n\n[walking]\n'
                     "sole_roll_limit = 0.2\n", encoding="utf-8")
    with pytest.raises(FileFormatError, match="applies to legs of five joints"):
        load_robot(talos)
    with pytest.raises(FileFormatError, match=r"sole_roll_limit = 1.6 must be below pi/2 rad"):
        load_robot(_h1_file(tmp_path, 1.6))


@pytest.mark.slow
@needs_h1
def test_h1_walks_forward_with_its_soles_rolled_balanced_by_its_steps(tmp_path: Path) -> None:
    """H1 with sole_roll_limit = 0.2 rad: the 10 x 10 cm walk (hyperbolic, the controller, the PD layer) ends
    standing where planned; the stabilizer leaves the sideways ZMP error of single support to the steps
    (measured: feet 16.3 mm from the plan, CoP - ZMP RMS 173 mm: its feet land before the plan's time)."""
    from zmpwalk.walk import WalkSpec, run_walk

    robot = load_robot(_h1_file(tmp_path, 0.2))
    outcome = run_walk(WalkSpec(robot=robot, commands=load_steps_file(EXAMPLES / "steps_forward_10cm.toml")))
    result = outcome.result
    assert not result.fell
    assert result.end_max_speed < 0.05  # [m/s] standing still at the end
    assert result.final_feet_error < 0.02  # [m] measured 16.3 mm (the verdict's limit)
    assert result.distance == pytest.approx(1.0, abs=0.03)  # [m] ten strides of 0.1 m
