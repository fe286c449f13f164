"""The capture step: continuity with the plan, the ZMP in the feet, the pendulum's dynamics, the landing rule,
the legs' reach; and in MuJoCo, a backward push that the stabilizer alone does not survive."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from zmpwalk import InfeasiblePatternError, InvalidParameterError, StepCommand, UnreachableError, generate
from zmpwalk.capture import REACH_MARGIN, CaptureSettings, capture_step, quintic_from_rest
from zmpwalk.footsteps import Pose2D, foot_corners
from zmpwalk.kinematics import leg_reach_excess, pattern_joint_trajectory
from zmpwalk.scenarios import load_scenario
from zmpwalk.zmp import point_margin

RATE = 1000.0  # [Hz]


@pytest.fixture(scope="module")
def walk(hubo):
    """HUBO's push walk (fig10's first step, eight 20 cm steps) and the middle of its fifth step's single support."""
    pattern = generate(hubo, load_scenario("fig10")[:1] + [StepCommand(duration=0.95, forward=0.2)] * 8, rate=RATE)
    step = pattern.steps[4]
    index = int(np.searchsorted(pattern.time, step.start + step.duration / 2))
    assert pattern.support[index] != 0  # the test's premise: single support there
    return pattern, index


def capture(hubo, walk, push, **kwargs):
    """A capture step from the middle of the walk's fifth step with the DCM moved by ``push`` [m]."""
    pattern, index = walk
    omega = math.sqrt(hubo.gravity / hubo.pendulum_length)
    com = pattern.position_pelvis_in_world[index]
    dcm = com[:2] + pattern.velocity_pelvis_in_world[index, :2] / omega + np.asarray(push)
    return capture_step(
        hubo, time=float(pattern.time[index]), rate=RATE, end=float(pattern.time[index]) + 3.0,
        stance="left" if pattern.support[index] == 1 else "right", position_com_in_world=com, dcm_in_world=dcm,
        yaw_pelvis_in_world=float(pattern.yaw_pelvis_in_world[index]),
        ankles_in_world=(pattern.position_left_ankle_in_world[index], pattern.position_right_ankle_in_world[index]),
        ankle_velocities_in_world=(pattern.velocity_left_ankle_in_world[index],
                                   pattern.velocity_right_ankle_in_world[index]),
        foot_yaws=(float(pattern.yaw_left_foot_in_world[index]), float(pattern.yaw_right_foot_in_world[index])),
        **kwargs)


PUSHES = [(-0.15, 0.0), (0.12, 0.0), (0.0, -0.1), (-0.1, -0.05), (0.05, 0.02)]  # [m] DCM moved (not to the stance side)


@pytest.mark.parametrize("push", PUSHES)
def test_capture_starts_on_the_plan_and_keeps_the_zmp_in_the_feet(hubo, walk, push):
    pattern, index = walk
    tail, plan = capture(hubo, walk, push)
    # continuous with the plan where it starts (the joint references do not jump)
    assert np.allclose(tail.position_pelvis_in_world[0], pattern.position_pelvis_in_world[index], atol=1e-12)
    for new, old in ((tail.position_left_ankle_in_world, pattern.position_left_ankle_in_world),
                     (tail.position_right_ankle_in_world, pattern.position_right_ankle_in_world)):
        assert np.allclose(new[0], old[index], atol=1e-12)
    swing = 0 if plan.swing == "left" else 1
    old_velocity = (pattern.velocity_left_ankle_in_world, pattern.velocity_right_ankle_in_world)[swing][index]
    new_velocity = (tail.velocity_left_ankle_in_world, tail.velocity_right_ankle_in_world)[swing][0]
    assert np.allclose(new_velocity, old_velocity, atol=1e-9)
    # the ZMP inside the support polygon at every sample: the stance sole in single support, inside it by the
    # inset; the hull of both soles after touchdown
    margin = tail.zmp_margin()
    single = tail.support != 0
    assert margin[single].min() >= CaptureSettings().zmp_inset - 1e-9
    assert margin[~single].min() >= -1e-9
    # it ends at rest: the CoM on the midpoint of the soles, within 1 mm, still to 1 mm/s
    assert np.linalg.norm(tail.position_pelvis_in_world[-1, :2] - plan.rest) < 1e-3
    assert np.linalg.norm(tail.velocity_pelvis_in_world[-1]) < 1e-3


