"""The WalkingController: against the mock plant (commands, velocities, hostile input) and in MuJoCo, where the
simulator runs it tick by tick with the commands given inside the loop, against today's batch simulation."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from zmpwalk import InfeasibleCommandError, InvalidParameterError, StepCommand, generate, pattern_joint_trajectory
from zmpwalk.balance import BalanceMeasurement, Stabilizer
from zmpwalk.control import MockPlant, WalkingController, sole_wrenches, velocity_command, velocity_step_time
from zmpwalk.online import START_DELAY
from zmpwalk.sim import simulate
from zmpwalk.sim.disturbances import SensorNoise
from zmpwalk.sim.loop import simulate_controller
from zmpwalk.sim.mujoco_plant import MujocoPlant
from zmpwalk.sim.verdict import HOLD, walk_verdict

RATE = 1000.0


def _loop(controller, plant, ticks, on_tick=None):
    """Run the robot's loop for ``ticks``; the targets of each tick."""
    log = []
    for k in range(ticks):
        if on_tick is not None:
            on_tick(k)
        targets = controller.update(plant.measure())
        plant.apply(targets)
        plant.step()
        log.append(targets)
    return log


def _landings(log):
    """(time [s], x of the landed ankle [m], foot) at each touchdown: where a single support turns double."""
    landings = []
    for before, after in itertools.pairwise(log):
        if before.sample.support != "double" and after.sample.support == "double":
            foot = 1 if before.sample.support == "left" else 0  # the swinging foot lands
            ankle = (after.sample.position_left_ankle_in_world, after.sample.position_right_ankle_in_world)[foot]
            landings.append((after.time, float(ankle[0]), foot))
    return landings


def _until_standing(controller, plant, limit=20_000):
    log = []
    while controller.walker.walking and len(log) < limit:
        log += _loop(controller, plant, 1)
    return log


def test_the_mock_soles_carry_the_pendulum_at_the_zmp(hubo):
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    controller.command(StepCommand(0.8, 0.15, turn=0.2))
    log = _loop(controller, plant, 4000)
    for targets in log[::97]:
        sample = targets.sample
        left, right = sole_wrenches(hubo, sample)
        total = 0.0
        moment = np.zeros(2)
        for wrench, ankle, yaw in ((left, sample.position_left_ankle_in_world, sample.yaw_left_foot_in_world),
                                   (right, sample.position_right_ankle_in_world, sample.yaw_right_foot_in_world)):
            c, s = math.cos(yaw), math.sin(yaw)
            to_world = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            force, torque = to_world @ wrench[:3], to_world @ wrench[3:]
            # the CoP on the floor (z = 0) from the wrench about the ankle
            h = ankle[2]
            cop = ankle[:2] + np.array([-(torque[1] + h * force[0]), torque[0] - h * force[1]]) / max(force[2], 1e-9)
            moment += force[2] * cop
            total += force[2]
        assert total == pytest.approx(hubo.mass * hubo.gravity, rel=1e-12)
        np.testing.assert_allclose(moment / total, sample.zmp_in_world, atol=1e-9, rtol=0)


def test_a_command_mid_walk_changes_the_walk(hubo):
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    first, second, third = StepCommand(0.8, 0.1), StepCommand(0.8, 0.1), StepCommand(0.8, 0.25)
    controller.command(first)

    def operator(tick):
        # each command during the step before it, once that step is under way
        walker = controller.walker
        if walker.current is first and walker.queued is None and walker.checking is None and tick % 200 == 0:
            controller.command(second)
        if walker.current is second and walker.queued is None and walker.checking is None:
            controller.command(third)  # a longer stride, given while the second step is under way

    log = _loop(controller, plant, 4000, operator) + _until_standing(controller, plant)
    landings = [x for _, x, _ in _landings(log)]
    np.testing.assert_allclose(landings, [0.1, 0.2, 0.45, 0.45], atol=1e-9, rtol=0)  # the last: the closing step
    final = log[-1].sample
    np.testing.assert_allclose([final.position_left_ankle_in_world[0], final.position_right_ankle_in_world[0]],
                               [0.45, 0.45], atol=1e-9, rtol=0)
    assert controller.faults == 0 and all(t.corrected for t in log)
    corrections = np.array([np.abs(t.angles - t.sample.joint_angles).max() for t in log])
    assert corrections.max() < 0.15  # [rad] the stabilizer's offsets on a plant that follows exactly


