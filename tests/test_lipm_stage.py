"""The hyperbolic pattern stage by stage: it solves the pendulum, it is the paper's steady step when steps
repeat, its ZMP stays in the feet, and the online walker rejects what would take it out."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from zmpwalk import InfeasibleCommandError, OnlineWalker, StepCommand, generate_hyperbolic
from zmpwalk.patterns.hyperbolic import solve_step
from zmpwalk.patterns.lipm_stage import dcm_zmps, propagate, sole_centre, solve_zmps
from zmpwalk.patterns.polynomial import StageTable, evaluate, plan_walk

ODE_TOL = 1e-7  # [m] closed form against numerical integration of the pendulum
STEADY_TOL = 1e-6  # [m] ZMPs of a repeated step against the paper's steady step (after 8 steps)
MARGIN_TOL = 1e-9  # [m] a ZMP on the sole's edge, from rounding


def _integrated(a, position, velocity, starts, zmps, duration, times):
    """Integrate p'' = a^2 (p - p_ZMP) through the pieces of one axis, each from where the integration
    (not the closed form) left the last one; positions at ``times`` from the stage start."""
    out = np.full(len(times), np.nan)
    bounds = [*starts[1:], duration]
    for start, end, zmp in zip(starts, bounds, zmps, strict=True):
        if end - start <= 0:
            continue
        coasting = math.isnan(zmp)

        def rhs(_, state, zmp=zmp, coasting=coasting):
            return [state[1], 0.0 if coasting else a * a * (state[0] - zmp)]

        ode = solve_ivp(rhs, (start, end), [position, velocity], rtol=1e-12, atol=1e-14, dense_output=True)
        inside = (times >= start) & (times <= end)
        out[inside] = ode.sol(times[inside])[0]
        position, velocity = ode.y[0, -1], ode.y[1, -1]
    return out


@pytest.mark.parametrize("commands", [
    [StepCommand(0.8, 0.15)] * 4,
    [StepCommand(0.8, side=0.05)] * 2 + [StepCommand(0.95, turn=-0.2)] * 2,
    [StepCommand(0.7, 0.1, turn=0.15), StepCommand(0.9, -0.05), StepCommand(0.8, 0.2)],
])
def test_the_pelvis_solves_the_pendulum_in_every_stage(hubo, commands):
    """Forward, side, turning and curved steps: each stage's pelvis, integrated numerically in the supporting
    foot's frame, is the sampled pattern's pelvis projected on that frame."""
    a = math.sqrt(hubo.gravity / hubo.pendulum_length)
    stages, _ = plan_walk(hubo, commands, pelvis="hyperbolic")
    table = StageTable(stages)
    worst = 0.0
    for k, stage in enumerate(stages):
        if stage.lipm is None:
            continue
        elapsed = np.linspace(0.0, stage.duration, 60, endpoint=False)
        samples = evaluate(table, stage.start + elapsed, hubo, np.full(len(elapsed), k))
        yaw = stage.lipm.yaw
        for axis, direction in ((stage.lipm.along, (math.cos(yaw), math.sin(yaw))),
                                (stage.lipm.across, (-math.sin(yaw), math.cos(yaw)))):
            numeric = _integrated(a, axis.position[0], axis.velocity[0], axis.starts, axis.zmp, stage.duration,
                                  elapsed)
            worst = max(worst, float(np.abs(samples.pelvis_xy @ np.array(direction) - numeric).max()))
    assert worst < ODE_TOL


def test_repeated_steps_converge_to_the_papers_steady_step(hubo):
    """Twelve equal steps: the single-support ZMPs of the late ones are Eq. 11's ``x_ZMP1``, ``x_ZMP2`` (straddling
    the sole centre), the lateral ZMP is the sole centre (Eq. 10), and the intervals are Eq. 11's."""
    command = StepCommand(0.8, 0.15)
    stages, _ = plan_walk(hubo, [command] * 12, pelvis="hyperbolic")
    a = math.sqrt(hubo.gravity / hubo.pendulum_length)
    steady = solve_step(a, 2 * command.forward, command.duration, hubo.dsp_time, hubo.hip_spacing / 2)
    middle = 0.5 * (steady.zmp1 + steady.zmp2)
    for stage in [s for s in stages if s.plan.kind == "step"][8:11]:
        plan, pelvis = stage.plan, stage.lipm
        centre = sole_centre(plan.support_pose, -plan.swing, hubo)
        heading = np.array([math.cos(pelvis.yaw), math.sin(pelvis.yaw)])
        left = np.array([-heading[1], heading[0]])
        along = np.array(pelvis.along.zmp)[[1, 3]] - centre @ heading
        np.testing.assert_allclose(along, [steady.zmp1 - middle, steady.zmp2 - middle], atol=STEADY_TOL, rtol=0)
        np.testing.assert_allclose(np.array(pelvis.across.zmp)[[1, 2]], centre @ left, atol=STEADY_TOL, rtol=0)
        durations = np.diff([*pelvis.along.starts, stage.duration])
        np.testing.assert_allclose(durations[1:4], [steady.t1, steady.t2, steady.t3], atol=1e-12, rtol=0)
        # the body is at x0 when the single support begins: half the ZMPs' span behind the sole centre
        assert pelvis.along.position[1] - centre @ heading == pytest.approx(-middle, abs=STEADY_TOL)