@pytest.mark.parametrize("push", PUSHES)
def test_capture_follows_the_pendulum(hubo, walk, push):
    """p = c - c'' / omega^2 (Eqs. 1-2, the LIPM) on central differences, away from the ZMP's jumps; the DCM
    c + c' / omega in closed form up to touchdown; velocities the positions' derivatives."""
    tail, plan = capture(hubo, walk, push)
    omega = math.sqrt(hubo.gravity / hubo.pendulum_length)
    c, dt = tail.position_pelvis_in_world[:, :2], 1.0 / RATE
    acceleration = (c[2:] - 2 * c[1:-1] + c[:-2]) / dt**2
    zmp = c[1:-1] - acceleration / omega**2
    s = tail.time - tail.time[0]
    away = np.abs(s[1:-1] - plan.swing_time) > 2.5 * dt
    assert np.abs(zmp - tail.zmp_in_world[1:-1])[away].max() < 2e-4  # [m]
    dcm = c + tail.velocity_pelvis_in_world[:, :2] / omega
    single = s < plan.swing_time - 1e-9
    closed = plan.zmp_stance + (plan.dcm_start - plan.zmp_stance) * np.exp(omega * s[single])[:, None]
    assert np.abs(dcm[single] - closed).max() < 1e-9
    touchdown = round(plan.swing_time * RATE)
    assert np.allclose(dcm[touchdown], plan.dcm_touchdown, atol=1e-9)
    swing = tail.position_left_ankle_in_world if plan.swing == "left" else tail.position_right_ankle_in_world
    rate = tail.velocity_left_ankle_in_world if plan.swing == "left" else tail.velocity_right_ankle_in_world
    assert np.abs(np.gradient(swing, tail.time, axis=0)[1:-1] - rate[1:-1]).max() < 5e-3  # [m/s]
    assert np.abs(np.gradient(c, tail.time, axis=0)[1:-1] - tail.velocity_pelvis_in_world[1:-1, :2]).max() < 5e-3


@pytest.mark.parametrize("push", PUSHES)
def test_the_closed_form_com_is_the_pendulum_s_integral(hubo, walk, push):
    """The CoM of every sample (closed form in each phase) against RK4 of c' = omega (xi - c) at 20 kHz over the
    planned DCM, from the same start: within 0.1 um over the swing, the settle and the rest."""
    from zmpwalk.capture_pattern import _dcm_at

    tail, plan = capture(hubo, walk, push)
    omega = math.sqrt(hubo.gravity / hubo.pendulum_length)
    settle = float(tail.steps[0].parameters["settle"])
    s = tail.time - tail.time[0]
    h, fine = 1.0 / 20_000, 20
    state, c = tail.position_pelvis_in_world[0, :2].copy(), [tail.position_pelvis_in_world[0, :2].copy()]
    times = np.arange(len(s) * fine) * h
    xi_at = {key: _dcm_at(_state_of(tail, plan, hubo), plan.rest, settle, times + key)[0] for key in (0.0, h / 2, h)}
    for k in range(len(times) - 1):
        a = omega * (xi_at[0.0][k] - state)
        b = omega * (xi_at[h / 2][k] - (state + h / 2 * a))
        d = omega * (xi_at[h / 2][k] - (state + h / 2 * b))
        e = omega * (xi_at[h][k] - (state + h * d))
        state = state + h / 6 * (a + 2 * b + 2 * d + e)
        if (k + 1) % fine == 0:
            c.append(state.copy())
    assert np.abs(np.array(c) - tail.position_pelvis_in_world[: len(c), :2]).max() < 1e-7  # [m]