def test_velocity_step_times_come_from_the_schedule(hubo, schedule):
    # HUBO's tables: strides up to 0.30 m at 0.95 s, 0.25 m at 0.8 and 0.7 s; side steps up to 0.07 m
    assert velocity_step_time(schedule, hubo, 0.2, 0.0, 0.0) == pytest.approx(0.95)  # 0.19 m at 0.95 s
    assert velocity_step_time(schedule, hubo, 0.35, 0.0, 0.0) == pytest.approx(0.7)  # 0.3325 > 0.30, 0.28 > 0.25
    assert velocity_step_time(schedule, hubo, 0.6, 0.0, 0.0) == pytest.approx(0.7)  # beyond every table: shortest
    assert velocity_step_time(schedule, hubo, 0.0, 0.05, 0.0) == pytest.approx(0.7)  # side 2 vy T = 0.070 m
    step = velocity_command(schedule, hubo, 0.1, -0.02, 0.1)
    assert (step.duration, step.forward, step.side, step.turn) == pytest.approx((0.95, 0.095, -0.038, 0.19))
    with pytest.raises(InvalidParameterError, match=r"wz = 3 .*turn = 2 wz T"):
        velocity_command(schedule, hubo, 0.0, 0.0, 3.0)
    with pytest.raises(InvalidParameterError, match="vx = nan"):
        velocity_command(schedule, hubo, math.nan, 0.0, 0.0)
    with pytest.raises(InvalidParameterError, match="step_time"):
        velocity_command(schedule, hubo, 0.1, 0.0, 0.0, step_time=0.01)


def test_set_velocity_walks_strides_of_velocity_times_step_time(hubo):
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    controller.set_velocity(0.1, 0.0, 0.0)  # 0.095 m at 0.95 s

    def operator(tick):
        if tick == 4000:
            controller.set_velocity(0.2, 0.0, 0.0)  # 0.19 m at 0.95 s, from the next step whose check completes
        if tick == 8000:
            controller.set_velocity(0.0, 0.0, 0.0)  # stops after the step under way

    log = _loop(controller, plant, 9000, operator) + _until_standing(controller, plant)
    landings = _landings(log)
    strides = np.diff([0.0] + [x for _, x, _ in landings])
    # first 0.095 m strides, then 0.19 m ones, the closing step lands beside the other foot
    slow = int(np.argmax(strides > 0.1))
    np.testing.assert_allclose(strides[:slow], 0.095, atol=1e-9, rtol=0)
    np.testing.assert_allclose(strides[slow:-1], 0.19, atol=1e-9, rtol=0)
    assert strides[-1] == pytest.approx(0.0, abs=1e-9) and slow >= 3 and len(strides) - 1 - slow >= 3
    times = np.diff([t for t, _, _ in landings[:-1]])
    np.testing.assert_allclose(times, 0.95, atol=1.5 / RATE, rtol=0)  # [s] one step time between touchdowns
    assert not controller.walker.walking and controller.velocity is None


def test_a_sideways_velocity_moves_the_feet_by_twice_vy_per_command(hubo):
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    controller.set_velocity(0.0, 0.05, 0.0)  # side = 2 vy T = 0.07 m at 0.7 s: two swings per command
    log = _loop(controller, plant, round((START_DELAY + 4 * 1.4) * RATE), lambda k: None)
    controller.set_velocity(0.0, 0.0, 0.0)
    log += _until_standing(controller, plant)
    final = log[-1].sample
    y = (final.position_left_ankle_in_world[1] + final.position_right_ankle_in_world[1]) / 2
    commands = round(y / 0.07)
    assert commands >= 3 and y == pytest.approx(0.07 * commands, abs=1e-9)


def test_a_velocity_beyond_reach_is_refused_not_clipped(hubo):
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    controller.set_velocity(0.6, 0.0, 0.0)  # 0.42 m at 0.7 s: beyond HUBO's legs
    log = _loop(controller, plant, 1500)
    assert controller.rejected is controller.velocity_step
    error = controller.rejection
    assert isinstance(error, InfeasibleCommandError) and error.parameter == "forward"
    assert 0.0 < error.largest["forward"] < 0.42
    # no step was taken (nothing was clipped to fit), and the refused step is not given again
    assert not controller.walker.walking and controller.walker.checking is None
    np.testing.assert_allclose(log[-1].sample.position_left_ankle_in_world[:2], [0.0, hubo.hip_spacing / 2],
                               atol=1e-12, rtol=0)
    with pytest.raises(InvalidParameterError, match="vx = 5 "):
        controller.set_velocity(5.0, 0.0, 0.0)  # 3.5 m per step: no StepCommand


