"""The stabilizer: each loop answers in the physically right direction, a perfect measurement changes nothing,
bad gains are rejected, and in MuJoCo it carries walks that fall or drift open loop."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from zmpwalk import balance_kernel as kernel
from zmpwalk.balance import BalanceMeasurement, Stabilizer, StabilizerGains
from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import leg_chains, pattern_joint_trajectory, rest_mass
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots import load_robot
from zmpwalk.robots.model import JOINT_NAMES, RobotModel

TALOS = Path(__file__).resolve().parents[2] / "shared" / "robots" / "pal_talos" / "scene_position.xml"


WHOLE_BODY = "whole_body"  # what standing() gives as the CoM point


def com_in_base(robot: RobotModel, angles: np.ndarray) -> np.ndarray:
    """The whole-body CoM in the base frame [m], (3,), of the legs at ``angles`` (12) and the rest of the body,
    from the leg chains (independently of the stabilizer's compiled sum)."""
    rest, rest_com = rest_mass(robot)
    moment, total = rest * np.asarray(rest_com), rest
    for index, chain in enumerate(leg_chains(robot)):
        moment = moment + chain.link_masses @ chain.link_com_positions(angles[None, 6 * index:6 * index + 6])[0]
        total += float(chain.link_masses.sum())
    return np.asarray(moment / total)


def standing() -> tuple[Stabilizer, dict[str, object], float]:
    """HUBO standing in the ready posture, the stabilizer's inputs for it (its whole-body CoM, where its
    kinematics put it, and the ZMP under it), and half its weight [N]."""
    robot = load_robot("hubo")
    pattern = generate(robot, [StepCommand(duration=0.8)], rate=1000.0)
    angles = pattern_joint_trajectory(pattern).angles[0]
    com = pattern.position_pelvis_in_world[0] + com_in_base(robot, angles)
    com[2] = pattern.position_pelvis_in_world[0, 2]
    inputs = {
        "support": 0, "position_com_in_world": com, "yaw_pelvis_in_world": 0.0, "zmp_in_world": com[:2].copy(),
        "ankles_in_world": (pattern.position_left_ankle_in_world[0], pattern.position_right_ankle_in_world[0]),
        "foot_yaws": (0.0, 0.0), "joint_angles": angles,
    }
    return Stabilizer(robot, 1000.0, com_reference=WHOLE_BODY), inputs, robot.mass * robot.gravity / 2


def wrench(force: float, cop_x: float = 0.0, cop_y: float = 0.0, ankle_height: float = 0.095) -> np.ndarray:
    """The ground's wrench on a foot about its ankle for a vertical force at (cop_x, cop_y) in the foot frame."""
    r = np.array([cop_x, cop_y, -ankle_height])
    f = np.array([0.0, 0.0, force])
    return np.concatenate([f, np.cross(r, f)])


def measured(stabilizer: Stabilizer, inputs: dict[str, object], cop_shift: tuple[float, float] = (0.0, 0.0),
             loads: tuple[float, float] = (1.0, 1.0), **changes: object) -> BalanceMeasurement:
    """Each sole carrying half the weight, the two CoPs placed so that the total is under the CoM (what the
    inputs plan), unless changed."""
    half = stabilizer.robot.mass * stabilizer.robot.gravity / 2
    com = np.asarray(inputs["position_com_in_world"])
    ankles = [np.asarray(a)[:2] for a in inputs["ankles_in_world"]]  # type: ignore[attr-defined]
    shift = com[:2] - (ankles[0] + ankles[1]) / 2 + np.asarray(cop_shift)
    values: dict[str, object] = {"wrench_left": wrench(loads[0] * half, shift[0], shift[1]),
                                 "wrench_right": wrench(loads[1] * half, shift[0], shift[1]),
                                 "attitude": np.zeros(2), "rate": np.zeros(3),
                                 "joint_angles": np.asarray(inputs["joint_angles"]).copy()}
    values.update(changes)
    return BalanceMeasurement(**values)  # type: ignore[arg-type]


def run(stabilizer: Stabilizer, inputs: dict[str, object], ticks: int, **changes: object) -> np.ndarray:
    angles = np.zeros(12)
    for _ in range(ticks):
        measurement = measured(stabilizer, inputs, **changes)  # type: ignore[arg-type]
        angles = stabilizer.update(**inputs, measurement=measurement)  # type: ignore[arg-type]
    return angles


KINEMATICS_TOL = 1e-12  # [m], [-], [m/rad]


@pytest.mark.parametrize("name", ["hubo", "talos"])
def test_the_ticks_compiled_kinematics_are_each_legs_own(name: str) -> None:
    """The stabilizer's compiled tick computes each leg's product of exponentials, ankle point and Jacobian
    from the role-ordered joint columns; they must be each leg chain's own."""
    if name == "talos" and not TALOS.is_file():
        pytest.skip("../shared/robots is absent")
    robot = load_robot(TALOS if name == "talos" else name)
    stabilizer = Stabilizer(robot, 1000.0)
    chains = leg_chains(robot)
    rng = np.random.default_rng(7)
    frames = np.zeros((7, 12))
    jacobian = np.zeros((6, 6))
    for _ in range(20):
        columns = np.zeros(12)  # role-ordered, as the pattern and the encoders give them
        for leg, chain in enumerate(chains):
            columns[6 * leg:6 * leg + 6] = (np.asarray(chain.reference) + rng.normal(0, 0.3, 6))[
                list(chain.role_order)]
        for leg, chain in enumerate(chains):
            pose = columns[6 * leg:6 * leg + 6][np.argsort(chain.role_order)][None]  # chain-ordered
            kernel.leg_kinematics(stabilizer._chain, leg, columns, frames)
            ankle = kernel.ankle_in_base(stabilizer._params, leg, frames)
            kernel.leg_jacobian(stabilizer._chain, leg, frames, ankle, jacobian)
            own_rotations, own_translations = chain.transforms(pose)
            assert np.abs(frames[:, :9].reshape(7, 3, 3) - own_rotations[0]).max() < KINEMATICS_TOL
            assert np.abs(frames[:, 9:] - own_translations[0]).max() < KINEMATICS_TOL
            assert np.abs(np.array(ankle) - chain.fk(pose)[0][0]).max() < KINEMATICS_TOL
            assert np.abs(jacobian - chain.jacobian(pose)[0]).max() < KINEMATICS_TOL


def test_the_compiled_solve_inverts_a_random_matrix_and_finds_a_singular_one() -> None:
    rng = np.random.default_rng(3)
    swaps = np.zeros(6)
    for _ in range(50):
        a = rng.normal(size=(6, 6))
        x = rng.normal(size=6)
        b = a @ x
        factors = a.copy()
        assert kernel.lu6(factors, swaps) > 0.0
        kernel.lu_solve6(factors, swaps, b)
        assert np.abs(b - x).max() < 1e-9 * max(1.0, np.linalg.cond(a) / 1e3)
    singular = rng.normal(size=(6, 6))
    singular[4] = 2.0 * singular[1] - singular[2]  # rank 5
    assert kernel.lu6(singular, swaps) < 1e-12


def test_a_perfect_measurement_changes_nothing() -> None:
    stabilizer, inputs, _ = standing()
    angles = run(stabilizer, inputs, 200)
    assert np.abs(angles - np.asarray(inputs["joint_angles"])).max() < 1e-6  # [rad]
    assert np.abs(stabilizer.state.dcm_error).max() < 1e-6  # [m]


def test_cop_behind_its_target_turns_the_foot_to_press_the_toes() -> None:
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 100, cop_shift=(-0.03, 0.0))
    assert stabilizer.state.ankle_offsets[0, 1] > 0.001  # pitch about +y: toes down [rad]
    assert stabilizer.state.ankle_offsets[1, 1] > 0.001


