"""What a pelvis model gives the stage engine, and the pelvis models the engine knows by name.

The stage engine (:mod:`zmpwalk.patterns.planning`) turns a step command into footstep plans, one per swing
(:func:`zmpwalk.footsteps.plan_command`), and hands them to a pelvis model with the continuity state they start
from (:class:`~zmpwalk.patterns.stages.Boundary`: the time, the pelvis velocity, and where it is not the middle of
the ankles, its position). The model returns the stages (:class:`~zmpwalk.patterns.stages.Stage`): the pelvis over
each, fixed from its boundary conditions, and the state each hands on. The swinging ankle, the support phases, the
legs' reach and the sampling are the engine's, the same for every model; the cart-table ZMP (Eqs. 1-2) follows from
the pelvis each stage carries (:mod:`zmpwalk.patterns.evaluation`).

The models:

* ``"cubic"``, ``"quintic"``: the paper's curves (Eqs. 12-20) and their jerk-continuous form
  (:class:`~zmpwalk.patterns.stages.CurvePelvis`);
* ``"hyperbolic"``: the linear inverted pendulum under a piecewise-constant ZMP, per stage
  (:class:`~zmpwalk.patterns.lipm_pelvis.HyperbolicPelvis`).

The preview-control pattern (:mod:`zmpwalk.patterns.preview`) is not one: its pelvis is a discrete-time servo
tracking a ZMP reference with a look-ahead of :data:`~zmpwalk.patterns.preview.PREVIEW_TIME` (longer than a step),
so the pelvis over a stage depends on the stages after it, not on the state the stage starts from, and has no
closed form to evaluate at any time; it runs on the sampled pattern of a whole walk.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol, runtime_checkable

from zmpwalk.errors import InvalidParameterError
from zmpwalk.footsteps import StagePlan
from zmpwalk.patterns.lipm_pelvis import HYPERBOLIC
from zmpwalk.patterns.stages import CUBIC, QUINTIC, Boundary, Stage
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import Parts


@runtime_checkable
class PelvisModel(Protocol):
    """A pelvis model of the stage engine: the named ones (:func:`pelvis_model`), or any object with these
    members, given as ``pelvis`` to :func:`~zmpwalk.patterns.planning.plan_walk` or
    :func:`~zmpwalk.patterns.polynomial.generate`."""

    @property
    def name(self) -> str:
        """Its name (for the named ones, the pelvis option: one of :data:`PELVIS_CURVES`)."""
        ...

    @property
    def generator(self) -> str:
        """The generator name a pattern of this pelvis carries (:attr:`WalkingPattern.generator`)."""
        ...

    def stages_in_parts(self, plans: Sequence[StagePlan], boundary: Boundary, robot: RobotModel
                        ) -> Parts[list[Stage]]:
        """The stages of one command's footstep ``plans`` (in order, a start stage first from standstill), the
        first from ``boundary`` and each from the one before's ``end``; in parts (:mod:`zmpwalk.slices`).

        Raises:
            ZmpwalkError: The pelvis cannot follow these footsteps (e.g. a ZMP outside the feet).
        """
        ...


# the pelvis option: the paper's cubics, jerk-continuous quintics, or the pendulum's own hyperbolic motion
PELVIS_CURVES = ("cubic", "quintic", "hyperbolic")
_MODELS: dict[str, PelvisModel] = {"cubic": CUBIC, "quintic": QUINTIC, "hyperbolic": HYPERBOLIC}


def check_pelvis(pelvis: object) -> str:
    """``pelvis`` if it is one of :data:`PELVIS_CURVES`.

    Raises:
        InvalidParameterError: Any other value (the message lists them).
    """
    if pelvis not in PELVIS_CURVES:
        raise InvalidParameterError("pelvis", pelvis, f"one of {', '.join(PELVIS_CURVES)}")
    return pelvis


def pelvis_model(pelvis: str | PelvisModel) -> PelvisModel:
    """The pelvis model named ``pelvis`` (one of :data:`PELVIS_CURVES`), or ``pelvis`` itself where it is a model.

    Raises:
        InvalidParameterError: Any other value (the message lists the names).
    """
    if not isinstance(pelvis, str) and isinstance(pelvis, PelvisModel):
        return pelvis
    return _MODELS[check_pelvis(pelvis)]