def test_update_never_raises_for_hostile_commands(hubo):
    rng = np.random.default_rng(33)
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    refused_at_call = refused = 0
    due = 0

    def operator(tick):
        nonlocal refused_at_call, refused, due
        if tick < due:
            return
        due = tick + int(rng.integers(100, 2500))  # [ticks] (a walk from standstill starts 600 ticks later)
        refused += controller.rejected is not None
        action = int(rng.integers(4))
        try:
            if action == 0:
                controller.command(StepCommand(float(rng.uniform(0.1, 2.0)), float(rng.uniform(-1.5, 1.5)),
                                               float(rng.uniform(-0.5, 0.5)), float(rng.uniform(-1.5, 1.5))))
            elif action == 1:
                controller.set_velocity(*rng.uniform(-1.5, 1.5, 3))
            elif action == 2:
                controller.stop()
            else:
                controller.command(StepCommand(0.8, float(rng.uniform(-0.1, 0.2)), turn=float(rng.uniform(-0.2, 0.2))))
        except InvalidParameterError:
            refused_at_call += 1

    log = _loop(controller, plant, 30_000, operator)
    angles = np.array([t.angles for t in log])
    assert angles.shape == (30_000, 12) and np.isfinite(angles).all()
    assert controller.faults == 0 and refused >= 5 and refused_at_call >= 1
    assert max(abs(t.sample.position_left_ankle_in_world[0]) for t in log) > 0.1  # it walked between refusals
    with pytest.raises(InvalidParameterError, match="measurement"):
        controller.update(None)


def test_a_measurement_the_stabilizer_cannot_use_gives_the_pattern_for_that_tick(hubo):
    controller, plant = WalkingController(hubo, RATE), MockPlant(hubo, RATE)
    controller.command(StepCommand(0.8, 0.1))
    _loop(controller, plant, 700)
    good = plant.measure()
    bad = BalanceMeasurement(good.wrench_left, good.wrench_right, good.attitude, good.rate, good.joint_angles[:5])
    targets = controller.update(bad)
    assert not targets.corrected and controller.faults == 1
    assert controller.fault is not None and "measurement.joint_angles" in str(controller.fault)
    np.testing.assert_array_equal(targets.angles, targets.sample.joint_angles)
    assert controller.update(plant.measure()).corrected


# --- MuJoCo: the simulator runs the controller

WALK = [StepCommand(0.8, 0.1)] * 3 + [StepCommand(0.8, 0.2)] * 3 + [StepCommand(0.8, stop=True)]


@pytest.fixture(scope="module")
def walks(hubo):
    """The same walk through the controller (commands given in the loop) and through today's batch simulate."""
    run = simulate_controller(hubo, WALK)
    pattern = generate(hubo, WALK, rate=RATE)
    batch = simulate(hubo, pattern_joint_trajectory(pattern, check_limits=False), pattern,
                     stabilizer=Stabilizer(hubo, RATE, com_reference=pattern.com_point), settle=START_DELAY, hold=HOLD)
    return run, batch


def test_hubo_walks_through_the_controller_with_the_stride_changed_mid_walk(walks):
    run, _ = walks
    result = run.result
    verdict = walk_verdict(result, HOLD)
    assert verdict.passed, verdict.lines()
    assert not run.rejections and run.faults == 0 and len(run.given) == len(WALK)
    # each command after the first given half a step time into the step before it
    assert run.given[0] == 0.0 and all(0.0 < b - a < 2.5 for a, b in itertools.pairwise(run.given))
    np.testing.assert_allclose(result.ankle_positions[-1, :, 0], [0.9, 0.9], atol=0.003, rtol=0)  # [m]
    assert result.final_feet_error < 0.003 and result.plan_zmp_margin > 0.0


def test_the_controller_walks_as_the_batch_simulation(walks):
    run, batch = walks
    result = run.result
    # the same pattern: the batch's settle (from -START_DELAY) is the controller's wait for its first step
    assert batch.time[0] == pytest.approx(-START_DELAY)
    n = min(len(result.time), len(batch.time))
    np.testing.assert_allclose(result.reference_zmp[:n], batch.reference_zmp[:n], atol=1e-9, rtol=0)
    controller_rms, batch_rms = result.cop_error_stats()[0], batch.cop_error_stats()[0]
    assert controller_rms == pytest.approx(batch_rms, abs=0.002)  # [m] measured 16.4 and 17.4 mm
    np.testing.assert_allclose(result.ankle_positions[-1, :, :2], batch.ankle_positions[-1, :, :2], atol=0.002,
                               rtol=0)  # [m]
    # the per-tick feedforward against the batch's (central differences at 5 ms, interpolated)
    difference = result.planned_torques[:n] - batch.planned_torques[:n]
    assert np.sqrt((difference**2).mean(axis=0)).max() < 3.0  # [N m] measured 2.2 (knees, RMS 41 N m)