def test_cop_right_of_its_target_turns_the_foot_to_press_its_left_edge() -> None:
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 100, cop_shift=(0.0, -0.02))
    assert stabilizer.state.ankle_offsets[0, 0] < -0.001  # roll about +x negative lowers the +y edge [rad]


def test_torso_leaning_forward_moves_the_desired_zmp_forward_and_turns_the_pelvis_back() -> None:
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 50, attitude=np.array([0.0, 0.03]))
    assert stabilizer.state.dcm_error[0] > 0.01  # the CoM is estimated ahead [m]
    assert stabilizer.state.zmp_desired[0] > np.asarray(inputs["zmp_in_world"])[0] + 0.01
    assert stabilizer.state.pelvis_turn[1] < 0.0


def test_measured_zmp_ahead_of_the_desired_accelerates_the_com_forward() -> None:
    stabilizer, inputs, _ = standing()
    gains = dataclasses.replace(stabilizer.gains, ankle_gain=0.0)
    stabilizer = Stabilizer(stabilizer.robot, 1000.0, gains, com_reference=WHOLE_BODY)
    run(stabilizer, inputs, 50, cop_shift=(0.02, 0.0))
    assert stabilizer.state.com_offset[0] > 0.0  # c'' = A (p_measured - p_desired) > 0


def test_left_foot_under_loaded_in_double_support_is_lowered() -> None:
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 100, loads=(0.6, 1.4))
    assert stabilizer.state.height_difference > 0.0  # left foot lowered by half of it [m]