def test_two_zmps_reach_the_end_state_and_one_shift_reaches_the_divergent_component():
    a, pieces = 4.0, [(0.05, -1), (0.3, 0), (0.3, 1), (0.05, -1)]
    rng = np.random.default_rng(5)
    for _ in range(20):
        x, v, target = rng.uniform(-0.1, 0.1), rng.uniform(-0.3, 0.3), tuple(rng.uniform(-0.1, 0.1, 2))
        zmps = solve_zmps(a, x, v, pieces, target)
        state = (x, v)
        for duration, slot in pieces:
            state = propagate(a, *state, duration, None if slot < 0 else zmps[slot])
        np.testing.assert_allclose(state, target, atol=1e-12)
        nominal = (rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05))
        first, second = dcm_zmps(a, x, v, pieces, nominal, target[0])
        assert first - nominal[0] == pytest.approx(second - nominal[1], abs=1e-15)  # one common shift
        state = (x, v)
        for duration, slot in pieces:
            state = propagate(a, *state, duration, None if slot < 0 else (first, second)[slot])
        assert state[0] + state[1] / a == pytest.approx(target[0], abs=1e-12)


def test_random_walks_keep_the_zmp_in_the_feet_and_end_at_rest(hubo):
    rng = np.random.default_rng(8)
    walked = 0
    for _ in range(12):
        commands = [StepCommand(float(rng.choice([0.7, 0.8, 0.95])), float(rng.uniform(-0.05, 0.2)),
                                side=float(rng.choice([0.0, rng.uniform(-0.05, 0.05)])),
                                turn=float(rng.choice([0.0, rng.uniform(-0.2, 0.2)]))) for _ in range(8)]
        pattern = generate_hyperbolic(hubo, commands, rate=1000.0)
        assert pattern.min_zmp_margin()[0] >= -MARGIN_TOL
        middle = 0.5 * (pattern.position_left_ankle_in_world[-1, :2] + pattern.position_right_ankle_in_world[-1, :2])
        np.testing.assert_allclose(pattern.position_pelvis_in_world[-1, :2], middle, atol=1e-9)
        np.testing.assert_allclose(pattern.velocity_pelvis_in_world[-1], 0.0, atol=1e-9)
        walked += 1
    assert walked == 12


def test_a_stride_that_would_take_the_zmp_out_of_the_feet_is_rejected_with_the_largest_that_fits(hubo):
    walker = OnlineWalker(hubo, rate=200.0, generator="hyperbolic")
    words = r"keeps the ZMP in the feet .* at most 0\.\d{3} m forward \(forward = 0\.\d{3} m\)"
    with pytest.raises(InfeasibleCommandError, match=words) as error:
        walker.command(StepCommand(0.6, 0.4), wait=True)
    largest = error.value.largest["forward"]
    assert 0.0 < largest < 0.4
    assert not walker.walking and walker.queued is None  # unchanged
    walker.command(StepCommand(0.6, largest), wait=True)  # the named stride is accepted from the same place
    assert walker.queued is not None


def test_the_hyperbolic_generator_takes_no_pelvis_curve(hubo):
    from zmpwalk import InvalidParameterError

    with pytest.raises(InvalidParameterError, match="pelvis"):
        OnlineWalker(hubo, generator="hyperbolic", pelvis="quintic")
    with pytest.raises(InvalidParameterError, match="generator"):
        OnlineWalker(hubo, generator="preview")
    with pytest.raises(InvalidParameterError, match="pelvis"):
        OnlineWalker(hubo, pelvis="hyperbolic")


def test_a_long_hyperbolic_walk_in_pieces_is_the_whole_walk(hubo):
    from zmpwalk.patterns.polynomial import generate_chunks

    commands = [StepCommand(0.8, 0.1, turn=0.05)] * 12
    whole = generate_hyperbolic(hubo, commands, rate=200.0)
    pieces = list(generate_chunks(hubo, commands, rate=200.0, chunk_stages=5, pelvis="hyperbolic"))
    assert whole.generator == "hyperbolic" and all(piece.generator == "hyperbolic" for piece in pieces)
    joined = np.concatenate([piece.position_pelvis_in_world for piece in pieces])
    np.testing.assert_array_equal(joined, whole.position_pelvis_in_world)