def test_a_velocity_operator_in_the_loop_walks_and_stops(hubo):
    def operator(controller, tick):
        if tick == 0:
            controller.set_velocity(0.1, 0.0, 0.0)
        if tick == 4000:
            controller.set_velocity(0.2, 0.0, 0.0)
        if tick == 7000:
            controller.set_velocity(0.0, 0.0, 0.0)

    run = simulate_controller(hubo, operator=operator, duration=12.5)  # it stands still from 9.95 s
    verdict = walk_verdict(run.result, HOLD)
    assert verdict.passed, verdict.lines()
    left, right = run.result.ankle_positions[-1, :, 0]
    assert left == pytest.approx(right, abs=0.003) and left > 0.5  # [m]


def test_bad_loop_input_is_named(hubo):
    with pytest.raises(InvalidParameterError, match="duration"):
        simulate_controller(hubo, operator=lambda controller, tick: None)
    with pytest.raises(InvalidParameterError, match="command_phase"):
        simulate_controller(hubo, WALK, command_phase=1.0)
    with pytest.raises(InvalidParameterError, match="rate = 3000"):
        MujocoPlant(hubo, 3000.0)
    with pytest.raises(InvalidParameterError, match=r"controller\.rate"):
        simulate_controller(hubo, WALK, controller=WalkingController(hubo, 500.0))


def _stood(hubo, **options):
    """A MuJoCo plant standing in the walker's ready pose, and its controller (stabilizer off: the same targets
    whatever the plant measures)."""
    plant = MujocoPlant(hubo, RATE, **options)
    controller = WalkingController(hubo, RATE, balance=False)
    plant.stand(controller.walker.tick())
    return plant, controller


def test_the_plant_measures_its_sensors_late_and_noisy_as_asked(hubo):
    """With ``latency`` the measurement of tick k is the latency-free plant's of tick k - 3 (the first before
    that); with ``noise`` it differs from the noiseless one by draws of the stated size, the same for one seed."""
    plain, late = _stood(hubo), _stood(hubo, latency=0.003)
    readings = []
    for k in range(40):
        if k == 5:
            for _, controller in (plain, late):
                controller.command(StepCommand(0.8, 0.1))
        now, delayed = plain[0].measure(), late[0].measure()
        readings.append(now)
        expected = readings[max(k - 3, 0)]
        np.testing.assert_array_equal(delayed.wrench_left, expected.wrench_left)
        np.testing.assert_array_equal(delayed.joint_angles, expected.joint_angles)
        for plant, controller in (plain, late):
            plant.apply(controller.update(now))
            plant.step()
    assert not np.array_equal(readings[0].wrench_left, readings[-1].wrench_left)  # the sensors did change
    noise = SensorNoise(force=5.0, encoder=0.001, seed=3)
    first, second, clean = _stood(hubo, noise=noise)[0], _stood(hubo, noise=noise)[0], _stood(hubo)[0]
    draws = [first.measure() for _ in range(200)]
    again, truth = second.measure(), clean.measure()
    np.testing.assert_array_equal(again.wrench_left, draws[0].wrench_left)
    forces = np.array([d.wrench_left[:3] - truth.wrench_left[:3] for d in draws])
    encoders = np.array([d.joint_angles - truth.joint_angles for d in draws])
    assert forces.std() == pytest.approx(5.0, rel=0.15) and encoders.std() == pytest.approx(0.001, rel=0.15)
    with pytest.raises(InvalidParameterError, match="latency"):
        MujocoPlant(hubo, RATE, latency=0.0015)
    with pytest.raises(InvalidParameterError, match="latency"):
        MujocoPlant(hubo, RATE, latency=0.5)


def test_the_controller_with_late_sensors_walks_as_the_batch_simulation(hubo):
    """10 ms of sensor latency through the controller (the plant's) and through the batch simulation: both pass,
    with the same CoP error (measured 39.4 and 38.9 mm RMS; 16-17 mm without latency)."""
    run = simulate_controller(hubo, WALK, latency=0.01)
    pattern = generate(hubo, WALK, rate=RATE)
    batch = simulate(hubo, pattern_joint_trajectory(pattern, check_limits=False), pattern,
                     stabilizer=Stabilizer(hubo, RATE, com_reference=pattern.com_point), settle=START_DELAY, hold=HOLD,
                     latency=0.01)
    for result in (run.result, batch):
        verdict = walk_verdict(result, HOLD)
        assert verdict.passed, verdict.lines()
    assert run.result.cop_error_stats()[0] == pytest.approx(batch.cop_error_stats()[0], abs=0.002)  # [m]
    assert run.result.cop_error_stats()[0] > 0.025  # [m] the latency does cost: 16 mm without it