def _state_of(tail, plan, hubo):
    """The CaptureState a capture's pattern was built from (what _dcm_at reads of it)."""
    from zmpwalk.capture_pattern import CaptureState

    return CaptureState(hubo, float(tail.time[0]), RATE, 0.0, math.sqrt(hubo.gravity / hubo.pendulum_length),
                        0, tail.position_pelvis_in_world[0], plan.dcm_start, plan.zmp_stance, plan.swing_time,
                        0.0, 0.0, [], [], (0.0, 0.0))


@pytest.mark.parametrize("push", PUSHES)
def test_capture_lands_on_the_dcm_within_reach_and_not_across(hubo, walk, push):
    tail, plan = capture(hubo, walk, push)
    sw = 1 if plan.swing == "left" else -1
    landing = Pose2D(*plan.landing)
    stance_ankle = (tail.position_right_ankle_in_world if plan.swing == "left" else
                    tail.position_left_ankle_in_world)[0]
    # the landing ankle at the end of the tail, on the floor at the stance ankle's height
    end = (tail.position_left_ankle_in_world if plan.swing == "left" else tail.position_right_ankle_in_world)[-1]
    assert np.allclose(end, [landing.x, landing.y, stance_ankle[2]], atol=1e-12)
    corners = foot_corners(landing, sw, hubo)
    inner_gap = abs(float(np.dot(np.array([landing.x, landing.y]) - stance_ankle[:2],
                                 [-math.sin(landing.yaw), math.cos(landing.yaw)])))
    least = hubo.foot_width - 2 * hubo.sole_center_y + CaptureSettings().feet_clearance
    assert inner_gap >= least - 1e-9
    if inner_gap > least + 1e-6 and plan.reached:  # not held off the stance foot: the DCM lands inside the sole
        assert point_margin(*plan.dcm_touchdown, [tuple(p) for p in corners]) >= CaptureSettings().landing_inset - 1e-9
    excess = leg_reach_excess(tail.position_pelvis_in_world, tail.yaw_pelvis_in_world,
                              tail.position_left_ankle_in_world, tail.position_right_ankle_in_world, hubo)
    assert max(excess[0].max(), excess[1].max()) <= -REACH_MARGIN + 1e-12
    pattern_joint_trajectory(tail, check_limits=False)  # the closed-form legs follow it
    # the swinging sole clears the floor by the lift on its way
    swing = (tail.position_left_ankle_in_world if plan.swing == "left" else tail.position_right_ankle_in_world)
    assert swing[: round(plan.swing_time * RATE), 2].max() >= stance_ankle[2] + CaptureSettings().lift - 1e-9


def test_a_fall_beyond_the_stance_foot_is_not_caught_by_one_step(hubo, walk):
    """Pushed towards the stance side (HUBO's fifth step stands on its left foot): the swinging foot may not cross
    the stance foot, so no ZMP in the feet brings the DCM to rest; said, not planned."""
    pattern, index = walk
    assert pattern.support[index] == 1
    with pytest.raises(InfeasiblePatternError, match="outside the feet"):
        capture(hubo, walk, (0.0, 0.15))


def test_a_backward_push_steps_back(hubo, walk):
    tail, plan = capture(hubo, walk, (-0.15, 0.0))
    stance_ankle = (tail.position_right_ankle_in_world if plan.swing == "left" else
                    tail.position_left_ankle_in_world)[0]
    assert plan.landing[0] < stance_ankle[0] - 0.1  # at least 10 cm behind the stance ankle
    assert plan.dcm_touchdown[0] < plan.dcm_start[0] < plan.zmp_stance[0] + 1e-12


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(dx=st.floats(-0.25, 0.25), dy=st.floats(-0.2, 0.2))
def test_any_capture_keeps_the_zmp_in_the_feet_and_the_legs_in_reach(hubo, walk, dx, dy):
    try:
        tail, _ = capture(hubo, walk, (dx, dy))
    except (UnreachableError, InfeasiblePatternError):
        return  # said so (the leg and its excess, or the DCM outside the feet): nothing fits
    assert tail.zmp_margin().min() >= -1e-9
    excess = leg_reach_excess(tail.position_pelvis_in_world, tail.yaw_pelvis_in_world,
                              tail.position_left_ankle_in_world, tail.position_right_ankle_in_world, hubo)
    assert max(excess[0].max(), excess[1].max()) <= -REACH_MARGIN + 1e-12


