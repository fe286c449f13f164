"""The online LIPM generator: the stage engine of :mod:`zmpwalk.patterns.planning` with the hyperbolic pelvis of
Lim et al. (Eqs. 4-11, per stage: :mod:`zmpwalk.patterns.lipm_stage`) for any step commands.

The paper's own straight walk, with its start and stop transients (Eqs. 12-15), is kept apart as a reproduction
of the paper: :mod:`zmpwalk.patterns.hyperbolic`.
"""

from __future__ import annotations

from collections.abc import Sequence

from zmpwalk.commands import StepCommand
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule


def generate_hyperbolic(robot: RobotModel, commands: Sequence[StepCommand], rate: float = 100.0,
                        schedule: Schedule | None = None, labels: Sequence[str] | None = None) -> WalkingPattern:
    """The hyperbolic pattern of any step commands (forward, side, turn), sampled at ``rate`` [Hz].

    Stage by stage as :class:`~zmpwalk.online.OnlineWalker` walks it with ``generator="hyperbolic"``
    (:mod:`zmpwalk.patterns.lipm_stage`): the footsteps, swings and timing of the polynomial generator,
    the pelvis of the linear inverted pendulum under a piecewise-constant ZMP, solved per stage from the
    state it inherits. The paper's own straight walk with its start and stop transients (Eqs. 12-15) is
    :func:`zmpwalk.patterns.hyperbolic.paper_walk`.

    Raises:
        InfeasiblePatternError: A stage would need its ZMP outside the feet (or has no steady step).
        UnreachableError: A leg cannot follow the pattern.
        ZmpwalkError: Any other infeasible command, as for :func:`zmpwalk.patterns.polynomial.generate`.
    """
    return generate(robot, commands, rate=rate, schedule=schedule, labels=labels, pelvis="hyperbolic")
