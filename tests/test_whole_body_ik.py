"""The compiled whole-body IK of an imported robot (zmpwalk.whole_body, zmpwalk.stabilizer.whole_body_ik): on a walk
with a turn and a side step, the legs' forward kinematics (the general chain's, zmpwalk.leg_chain.LegChain) puts each
ankle and sole where the pattern does, the whole-body CoM is the pattern's point, the rates are the chain's
``J^-1 twist``, and the parts are bounded in samples; on a closed-form leg (TALOS), a numeric one (Booster T1), a
five-joint one (Unitree H1's chain with its virtual ankle roll) and a sole pitched at zero angles (the keyframe
biped)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from test_keyframe_sole import pitched_biped
from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError, UnreachableError
from zmpwalk.kinematics import JointTrajectory, pattern_joint_trajectory, rot_z
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots import load_robot
from zmpwalk.robots.model import RobotModel
from zmpwalk.whole_body import COM_TOLERANCE, IK_CHUNK, LegFill, compile_kernel, imported_legs_in_parts, leg_parts

ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
MODELS = {"talos": ROBOTS / "pal_talos" / "scene_position.xml", "booster_t1": ROBOTS / "booster_t1" / "scene.xml",
          "unitree_h1": ROBOTS / "unitree_h1" / "scene.xml"}
FEET_TOLERANCE = 1e-9  # [m] and [-] (rotation matrices): the IK converges to 1e-10 per component
RATE_TOLERANCE = 1e-7  # [rad/s] against numpy's solve of the chain's Jacobian
WALK = [StepCommand(duration=1.0, forward=0.1), StepCommand(duration=1.0, forward=0.1, turn=0.2),
        StepCommand(duration=1.0, side=0.05)]


def robot_of(name: str, tmp_path: Path) -> RobotModel:
    if name == "pitched":
        path = tmp_path / "pitched.xml"
        path.write_text(pitched_biped(), encoding="utf-8")
        return load_robot(path)
    if not MODELS[name].is_file():
        pytest.skip(f"{MODELS[name]} is absent")
    return load_robot(MODELS[name])


def walk_of(robot: RobotModel) -> tuple[WalkingPattern, JointTrajectory]:
    pattern = generate(robot, WALK[:2] if robot.legs is not None and robot.legs[0].virtual is not None else WALK,
                       rate=500.0)
    if robot.legs is not None and robot.legs[0].virtual is not None:  # H1: the sole's roll is what gives
        return pattern, pattern_joint_trajectory(pattern, check_limits=False)
    return pattern, pattern_joint_trajectory(pattern)


def chain_angles(trajectory: JointTrajectory, robot: RobotModel, leg: int) -> np.ndarray:
    """The leg's angles in chain order (n, 6)."""
    assert robot.legs is not None
    chain = robot.legs[leg]
    q = np.empty((len(trajectory.time), 6))
    q[:, list(chain.role_order)] = trajectory.angles[:, 6 * leg:6 * leg + 6]
    return q