def test_quintic_from_rest_meets_its_ends():
    rng = np.random.default_rng(3)
    start, velocity, end = rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)
    duration = 0.37
    s = np.array([0.0, duration])
    value, rate = quintic_from_rest(start, velocity, end, duration, s)
    assert np.allclose(value, [start, end], atol=1e-12) and np.allclose(rate, [velocity, np.zeros(3)], atol=1e-12)
    h = 1e-7  # zero acceleration at both ends: the rate's one-sided differences vanish with h
    _, near = quintic_from_rest(start, velocity, end, duration, np.array([h, duration - h]))
    assert np.allclose((near[0] - velocity) / h, 0.0, atol=1e-3)
    assert np.allclose(-near[1] / h, 0.0, atol=1e-3)


def test_bad_input_is_rejected(hubo, walk):
    with pytest.raises(InvalidParameterError, match="stance"):
        capture_step(hubo, time=0.0, rate=RATE, end=1.0, stance="middle", position_com_in_world=np.zeros(3),
                     dcm_in_world=np.zeros(2), yaw_pelvis_in_world=0.0, ankles_in_world=(np.zeros(3), np.zeros(3)),
                     ankle_velocities_in_world=(np.zeros(3), np.zeros(3)), foot_yaws=(0.0, 0.0))
    with pytest.raises(InvalidParameterError, match="end"):
        capture_step(hubo, time=2.0, rate=RATE, end=1.0, stance="left", position_com_in_world=np.zeros(3),
                     dcm_in_world=np.zeros(2), yaw_pelvis_in_world=0.0, ankles_in_world=(np.zeros(3), np.zeros(3)),
                     ankle_velocities_in_world=(np.zeros(3), np.zeros(3)), foot_yaws=(0.0, 0.0))
    with pytest.raises(InvalidParameterError, match="shortest_swing"):
        CaptureSettings(shortest_swing=0.7, longest_swing=0.6)
    with pytest.raises(InvalidParameterError, match=r"capture\.trigger"):
        CaptureSettings(trigger=-0.1)
    with pytest.raises(InvalidParameterError, match="foot_speed"):
        CaptureSettings(foot_speed=0.0)
    with pytest.raises(InvalidParameterError, match=r"capture\.lead = 0\.5 .*at most 0\.2 s"):
        CaptureSettings(lead=0.5)
    with pytest.raises(InvalidParameterError, match=r"capture\.lead"):
        CaptureSettings(lead=-0.01)


@pytest.mark.slow
def test_a_backward_push_is_survived_with_a_capture_step_and_not_without(hubo, walk):
    """HUBO pushed backward with 36 N s mid single support (``bench/bench_robustness.py``'s case): with the
    stabilizer alone it falls; with capture steps it steps back, comes to rest and ends with its feet where the
    capture planned them (within 20 mm, the verdict's bound)."""
    from zmpwalk import Stabilizer
    from zmpwalk.sim import simulate
    from zmpwalk.sim.disturbances import Disturbances

    pattern, index = walk
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    push = Disturbances(push_time=float(pattern.time[index]), push_impulse=(-36.0, 0.0, 0.0))
    results = [simulate(hubo, joints, pattern, stabilizer=Stabilizer(hubo, RATE), settle=0.5, hold=2.0,
                        disturbances=push, capture=capture) for capture in (None, CaptureSettings())]
    assert results[0].fell and not results[0].captures
    result = results[1]
    assert not result.fell
    assert 1 <= len(result.captures) <= 5
    first = result.captures[0]
    assert first.swing == pattern.steps[4].swing
    assert push.push_time < first.time < push.push_time + 0.2  # planned within the push's first 0.2 s
    assert result.final_feet_error < 0.02  # [m]
    assert result.end_min_sole_force > 0.0  # ends on both feet
    with pytest.raises(InvalidParameterError, match="capture"):
        simulate(hubo, joints, pattern, capture=CaptureSettings())  # needs the stabilizer's estimate


