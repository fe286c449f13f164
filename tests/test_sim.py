"""The MuJoCo simulation: model, standing, the paper's walk on the small biped, masses, falls, CLI.

Short simulations only (a few seconds of simulated time each).
"""

from __future__ import annotations

import dataclasses
import json

import mujoco
import numpy as np
import pytest

from zmpwalk import InvalidParameterError, StepCommand, generate, load_robot
from zmpwalk.cli import main
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.hyperbolic import paper_walk
from zmpwalk.robots.model import Servos
from zmpwalk.sim import actuator_table, contact_mapping, robot_mjcf, simulate


@pytest.fixture(scope="module")
def paper(mju):
    pattern = paper_walk(mju, steps=2).sample(1000.0)
    return pattern, pattern_joint_trajectory(pattern)


@pytest.fixture(scope="module")
def paper_result(mju, paper):
    pattern, joints = paper
    return simulate(mju, joints, pattern)


@pytest.mark.parametrize("name", ["hubo", "mju"])
def test_model_has_the_robot_file_masses(request, name):
    robot = request.getfixturevalue(name)
    model = mujoco.MjModel.from_xml_string(robot_mjcf(robot))
    assert model.body_subtreemass[1] == pytest.approx(robot.link_mass, rel=1e-9)
    assert model.nu == 12 and model.njnt == 13
    doubled = mujoco.MjModel.from_xml_string(robot_mjcf(robot, mass_scale=2.0))
    assert doubled.body_subtreemass[1] == pytest.approx(2 * robot.link_mass, rel=1e-9)


def test_contact_mapping_sinks_a_foot_by_the_static_penetration_of_eq16(mju):
    mapping = contact_mapping(mju)
    half_weight = mju.link_mass * mju.gravity / 2
    assert mju.contact.stiffness * mapping.penetration**1.5 == pytest.approx(half_weight, rel=1e-12)  # Eq. 16
    assert mapping.stiffness * mapping.penetration == pytest.approx(1.5 * half_weight, rel=1e-12)
    assert mapping.damping_ratio > 1.0  # still beyond critical after the stability cap


def test_paper_walk_on_the_small_biped_does_not_fall(paper, paper_result):
    pattern, _ = paper
    result = paper_result
    assert not result.fell and result.fall_time is None
    planned = np.linalg.norm(pattern.position_pelvis_in_world[-1, :2] - pattern.position_pelvis_in_world[0, :2])
    assert result.distance == pytest.approx(planned, rel=0.05)
    assert result.foot_slip < 0.005  # [m]
    assert np.nanmedian(result.cop_margin) > 0.005  # [m] the pressure stays inside the soles


def test_hip_roll_needs_the_largest_torque_as_in_the_paper(paper_result):
    rows = actuator_table(paper_result)
    largest = max(rows, key=lambda row: row.peak_torque)
    assert largest.joint.endswith("hip_roll")
    assert 1.0 < largest.peak_torque < 2.5  # [N m] paper: about 1.3 N m at M2/M8
    assert all(row.peak_power < 3.0 for row in rows)  # [W] paper: about 1 W


def test_same_input_same_result(mju, paper, paper_result):
    pattern, joints = paper
    again = simulate(mju, joints, pattern)
    np.testing.assert_array_equal(again.joint_torques, paper_result.joint_torques)
    np.testing.assert_array_equal(again.cop, paper_result.cop)


def test_mass_scales_torque_and_power_not_speed(mju, paper, paper_result):
    pattern, joints = paper
    heavy = simulate(mju, joints, pattern, mass_scale=2.0)
    assert heavy.average_speed == pytest.approx(paper_result.average_speed, rel=0.05)
    torque = np.abs(heavy.joint_torques).max() / np.abs(paper_result.joint_torques).max()
    power = np.abs(heavy.joint_power).max() / np.abs(paper_result.joint_power).max()
    assert torque == pytest.approx(2.0, rel=0.1) and power == pytest.approx(2.0, rel=0.1)


def test_soft_servos_fall_and_it_is_reported(mju, paper):
    pattern, joints = paper
    soft = dataclasses.replace(mju, servos=Servos(5.0, 0.05, 1e-4))
    result = simulate(soft, joints, pattern)
    assert result.fell and 0.0 < result.fall_time < pattern.time[-1]
    assert result.time[-1] < pattern.time[-1]  # stopped shortly after the fall