@pytest.mark.parametrize("name", ["talos", "booster_t1", "unitree_h1", "pitched"])
def test_the_legs_meet_the_feet_and_the_com_meets_the_pattern(name: str, tmp_path: Path) -> None:
    robot = robot_of(name, tmp_path)
    assert robot.legs is not None and robot.plant is not None
    pattern, trajectory = walk_of(robot)
    base = trajectory.position_base_in_world
    assert base is not None
    rotation = rot_z(pattern.yaw_pelvis_in_world)
    moment = robot.plant.rest_mass * np.asarray(robot.plant.rest_com)
    mass = robot.plant.rest_mass
    feet = ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world),
            (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world))
    for leg, (chain, (ankle, yaw)) in enumerate(zip(robot.legs, feet, strict=True)):
        q = chain_angles(trajectory, robot, leg)
        position, sole = chain.fk(q)
        np.testing.assert_allclose(base + np.einsum("nij,nj->ni", rotation, position), ankle, rtol=0,
                                   atol=FEET_TOLERANCE)
        if chain.virtual is None:  # a five-joint leg's sole rolls about its centre line (its virtual joint)
            np.testing.assert_allclose(rotation @ sole, rot_z(yaw), rtol=0, atol=FEET_TOLERANCE)
        moment = moment + np.einsum("k,nki->ni", chain.link_masses, chain.link_com_positions(q))
        mass += float(chain.link_masses.sum())
    com = base + np.einsum("nij,nj->ni", rotation, moment / mass)
    np.testing.assert_allclose(com[:, :2], pattern.position_pelvis_in_world[:, :2], rtol=0, atol=COM_TOLERANCE)
    np.testing.assert_allclose(base[:, 2], pattern.position_pelvis_in_world[:, 2], rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", ["talos", "booster_t1"])
def test_the_rates_are_the_chains_inverse_jacobian_of_the_feet_twists(name: str, tmp_path: Path) -> None:
    robot = robot_of(name, tmp_path)
    assert robot.legs is not None
    pattern, trajectory = walk_of(robot)
    base = trajectory.position_base_in_world
    assert base is not None
    velocity_base = pattern.velocity_pelvis_in_world + np.gradient(base - pattern.position_pelvis_in_world,
                                                                    pattern.time, axis=0)
    c, s, w = np.cos(pattern.yaw_pelvis_in_world), np.sin(pattern.yaw_pelvis_in_world), pattern.yaw_rate_pelvis
    feet = ((pattern.position_left_ankle_in_world, pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
            (pattern.position_right_ankle_in_world, pattern.velocity_right_ankle_in_world,
             pattern.yaw_rate_right_foot))
    for leg, (chain, (position, velocity, yaw_rate)) in enumerate(zip(robot.legs, feet, strict=True)):
        rel, v = position - base, velocity - velocity_base
        vx, vy = v[:, 0] + w * rel[:, 1], v[:, 1] - w * rel[:, 0]
        zero = np.zeros(len(c))
        twist = np.column_stack([c * vx + s * vy, -s * vx + c * vy, v[:, 2], zero, zero, yaw_rate - w])
        expected = chain.joint_rates(chain_angles(trajectory, robot, leg), twist)
        rates = np.empty_like(expected)
        rates[:, :] = trajectory.velocities[:, 6 * leg:6 * leg + 6][:, np.argsort(chain.role_order)]
        np.testing.assert_allclose(rates, expected, rtol=0, atol=RATE_TOLERANCE)
    # and they are the angles' time derivative (central differences at 500 Hz: O(dt^2))
    finite = np.gradient(np.unwrap(trajectory.angles, axis=0), pattern.time, axis=0)
    assert np.abs(finite[1:-1] - trajectory.velocities[1:-1]).max() < 0.02  # [rad/s]


def test_compiling_ahead_gives_the_kernel_the_types_a_fill_gives_it(tmp_path: Path) -> None:
    """The build's warm-up (compile_kernel, run by setup.py so that the first walk of an imported robot loads the
    kernel instead of compiling it) compiles the one specialisation that a walk's fill then calls: no other."""
    from zmpwalk.stabilizer import whole_body_ik

    compile_kernel()
    walk_of(robot_of("talos", tmp_path))
    assert len(whole_body_ik.base_under_com.signatures) == 1
    assert len(whole_body_ik.joint_rates.signatures) == 1


def test_a_part_solves_at_most_a_chunk_of_samples(tmp_path: Path) -> None:
    """Bounded work per part: a walk's legs take a part per chunk of IK_CHUNK samples (leg_parts), and give what
    the joint trajectory gives."""
    robot = robot_of("talos", tmp_path)
    pattern, trajectory = walk_of(robot)
    n = len(pattern.time)
    feet = ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
             pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
            (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
             pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot))
    parts = imported_legs_in_parts(pattern.time, pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
                                   pattern.velocity_pelvis_in_world, pattern.yaw_rate_pelvis, feet, robot)
    count = 0
    try:
        while True:
            next(parts)
            count += 1
    except StopIteration as done:
        base, angles, rates, excess = done.value
    assert count == -(-n // IK_CHUNK) == leg_parts(robot, n)
    assert np.array_equal(angles, trajectory.angles) and np.array_equal(rates, trajectory.velocities)
    assert np.array_equal(base, trajectory.position_base_in_world)
    assert np.all(excess == -1.0)  # every sample converged

def test_the_chunks_do_not_change_the_walk(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The same legs in one chunk as in chunks of IK_CHUNK samples (each sample starts from the last ones, whichever
    part solved them), and in chunks of 1, 2 or 3 samples for walks of 0 to 3 samples."""
    import zmpwalk.whole_body as whole_body

    robot = robot_of("talos", tmp_path)
    pattern, trajectory = walk_of(robot)
    monkeypatch.setattr(whole_body, "IK_CHUNK", len(pattern.time))
    again = pattern_joint_trajectory(pattern)
    assert np.array_equal(again.angles, trajectory.angles) and np.array_equal(again.velocities, trajectory.velocities)
    for n in range(4):
        first: JointTrajectory | None = None
        for chunk in (1, 2, 3):
            monkeypatch.setattr(whole_body, "IK_CHUNK", chunk)
            fill = pattern_leg_fill(_rows(pattern, n))
            assert leg_parts(robot, n) == -(-n // chunk) and all(True for _ in fill.parts()) and fill.complete
            assert np.isfinite(fill.rates[:n]).all() and np.all(fill.excess == -1.0)
            if first is None:
                first = JointTrajectory(fill.time, fill.angles.copy(), fill.rates.copy())
            assert np.array_equal(fill.angles, first.angles) and np.array_equal(fill.rates, first.velocities)


def pattern_leg_fill(pattern: WalkingPattern) -> LegFill:
    """The legs of ``pattern`` to be filled chunk by chunk."""
    return LegFill(pattern.time, pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
                   pattern.velocity_pelvis_in_world, pattern.yaw_rate_pelvis,
                   ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
                     pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
                    (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
                     pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot)), pattern.robot)


def _rows(pattern: WalkingPattern, n: int) -> WalkingPattern:
    """The first ``n`` samples of ``pattern`` (its fields that are per-sample arrays)."""
    from dataclasses import fields, replace

    size = len(pattern.time)
    return replace(pattern, **{f.name: getattr(pattern, f.name)[:n] for f in fields(pattern)
                               if isinstance(getattr(pattern, f.name), np.ndarray)
                               and len(getattr(pattern, f.name)) == size})


def test_a_foot_out_of_reach_or_not_finite_is_refused_and_the_samples_after_it_are_solved(tmp_path: Path) -> None:
    """A sample whose ankle is 0.5 m beyond the leg's reach, and one whose CoM is NaN: each raises UnreachableError
    naming the leg and the time (from the sample's residual), and the fill's other samples are those of the walk
    without them (the sample after a bad one starts from the last good one)."""
    from dataclasses import replace

    robot = robot_of("talos", tmp_path)
    pattern, trajectory = walk_of(robot)
    bad = 600
    for field, change in (("position_left_ankle_in_world", (0.0, 0.0, -0.5)),
                          ("position_pelvis_in_world", (np.nan, 0.0, 0.0))):
        values = getattr(pattern, field).copy()
        values[bad] += change
        broken = replace(pattern, **{field: values})
        with pytest.raises(UnreachableError, match="left" if "ankle" in field else "left|right") as error:
            pattern_joint_trajectory(broken)
        assert error.value.time == pytest.approx(pattern.time[bad])
        fill = pattern_leg_fill(broken)
        for _ in fill.parts():
            pass
        assert not fill.excess[0, bad] <= 0.0 and np.all(fill.excess[:, bad + 2:] == -1.0)
        assert np.abs(fill.angles[bad + 2:] - trajectory.angles[bad + 2:]).max() < 1e-8  # [rad]


def test_a_robot_file_robot_is_not_an_imported_one(hubo: RobotModel) -> None:
    empty = np.zeros((1, 3))
    feet = ((empty, np.zeros(1), empty, np.zeros(1)),) * 2
    with pytest.raises(InvalidParameterError, match="an imported robot"):
        next(imported_legs_in_parts(np.zeros(1), empty, np.zeros(1), empty, np.zeros(1), feet, hubo))


def test_each_guess_is_the_parabola_through_the_last_three_samples_and_a_restart_starts_over() -> None:
    """The solver's first guess per sample (``_extrapolate``, the state layout of START_SIZE), each sample's
    solution then written over it: a quadratic sequence of angles and offsets is guessed exactly once three samples
    are solved (the line through two before, the last one alone before that; the posture the fill starts from is
    not a solved sample); after a sample that did not converge (``_restart``) the next starts from the last good
    one and the history builds up again from there, never a parabola through unevenly spaced samples."""
    from zmpwalk.stabilizer.whole_body_ik import START_SIZE, _extrapolate, _restart

    extrapolate, restart = _extrapolate.py_func, _restart.py_func
    rng = np.random.default_rng(3)
    a, b, c = rng.normal(size=(3, 14))

    def x(k: float) -> np.ndarray:  # [rad] and [m]: the samples' angles and offsets
        return a + b * k + c * k * k

    def guess(start: np.ndarray) -> np.ndarray:
        extrapolate(start)
        return start[:14].copy()

    start = np.zeros(START_SIZE)
    start[:14] = x(0)  # the posture the fill starts from
    expected = {1: x(0), 2: x(1), 3: 2 * x(2) - x(1), 4: x(4), 5: x(5)}
    for k in range(1, 6):
        assert guess(start) == pytest.approx(expected[k], abs=1e-12)
        start[:14] = x(k)  # the solver's solution
    guess(start)  # sample 6 ...
    restart(start)  # ... did not converge: back to sample 5, not extrapolated
    assert start[:14] == pytest.approx(x(5), abs=1e-12) and start[30] == 0.0
    expected = {7: x(5), 8: x(7), 9: 2 * x(8) - x(7), 10: x(10)}  # from 5, then the history of 7, 8, 9 alone
    for k in range(7, 11):
        assert guess(start) == pytest.approx(expected[k], abs=1e-12)
        start[:14] = x(k)