def test_capture_without_what_it_needs_is_refused(hubo, walk, capsys):
    """A multibody-corrected pattern (its CoM point is not the pelvis point a capture step plans) and the command
    line without the stabilizer: one clear error each, before anything is simulated."""
    import dataclasses

    from zmpwalk import Stabilizer
    from zmpwalk.cli import main
    from zmpwalk.sim import simulate

    pattern, _ = walk
    corrected = dataclasses.replace(pattern, position_com_in_world=pattern.position_pelvis_in_world.copy())
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    with pytest.raises(InvalidParameterError, match="multibody-corrected"):
        simulate(hubo, joints, corrected, stabilizer=Stabilizer(hubo, RATE, com_reference="whole_body"),
                 capture=CaptureSettings())
    assert main(["simulate", "--scenario", "fig10", "--balance", "off", "--capture"]) == 2
    assert "--capture needs the stabilizer" in capsys.readouterr().err


@pytest.mark.slow
def test_the_controller_takes_the_capture_step_that_saves_a_pushed_walk(hubo, walk):
    """The same push through the walking controller (commands given in the loop, the capture policy in the
    controller): without capture steps HUBO falls; with them it steps back within the push's first 0.2 s, comes to
    rest on both feet with them within 20 mm of the capture's plan (measured 13.7 mm; the batch walk's 4.5 mm)."""
    from zmpwalk.online import START_DELAY
    from zmpwalk.sim.disturbances import Disturbances
    from zmpwalk.sim.loop import simulate_controller

    pattern, index = walk
    commands = load_scenario("fig10")[:1] + [StepCommand(duration=0.95, forward=0.2)] * 8
    push_time = float(pattern.time[index]) + START_DELAY  # the controller's clock starts START_DELAY earlier
    push = Disturbances(push_time=push_time, push_impulse=(-36.0, 0.0, 0.0))
    runs = [simulate_controller(hubo, commands, disturbances=push, capture=capture)
            for capture in (None, CaptureSettings())]
    assert runs[0].result.fell and not runs[0].result.captures
    result = runs[1].result
    assert not result.fell
    assert 1 <= len(result.captures) <= 5
    first = result.captures[0]
    assert first.swing == pattern.steps[4].swing
    assert push_time < first.time < push_time + 0.2
    assert result.final_feet_error < 0.02  # [m]
    assert result.end_min_sole_force > 0.0 and result.end_max_speed < 0.05  # ends standing still on both feet
    standing = runs[1].controller.walker.tick()  # the walker stands where the capture left the feet
    landing = first if len(result.captures) == 1 else result.captures[-1]
    side = standing.position_left_ankle_in_world if landing.swing == "left" else standing.position_right_ankle_in_world
    np.testing.assert_allclose(side[:2], landing.landing[:2], atol=1e-9, rtol=0)


