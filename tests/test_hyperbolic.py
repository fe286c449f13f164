"""The hyperbolic LIPM pattern of Lim et al.: the paper's example, Eq. 15, ODE agreement, continuity."""

from __future__ import annotations

import itertools
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from zmpwalk import InfeasiblePatternError, StepCommand
from zmpwalk.cli import main
from zmpwalk.patterns.hyperbolic import (
    HyperbolicGait,
    HyperbolicWalk,
    paper_walk,
    solve_step,
    steady_step,
    transient_zmps,
)
from zmpwalk.patterns.lipm import generate_hyperbolic

TIME_TOL = 0.5e-3  # [s] on the printed times
ZMP_TOL = 0.5e-3  # [m] on the printed ZMPs
POSITION_TOL = 1e-9  # [m]
VELOCITY_TOL = 1e-6  # [m/s]


def test_paper_example_times_match_the_printed_values():
    step = HyperbolicGait().steady()
    assert step.t1 == pytest.approx(0.1464, abs=TIME_TOL)
    assert step.t3 == pytest.approx(0.1464, abs=TIME_TOL)
    assert step.t2 == pytest.approx(0.1597, abs=TIME_TOL)
    assert step.t4 == pytest.approx(0.1250, abs=TIME_TOL)
    assert step.t5 == pytest.approx(0.4526, abs=TIME_TOL)
    assert 2 * step.period == pytest.approx(1.152, abs=5e-3)  # printed T_s (READING-NOTES: 1.155)


def test_paper_example_transient_zmps_match_the_printed_values():
    (xd, yd), (xs, ys) = HyperbolicGait().start_zmps()
    assert (xd, yd) == pytest.approx((-0.0193276, -0.0324849), abs=ZMP_TOL)
    assert (xs, ys) == pytest.approx((0.0259193, 0.0803014), abs=ZMP_TOL)