def test_a_sole_the_plan_has_down_that_carries_no_load_is_lowered_in_double_support_only() -> None:
    """Landing timing: in double support a sole without load reads the whole weight as the force difference
    and is lowered at the touchdown speed, h' = touchdown_speed * (wanted - (f_l - f_r)) / W - h / T; with the
    left sole bare and the desired ZMP between the soles (wanted ~ 0) that is h(t) = v T (1 - exp(-t / T)).
    In single support the same sole is the swinging one and nothing moves."""
    stabilizer, inputs, _ = standing()
    gains = stabilizer.gains
    run(stabilizer, inputs, 100, loads=(0.0, 2.0))
    rate, time_constant = gains.touchdown_speed, gains.force_time_constant
    expected = rate * time_constant * (1 - math.exp(-0.1 / time_constant))
    assert stabilizer.state.height_difference == pytest.approx(expected, rel=0.01)  # [m] left lowered by half
    swinging = Stabilizer(stabilizer.robot, 1000.0, com_reference=WHOLE_BODY)
    run(swinging, {**inputs, "support": 2}, 100, loads=(0.0, 2.0))  # right stance: the left foot swings
    assert swinging.state.height_difference == 0.0


def test_a_swinging_sole_that_touches_down_early_is_raised() -> None:
    """Early touchdown: in single support the swinging sole's desired share of the load is none. With the left
    foot swinging (right stance), lifted, and then carrying 30 % of the weight, the error of the force
    difference is -0.6 of the weight, and h(t) = -0.6 v T (1 - exp(-t / T)) (negative: the left foot raised).
    A sole that still carries load as it lifts (the load passes to the stance sole) is left to the plan."""
    stabilizer, inputs, _ = standing()
    gains = stabilizer.gains
    swing = {**inputs, "support": 2}
    run(stabilizer, swing, 100, loads=(0.6, 1.4))  # not lifted yet
    assert stabilizer.state.height_difference == 0.0
    run(stabilizer, swing, 1, loads=(0.0, 2.0))  # lifted
    run(stabilizer, swing, 100, loads=(0.6, 1.4))  # down again
    rate, time_constant = gains.touchdown_speed, gains.force_time_constant
    expected = -0.6 * rate * time_constant * (1 - math.exp(-0.1 / time_constant))
    assert stabilizer.state.height_difference == pytest.approx(expected, rel=0.01)  # [m]


def left_ankle_height_change(stabilizer: Stabilizer, inputs: dict[str, object], targets: np.ndarray) -> float:
    """The height change of the left ankle in the base frame that the targets ask for [m]: the Jacobian at the
    pattern's angles times the change of the joints (the stabilizer maps its foot changes onto the joints
    through the inverse of that Jacobian)."""
    chain = leg_chains(stabilizer.robot)[0]
    order = np.argsort(chain.role_order)  # role-ordered columns -> chain order
    reference = np.asarray(inputs["joint_angles"])[:6][order]
    change = (np.asarray(targets)[:6] - np.asarray(inputs["joint_angles"])[:6])[order]
    return float((chain.jacobian(reference[None])[0] @ change)[2])


@pytest.mark.parametrize("roll", [0.0, -0.02])
def test_the_swinging_foot_aims_at_its_planned_height_above_the_floor(roll: float) -> None:
    """With landing_height_limit the swinging left foot (planned on the floor, level with the stance foot)
    is moved up in the base frame by what the measured attitude and the stance sole's compression take from
    its height above the floor: the stance sole sinks (W / k)^(1/e) under the whole weight W, and a torso
    rolled by phi lowers the left foot relative to the right one, in the base frame, by sin(phi) dy:

    .. math:: \\Delta z = -\\sin\\phi\\, \\Delta y + \\cos\\phi\\, (W / k)^{1/e}
    """
    stabilizer, inputs, half = standing()
    robot = stabilizer.robot
    gains = dataclasses.replace(stabilizer.gains, landing_height_limit=0.02)
    stabilizer = Stabilizer(robot, 1000.0, gains, com_reference=WHOLE_BODY)
    swing = {**inputs, "support": 2}  # right stance: the left foot swings
    targets = run(stabilizer, swing, 5000, loads=(0.0, 2.0), attitude=np.array([roll, 0.0]))  # 25 time constants
    assert robot.contact is not None
    compression = (2 * half / robot.contact.stiffness) ** (1 / robot.contact.exponent)  # [m]
    left, right = (np.asarray(a) for a in inputs["ankles_in_world"])  # type: ignore[attr-defined]
    expected = -math.sin(roll) * (left[1] - right[1]) + math.cos(roll) * compression
    assert left_ankle_height_change(stabilizer, swing, targets) == pytest.approx(expected, abs=1e-9)  # [m]
    off = Stabilizer(robot, 1000.0, dataclasses.replace(gains, landing_height_limit=0.0),  # the pattern's height
                     com_reference=WHOLE_BODY)
    targets = run(off, swing, 100, loads=(0.0, 2.0))
    assert abs(left_ankle_height_change(off, swing, targets)) < 1e-9  # [m]


