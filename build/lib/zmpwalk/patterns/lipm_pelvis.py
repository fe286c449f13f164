"""The hyperbolic pelvis model: the stage engine's stages with the pelvis of the linear inverted pendulum.

A pelvis model (:class:`~zmpwalk.patterns.pelvis_model.PelvisModel`) for the online hyperbolic pattern of
Lim et al.: each stage's footsteps, swing and timing are those of :mod:`zmpwalk.patterns.stages`, and its pelvis
is the pendulum's own motion under a piecewise-constant ZMP, solved per stage from the state it inherits
(:func:`~zmpwalk.patterns.lipm_stage.lipm_pelvis`). The paper's own straight walk is kept apart:
:mod:`zmpwalk.patterns.hyperbolic`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from zmpwalk.footsteps import StagePlan
from zmpwalk.patterns.lipm_stage import lipm_pelvis_in_parts
from zmpwalk.patterns.stages import CUBIC, Boundary, Stage, as_pair
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import ALONE, Parts


@dataclass(frozen=True)
class HyperbolicPelvis:
    """The pelvis of the linear inverted pendulum (:mod:`zmpwalk.patterns.lipm_stage`), in place of the curves.

    A stage keeps the paper's cubic curves between its footsteps (:class:`~zmpwalk.patterns.stages.CurvePelvis`)
    beside the pendulum's pieces (``Stage.lipm``); the pendulum's are the pelvis it is evaluated with, and its
    end state is the one the next stage inherits.
    """

    name: str = "hyperbolic"

    @property
    def generator(self) -> str:
        """The name a pattern of this pelvis carries."""
        return "hyperbolic"

    def stages_in_parts(self, plans: Sequence[StagePlan], boundary: Boundary, robot: RobotModel
                        ) -> Parts[list[Stage]]:
        """The stages of ``plans`` from ``boundary``: the curves' stages, a part each, then each stage's
        pendulum (:func:`hyperbolic_stages`)."""
        stages = yield from CUBIC.stages_in_parts(plans, boundary, robot)
        return (yield from hyperbolic_stages(stages, boundary, robot))


HYPERBOLIC = HyperbolicPelvis()


def hyperbolic_stages(stages: list[Stage], boundary: Boundary, robot: RobotModel) -> Parts[list[Stage]]:
    """``stages`` (one command's, from ``boundary``) with the hyperbolic pelvis, in parts (:mod:`zmpwalk.slices`:
    a planner that works in slices takes a few per tick)."""
    result = []
    for number, stage in enumerate(stages):
        first_swing = stages[number + 1].plan if stage.plan.kind == "start" else None
        stage = yield from hyperbolic_stage(stage, boundary, robot, first_swing)
        boundary = stage.end
        result.append(stage)
    return result


def hyperbolic_stage(stage: Stage, boundary: Boundary, robot: RobotModel, next_plan: StagePlan | None
                     ) -> Parts[Stage]:
    """``stage`` with the hyperbolic pelvis of :func:`~zmpwalk.patterns.lipm_stage.lipm_pelvis` from ``boundary``
    (``next_plan``: the first swing, for a start stage), in parts."""
    plan = stage.plan
    position = boundary.pelvis_position
    if position is None:  # standing: above the middle of the ankles
        position = as_pair(0.5 * (np.array([plan.support_pose.x, plan.support_pose.y])
                                + [plan.swing_start.x, plan.swing_start.y]))
    yield ALONE  # the pendulum's targets (a steady step solved): a long part
    pelvis, end_position, end_velocity = yield from lipm_pelvis_in_parts(plan, position, boundary.pelvis_velocity,
                                                                         robot, next_plan)
    end = Boundary(time=boundary.time + plan.duration, pelvis_velocity=end_velocity, at_rest=plan.stop,
                   pelvis_position=end_position)
    return replace(stage, lipm=pelvis, end=end)
