"""Each clip checked from its own file: replayed kinematically in MuJoCo, its stance feet must hold still.

:func:`replay_check` sets the model's ``qpos`` to each frame (:func:`mujoco.mj_kinematics`) and finds, per foot
(the rigid bodies of the ``left_ankle`` and ``right_ankle`` sites), its **stance phases**: runs of frames where
the foot's lowest collision point is within :data:`STANCE_HEIGHT` of the floor (z = 0) and the foot's origin
moves horizontally at most :data:`STANCE_SPEED`, at least :data:`MIN_STANCE` long. Over each phase:

- **slide**: how far a point of the sole moves along the floor while it touches it: for each collision point of
  the foot (:func:`zmpwalk.robots.collision.collision_points`: box corners, mesh vertices, ...), the largest
  horizontal distance [m] between the frames of the phase where it is in contact (at most
  :data:`CONTACT_HEIGHT` above the floor) and the first of them; the phase's slide is the largest over its points.
  A sole that rocks on an edge moves its origin (a foot 0.1 m above its sole pitched 0.05 rad moves it 5 mm)
  and the points that lift, not the points that stay down; a sole that turns about one corner moves the others;
  a foot still coming down (above the floor) is not sliding yet. A sphere's, capsule's or cylinder's lowest point
  is not a point of the sole: its rolling counts as slide (on the safe side). A phase in which no point touches
  (the foot hovering within the stance band) takes its origin's largest horizontal distance instead;
- **penetration**: the deepest its lowest point goes below the floor [m].

A clip passes when every phase slides at most :data:`MAX_SLIDE` and penetrates at most :data:`MAX_PENETRATION`
and there is at least one stance phase.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.export.clips import foot_bodies
from zmpwalk.robots.collision import collision_points

Array = NDArray[np.float64]

STANCE_HEIGHT = 0.002  # [m] lowest point of a foot in stance at most this high
CONTACT_HEIGHT = 0.0001  # [m] a collision point at most this high touches the floor (a file's precision, 0.1 mm)
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
        points: Per foot, its collision points in world (n, m, 3) [m], the same points in every frame.
    """

    phases: tuple[list[tuple[int, int]], list[tuple[int, int]]]
    origin: Array
    lowest: Array
    points: tuple[Array, Array]


def stance_phases(model: mujoco.MjModel, qpos: Array, fps: float) -> StancePhases:
    """Replay ``qpos`` rows at ``fps`` [Hz] and find each foot's stance phases (module docstring)."""
    feet = foot_bodies(model)
    data = mujoco.MjData(model)
    n = len(qpos)
    origin = np.empty((n, 2, 2))
    points: list[list[Array]] = [[], []]
    for i in range(n):
        data.qpos[:] = qpos[i]
        mujoco.mj_kinematics(model, data)
        for foot, bodies in enumerate(feet):
            points[foot].append(collision_points(model, data, bodies))
        origin[i] = [data.xpos[bodies[0], :2] for bodies in feet]
    cloud = (np.asarray(points[0]).reshape(n, -1, 3), np.asarray(points[1]).reshape(n, -1, 3))
    lowest = np.stack([cloud[foot][:, :, 2].min(axis=1) for foot in range(2)], axis=1)
    speed = np.zeros((n, 2))
    if n > 1:
        speed = np.linalg.norm(np.gradient(origin, 1.0 / fps, axis=0), axis=2)
    runs = [[(a, b) for a, b in _runs((lowest[:, foot] <= STANCE_HEIGHT) & (speed[:, foot] <= STANCE_SPEED))
             if (b - a + 1) / fps >= MIN_STANCE] for foot in range(2)]
    return StancePhases((runs[0], runs[1]), origin, lowest, cloud)


def contact_slide(points: Array) -> float:
    """The slide [m] of one stance phase's collision points (frames, m, 3): per point, the largest horizontal
    distance between the frames where it touches the floor and the first of them; the largest over the points
    (0 where none touches)."""
    touching = points[:, :, 2] <= CONTACT_HEIGHT
    slide = 0.0
    for j in np.flatnonzero(touching.any(axis=0)):
        where = points[touching[:, j], j, :2]
        slide = max(slide, float(np.linalg.norm(where - where[0], axis=1).max()))
    return slide


def replay_check(model: mujoco.MjModel, qpos: Array, fps: float) -> ReplayCheck:
    """Replay ``qpos`` rows at ``fps`` [Hz] and judge the stance feet (module docstring)."""
    stance = stance_phases(model, qpos, fps)
    phases, slide, penetration = 0, 0.0, 0.0
    for foot in range(2):
        for a, b in stance.phases[foot]:
            phases += 1
            points = stance.points[foot][a:b + 1]
            if (points[:, :, 2] <= CONTACT_HEIGHT).any():
                slide = max(slide, contact_slide(points))
            else:  # the foot hovers within the stance band without touching: its origin's way
                origin = stance.origin[a:b + 1, foot]
                slide = max(slide, float(np.linalg.norm(origin - origin[0], axis=1).max()))
            penetration = max(penetration, float(-stance.lowest[a:b + 1, foot].min()))
    passed = phases > 0 and slide <= MAX_SLIDE and penetration <= MAX_PENETRATION
    return ReplayCheck(passed, phases, slide, penetration)