def test_hubo_walks_a_few_steps(hubo):
    pattern = generate(hubo, [StepCommand(0.95, 0.0), StepCommand(0.95, 0.2), StepCommand(0.95, 0.1)], rate=1000)
    result = simulate(hubo, pattern_joint_trajectory(pattern), pattern)
    assert not result.fell
    planned = np.linalg.norm(pattern.position_pelvis_in_world[-1, :2])
    assert result.distance == pytest.approx(planned, abs=0.02)  # [m]


def test_bad_simulation_input(mju, paper):
    pattern, joints = paper
    with pytest.raises(InvalidParameterError, match="mass_scale"):
        simulate(mju, joints, pattern, mass_scale=0.0)
    short = dataclasses.replace(joints, time=joints.time[:10], angles=joints.angles[:10])
    with pytest.raises(InvalidParameterError, match="joints"):
        simulate(mju, short, pattern)


def test_simulate_command_writes_results_and_json(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["simulate", "--paper-example", "--robot", "mju-biped", "--out", str(out), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    for key in ("fell", "fall_time", "distance", "average_speed", "cop_error_rms", "cop_error_max",
                "min_cop_margin", "actuators"):
        assert key in summary
    assert summary["fell"] is False and len(summary["actuators"]) == 12
    assert set(summary["actuators"][0]) == {"joint", "peak_torque", "impact_torque", "rms_torque", "peak_velocity",
                                            "peak_power", "mean_power", "torque_limit", "planned_torque"}
    assert {p.name for p in out.iterdir()} == {"actuators.csv", "actuators.md", "simulation.csv"}
    assert not list(out.glob("*.part"))  # written through temporary files, renamed when complete


def test_simulate_with_the_zmp_correction_reports_it(capsys):
    main(["simulate", "--paper-example", "--robot", "mju-biped", "--zmp-correction", "--json"])
    correction = json.loads(capsys.readouterr().out)["zmp_correction"]
    # the small biped's paper walk: 10.3 mm RMS of multibody against planned ZMP as generated
    assert correction["multibody_error_rms_before"] == pytest.approx(0.0103, abs=0.5e-3)
    assert correction["multibody_error_rms_after"] < correction["multibody_error_rms_before"]
    assert correction["passes"] >= 1


@pytest.mark.parametrize("argv, message", [
    (["simulate", "--paper-example", "--robot", "asimo"], "unknown robot"),
    (["simulate", "--paper-example", "--robot", "mju-biped", "--mass-scale", "0"], "mass_scale"),
    (["simulate", "--paper-example", "--scenario", "fig10"], "--paper-example takes no"),
])
def test_simulate_command_errors(capsys, argv, message):
    assert main(argv) == 2
    assert message in capsys.readouterr().err


def test_disturbances_tilt_gravity_scale_masses_and_push_in_their_window():
    from zmpwalk.sim.disturbances import Disturbances

    model = mujoco.MjModel.from_xml_string(robot_mjcf(load_robot("mju-biped")))
    mass = float(model.body_mass.sum())
    tilt = np.radians(2.0)
    Disturbances(floor_tilt=(0.0, tilt), mass_error=0.05).apply(model)
    assert float(model.body_mass.sum()) == pytest.approx(1.05 * mass, rel=1e-12)
    g = model.opt.gravity
    assert np.linalg.norm(g) == pytest.approx(9.81, rel=1e-12)
    assert g[0] == pytest.approx(9.81 * np.sin(tilt), rel=1e-9)  # downhill ahead pulls forward [m/s^2]
    push = Disturbances(push_time=1.0, push_impulse=(20.0, 0.0, 0.0), push_duration=0.1)
    assert push.force_at(0.99)[0] == 0.0 and push.force_at(1.05)[0] == pytest.approx(200.0)  # [N]
    assert push.force_at(1.1)[0] == 0.0
    for fields, name in (({"mass_error": 2.0}, "mass_error"), ({"floor_tilt": (0.0, 1.0)}, "floor_tilt"),
                         ({"push_duration": 0.0}, "push_duration"),
                         ({"push_impulse": (float("nan"), 0.0, 0.0)}, "push_impulse")):
        with pytest.raises(InvalidParameterError, match=name):
            Disturbances(**fields)


def test_the_reference_zmp_of_the_standing_before_a_walk_is_under_the_com():
    """Standing still during the settle the ZMP is under the CoM (Eqs. 1-2 with no acceleration), not the walk's
    first ZMP: the paper walk of Lim et al. starts with its ZMP 38 mm from the CoM (the start transient)."""
    robot = load_robot("mju-biped")
    pattern = paper_walk(robot, steps=2).sample(1000.0)
    start_offset = np.linalg.norm(pattern.zmp_in_world[0] - pattern.position_pelvis_in_world[0, :2])
    assert start_offset > 0.03  # [m]
    result = simulate(robot, pattern_joint_trajectory(pattern), pattern, settle=0.2, hold=0.0)
    before = result.time < pattern.time[0]
    assert before.sum() == 200
    np.testing.assert_array_equal(result.reference_zmp[before],
                                  np.broadcast_to(pattern.position_pelvis_in_world[0, :2], (200, 2)))
    first = int(np.argmax(~before))
    np.testing.assert_allclose(result.reference_zmp[first], pattern.zmp_in_world[0], atol=1e-12)


def test_loaded_soles_on_a_tilted_floor_do_not_creep():
    """On a 2 degree floor gravity pulls along the floor at the soles all the time; MuJoCo's soft contacts let a
    sole creep under it (the noslip solver runs on a tilted floor, Disturbances.apply). HUBO standing 2 s on
    the slope: each ankle stays within 0.03 mm (0.06-0.08 mm without noslip; TALOS 1.9-3.0 mm without, 0.2
    with). A level floor keeps the cheaper contacts."""
    from zmpwalk.sim.disturbances import NOSLIP_ITERATIONS, Disturbances

    robot = load_robot("hubo")
    level = mujoco.MjModel.from_xml_string(robot_mjcf(robot))
    Disturbances(mass_error=0.05).apply(level)
    assert level.opt.noslip_iterations == 0
    pattern = generate(robot, [StepCommand(0.8, 0.0)], rate=1000.0)
    result = simulate(robot, pattern_joint_trajectory(pattern), pattern, settle=2.0, hold=0.0, feedforward=True,
                      disturbances=Disturbances(floor_tilt=(0.0, np.radians(2.0))))
    assert NOSLIP_ITERATIONS > 0 and not result.fell
    start, end = 50, int(np.searchsorted(result.time, 0.0))  # the 2 s standing before the step [samples]
    drift = np.abs(result.ankle_positions[end, :, :2] - result.ankle_positions[start, :, :2])
    assert drift.max() < 3e-5  # [m]


def test_noisy_delayed_sensors_reach_the_stabilizer_and_bad_noise_is_rejected():
    from zmpwalk.balance import Stabilizer
    from zmpwalk.sim.disturbances import SensorNoise

    with pytest.raises(InvalidParameterError, match=r"noise\.force"):
        SensorNoise(force=-1.0)
    mju = load_robot("mju-biped")
    pattern = paper_walk(mju, steps=1).sample(1000.0)
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    small = {"force": 0.2, "torque": 0.005}  # [N], [N m]: the 2.2 kg robot's sensors (the defaults are HUBO's)
    runs = [simulate(mju, joints, pattern, stabilizer=Stabilizer(mju, 1000.0), latency=latency,
                     noise=SensorNoise(seed=seed, **small), settle=0.2, hold=0.5)
            for seed, latency in ((1, 0.0), (1, 0.0), (2, 0.0), (1, 0.002))]
    # (with 4 ms or more of latency the default gains topple this small, fast robot: docs/balance.md)
    assert not any(run.fell for run in runs)
    assert np.array_equal(runs[0].joint_angles, runs[1].joint_angles)  # seeded: the same walk again
    assert not np.array_equal(runs[0].joint_angles, runs[3].joint_angles)  # the delay reaches the loop
    assert not np.array_equal(runs[0].joint_angles, runs[2].joint_angles)  # the noise reaches the loop


@pytest.mark.slow
def test_a_sweep_on_two_processes_gives_the_walks_of_one():
    """zmpwalk.sweep: the same figures whether the walks run in a process pool or one after the other."""
    from zmpwalk.sweep import sweep

    pooled = sweep("hubo", ["fig10", "turn45"], workers=2)
    inline = sweep("hubo", ["fig10", "turn45"], workers=1)
    assert [r.scenario for r in pooled] == ["fig10", "turn45"]
    for a, b in zip(pooled, inline, strict=True):
        assert (a.passed, a.failed, a.fell) == (b.passed, b.failed, b.fell)
        assert a.distance == pytest.approx(b.distance, abs=1e-12)  # [m] deterministic simulation
        assert a.cop_error_rms == pytest.approx(b.cop_error_rms, abs=1e-12)  # [m]
        assert a.simulated > 5.0 and a.passed  # both walks stand at the end (verdict)


@pytest.mark.slow
def test_a_sweep_on_a_local_dask_cluster_gives_the_walks_of_one_process():
    """Past one machine the same jobs run on Dask (here a local cluster of two processes)."""
    pytest.importorskip("dask.distributed")
    from zmpwalk.sweep import sweep

    on_dask = sweep("hubo", ["fig10", "turn45"], workers=2, scheduler="local")
    inline = sweep("hubo", ["fig10", "turn45"], workers=1)
    assert [r.scenario for r in on_dask] == ["fig10", "turn45"]
    for a, b in zip(on_dask, inline, strict=True):
        assert (a.passed, a.failed, a.fell) == (b.passed, b.failed, b.fell)
        assert a.distance == pytest.approx(b.distance, abs=1e-12)  # [m] deterministic simulation


def test_a_bad_dask_scheduler_or_no_dask_is_one_clear_error(monkeypatch):
    import sys

    from zmpwalk.sweep import sweep

    pytest.importorskip("dask.distributed")
    with pytest.raises(InvalidParameterError, match=r"scheduler = 'not an address'.*Dask scheduler reachable"):
        sweep("hubo", ["fig10", "turn45"], workers=2, scheduler="not an address")
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # as if Dask were not installed
    with pytest.raises(InvalidParameterError, match=r'pip install "zmpwalk\[distributed\]"'):
        sweep("hubo", ["fig10", "turn45"], workers=2, scheduler="local")


@pytest.mark.slow
def test_sweep_cli_exit_status_follows_the_verdicts(capsys):
    from zmpwalk.cli import EXIT_FAILED, main

    assert main(["sweep", "--scenario", "turn45", "--workers", "1"]) == 0
    assert "turn45" in capsys.readouterr().out
    assert main(["sweep", "--scenario", "fig27", "--workers", "1", "--balance", "off"]) == EXIT_FAILED  # falls
    assert main(["sweep", "--scenario", "nope"]) == 2
    assert "unknown scenario 'nope'" in capsys.readouterr().err


def test_a_sweep_reports_a_walk_its_generator_cannot_plan_instead_of_failing():
    from zmpwalk.sweep import sweep

    # the small biped's first 0.2 m step would take the hyperbolic pattern's ZMP out of its feet
    (result,) = sweep("mju-biped", ["fig10"], workers=1, generator="hyperbolic")
    assert not result.passed and result.failed == ("planned",) and "ZMP" in result.error


@pytest.mark.slow
def test_a_sweep_walks_a_tuned_schedule_and_the_quintic_pelvis():
    from pathlib import Path

    from zmpwalk.sweep import sweep

    tuned = str(Path(__file__).parent.parent / "examples" / "schedule_hubo_tuned.toml")
    (result,) = sweep("hubo", ["fig28"], workers=1, schedule=tuned)
    assert result.passed  # open loop on the box model: the paper's tables fail this walk's verdict
    (quintic,) = sweep("hubo", ["turn45"], workers=1, pelvis="quintic")
    assert quintic.simulated > 5.0 and not quintic.fell


def test_the_simulation_names_are_found_where_the_cli_the_report_and_the_plant_import_them():
    import zmpwalk.sim as sim
    from zmpwalk.sim import closed_loop, disturbances, measure, references, result, run

    assert sim.simulate is run.simulate and sim.SimulationResult is run.SimulationResult is result.SimulationResult
    assert run.Disturbances is disturbances.Disturbances and run.SensorNoise is disturbances.SensorNoise
    assert run.write_result_csv is result.write_result_csv
    assert (run.FALL_TILT, run.FALL_HEIGHT_FRACTION, run.AFTER_FALL) == (
        measure.FALL_TILT, measure.FALL_HEIGHT_FRACTION, measure.AFTER_FALL)
    assert run.CONTROL_RATE == references.CONTROL_RATE and run.CAPTURE_INTERVAL == closed_loop.CAPTURE_INTERVAL
    assert run._MeasurementReader is disturbances._MeasurementReader  # the controller's plant reads its sensors so


def test_a_robots_own_model_settles_and_holds_longer_than_a_judged_walk_when_simulate_is_given_neither():
    from zmpwalk.sim import run, verdict

    assert (run.OWN_MODEL_SETTLE, run.OWN_MODEL_HOLD) == (1.0, 2.0)  # [s]
    assert (verdict.SETTLE, verdict.HOLD) == (0.5, 2.0)  # [s] what the CLI, the report and the sweeps simulate
    assert run._settle_and_hold(load_robot("hubo"), None, None) == (0.0, 0.0)  # a box model starts at rest
