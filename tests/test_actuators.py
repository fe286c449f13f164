"""The motor table a builder can size motors from: no peak from one sample, agreement with inverse dynamics,
motor envelopes from a motor file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from zmpwalk.errors import FileFormatError
from zmpwalk.kinematics import JOINT_COLUMNS, pattern_joint_trajectory
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots import load_robot
from zmpwalk.scenarios import load_scenario
from zmpwalk.sim import actuator_table, simulate
from zmpwalk.sim.actuators import IMPACT_WINDOW, sustained
from zmpwalk.sim.motors import load_motors, motor_fits
from zmpwalk.sim.plant import build_plant, planned_torques
from zmpwalk.sim.poses import plant_qpos

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "motors.toml"


def test_a_spike_shorter_than_the_window_is_not_a_peak() -> None:
    torque = np.full((200, 1), 10.0)
    torque[100] = 177.0  # one sample after a touchdown
    torque[150:150 + 19] = 60.0  # 19 ms at 1 kHz: still an impact
    torque[20:20 + 21] = 40.0  # 21 ms: held long enough to count
    assert sustained(torque, round(IMPACT_WINDOW * 1000))[0] == pytest.approx(40.0)


@pytest.fixture(scope="module")
def demo() -> tuple[object, np.ndarray]:
    robot = load_robot("hubo")
    pattern = generate(robot, load_scenario("demo"), rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    result = simulate(robot, joints, pattern, feedforward=True)
    plant = build_plant(robot)
    qpos = plant_qpos(plant, pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world, joints.angles)
    ideal = planned_torques(plant, qpos, pattern.zmp_in_world, pattern.support,
                            (pattern.position_left_ankle_in_world, pattern.position_right_ankle_in_world))
    return result, ideal


def test_held_peaks_agree_with_inverse_dynamics_of_the_plan(demo: tuple[object, np.ndarray]) -> None:
    result, ideal = demo
    rows = actuator_table(result)  # type: ignore[arg-type]
    ideal_peaks = sustained(np.abs(ideal), round(IMPACT_WINDOW * 1000))
    largest = float(ideal_peaks.max())
    for row, peak, column in zip(rows, ideal_peaks, JOINT_COLUMNS, strict=True):
        assert row.peak_torque <= row.impact_torque
        if peak >= 0.3 * largest:  # the joints that size the motors (hip roll, knee, ankle roll): within 20 %
            assert row.peak_torque == pytest.approx(peak, rel=0.2), column
        else:  # pitch and yaw joints: the real CoP is off the cart-table ZMP (27 mm RMS on the demo), which at
            # the stance foot's load moves their torque by up to 15 % of the largest peak (docs/simulation.md)
            assert abs(row.peak_torque - peak) < 0.15 * largest, column


PLANNED_TOL = 1.0  # [N m]: the planned torques are the same inverse dynamics, at the control rate and from the
# settle phase on; the held peaks of the two samplings of the plan agree to this


def test_the_table_carries_the_plans_own_torques_and_flags_what_no_motor_gives(
        demo: tuple[object, np.ndarray]) -> None:
    """With the feedforward on, every row also says what the plan needs on an ideal robot (what the feedforward
    sends); a joint whose plan asks more than its actuator's limit is named whatever the control does."""
    import dataclasses
    import math

    from zmpwalk.sim.actuators import planned_over_limit

    result, ideal = demo
    rows = actuator_table(result)  # type: ignore[arg-type]
    assert result.planned_torques is not None and result.planned_torques.shape == (len(result.time), 12)  # type: ignore[attr-defined]
    ideal_peaks = sustained(np.abs(ideal), round(IMPACT_WINDOW * 1000))
    for row, peak in zip(rows, ideal_peaks, strict=True):
        assert row.planned_torque == pytest.approx(peak, abs=PLANNED_TOL)
    assert planned_over_limit(rows) == []  # HUBO's box model has no limits
    limited = [dataclasses.replace(row, torque_limit=row.planned_torque * 0.9) if row.joint == "left_knee" else row
               for row in rows]
    assert [row.joint for row in planned_over_limit(limited)] == ["left_knee"]
    open_loop = dataclasses.replace(result, planned_torques=None)  # type: ignore[type-var]
    assert all(math.isnan(row.planned_torque) for row in actuator_table(open_loop))  # type: ignore[arg-type]


def test_motor_file_fits_and_exceeds(demo: tuple[object, np.ndarray], tmp_path: Path) -> None:
    result, _ = demo
    fits = motor_fits(result, load_motors(EXAMPLE))  # type: ignore[arg-type]
    assert len(fits) == 12 and all(f.fits for f in fits)
    weak = tmp_path / "weak.toml"
    weak.write_text('[[motors]]\nname = "small"\njoints = ["knee"]\nrated_torque = 0.1\npeak_torque = 0.3\n'
                    'no_load_speed = 700.0\ngear_ratio = 100.0\nefficiency = 0.7\n', encoding="utf-8")
    knees = motor_fits(result, load_motors(weak))  # type: ignore[arg-type]
    assert [f.joint for f in knees] == ["left_knee", "right_knee"]
    for fit in knees:
        assert not fit.fits and fit.verdict.startswith("exceeds by ")
        assert fit.rms_use > 1.0  # RMS about 42 N m against 7 N m rated


@pytest.mark.parametrize(("text", "words"), [
    ("[[motors]]\njoints = [\"elbow\"]\n", "joints must list roles"),
    ("[[motors]]\njoints = [\"knee\"]\nrated_torque = -1\n", "rated_torque = -1"),
    ("motors = 3\n", "needs .* tables"),
])
def test_bad_motor_files(tmp_path: Path, text: str, words: str) -> None:
    path = tmp_path / "m.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match=words):
        load_motors(path)


def test_the_markdown_table_has_as_many_cells_in_its_header_as_in_each_row() -> None:
    import math

    from zmpwalk.sim.actuators import ActuatorRow, actuator_markdown

    rows = [ActuatorRow("left_knee", 61.0, 70.0, 15.0, 2.0, 20.0, 2.0, 60.0, 27.0),  # over its limit
            ActuatorRow("left_hip_yaw", 5.0, 6.0, 2.0, 0.5, 2.0, 0.3, math.inf, math.nan)]
    lines = actuator_markdown(rows).splitlines()
    counts = [len(line.strip().strip("|").split("|")) for line in lines]
    assert counts == [9] * 4
    assert "60 (102 %, EXCEEDED)" in lines[2] and "| none | - |" in lines[3]
