"""The feet and the support phases: one encoding, read the same by the pattern, the walker and the stabilizer."""

import numpy as np

from zmpwalk import StepCommand, generate, load_robot
from zmpwalk.sides import SUPPORT_LABELS, SUPPORT_OF_LABEL, Side, Support


def test_a_side_is_the_sign_of_its_lateral_offset_and_names_its_row_and_support() -> None:
    assert [int(side) for side in Side] == [1, -1]
    assert [side.index for side in Side] == [0, 1]
    assert [side.label for side in Side] == ["left", "right"]
    assert Side.LEFT.other is Side.RIGHT and Side.RIGHT.other is Side.LEFT
    assert [side.single_support for side in Side] == [Support.LEFT, Support.RIGHT]
    robot = load_robot("hubo")
    for side in Side:  # the lateral place of a hip is on the side's sign
        assert np.sign(robot.hip_in_pelvis(side)[1]) == int(side)


def test_support_codes_and_labels_round_trip() -> None:
    assert [int(support) for support in Support] == [0, 1, 2]
    assert SUPPORT_LABELS == ("double", "left", "right")
    for support in Support:
        assert SUPPORT_LABELS[support] == support.label
        assert SUPPORT_OF_LABEL[support.label] is support
        assert Support.of_label(support.label) is support


def test_a_single_support_code_holds_its_own_foot_still() -> None:
    """In a pattern, ``Support.LEFT`` samples have the left ankle at rest and the right one moving (and the mirror),
    so the code names the foot on the ground."""
    robot = load_robot("hubo")
    pattern = generate(robot, [StepCommand(duration=0.8, forward=0.1)] * 4, rate=200.0)
    for support, stance, swing in ((Support.LEFT, pattern.velocity_left_ankle_in_world,
                                    pattern.velocity_right_ankle_in_world),
                                   (Support.RIGHT, pattern.velocity_right_ankle_in_world,
                                    pattern.velocity_left_ankle_in_world)):
        rows = pattern.support == support
        assert rows.sum() > 100
        assert np.abs(stance[rows]).max() < 1e-9  # [m/s]
        assert np.linalg.norm(swing[rows], axis=1).max() > 0.1  # [m/s]
