"""The result type shared by every pattern generator: :class:`WalkingPattern`.

Inverse kinematics, the ZMP check, the simulator and the reports read only
this type and never ask which generator made it.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.files import atomic_output
from zmpwalk.footsteps import Pose2D, foot_corners, sole_corners
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import SUPPORT_LABELS
from zmpwalk.zmp import convex_hull, edge_margin, hull_edges

Array = NDArray[np.float64]

MARGIN_CHUNK = 2048  # support phases whose ZMP margins are computed in one vectorised pass
PHASE_TIME_TOL = 1e-9  # [s] a sample this close to a phase change is at it (times are rounded sums)

def check_rate(rate: float) -> None:
    """Raise unless ``rate`` is a sampling rate zmpwalk supports (1 Hz .. 10 kHz)."""
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (1.0 <= rate <= 10_000.0):
        raise InvalidParameterError("rate", rate, "a sampling rate in [1, 10000] Hz")


def sample_times(end: float, rate: float) -> Array:
    """Sample times ``k / rate`` [s] from 0 up to the first sample at or after ``end`` [s].

    Raises:
        InvalidParameterError: An unsupported rate.
    """
    check_rate(rate)
    return np.arange(math.ceil(end * rate - 1e-9) + 1) / rate


CSV_COLUMNS = (
    "t", "support", "pelvis_x", "pelvis_y", "pelvis_z", "pelvis_yaw", "left_x", "left_y", "left_z",
    "left_yaw", "right_x", "right_y", "right_z", "right_yaw", "zmp_x", "zmp_y",
)


@dataclass(frozen=True)
class SupportPhase:
    """An interval with a fixed set of feet on the ground.

    Attributes:
        begin: Start time [s].
        end: End time [s] (``inf`` for standing at the end).
        support: 0 double, 1 left, 2 right.
        feet: The feet on the ground: ``(pose, side)`` with ``side`` +1 left, -1 right.
    """

    begin: float  # [s]
    end: float  # [s]
    support: int
    feet: tuple[tuple[Pose2D, int], ...]

    def polygon(self, robot: RobotModel) -> Array:
        """Support polygon in world, counter-clockwise, shape (m, 2) [m]: one sole or the hull of two."""
        corners = [foot_corners(pose, side, robot) for pose, side in self.feet]
        if len(corners) == 1:
            return corners[0]
        return convex_hull(np.vstack(corners))


@dataclass(frozen=True)
class StepRecord:
    """One swing of the walk, as planned.

    Attributes:
        start: Lift-off stage start ``t1`` [s].
        duration: Step time [s].
        swing: ``"left"`` or ``"right"``.
        kind: ``"step"``, ``"open"``, ``"recovery"``, ``"inserted"``, ``"stop"``, or a generator's own.
        landing: Landing pose of the swinging ankle ``(x [m], y [m], yaw [rad])`` in world.
        parameters: The shape parameters used, by name (SI).
    """

    start: float  # [s]
    duration: float  # [s]
    swing: str
    kind: str
    landing: tuple[float, float, float]
    parameters: dict[str, float | str] = field(default_factory=dict)


@dataclass
class WalkingPattern:
    """A walking pattern sampled at a fixed rate, in world (SI).

    Attributes:
        robot: The robot it was made for.
        rate: Samples per second [Hz].
        generator: Name of the generator.
        time: Sample times [s], shape (n,).
        support: Support phase code per sample (0 double, 1 left, 2 right), shape (n,).
        position_pelvis_in_world: Pelvis centre [m], (n, 3).
        velocity_pelvis_in_world: [m/s], (n, 3).
        yaw_pelvis_in_world: [rad], (n,).
        yaw_rate_pelvis: [rad/s], (n,).
        position_left_ankle_in_world, position_right_ankle_in_world: [m], (n, 3).
        velocity_left_ankle_in_world, velocity_right_ankle_in_world: [m/s], (n, 3).
        yaw_left_foot_in_world, yaw_right_foot_in_world: [rad], (n,).
        yaw_rate_left_foot, yaw_rate_right_foot: [rad/s], (n,).
        zmp_in_world: Cart-table ZMP (Eqs. 1-2) [m], (n, 2).
        steps: The swings, in order.
        support_phases: Support polygons over time.
        position_com_in_world: Whole-body centre of mass [m], (n, 3), where it differs from the pelvis point
            and is known (a box model's pattern corrected by its multibody ZMP,
            :func:`zmpwalk.correction.correct_pattern`); None: the pelvis point stands for it.
    """

    robot: RobotModel
    rate: float  # [Hz]
    generator: str
    time: Array
    support: NDArray[np.int8]
    position_pelvis_in_world: Array
    velocity_pelvis_in_world: Array
    yaw_pelvis_in_world: Array
    yaw_rate_pelvis: Array
    position_left_ankle_in_world: Array
    velocity_left_ankle_in_world: Array
    yaw_left_foot_in_world: Array
    yaw_rate_left_foot: Array
    position_right_ankle_in_world: Array
    velocity_right_ankle_in_world: Array
    yaw_right_foot_in_world: Array
    yaw_rate_right_foot: Array
    zmp_in_world: Array
    steps: list[StepRecord]
    support_phases: list[SupportPhase]
    position_com_in_world: Array | None = None  # [m]
    _polygons: list[Array] | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def duration(self) -> float:
        """Time of the last sample [s]."""
        return float(self.time[-1])

    @property
    def com_point(self) -> str:
        """What a stabilizer tracks as this pattern's CoM (:class:`zmpwalk.balance.Stabilizer`'s
        ``com_reference``): ``"whole_body"`` where it records ``position_com_in_world`` or its robot is imported
        (the base is placed under the pattern's point), else ``"pelvis"`` (a box model's pelvis point)."""
        return "whole_body" if self.position_com_in_world is not None or self.robot.own_model else "pelvis"

    @property
    def position_com_point_in_world(self) -> Array:
        """The CoM point a stabilizer tracks [m], (n, 3): ``position_com_in_world`` where the pattern records it
        (a multibody-corrected pattern), else the pelvis point."""
        return self.position_pelvis_in_world if self.position_com_in_world is None else self.position_com_in_world

    def _in_pelvis(self, position: Array) -> Array:
        rel = position - self.position_pelvis_in_world
        c, s = np.cos(self.yaw_pelvis_in_world), np.sin(self.yaw_pelvis_in_world)
        return np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])

    @property
    def position_left_ankle_in_pelvis(self) -> Array:
        """Left ankle in the pelvis frame [m], (n, 3): the paper's hat-x_A, hat-y_A."""
        return self._in_pelvis(self.position_left_ankle_in_world)

    @property
    def position_right_ankle_in_pelvis(self) -> Array:
        """Right ankle in the pelvis frame [m], (n, 3)."""
        return self._in_pelvis(self.position_right_ankle_in_world)

    @property
    def yaw_left_foot_in_pelvis(self) -> Array:
        """Left hip yaw: left foot yaw relative to the pelvis [rad] (Eqs. 21-22)."""
        return self.yaw_left_foot_in_world - self.yaw_pelvis_in_world

    @property
    def yaw_right_foot_in_pelvis(self) -> Array:
        """Right hip yaw [rad] (Eq. 23: minus the left one)."""
        return self.yaw_right_foot_in_world - self.yaw_pelvis_in_world

    def support_polygons(self) -> list[Array]:
        """The support polygon of each support phase, in world [m] (computed once)."""
        if self._polygons is None:
            self._polygons = [phase.polygon(self.robot) for phase in self.support_phases]
        return self._polygons

    def zmp_margin(self) -> Array:
        """Signed distance of the ZMP to the support polygon per sample [m] (> 0 inside).

        Linear in the walk's length and in bounded memory: the polygons' edges are found for
        :data:`MARGIN_CHUNK` phases at a time, and the samples of those phases measured together.
        """
        margin = np.full(len(self.time), np.nan)
        phases = self.support_phases
        begins = np.array([phase.begin for phase in phases])
        # the samples of each phase are one slice of the (sorted) times; a sample at a phase change (to
        # PHASE_TIME_TOL, whatever the rounding of the times) belongs to the phase that begins, whose ZMP it shows
        cuts = np.r_[0, np.searchsorted(self.time, begins[1:] - PHASE_TIME_TOL, side="left"), len(self.time)]
        for first in range(0, len(phases), MARGIN_CHUNK):
            last = min(first + MARGIN_CHUNK, len(phases))
            start, edge, valid = hull_edges(_phase_vertices(phases[first:last], self.robot))
            which = np.repeat(np.arange(last - first), np.diff(cuts[first:last + 1]))
            rows = slice(cuts[first], cuts[last])
            margin[rows] = edge_margin(self.zmp_in_world[rows], start[which], edge[which], valid[which])
        return margin

    def min_zmp_margin(self) -> tuple[float, float]:
        """Smallest ZMP margin [m] and the time it occurs [s]."""
        margin = self.zmp_margin()
        index = int(np.nanargmin(margin))
        return float(margin[index]), float(self.time[index])

    def columns(self) -> dict[str, NDArray[np.generic]]:
        """The CSV columns of ``zmpwalk plan`` as arrays, in order."""
        p, pl, pr = self.position_pelvis_in_world, self.position_left_ankle_in_world, self.position_right_ankle_in_world
        return {
            "t": self.time,
            "support": np.array(SUPPORT_LABELS)[self.support],
            "pelvis_x": p[:, 0], "pelvis_y": p[:, 1], "pelvis_z": p[:, 2], "pelvis_yaw": self.yaw_pelvis_in_world,
            "left_x": pl[:, 0], "left_y": pl[:, 1], "left_z": pl[:, 2], "left_yaw": self.yaw_left_foot_in_world,
            "right_x": pr[:, 0], "right_y": pr[:, 1], "right_z": pr[:, 2], "right_yaw": self.yaw_right_foot_in_world,
            "zmp_x": self.zmp_in_world[:, 0], "zmp_y": self.zmp_in_world[:, 1],
        }

    def write_csv(self, path: Path, extra: dict[str, Array] | None = None) -> None:
        """Write one row per sample with :data:`CSV_COLUMNS` (then ``extra`` columns) in SI units."""
        write_pieces_csv(path, [(self, extra)])


