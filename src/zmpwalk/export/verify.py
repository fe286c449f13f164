"""Each clip checked from its own file: replayed kinematically in MuJoCo, its stance feet must hold still.

:func:`replay_check` sets the model's ``qpos`` to each frame (:func:`mujoco.mj_kinematics`) and finds, per foot
(the rigid bodies of the ``left_ankle`` and ``right_ankle`` sites), its **stance phases**: runs of frames where
the foot's lowest collision point is within :data:`STANCE_HEIGHT` of the floor (z = 0) and the foot's origin
moves horizontally at most :data:`STANCE_SPEED`, at least :data:`MIN_STANCE` long. Over each phase:

- **slide**: the largest horizontal distance [m] of the foot's origin from where the phase began;
- **penetration**: the deepest its lowest point goes below the floor [m].

A clip passes when every phase slides at most :data:`MAX_SLIDE` and penetrates at most :data:`MAX_PENETRATION`
and there is at least one stance phase.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.export.clips import foot_bodies, lowest_sole_height

Array = NDArray[np.float64]

STANCE_HEIGHT = 0.002  # [m] lowest point of a foot in stance at most this high
STANCE_SPEED = 0.05  # [m/s] horizontal speed of a foot in stance at most this (a swing: about 0.5-1 m/s)
MIN_STANCE = 0.1  # [s] shortest stance phase judged
MAX_SLIDE = 0.005  # [m]
MAX_PENETRATION = 0.005  # [m]


@dataclass(frozen=True)
class ReplayCheck:
    """A clip's kinematic replay.

    Attributes:
        passed: Every stance phase within the limits, and at least one phase.
        phases: Stance phases found, both feet.
        slide: Largest slide of a stance foot [m].
        penetration: Deepest penetration of a stance foot into the floor [m] (0 when none goes below it).
    """

    passed: bool
    phases: int
    slide: float  # [m]
    penetration: float  # [m]


def _runs(mask: NDArray[np.bool_]) -> list[tuple[int, int]]:
    """The runs of True in ``mask``: first and last index of each."""
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), (np.flatnonzero(edges == -1) - 1).tolist(), strict=True))


@dataclass(frozen=True)
class StancePhases:
    """Where a clip's feet stand (module docstring).

    Attributes:
        phases: Per foot (left, right), the first and last frame of each stance phase.
        origin: Each foot's origin in world (n, 2, 2) [m], horizontal.
        lowest: Each foot's lowest collision point's height (n, 2) [m].
    """

    phases: tuple[list[tuple[int, int]], list[tuple[int, int]]]
    origin: Array
    lowest: Array


def stance_phases(model: mujoco.MjModel, qpos: Array, fps: float) -> StancePhases:
    """Replay ``qpos`` rows at ``fps`` [Hz] and find each foot's stance phases (module docstring)."""
    feet = foot_bodies(model)
    data = mujoco.MjData(model)
    n = len(qpos)
    lowest, origin = np.empty((n, 2)), np.empty((n, 2, 2))
    for i in range(n):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        lowest[i] = lowest_sole_height(model, data, feet)
        origin[i] = [data.xpos[bodies[0], :2] for bodies in feet]
    speed = np.zeros((n, 2))
    if n > 1:
        speed = np.linalg.norm(np.gradient(origin, 1.0 / fps, axis=0), axis=2)
    runs = [[(a, b) for a, b in _runs((lowest[:, foot] <= STANCE_HEIGHT) & (speed[:, foot] <= STANCE_SPEED))
             if (b - a + 1) / fps >= MIN_STANCE] for foot in range(2)]
    return StancePhases((runs[0], runs[1]), origin, lowest)


def replay_check(model: mujoco.MjModel, qpos: Array, fps: float) -> ReplayCheck:
    """Replay ``qpos`` rows at ``fps`` [Hz] and judge the stance feet (module docstring)."""
    stance = stance_phases(model, qpos, fps)
    phases, slide, penetration = 0, 0.0, 0.0
    for foot in range(2):
        for a, b in stance.phases[foot]:
            phases += 1
            origin = stance.origin[a:b + 1, foot]
            slide = max(slide, float(np.linalg.norm(origin - origin[0], axis=1).max()))
            penetration = max(penetration, float(-stance.lowest[a:b + 1, foot].min()))
    passed = phases > 0 and slide <= MAX_SLIDE and penetration <= MAX_PENETRATION
    return ReplayCheck(passed, phases, slide, penetration)