@pytest.mark.slow
def test_a_joystick_walk_walks_on_after_the_controller_s_capture_step(hubo):
    """Velocity commands through a push: the controller takes a capture step, the walker stands where it left the
    feet, and the velocity's steps walk on from there until the stop (the capture's stop is not the walk's end)."""
    from zmpwalk.control import WalkingController
    from zmpwalk.sim.disturbances import Disturbances
    from zmpwalk.sim.loop import simulate_controller
    from zmpwalk.sim.mujoco_plant import MujocoPlant

    plant = MujocoPlant(hubo, RATE, disturbances=Disturbances(push_time=3.2, push_impulse=(-36.0, 0.0, 0.0)))
    controller = WalkingController(hubo, RATE, feedforward=plant.feedforward(), capture=CaptureSettings())
    captured_at: list[float] = []

    def joystick(controller: WalkingController, tick: int) -> None:
        if tick == 0:
            controller.set_velocity(0.15, 0.0, 0.0)
        if controller.captures and not captured_at:
            captured_at.append(float(controller.sample.position_left_ankle_in_world[0]) if controller.sample else 0.0)
        if tick == 11000:
            controller.set_velocity(0.0, 0.0, 0.0)

    run = simulate_controller(hubo, operator=joystick, duration=16.0, controller=controller, plant=plant)
    result = run.result
    assert not result.fell and len(result.captures) >= 1
    assert 3.2 < result.captures[0].time < 3.4  # [s] within the push's first 0.2 s
    assert result.ankle_positions[-1, :, 0].min() > captured_at[0] + 0.3  # [m] walked on after the capture
    assert result.final_feet_error < 0.02 and result.end_max_speed < 0.05  # [m], [m/s] ends standing as planned


@pytest.mark.slow
def test_a_capture_the_walker_cannot_stand_after_holds_its_rest_pose(hubo, walk, monkeypatch):
    """Where the walker's standing pose cannot reach the capture's feet (a wide sideways capture; here made so),
    no tick raises: the controller holds the capture's rest pose (``stranded``) and the robot ends standing."""
    from zmpwalk.errors import UnreachableError
    from zmpwalk.online import START_DELAY, OnlineWalker
    from zmpwalk.sim.disturbances import Disturbances
    from zmpwalk.sim.loop import simulate_controller

    def unreachable(self, stance):
        raise UnreachableError("left", math.nan, 0.0067)

    monkeypatch.setattr(OnlineWalker, "stand_at", unreachable)
    pattern, index = walk
    commands = load_scenario("fig10")[:1] + [StepCommand(duration=0.95, forward=0.2)] * 8
    push = Disturbances(push_time=float(pattern.time[index]) + START_DELAY, push_impulse=(-36.0, 0.0, 0.0))
    run = simulate_controller(hubo, commands, disturbances=push, capture=CaptureSettings())
    assert run.controller.stranded and run.result.captures and not run.result.fell
    assert run.result.final_feet_error < 0.02 and run.result.end_max_speed < 0.05  # [m], [m/s]
    held = run.controller.sample  # the capture's last sample: its pelvis point 0.2 mm from where the DCM rests
    np.testing.assert_allclose(held.position_pelvis_in_world[:2], run.controller.captures[-1].rest, atol=1e-3, rtol=0)


def test_a_capture_is_wanted_only_beyond_the_trigger_with_the_swinging_sole_unloaded():
    """The trigger's rule, shared by the controller and the batch loop: the DCM error's length against the trigger
    (100 mm beyond it, 70 mm not), and never once the swinging sole carries load."""
    from zmpwalk.capture import capture_wanted

    trigger, threshold = 0.08, 25.0  # [m], [N]
    assert capture_wanted(np.array([0.06, 0.08]), trigger, 0.0, threshold)  # 100 mm
    assert not capture_wanted(np.array([0.042, 0.056]), trigger, 0.0, threshold)  # 70 mm
    assert capture_wanted(np.array([0.0, -0.0801]), trigger, threshold, threshold)  # at the threshold: unloaded
    assert not capture_wanted(np.array([0.2, 0.0]), trigger, threshold + 0.1, threshold)  # landed