def test_a_floor_rising_ahead_moves_the_com_uphill_by_l_tan_slope() -> None:
    """Standing on a floor that rises 2 degrees ahead, the torso square to it (pitched back by the slope), the
    soles' normal is the floor's; the CoM offset's target is l tan(slope) uphill (forward)."""
    stabilizer, inputs, _ = standing()
    slope = math.radians(2.0)
    run(stabilizer, inputs, 3000, attitude=np.array([0.0, -slope]))
    expected = stabilizer.robot.pendulum_length * math.tan(slope)
    assert stabilizer.state.slope_offset[0] == pytest.approx(expected, rel=0.01)  # 5 filter time constants
    assert abs(stabilizer.state.slope_offset[1]) < 1e-3 * expected
    off = Stabilizer(stabilizer.robot, 1000.0, dataclasses.replace(stabilizer.gains, slope_time_constant=0.0),
                     com_reference=WHOLE_BODY)
    run(off, inputs, 100, attitude=np.array([0.0, -slope]))
    assert np.all(off.state.slope_offset == 0.0)


def test_odometry_follows_the_newer_foot_through_double_support() -> None:
    """While both soles carry load, the newer one is placed from the reference by the measured kinematics at
    every tick (a foot landing heel first rolls flat after the load has passed to it); once the reference
    unloads, the other foot becomes the reference."""
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 5)
    assert stabilizer._anchor == 0
    before = list(stabilizer._feet[1])
    angles = np.asarray(inputs["joint_angles"]).copy()
    angles[6 + 2] += 0.02  # the right hip pitch: the right ankle moves relative to the base
    run(stabilizer, inputs, 1, joint_angles=angles, loads=(1.5, 0.5))
    chains = leg_chains(stabilizer.robot)
    left, right = (chain.fk(a[None])[0][0] for chain, a in zip(chains, (angles[:6], angles[6:]), strict=True))
    expected = np.asarray(stabilizer._feet[0]) + (right - left)[:2]  # upright torso, heading 0
    assert np.asarray(stabilizer._feet[1]) == pytest.approx(expected, abs=1e-12)
    assert abs(stabilizer._feet[1][0] - before[0]) > 1e-3
    run(stabilizer, inputs, 1, joint_angles=angles, loads=(0.0, 2.0))  # the left foot lifts
    assert stabilizer._anchor == 1


def off_plan(error_x: float, error_y: float = 0.0,
             gains: StabilizerGains | None = None) -> tuple[Stabilizer, dict[str, object]]:
    """HUBO standing (as :func:`standing`) with the plan's CoM moved so that the body is ``(error_x, error_y)``
    [m] ahead and left of it: a DCM error of that much. Double support; the caller picks the support."""
    stabilizer, inputs, _ = standing()
    if gains is not None:
        stabilizer = Stabilizer(stabilizer.robot, 1000.0, gains, com_reference=WHOLE_BODY)
    com = np.asarray(inputs["position_com_in_world"]) - np.array([error_x, error_y, 0.0])
    return stabilizer, {**inputs, "position_com_in_world": com}


def test_a_large_dcm_error_moves_the_swinging_foot_towards_the_fall() -> None:
    """Standing on the left foot with the body 6 cm ahead of its plan: the right foot's aim moves forward by
    step_gain times the DCM error beyond the deadband; within the deadband it lands where planned."""
    def landing(shift: float, gains: StabilizerGains) -> float:
        stabilizer, inputs = off_plan(shift, gains=gains)
        run(stabilizer, {**inputs, "support": 1}, 1500, loads=(2.0, 0.0))
        return float(stabilizer._landing[1][0])

    gains = StabilizerGains(step_gain=0.5, step_deadband=0.03)
    without = dataclasses.replace(gains, step_gain=0.0)
    moved = landing(0.06, gains) - landing(0.06, without)
    assert moved > 0.0  # forward, where the body falls
    assert landing(0.02, gains) == pytest.approx(landing(0.02, without), abs=1e-12)  # inside the deadband


