"""The stage engine's pelvis models: the named ones, and a model of the user's own in their place."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pytest

from zmpwalk import InvalidParameterError, StepCommand, generate
from zmpwalk.footsteps import StagePlan
from zmpwalk.patterns.lipm_pelvis import HYPERBOLIC
from zmpwalk.patterns.pelvis_model import PELVIS_CURVES, PelvisModel, pelvis_model
from zmpwalk.patterns.stages import CUBIC, QUINTIC, Boundary, Stage
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import Parts

WALK = [StepCommand(0.8, forward=0.1), StepCommand(0.8, side=0.05), StepCommand(0.9, turn=0.2)]


def test_every_pelvis_option_names_a_model_with_its_generator():
    assert [pelvis_model(name) for name in PELVIS_CURVES] == [CUBIC, QUINTIC, HYPERBOLIC]
    assert [pelvis_model(name).name for name in PELVIS_CURVES] == list(PELVIS_CURVES)
    assert [pelvis_model(name).generator for name in PELVIS_CURVES] == ["polynomial", "polynomial", "hyperbolic"]
    assert all(isinstance(pelvis_model(name), PelvisModel) for name in PELVIS_CURVES)


def test_an_unknown_pelvis_lists_the_models():
    with pytest.raises(InvalidParameterError, match="cubic, quintic, hyperbolic"):
        pelvis_model("spline")
    with pytest.raises(InvalidParameterError, match="pelvis"):
        pelvis_model(3.0)  # type: ignore[arg-type]


@dataclass(frozen=True)
class _Counting:
    """A model of the user's own: the cubic curves, counting the stages it is asked for."""

    calls: list[int]
    name: str = "counting"
    generator: str = "polynomial"

    def stages_in_parts(self, plans: Sequence[StagePlan], boundary: Boundary, robot: RobotModel
                        ) -> Parts[list[Stage]]:
        self.calls.append(len(plans))
        return (yield from CUBIC.stages_in_parts(plans, boundary, robot))


@pytest.mark.parametrize("rate", [100.0, 1000.0])
def test_the_engine_asks_nothing_of_a_model_but_its_interface(hubo, rate):
    """A model given in place of a name walks the same pattern as the model it wraps, stage by stage."""
    calls: list[int] = []
    own = generate(hubo, WALK, rate=rate, pelvis=_Counting(calls))
    cubic = generate(hubo, WALK, rate=rate)
    assert calls and sum(calls) == len(cubic.steps)  # every stage of every command, the closing stop's included
    assert own.generator == cubic.generator == "polynomial"
    for field in ("position_pelvis_in_world", "velocity_pelvis_in_world", "zmp_in_world",
                  "position_left_ankle_in_world", "position_right_ankle_in_world"):
        np.testing.assert_array_equal(getattr(own, field), getattr(cubic, field))