@pytest.mark.parametrize("push", PUSHES)
@pytest.mark.parametrize("settle", [1.0, 0.25])
def test_the_zmp_margin_in_closed_form_is_the_sampled_patterns(hubo, walk, push, settle):
    """The capture's least ZMP margin in closed form (p1 in the single support; in the settle the extremes of g on
    the ZMP's line, the root of tau^2 - (1 + 4k) tau + 2k) bounds the margin of the pattern sampled at 1 kHz from
    below, within 0.5 mm: a short settle overshoots the ZMP past xi(T) (g > 1), which the ends alone miss."""
    from zmpwalk.capture_pattern import CaptureState, zmp_margin_of_capture

    tail, plan = capture(hubo, walk, push, settings=CaptureSettings(settle=settle))
    st = 0 if plan.swing == "right" else 1
    ankles = [tail.position_left_ankle_in_world[0], tail.position_right_ankle_in_world[0]]
    state = CaptureState(hubo, float(tail.time[0]), RATE, 0.0, math.sqrt(hubo.gravity / hubo.pendulum_length), st,
                         tail.position_pelvis_in_world[0], plan.dcm_start, plan.zmp_stance, plan.swing_time,
                         plan.landing[2], 0.0, ankles, [np.zeros(3), np.zeros(3)], (0.0, 0.0))
    used = float(tail.steps[0].parameters["settle"])
    closed = zmp_margin_of_capture(state, np.array(plan.landing[:2]), used)
    sampled = float(tail.zmp_margin().min())
    assert sampled - 5e-4 <= closed <= sampled + 1e-12  # [m]


def test_the_predicted_dcm_error_follows_the_pendulum(hubo):
    """The DCM error observed tick by tick as the pendulum's, e = dp + (e0 - dp) exp(omega t) (a ZMP offset held,
    the stabilizer's or a push's): predicted 29 ticks on within 2 % of its growth from the last observed one."""
    from zmpwalk.control.capture import CapturePolicy

    policy = CapturePolicy(hubo, RATE, CaptureSettings())
    omega = math.sqrt(hubo.gravity / hubo.pendulum_length)
    offset, start = np.array([0.05, 0.03]), np.array([-0.08, 0.0])  # [m] the ZMP held ahead of a push backward

    def error(tick):
        return offset + (start - offset) * math.exp(omega * tick / RATE)

    for tick in range(10):
        policy.observe(error(tick))
    truth, last = error(9 + 29), error(9)
    predicted = policy.predicted_dcm_error(29)
    assert np.abs(predicted - truth).max() <= 0.02 * np.abs(truth - last).max()
    assert np.abs(truth - last).max() > 0.01  # the premise: it grows by centimetres over the lead


def test_the_controller_plans_a_capture_over_its_lead_a_few_parts_a_tick(hubo, monkeypatch):
    """A capture forced 200 ticks into a single support (the trigger replaced) on the mock plant: it takes over
    exactly ``lead`` ticks after its trigger, with no tick running more than two of its parts (1 kHz, 0.04 s: paced
    for the parts of the last plan and of one more landing tried), and
    the references stay continuous there (the pelvis point moves at most 1 mm and each joint at most twice its
    largest move per tick over the 100 ticks before)."""
    import zmpwalk.control.capture as policy_module
    from zmpwalk.control import MockPlant, WalkingController

    calls = itertools.count()
    monkeypatch.setattr(policy_module, "capture_wanted", lambda *args: next(calls) == 200)
    controller, plant = WalkingController(hubo, RATE, capture=CaptureSettings()), MockPlant(hubo, RATE)
    policy = controller.capture
    starts = []
    start = policy.start
    monkeypatch.setattr(policy, "start", lambda tick, *args: starts.append(tick) or start(tick, *args))
    for _ in range(4):
        controller.command(StepCommand(duration=0.95, forward=0.15))
    log = []
    for _ in range(4000):
        targets = controller.update(plant.measure())
        plant.apply(targets)
        plant.step()
        log.append(targets)
    assert len(starts) == 1 and len(controller.captures) == 1
    first = starts[0] + policy.lead
    assert policy.lead == 40 and controller.captures[0].time == pytest.approx(log[first].sample.time, abs=1e-12)
    assert log[first].sample.support == log[first - 1].sample.support  # taken over within the single support
    assert 1 <= policy.parts_per_tick <= 2
    pelvis = np.array([t.sample.position_pelvis_in_world for t in log[first - 100:first + 1]])
    angles = np.array([t.sample.joint_angles for t in log[first - 100:first + 1]])
    assert np.linalg.norm(pelvis[-1] - pelvis[-2]) < 1e-3  # [m]
    steps = np.abs(np.diff(angles, axis=0))
    assert (steps[-1] <= 2.0 * steps[:-1].max(axis=0) + 1e-9).all()