def test_a_late_touchdown_keeps_its_aim_and_a_moment_without_load_is_no_late_touchdown() -> None:
    """The right foot swings with the body 6 cm off its plan and builds a landing correction ``c``. Once
    the plan puts it down it is released, ``c exp(-t / T_release)``, only if the sole carries load; a sole the
    plan has down that stays bare (a late touchdown) keeps aiming. A stance sole bare for 3/4 of
    ``AIRBORNE_AIM`` (20 ms) is not a late touchdown and gets no correction; bare for 3/2 of it, it is one."""
    def swung() -> tuple[Stabilizer, dict[str, object]]:
        stabilizer, inputs = off_plan(0.06)
        run(stabilizer, {**inputs, "support": 1}, 1500, loads=(2.0, 0.0))  # left stance: the right foot swings
        return stabilizer, inputs

    stabilizer, inputs = swung()
    aimed = float(stabilizer._landing[1][0])
    assert abs(aimed) > 0.005  # [m]
    run(stabilizer, {**inputs, "support": 0}, 300, loads=(1.0, 1.0))  # touched down
    release = stabilizer.gains.landing_release
    assert stabilizer._landing[1][0] == pytest.approx(aimed * math.exp(-0.3 / release), rel=0.01)
    stabilizer, inputs = swung()
    run(stabilizer, {**inputs, "support": 0}, 300, loads=(2.0, 0.0))  # the plan has it down; it is bare
    assert stabilizer._landing[1][0] == pytest.approx(aimed, rel=0.05)
    ticks = round(kernel.AIRBORNE_AIM * 1000.0)  # at 1 kHz
    for bare, aims in ((ticks * 3 // 4, False), (ticks * 3 // 2, True)):
        stabilizer, inputs = off_plan(0.06)
        run(stabilizer, inputs, 100)
        run(stabilizer, inputs, bare, loads=(2.0, 0.0))
        run(stabilizer, inputs, 100)
        assert (abs(stabilizer._landing[1][0]) > 1e-4) == aims


def test_a_step_towards_a_fall_never_crosses_the_stance_foot() -> None:
    """Standing on the left foot with the body 10 cm left of its plan (a fall towards the stance side): the right
    foot's aim moves left only until the soles' inner edges are feet_clearance apart."""
    gains = StabilizerGains(landing_limit=0.2)
    stabilizer, inputs = off_plan(0.0, 0.10, gains)  # the plan is right of the body
    robot = stabilizer.robot
    run(stabilizer, {**inputs, "support": 1}, 1500, loads=(2.0, 0.0))
    left, right = (np.asarray(a) for a in inputs["ankles_in_world"])  # type: ignore[attr-defined]
    right_y = right[1] + float(stabilizer._landing[1][1])  # where the right ankle lands (upright, heading 0)
    inner = robot.sole_center_y - robot.foot_width / 2  # the inner edge of the left sole from its ankle [m]
    gap = (left[1] + inner) - (right_y - inner)
    assert float(stabilizer._landing[1][1]) > 0.0  # it does step towards the fall
    assert gap == pytest.approx(gains.feet_clearance, abs=1e-3)  # [m] but no closer (the legs' pose: 1 mm)


@pytest.mark.parametrize("field", ["dcm", "ankle_gain", "com_limit"])
def test_bad_gains_are_rejected(field: str) -> None:
    with pytest.raises(InvalidParameterError, match=f"gains.{field}"):
        StabilizerGains(**{field: -1.0})
    with pytest.raises(InvalidParameterError, match=r"gains.landing_release.*> 0 s"):
        StabilizerGains(landing_release=0.0)
    assert StabilizerGains(slope_time_constant=0.0).slope_time_constant == 0.0  # 0 turns the slope loop off
    with pytest.raises(InvalidParameterError, match="rate"):
        Stabilizer(load_robot("hubo"), 5.0)
    with pytest.raises(InvalidParameterError, match=r"com_reference.*'pelvic'.*auto, pelvis, whole_body"):
        Stabilizer(load_robot("hubo"), 1000.0, com_reference="pelvic")


def test_inputs_as_lists_give_the_same_targets_and_bad_inputs_are_rejected_leaving_the_state() -> None:
    """The tick takes float64 vectors; lists and other dtypes are converted (same targets), short vectors and a
    support other than 0, 1, 2 raise an InvalidParameterError naming the input, and the state is as it was."""
    stabilizer, inputs, _ = standing()
    twin = Stabilizer(stabilizer.robot, 1000.0, com_reference=WHOLE_BODY)
    run(stabilizer, inputs, 20, cop_shift=(0.01, -0.005))
    run(twin, inputs, 20, cop_shift=(0.01, -0.005))
    measurement = measured(stabilizer, inputs, cop_shift=(0.01, -0.005))
    as_lists = {**inputs, "position_com_in_world": list(np.asarray(inputs["position_com_in_world"])),
                "joint_angles": np.asarray(inputs["joint_angles"]).tolist()}
    listed = BalanceMeasurement(list(measurement.wrench_left), measurement.wrench_right[::1], [0.0, 0.0],
                                np.zeros(3, dtype=np.float32), list(measurement.joint_angles))
    expected = stabilizer.update(**inputs, measurement=measurement).copy()  # type: ignore[arg-type]
    assert np.abs(twin.update(**as_lists, measurement=listed) - expected).max() < 1e-12  # type: ignore[arg-type]
    state = stabilizer._state.copy()
    short = BalanceMeasurement(measurement.wrench_left[:5], measurement.wrench_right, measurement.attitude,
                               measurement.rate, measurement.joint_angles)
    with pytest.raises(InvalidParameterError, match=r"measurement\.wrench_left.*5 values.*6 values"):
        stabilizer.update(**inputs, measurement=short)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="support"):
        stabilizer.update(**{**inputs, "support": 3}, measurement=measurement)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="zmp_in_world"):
        stabilizer.update(**{**inputs, "zmp_in_world": ["a", 0.0]}, measurement=measurement)  # type: ignore[arg-type]
    assert np.array_equal(stabilizer._state, state)