def test_paper_example_command_prints_the_same_json(capsys):
    assert main(["hyperbolic", "--paper-example", "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    for key, value in {"t1": 0.1464, "t2": 0.1597, "t3": 0.1464, "t4": 0.1250, "t5": 0.4526}.items():
        assert result[key] == pytest.approx(value, abs=TIME_TOL)
    assert result["zmp_start_double"] == pytest.approx([-0.0193276, -0.0324849], abs=ZMP_TOL)
    assert result["zmp_start_single"] == pytest.approx([0.0259193, 0.0803014], abs=ZMP_TOL)
    assert set(result) >= {"y0", "v_y"}


def test_average_speed_of_the_steady_gait_is_86_mm_per_s():
    step = HyperbolicGait().steady()
    assert (step.stride / 2) / step.period == pytest.approx(0.086, abs=1e-3)  # Table 2 of the paper


def test_eq15_solves_the_transient_boundary_problem():
    """Eq. 15 as printed against a direct solve of Eqs. 12-14 for the two ZMPs."""
    rng = np.random.default_rng(5)
    a = math.sqrt(9.8 / 0.395)
    for _ in range(20):
        t_star, tau_star = rng.uniform(0.1, 0.5, 2)
        position, velocity = rng.uniform(-0.1, 0.1), rng.uniform(-0.3, 0.3)

        def end(zd, zs, t_star=t_star, tau_star=tau_star):
            x1, v1 = zd * (1 - math.cosh(a * t_star)), -a * zd * math.sinh(a * t_star)  # Eq. 12
            c, s = math.cosh(a * tau_star), math.sinh(a * tau_star)
            return np.array([(x1 - zs) * c + v1 / a * s + zs, (x1 - zs) * a * s + v1 * c])  # Eq. 13

        base = end(0, 0)
        matrix = np.column_stack([end(1, 0) - base, end(0, 1) - base])
        expected = np.linalg.solve(matrix, np.array([position, velocity]) - base)
        assert transient_zmps(a, t_star, tau_star, position, velocity) == pytest.approx(expected, abs=1e-12)


def test_solve_step_recovers_the_paper_step():
    gait = HyperbolicGait()
    paper = gait.steady()
    solved = solve_step(gait.a, gait.stride, paper.period, paper.t4, gait.y_zmp)
    assert solved.zmp1 == pytest.approx(gait.stride / 8, abs=1e-12)
    assert solved.v_double == pytest.approx(gait.v_double, abs=1e-12)
    assert solved.t5 == pytest.approx(paper.t5, abs=1e-12)


def _ode_error(walk: HyperbolicWalk) -> float:
    """Largest difference of the closed form from integrating x'' = a^2 (x - p) piece by piece."""
    worst = 0.0
    for axis in (walk.x_axis, walk.y_axis):
        for piece in axis.pieces:
            if not piece.hyperbolic or piece.duration <= 0:
                continue
            ode = solve_ivp(lambda _, s, p=piece.c: [s[1], walk.a**2 * (s[0] - p)], (0, piece.duration),
                            [piece.x0, piece.v0], rtol=1e-12, atol=1e-14, dense_output=True)
            tau = np.linspace(0.0, piece.duration, 41)[:-1]
            position, _, _ = axis.evaluate(piece.start + tau)
            worst = max(worst, float(np.abs(ode.sol(tau)[0] - position).max()))
    return worst


def _assert_continuous(walk: HyperbolicWalk) -> None:
    for axis in (walk.x_axis, walk.y_axis):
        pieces = axis.pieces
        for previous, piece in itertools.pairwise(pieces):
            # the closed-form end of one piece against the start the next one was built from
            if previous.hyperbolic:
                c, s = math.cosh(walk.a * previous.duration), math.sinh(walk.a * previous.duration)
                x1 = (previous.x0 - previous.c) * c + previous.v0 / walk.a * s + previous.c
                v1 = (previous.x0 - previous.c) * walk.a * s + previous.v0 * c
            else:
                x1, v1 = previous.c, previous.v1
            assert abs(x1 - piece.x0) <= POSITION_TOL and abs(v1 - piece.v0) <= VELOCITY_TOL
        starts = np.array([p.start for p in pieces[1:]])
        left = axis.evaluate(starts - 1e-11)
        right = axis.evaluate(starts + 1e-11)
        np.testing.assert_allclose(left[0], right[0], atol=POSITION_TOL)
        np.testing.assert_allclose(left[1], right[1], atol=VELOCITY_TOL)


def test_paper_walk_agrees_with_numerical_integration_and_is_continuous(mju):
    walk = paper_walk(mju, steps=4)
    assert _ode_error(walk) < 1e-6
    _assert_continuous(walk)
    pattern = walk.sample(1000)
    assert pattern.min_zmp_margin()[0] > 0
    # the steady single-support ZMPs are the paper's x_s/8, x_s/4 ahead of the supporting ankle
    zmps = [p.c for p in walk.x_axis.pieces if p.hyperbolic][2:6]
    assert zmps == pytest.approx([0.0625, 0.075, 0.1125, 0.125], abs=1e-12)


@pytest.mark.slow
@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(st.floats(0.0, 0.04), st.sampled_from([0.55, 0.6, 0.7, 0.8])), min_size=2, max_size=8))
def test_random_stride_sequences_are_continuous_and_solve_the_pendulum(mju, steps):
    """The paper's construction (start transient, steady steps, stop) for any strides and step times."""
    commands = [StepCommand(duration, forward) for forward, duration in steps]
    try:
        walk = _last_walk(mju, commands)
    except InfeasiblePatternError:
        return
    _assert_continuous(walk)
    assert _ode_error(walk) < 1e-6
    pattern = walk.sample(200)
    np.testing.assert_allclose(pattern.velocity_pelvis_in_world[-1], 0.0, atol=1e-9)  # at rest


def _last_walk(robot, commands):
    a = math.sqrt(robot.gravity / robot.pendulum_length)
    steps = [solve_step(a, 2 * c.forward, c.duration, robot.dsp_time, robot.hip_spacing / 2) for c in commands]
    first, last = commands[0].duration, commands[-1].duration
    return HyperbolicWalk(robot, steps, (0.4 * first, 0.6 * first), (0.4 * last, 0.6 * last))


def test_feet_land_at_the_strides(mju):
    pattern = generate_hyperbolic(mju, [StepCommand(0.6, 0.03)] * 4, rate=1000)
    landings = [s.landing[0] for s in pattern.steps if s.kind in ("step", "stop")]
    assert landings == pytest.approx([0.03, 0.06, 0.09, 0.12, 0.12], abs=1e-12)


@pytest.mark.parametrize("kwargs, condition", [
    ({"v_double": 0.02}, r"v_xD > a \(x_ZMP1 - x0\)"),
    ({"zmp2": 0.045}, r"Eq\. 11d"),
])
def test_infeasible_steady_steps_name_the_condition(kwargs, condition):
    gait = HyperbolicGait()
    values = {"stride": 0.1, "zmp1": 0.0125, "zmp2": 0.025, "v_double": 0.1, "y_zmp": 0.068} | kwargs
    with pytest.raises(InfeasiblePatternError, match=condition):
        steady_step(gait.a, **values)


def test_transient_zmp_outside_the_feet_is_reported(mju):
    gait = HyperbolicGait(t_star=0.05, tau_star=0.1)
    with pytest.raises(InfeasiblePatternError, match=r"start transient's .*-support ZMP .* mm outside"):
        paper_walk(mju, gait)
