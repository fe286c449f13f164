r"""A dynamically consistent pattern: the pelvis corrected until the multibody ZMP follows the pattern's ZMP.

Every generator plans one mass (the cart-table of Eqs. 1-2 of Park et al., the LIPM of Eq. 4 of Lim et
al.); the robot's legs carry the rest. Along the same pattern the multibody ZMP of Eq. 3 (Lim et al.,
:mod:`zmpwalk.dynamics`) misses the planned ZMP by 23-28 mm RMS on HUBO and 8-10 mm on the small biped of
Lim et al., mostly a steady 21-27 mm forward (bent knees put the legs' mass ahead of the hips). The
correction is the second stage of Kajita et al. (2003, Section IV): the error

.. math:: e(t) = p_{multibody}(t) - p_{ref}(t)

is treated as a ZMP reference for the cart-table, and the preview controller of
:mod:`zmpwalk.patterns.preview` gives the pelvis motion ``Δc`` whose cart-table ZMP is ``-e``:

.. math:: Δc - \frac{l}{g}\, Δ\ddot c = -e \quad\Rightarrow\quad
          p_{multibody}(c + Δc) \approx p_{multibody}(c) - e = p_{ref}

The approximation is that the whole body moves with the pelvis; the feet do not, so the correction
falls short and may be repeated. Each pass recomputes the multibody ZMP along the corrected pattern and
is kept only while it lowers the RMS error (repeated passes also answer the error's spikes at the
instants where the planned ZMP jumps, which do not shrink). The planned ZMP, the feet and the timing
stay as they were; the corrected pattern records the whole-body centre of mass
(:attr:`WalkingPattern.position_com_in_world`), the reference a stabilizer must track.

Box models only: the multibody ZMP needs the links of the robot file's ``[bodies]``. A robot imported from
its own model is placed by its whole-body centre of mass instead (:func:`zmpwalk.kinematics.joint_trajectory`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from zmpwalk.dynamics import ZmpComparison, compare_zmp
from zmpwalk.errors import InvalidParameterError
from zmpwalk.patterns.preview import preview_gains, track
from zmpwalk.patterns.result import WalkingPattern

Array = NDArray[np.float64]

MAX_PASSES = 5


@dataclass(frozen=True)
class ZmpCorrection:
    """A pattern corrected by its multibody ZMP.

    Attributes:
        pattern: The corrected pattern (pelvis moved, ``position_com_in_world`` set).
        before: Multibody against planned ZMP along the pattern as generated.
        after: The same along the corrected pattern.
        passes: Correction passes kept (0: none lowered the error; the pattern is then the original one
            with its whole-body CoM recorded).
    """

    pattern: WalkingPattern
    before: ZmpComparison
    after: ZmpComparison
    passes: int


def correct_pattern(pattern: WalkingPattern, passes: int = 3) -> ZmpCorrection:
    """Move the pelvis of ``pattern`` until its multibody ZMP (Eq. 3) follows its planned ZMP.

    Args:
        pattern: A box model's pattern (any generator), sampled uniformly.
        passes: Most correction passes, 1 to :data:`MAX_PASSES`; each is kept only while it lowers the RMS
            difference of the multibody and the planned ZMP.

    Raises:
        InvalidParameterError: ``passes`` out of range, or a robot without ``[bodies]`` links (an imported
            robot, or a robot file without masses).
    """
    if isinstance(passes, bool) or not isinstance(passes, int) or not 1 <= passes <= MAX_PASSES:
        raise InvalidParameterError("passes", passes, f"an integer in [1, {MAX_PASSES}]")
    robot = pattern.robot
    if robot.own_model or not robot.links:
        raise InvalidParameterError("robot", robot.name, "a robot file with [bodies] (the multibody ZMP's links); "
                                    "an imported robot is placed by its whole-body centre of mass instead")
    gains = preview_gains(1.0 / pattern.rate, robot.pendulum_length, robot.gravity)
    before = compare_zmp(pattern)
    best, best_comparison, kept = pattern, before, 0
    shift = np.zeros((len(pattern.time), 2))
    rate = np.zeros((len(pattern.time), 2))
    comparison = before
    for done in range(1, passes + 1):
        error = comparison.multibody - pattern.zmp_in_world
        for axis in range(2):
            # start at rest where the static error puts it: the cart-table ZMP of a CoM at rest is the CoM
            states, _ = track(gains, -error[:, axis], np.array([-error[0, axis], 0.0, 0.0]))
            shift[:, axis] += states[:, 0]
            rate[:, axis] += states[:, 1]
        position = pattern.position_pelvis_in_world.copy()
        position[:, :2] += shift
        velocity = pattern.velocity_pelvis_in_world.copy()
        velocity[:, :2] += rate
        candidate = replace(pattern, position_pelvis_in_world=position, velocity_pelvis_in_world=velocity)
        comparison = compare_zmp(candidate)
        if comparison.rms >= best_comparison.rms:
            break
        best, best_comparison, kept = candidate, comparison, done
    corrected = replace(best, position_com_in_world=best_comparison.center_of_mass)
    return ZmpCorrection(corrected, before, best_comparison, kept)