def test_the_walk_s_clock_and_settle(hubo):
    """With ``settle`` the first command waits ``settle - START_DELAY``; the result's time and the plant's clock (a
    push's) are 0 where the walk begins, on whole ticks, as the batch walk's; a capture needs its settings."""
    from zmpwalk.sim.loop import walk_start

    assert walk_start(0.5, RATE) == pytest.approx(START_DELAY) and walk_start(1.0, RATE) == pytest.approx(1.0)
    plant = MujocoPlant(hubo, RATE, time_origin=1.0)
    plant.stand(WalkingController(hubo, RATE, balance=False).walker.tick())
    assert plant.time == -1.0
    for _ in range(1000):
        plant.step()
    assert plant.time == 0.0
    run = simulate_controller(hubo, WALK[:2] + WALK[-1:], settle=1.0)
    assert run.result.time[0] == -1.0 and run.given[0] == pytest.approx(-START_DELAY)  # [s] given 0.6 s before
    moved = np.flatnonzero(np.abs(run.result.reference_zmp[:, 1] - run.result.reference_zmp[0, 1]) > 1e-6)
    assert run.result.time[moved[0]] == pytest.approx(0.0, abs=0.002)  # [s] the ZMP leaves the middle at 0
    with pytest.raises(InvalidParameterError, match="capture"):
        WalkingController(hubo, RATE, capture=True)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="noise"):
        MujocoPlant(hubo, RATE, noise=0.1)  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_simulated_walk_is_the_same_on_a_busy_machine(hubo, monkeypatch):
    """The simulator's walker counts the parts of a command's check (sim.loop.simulated_clock) instead of timing
    them: on a machine 20 times slower (every reading of the machine's clock 1 ms on) turn45 walks to the same
    metre, its commands given at the same ticks. (The machine's own clock there gives the commands 1.563 s later
    and another walk.)"""
    from zmpwalk import online
    from zmpwalk.scenarios import load_scenario

    commands = load_scenario("turn45")
    quiet = simulate_controller(hubo, commands)
    now = [0.0]

    def busy() -> float:
        now[0] += 1e-3
        return now[0]

    monkeypatch.setattr(online, "_clock", busy)
    loaded = simulate_controller(hubo, commands)
    assert loaded.given == quiet.given
    assert loaded.result.distance == quiet.result.distance  # [m] bitwise
    plant = MujocoPlant(hubo, RATE)
    machine = simulate_controller(hubo, commands, plant=plant,
                                  controller=WalkingController(hubo, RATE, feedforward=plant.feedforward()))
    assert machine.given[1] > quiet.given[1] + 1.0  # [s] the premise: the machine's clock is the difference


def test_a_budget_clock_that_is_not_callable_is_refused(hubo):
    """OnlineWalker / WalkingController ``clock``: a callable returning seconds, or None."""
    from zmpwalk import OnlineWalker

    with pytest.raises(InvalidParameterError, match=r"clock = 0\.001 .*a callable returning seconds"):
        OnlineWalker(hubo, RATE, clock=0.001)  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="clock"):
        WalkingController(hubo, RATE, clock="perf_counter")  # type: ignore[arg-type]


def test_the_controller_s_budget_is_the_walker_s(hubo):
    """``WalkingController(budget=...)`` gives the walker's check that much of each tick: on a clock that counts
    (one reading 10 us, one before a tick's parts and one after each), 50 us run 4 parts a tick and 150 us 14, so
    a check given three times the budget ends in 1/3.5 of the ticks."""
    from zmpwalk.online import work_budget
    from zmpwalk.slices import CountingClock

    ticks = {}
    for budget in (None, 3 * work_budget(RATE)):
        controller = WalkingController(hubo, RATE, balance=False, clock=CountingClock(10e-6), budget=budget)
        assert controller.walker.budget == pytest.approx(budget or work_budget(RATE), rel=1e-12)
        plant = MockPlant(hubo, RATE)
        controller.command(StepCommand(0.8, 0.1))
        count = 0
        while controller.walker.checking is not None:
            plant.apply(controller.update(plant.measure()))
            count += 1
        ticks[budget] = count
    default, larger = ticks.values()
    assert default > 100  # [ticks] a check of some hundred parts, a few a tick
    assert 3.0 < default / larger < 4.5  # measured 146 and 38 ticks: 3.8
    with pytest.raises(InvalidParameterError, match="budget"):
        WalkingController(hubo, RATE, budget=0.002)  # [s] beyond the 1 ms period