def write_pieces_csv(path: Path, pieces: Iterable[tuple[WalkingPattern, dict[str, Array] | None]]) -> None:
    """Write consecutive pieces of one walk as one CSV file, a piece at a time (bounded memory).

    The header comes from the first piece; the file appears only once every row is written.
    """
    with atomic_output(path) as temporary, temporary.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        for number, (pattern, extra) in enumerate(pieces):
            columns = pattern.columns()
            if extra:
                columns.update(extra)
            data = list(columns.values())
            if number == 0:
                writer.writerow(list(columns))
            for i in range(len(pattern.time)):
                writer.writerow([
                    value[i] if isinstance(value[i], str) else _fmt(float(value[i])) for value in data
                ])


def _phase_vertices(phases: list[SupportPhase], robot: RobotModel) -> Array:
    """The sole corners of each phase's feet, shape (p, 8, 2) [m] (a single sole twice)."""
    feet = [(phase.feet * 2)[:2] for phase in phases]
    x, y, yaw, side = np.array([[pose.x, pose.y, pose.yaw, foot] for pair in feet for pose, foot in pair]).T
    return sole_corners(x, y, yaw, side, robot).reshape(len(phases), 8, 2)


def _fmt(value: float) -> str:
    if math.isfinite(value) and value == 0.0:
        return "0"
    return f"{value:.9g}"