def test_a_straight_leg_in_the_pattern_is_rejected_leaving_the_state() -> None:
    """A straight knee makes the leg's Jacobian singular: no foot correction maps onto the joints there. The
    tick raises an InvalidParameterError naming the leg's angles (it divided by a zero pivot before) and the
    state is as it was; a knee bent by 0.05 rad is accepted."""
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 20, cop_shift=(0.01, -0.005))
    state, log = stabilizer._state.copy(), stabilizer._log.copy()
    straight = np.asarray(inputs["joint_angles"]).copy()
    straight[6:12] = 0.0  # the right leg hangs straight below the hip
    measurement = measured(stabilizer, inputs)
    with pytest.raises(InvalidParameterError, match=r"joint_angles\[6:12\] \(right leg\).*knee that is not straight"):
        stabilizer.update(**{**inputs, "joint_angles": straight}, measurement=measurement)  # type: ignore[arg-type]
    assert np.array_equal(stabilizer._state, state) and np.array_equal(stabilizer._log, log)
    bent = straight.copy()
    bent[6 + JOINT_NAMES.index("knee")] = 0.05  # [rad] the columns are in JOINT_NAMES' order for each leg
    targets = stabilizer.update(**{**inputs, "joint_angles": bent}, measurement=measurement)  # type: ignore[arg-type]
    assert np.all(np.isfinite(targets))


