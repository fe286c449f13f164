"""Preview control of the ZMP (Kajita et al. 2003): Riccati solution, gains, tracking, the baseline pattern."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from zmpwalk import generate, pattern_joint_trajectory
from zmpwalk.cli import main
from zmpwalk.patterns import generator
from zmpwalk.patterns.preview import PREVIEW_TIME, generate_preview, preview_gains, solve_dare, track, zmp_reference
from zmpwalk.scenarios import load_scenario


@pytest.mark.parametrize("period", [0.005, 0.001])
def test_riccati_solution_equals_scipys(period):
    gains = preview_gains(period, 0.62)
    t = period
    a, b, c = gains.a, gains.b, gains.c
    a_tilde = np.zeros((4, 4))
    a_tilde[0, 0] = 1.0
    a_tilde[0, 1:] = c @ a
    a_tilde[1:, 1:] = a
    b_tilde = np.concatenate([[c @ b], b])
    q = np.diag([1.0, 0.0, 0.0, 0.0])
    r = 1e-6 * (0.005 / t) ** 2
    ours = solve_dare(a_tilde, b_tilde, q, r)
    reference = scipy.linalg.solve_discrete_are(a_tilde, b_tilde[:, None], q, np.array([[r]]))
    np.testing.assert_allclose(ours, reference, rtol=1e-6)


@pytest.mark.parametrize("rate", [200.0, 1000.0])
def test_preview_gains_decay_and_balance_the_state_gain(rate):
    """G_d(j) fades over the horizon, and a still reference asks for no jerk: sum G_d = -G_x[0] (to the tail)."""
    gains = preview_gains(1.0 / rate, 0.62)
    assert len(gains.preview) == round(PREVIEW_TIME * rate)
    assert abs(gains.preview[-1]) < 0.01 * abs(gains.preview[0])
    assert gains.preview.sum() == pytest.approx(-gains.state[0], rel=0.01)


@pytest.mark.parametrize("rate", [200.0, 1000.0])
def test_tracking_a_step_of_the_reference_starts_early_and_settles(rate):
    """The ZMP of the CoM moves before the reference does (the preview) and reaches it within 1 mm."""
    gains = preview_gains(1.0 / rate, 0.62)
    n = round(6.0 * rate)
    reference = np.where(np.arange(n) < 3.0 * rate, 0.0, 0.1)  # [m] a 10 cm step at t = 3 s
    states, zmp = track(gains, reference, np.zeros(3))
    before = round(2.9 * rate)
    assert abs(states[before, 0]) > 1e-3  # [m] the CoM is already moving 0.1 s before the step
    np.testing.assert_allclose(zmp[-round(0.5 * rate):], 0.1, atol=1e-3)  # [m]
    np.testing.assert_allclose(states[-1], [0.1, 0.0, 0.0], atol=1e-3)


def test_the_baseline_walks_the_same_footsteps_with_its_zmp_on_the_reference(hubo):
    commands = load_scenario("fig28")
    preview = generate_preview(hubo, commands, rate=1000.0)
    polynomial = generate(hubo, commands, rate=1000.0)
    pad = round(PREVIEW_TIME * 1000.0)
    assert preview.generator == "preview" and len(preview.time) == len(polynomial.time) + 2 * pad
    np.testing.assert_array_equal(preview.position_left_ankle_in_world[pad:-pad],
                                  polynomial.position_left_ankle_in_world)  # the same footsteps, later
    reference = zmp_reference(preview, PREVIEW_TIME)
    error = np.linalg.norm(preview.zmp_in_world - reference, axis=1)
    assert np.sqrt(np.mean(error**2)) < 0.002  # [m] RMS tracking
    margin, _ = preview.min_zmp_margin()
    assert margin > 0.05  # [m] on the sole centres, well inside (the polynomial pattern: -12.7 mm on fig28)
    np.testing.assert_allclose(preview.velocity_pelvis_in_world[[0, -1]], 0.0, atol=1e-3)  # at rest at both ends
    pattern_joint_trajectory(preview)  # and the legs follow it


def test_preview_is_a_generator_of_the_command_line(tmp_path, capsys):
    assert generator("preview") is generate_preview
    steps = tmp_path / "walk.toml"
    steps.write_text("[[steps]]\nduration = 0.8\nforward = 0.15\nrepeat = 4\n", encoding="utf-8")
    assert main(["plan", str(steps), "--generator", "preview", "--json"]) == 0
    assert '"generator": "preview"' in capsys.readouterr().out
