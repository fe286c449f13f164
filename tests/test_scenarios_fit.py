"""Which built-in scenario fits which robot and generator (docs/generators.md keeps the same table)."""

from __future__ import annotations

import pytest

from zmpwalk import (
    InfeasibleCommandError,
    InfeasiblePatternError,
    generate,
    load_robot,
)
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.lipm import generate_hyperbolic
from zmpwalk.scenarios import load_scenario

OK = None
ALL = ["demo", "fig10", "fig27", "fig28", "fig29", "fig30", "fig31", "turn45"]
EXPECTED = {
    ("hubo", "polynomial"): dict.fromkeys(ALL, OK),
    ("hubo", "hyperbolic"): dict.fromkeys(ALL, OK),
    # a stride beyond reach is named with the largest that fits (the reach error is its cause)
    ("mju-biped", "polynomial"): {"demo": InfeasibleCommandError, "fig10": InfeasibleCommandError,
                                  "fig27": InfeasibleCommandError, "fig28": InfeasibleCommandError,
                                  "fig29": InfeasibleCommandError, "fig30": OK, "fig31": OK, "turn45": OK},
    # the ZMP of fig10's first step would leave the feet (a plan of a whole walk names the step, not a stride)
    ("mju-biped", "hyperbolic"): {"demo": InfeasibleCommandError, "fig10": InfeasiblePatternError,
                                  "fig27": InfeasibleCommandError, "fig28": InfeasibleCommandError,
                                  "fig29": InfeasibleCommandError, "fig30": OK, "fig31": OK, "turn45": OK},
}
CASES = [(robot, generator, name, outcome) for (robot, generator), table in EXPECTED.items()
         for name, outcome in table.items()]


@pytest.mark.parametrize("robot_name, generator, scenario, outcome", CASES)
def test_scenario_fits_or_fails_as_documented(robot_name, generator, scenario, outcome):
    robot = load_robot(robot_name)
    make = generate if generator == "polynomial" else generate_hyperbolic
    commands = load_scenario(scenario)
    if outcome is OK:
        joints = pattern_joint_trajectory(make(robot, commands, rate=200.0))
        assert joints.angles.shape[1] == 12
    else:
        with pytest.raises(outcome):
            pattern_joint_trajectory(make(robot, commands, rate=200.0))