def test_stabilizer_carries_hubo_on_soft_servos() -> None:
    from zmpwalk.scenarios import load_scenario
    from zmpwalk.sim import simulate

    robot = load_robot("hubo")
    assert robot.servos is not None
    soft = dataclasses.replace(robot, servos=dataclasses.replace(robot.servos, kp=3000.0, kv=60.0))
    pattern = generate(soft, load_scenario("fig27"), rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    bare = simulate(soft, joints, pattern, feedforward=False, settle=0.5, hold=2.0)
    feedforward = simulate(soft, joints, pattern, feedforward=True, settle=0.5, hold=2.0)
    closed = simulate(soft, joints, pattern, stabilizer=Stabilizer(soft, 1000.0), settle=0.5, hold=2.0)
    assert not closed.fell
    # RMS CoP - ZMP: measured 233 mm bare, 54 mm with the feedforward, 34 mm with the stabilizer too
    assert closed.cop_error_stats()[0] < 0.2 * bare.cop_error_stats()[0]
    assert closed.cop_error_stats()[0] < 0.75 * feedforward.cop_error_stats()[0]
    assert closed.final_feet_error < 0.02  # [m]
    assert closed.end_min_sole_force > 0.3 * soft.mass * soft.gravity / 2  # both soles loaded at the end [N]
    assert closed.end_attitude_range < 0.01  # [rad]


@pytest.mark.slow
@pytest.mark.skipif(not TALOS.is_file(), reason="../shared/robots is absent")
def test_talos_walks_with_its_own_servos_and_the_stabilizer() -> None:
    from zmpwalk.sim import simulate

    robot = load_robot(TALOS)
    pattern = generate(robot, [StepCommand(duration=1.0, turn=np.radians(15))] * 3, rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    result = simulate(robot, joints, pattern, stabilizer=Stabilizer(robot, 1000.0))
    assert not result.fell
    assert result.final_feet_error < 0.02  # [m]
    assert result.final_feet_yaw_error < np.radians(2)
    assert result.end_max_speed < 0.05  # [m/s] standing still over the last 2 s
    assert result.end_min_sole_force > 100.0  # [N] both soles loaded


def test_odometry_follows_a_loaded_sole_rolling_on_its_edge() -> None:
    """The reference sole (left, loaded) pitches by 0.02 rad (a heel-first landing rolling flat): its ankle
    moves by the ankle height times the change of the sole normal's horizontal part, h dphi forward."""
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 5, loads=(1.5, 0.5))
    assert stabilizer._anchor == 0
    before = np.asarray(stabilizer._feet[0]).copy()
    angles = np.asarray(inputs["joint_angles"]).copy()
    angles[4] += 0.02  # the left ankle pitch
    run(stabilizer, inputs, 1, joint_angles=angles, loads=(2.0, 0.0))
    chains = leg_chains(stabilizer.robot)
    normals = [chains[0].fk(a[None])[1][0][:, 2] for a in (np.asarray(inputs["joint_angles"])[:6], angles[:6])]
    expected = before + stabilizer.robot.ankle_height * (normals[1] - normals[0])[:2]  # upright torso, heading 0
    assert np.asarray(stabilizer._feet[0]) == pytest.approx(expected, abs=1e-12)
    assert abs(stabilizer._feet[0][0] - before[0]) > 0.5 * stabilizer.robot.ankle_height * 0.02


def test_a_torso_turned_from_its_plan_turns_the_swinging_foot_back_to_its_planned_heading() -> None:
    """Standing on the left foot with the torso measured 0.05 rad left of its plan (a sole slipped in yaw): the
    right foot turns by -0.05 rad relative to the pelvis, i.e. to its planned heading in world (its hip yaw
    moves by as much); the loaded foot keeps its joints; without a measured yaw nothing turns."""
    stabilizer, inputs, _ = standing()
    inputs = {**inputs, "support": 1}
    reference = np.asarray(inputs["joint_angles"])
    angles = run(stabilizer, inputs, 3000, loads=(2.0, 0.0), yaw=0.05)
    assert stabilizer._landing_yaw[1] == pytest.approx(-0.05, abs=1e-6)  # [rad] 15 landing time constants
    assert stabilizer._landing_yaw[0] == 0.0
    right_hip_yaw = 6 + JOINT_NAMES.index("hip_yaw")
    assert angles[right_hip_yaw] - reference[right_hip_yaw] == pytest.approx(-0.05, abs=2e-3)  # [rad]
    plain, inputs, _ = standing()
    run(plain, {**inputs, "support": 1}, 3000, loads=(2.0, 0.0))
    assert np.all(plain._landing_yaw == 0.0)


T1 = Path(__file__).resolve().parents[2] / "shared" / "robots" / "booster_t1" / "scene.xml"


def test_servos_softer_than_kappa_m_g_l_get_an_encoder_loop_of_that_stiffness() -> None:
    """Step 8: G = kappa m g l / k - 1 where the servo is softer, 0 where it is stiffer (HUBO's 20 000
    N m/rad), and the output moves by G times its own tracking error, nothing else changing."""
    hubo, inputs, _ = standing()
    assert not hubo.servo_gain.any()
    robot = hubo.robot
    assert robot.servos is not None
    soft = dataclasses.replace(robot, servos=dataclasses.replace(robot.servos, kp=100.0))
    stiffened = Stabilizer(soft, 1000.0, com_reference=WHOLE_BODY)
    plain = Stabilizer(soft, 1000.0, dataclasses.replace(stiffened.gains, servo_stiffness=0.0),
                       com_reference=WHOLE_BODY)
    weight_moment = robot.mass * robot.gravity * robot.pendulum_length  # the box legs' links sum to the mass
    kappa = StabilizerGains().servo_stiffness
    assert stiffened.servo_gain == pytest.approx(np.full(12, kappa * weight_moment / 100.0 - 1.0), rel=1e-9)
    sagging = np.asarray(inputs["joint_angles"]).copy()
    sagging[3] -= 0.05  # the left knee 0.05 rad short of its target
    for _ in range(3):
        measurement = measured(plain, inputs, joint_angles=sagging)
        without = plain.update(**inputs, measurement=measurement)  # type: ignore[arg-type]
        measurement = measured(stiffened, inputs, joint_angles=sagging)
        with_loop = stiffened.update(**inputs, measurement=measurement)  # type: ignore[arg-type]
        expected = without + stiffened.servo_gain * (without - sagging)
        assert with_loop == pytest.approx(expected, abs=1e-12)
    assert with_loop[3] - without[3] == pytest.approx(stiffened.servo_gain[3] * (without[3] - sagging[3]), abs=1e-12)
    assert with_loop[3] - without[3] > 0.04  # [rad] the knee's target moves on, towards the sag's side


@pytest.mark.slow
@pytest.mark.skipif(not T1.is_file(), reason="../shared/robots is absent")
def test_booster_t1_walks_ten_steps_on_its_own_servos_with_the_stabilizer() -> None:
    """Booster T1's 75 N m/rad servos, its own model: 10 steps of 10 cm at 0.9 s (the HUBO tables scaled),
    the last 2 s standing. Measured: walks, 0.98 m, feet 25.2 mm from their plan, 122 N on the lighter sole."""
    from zmpwalk.sim import simulate

    robot = load_robot(T1)
    pattern = generate(robot, [StepCommand(duration=0.9, forward=0.1)] * 10, rate=1000.0)
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    result = simulate(robot, joints, pattern, stabilizer=Stabilizer(robot, 1000.0))
    assert not result.fell
    assert result.distance == pytest.approx(1.0, abs=0.05)  # [m] the base moved as far as the plan
    assert result.final_feet_error < 0.04  # [m]
    assert result.end_max_speed < 0.05  # [m/s] standing still over the last 2 s
    assert result.end_min_sole_force > 0.15 * robot.mass * robot.gravity  # [N] both soles loaded


def test_a_sole_that_takes_the_load_with_no_tick_of_both_loaded_is_placed_by_the_measured_legs() -> None:
    """After a push the swinging foot can land as the other lifts, with no tick where both carry load: the
    newly loaded sole is placed from the last one by the measured kinematics (its old place, from the last
    double support, is a step behind), and becomes the odometry's reference."""
    stabilizer, inputs, _ = standing()
    run(stabilizer, inputs, 5, loads=(2.0, 0.0))
    assert stabilizer._anchor == 0
    stabilizer._feet[1] = [-1.0, -1.0]  # where the right sole was a step ago
    run(stabilizer, inputs, 1, loads=(0.0, 2.0))
    assert stabilizer._anchor == 1
    left, right = (np.asarray(a) for a in inputs["ankles_in_world"])  # type: ignore[attr-defined]
    expected = np.asarray(stabilizer._feet[0]) + (right - left)[:2]  # upright, heading 0: the legs as planned
    assert np.asarray(stabilizer._feet[1]) == pytest.approx(expected, abs=1e-9)


WHOLE_BODY_TOL = 1e-12  # [m]


def test_against_a_pelvis_point_the_com_offset_rests_where_the_planned_whole_body_com_stands_on_it() -> None:
    """A box model's pattern plans its pelvis point as the cart-table's mass. The planned whole-body CoM lies
    ``d`` from it (the legs at the pattern's angles and the rest of the body, turned by the pelvis yaw), and the
    CoM offset rests at ``-d``: with no admittance, ``Delta c'' = -K_v Delta c' - K_p (Delta c + d)``, it
    settles there (the gain ``whole_body_rest`` 1, HUBO's). Against a whole-body CoM point it stays at zero."""
    whole, inputs, _ = standing()
    robot = whole.robot
    assert Stabilizer(robot, 1000.0).com_reference == "pelvis"  # "auto" for a box model
    gains = dataclasses.replace(whole.gains, com_admittance=0.0, com_stiffness=10.0, com_damping=6.0,
                                slope_time_constant=0.0, whole_body_rest=1.0)
    yaw = 0.3  # [rad]
    in_base = com_in_base(robot, np.asarray(inputs["joint_angles"]))
    expected = np.array([math.cos(yaw) * in_base[0] - math.sin(yaw) * in_base[1],
                         math.sin(yaw) * in_base[0] + math.cos(yaw) * in_base[1]])
    assert np.linalg.norm(expected) > 0.005  # [m] HUBO's legs and body: a real offset to rest at
    turned = {**inputs, "yaw_pelvis_in_world": yaw}
    for reference, rest_at in (("pelvis", -expected), (WHOLE_BODY, np.zeros(2))):
        stabilizer = Stabilizer(robot, 1000.0, gains, com_reference=reference)
        run(stabilizer, turned, 1)
        assert np.abs(stabilizer.state.whole_body_offset + rest_at).max() < WHOLE_BODY_TOL
        run(stabilizer, turned, 4000)  # 4 s: K_p = 10 /s^2, K_v = 6 /s settle within 2 s
        assert np.abs(stabilizer.state.com_offset - rest_at).max() < 0.01 * np.linalg.norm(expected) + 1e-12


def test_a_swinging_sole_that_touches_down_early_does_not_move_the_com() -> None:
    """In single support the CoM admittance answers the stance sole's CoP once the swinging sole has lifted: one
    that touches down early (the left carrying 30 % of the weight, 0.17 m aside, while the plan stands on the right)
    moves the measured ZMP by about 50 mm, and answering that error accelerated the CoM towards the landing foot
    (Menagerie's earlier G1 fell so in its side steps); the force difference control raises the foot instead. Against
    the same walk with the left sole bare, the CoM offset differs by under 0.1 mm after 200 ms. A sole that still
    carries load as it lifts is part of the measured ZMP (the load passes to the stance sole)."""
    bare, inputs, _ = standing()
    swing = {**inputs, "support": 2}
    run(bare, swing, 201, loads=(0.0, 2.0))
    early = Stabilizer(bare.robot, 1000.0, com_reference=WHOLE_BODY)
    run(early, swing, 1, loads=(0.0, 2.0))  # lifted
    run(early, swing, 200, loads=(0.6, 1.4))  # down again
    assert np.abs(early.state.com_offset - bare.state.com_offset).max() < 1e-4  # [m]
    lifting = Stabilizer(bare.robot, 1000.0, com_reference=WHOLE_BODY)
    run(lifting, swing, 201, loads=(0.6, 1.4))  # never lifted: its load counts
    assert np.abs(lifting.state.com_offset - bare.state.com_offset).max() > 1e-3  # [m]
