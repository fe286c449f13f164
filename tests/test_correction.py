"""The multibody-ZMP correction of a pattern (``zmpwalk.correction``): the multibody ZMP of Eq. 3
follows the planned ZMP after it, nothing but the pelvis moves, and the pelvis stays smooth."""

from __future__ import annotations

import numpy as np
import pytest

from zmpwalk.commands import StepCommand
from zmpwalk.correction import correct_pattern
from zmpwalk.dynamics import compare_zmp
from zmpwalk.errors import InvalidParameterError
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.preview import generate_preview
from zmpwalk.robots import load_robot
from zmpwalk.scenarios import load_scenario

EXACT = 0.0  # [m] what the correction must not touch is equal bit for bit
RATE_TOL = 2e-3  # [m/s] the pelvis velocity against the central difference of its position at 1 kHz


@pytest.fixture(scope="module")
def fig10() -> object:
    return generate(load_robot("hubo"), load_scenario("fig10"), rate=1000.0)


def test_multibody_zmp_follows_the_plan_after_correction(fig10: object) -> None:
    correction = correct_pattern(fig10)  # type: ignore[arg-type]
    # HUBO, fig10: 23.5 mm RMS as generated (mostly the legs' mass 21 mm ahead of the hips), 5.7 mm after one pass
    assert correction.before.rms == pytest.approx(0.0235, abs=0.5e-3)
    assert correction.after.rms < 0.007
    assert correction.passes >= 1
    again = compare_zmp(correction.pattern)
    assert again.rms == pytest.approx(correction.after.rms, abs=1e-12)
    assert correction.pattern.position_com_in_world is not None
    assert np.abs(correction.pattern.position_com_in_world - again.center_of_mass).max() <= EXACT
    # the CoM point a stabilizer tracks: the whole-body CoM after the correction, the pelvis point before
    assert np.abs(correction.pattern.position_com_point_in_world - again.center_of_mass).max() <= EXACT
    assert np.abs(fig10.position_com_point_in_world - fig10.position_pelvis_in_world).max() <= EXACT  # type: ignore[attr-defined]


def test_only_the_pelvis_moves(fig10: object) -> None:
    original = fig10
    corrected = correct_pattern(original).pattern  # type: ignore[arg-type]
    for name in ("time", "zmp_in_world", "position_left_ankle_in_world", "position_right_ankle_in_world",
                 "yaw_pelvis_in_world", "yaw_left_foot_in_world", "yaw_right_foot_in_world", "support"):
        assert np.abs(np.asarray(getattr(corrected, name), dtype=float)
                      - np.asarray(getattr(original, name), dtype=float)).max() <= EXACT, name
    pelvis = corrected.position_pelvis_in_world
    assert np.abs(pelvis[:, 2] - original.position_pelvis_in_world[:, 2]).max() <= EXACT  # height unchanged
    shift = pelvis[:, :2] - original.position_pelvis_in_world[:, :2]
    # the standing robot's legs sit ahead of its hips: the pelvis goes back to put the whole CoM over the feet
    assert -0.030 < shift[0, 0] < -0.015
    # smooth: the recorded velocity is the derivative of the recorded position
    difference = np.gradient(pelvis[:, :2], corrected.time, axis=0)
    assert np.abs(difference[1:-1] - corrected.velocity_pelvis_in_world[1:-1, :2]).max() < RATE_TOL


def test_any_generator_and_the_small_biped() -> None:
    biped = load_robot("mju-biped")
    pattern = generate_preview(biped, [StepCommand(duration=0.6, forward=0.04)] * 4, rate=500.0)
    correction = correct_pattern(pattern)
    assert correction.after.rms < correction.before.rms


def test_bad_input_is_one_clear_error(fig10: object) -> None:
    for passes in (0, 6, 1.5, True):
        with pytest.raises(InvalidParameterError, match="passes"):
            correct_pattern(fig10, passes=passes)  # type: ignore[arg-type]
    robot = load_robot("hubo")
    bare = type(robot)(**{**vars(robot), "links": {}})
    with pytest.raises(InvalidParameterError, match=r"\[bodies\]"):
        correct_pattern(generate(bare, load_scenario("fig10"), rate=100.0))