@pytest.mark.slow
def test_the_corrected_targets_do_not_jump_where_a_capture_takes_over(hubo):
    """HUBO walking at 0.15 m/s, pushed 36 N s backward at 3.2 s: the stabilizer's landing correction of the
    swinging foot grows during the 40 ms lead (-4.6 mm at the trigger, -19.2 mm at the take-over); the capture
    starts from the first and the stabilizer keeps the rest, so no corrected joint target moves more at the take-over
    than the most it moved per tick over the 100 ticks before (taking all of it at the take-over moved two joints
    33.5 and 26.3 mrad, against 1.5 and 0.4 mrad)."""
    from zmpwalk.control import WalkingController
    from zmpwalk.sim.disturbances import Disturbances
    from zmpwalk.sim.loop import simulate_controller, simulated_clock
    from zmpwalk.sim.mujoco_plant import MujocoPlant

    log = []

    class Logged(WalkingController):
        def update(self, measurement):
            targets = super().update(measurement)
            log.append((targets.angles.copy(), len(self.captures)))
            return targets

    plant = MujocoPlant(hubo, RATE, disturbances=Disturbances(push_time=3.2, push_impulse=(-36.0, 0.0, 0.0)))
    controller = Logged(hubo, RATE, feedforward=plant.feedforward(), capture=CaptureSettings(),
                        clock=simulated_clock(RATE))
    run = simulate_controller(hubo, operator=lambda c, k: c.set_velocity(0.15, 0.0, 0.0) if k == 0 else None,
                              duration=5.0, controller=controller, plant=plant)
    assert not run.result.fell
    first = [count for _, count in log].index(1)  # the take-over tick
    steps = np.abs(np.diff(np.array([angles for angles, _ in log]), axis=0))
    assert (steps[first - 1] <= steps[first - 101:first - 1].max(axis=0) + 1e-4).all()  # [rad]


def test_a_landing_correction_handed_over_keeps_what_the_plan_did_not_take(hubo):
    """Stabilizer.hand_over_landing(foot, taken): the correction keeps its part beyond ``taken``; None takes it all;
    a malformed ``taken`` is refused by name, the correction unchanged."""
    from zmpwalk.balance import Stabilizer

    stabilizer = Stabilizer(hubo, RATE)
    stabilizer._landing[1] = (0.010, -0.020)  # [m] the right foot's, as a swing would leave it
    taken = stabilizer.hand_over_landing("right", np.array([0.004, -0.005]))
    np.testing.assert_allclose(taken, [0.004, -0.005], atol=1e-15)
    np.testing.assert_allclose(stabilizer.landing_correction("right"), [0.006, -0.015], atol=1e-15)
    with pytest.raises(InvalidParameterError, match="taken"):
        stabilizer.hand_over_landing("right", np.array([math.nan, 0.0]))
    np.testing.assert_allclose(stabilizer.landing_correction("right"), [0.006, -0.015], atol=1e-15)
    np.testing.assert_allclose(stabilizer.hand_over_landing("right"), [0.006, -0.015], atol=1e-15)
    np.testing.assert_allclose(stabilizer.landing_correction("right"), [0.0, 0.0], atol=0)


def test_a_slow_loop_plans_its_capture_within_the_triggering_tick(hubo):
    """The lead in ticks: 40 at 1 kHz, 8 at 200 Hz; one (the whole plan in the triggering tick) at 125 Hz and below,
    whose period holds the plan's 40 nominal parts of 0.1 ms twice over."""
    from zmpwalk.control.capture import CapturePolicy

    leads = {rate: CapturePolicy(hubo, rate, CaptureSettings()).lead for rate in (1000.0, 200.0, 125.0, 100.0, 50.0)}
    assert leads == {1000.0: 40, 200.0: 8, 125.0: 1, 100.0: 1, 50.0: 1}
