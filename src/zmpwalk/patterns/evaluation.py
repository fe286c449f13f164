"""Evaluating a walk's stages at any times, vectorised: the closed forms of :mod:`zmpwalk.patterns.stages`.

A :class:`StageTable` holds the stages as column arrays; :func:`evaluate` gives the pelvis, both ankles, their
rates, yaws and the cart-table ZMP at many times in one vectorised pass. :func:`evaluate_in_parts` is the same
computation cut into parts of a few numpy calls each (:mod:`zmpwalk.slices`): the swinging ankle, the pelvis
base and side shift, the sway, the feet, the ZMP, so that :class:`zmpwalk.online.OnlineWalker` runs a few
per control tick; :func:`evaluate` runs it whole (the batch paths: the same code, the same numbers).
Where a stage carries the pendulum's pieces (the hyperbolic pelvis model), its pelvis replaces the curves'
(:class:`~zmpwalk.patterns.lipm_stage.LipmColumns`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, fields
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from zmpwalk import curves
from zmpwalk.footsteps import StagePlan
from zmpwalk.patterns.lipm_stage import LipmColumns, LipmPelvis
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Side, Support
from zmpwalk.slices import Parts, run_to_end, whole

Array = NDArray[np.float64]

SHIFT_NONE = 0
SHIFT_OPEN = 1
SHIFT_RECOVERY = 2
SHIFT_PROFILES = {"open": SHIFT_OPEN, "recovery": SHIFT_RECOVERY}
# d(profile)/d(tau) at tau = 0 and tau = 1 of side_shift_profile (cubic pelvis: cosine; quintic: smoothstep)
SHIFT_END_RATES = {SHIFT_NONE: (0.0, 0.0), SHIFT_OPEN: (0.0, math.pi), SHIFT_RECOVERY: (math.pi, 0.0)}
QUINTIC_SHIFT_RATE = 2.0 * 15.0 / 8.0  # [-] 2 S'(1/2) of the quintic smoothstep S
QUINTIC_SHIFT_END_RATES = {SHIFT_NONE: (0.0, 0.0), SHIFT_OPEN: (0.0, QUINTIC_SHIFT_RATE),
                           SHIFT_RECOVERY: (QUINTIC_SHIFT_RATE, 0.0)}


def side_shift_profile(tau: Array, profile: NDArray[np.integer], quintic: bool = False) -> curves.Curve:
    """Pelvis shift of side walking (Eqs. 15-16) as a fraction of a stage's shift, per unit ``tau``.

    The paper moves the pelvis sideways from the middle of the open-stance
    stage ``t0`` to the end of it and from the start of the recovery to its
    ``t0``, each a half cosine that stops at the step change. zmpwalk joins the
    two into one cosine from ``t0`` of the open stance to ``t0`` of the
    recovery, so the pelvis keeps its sideways speed through the step change
    instead of stopping and restarting there: same timing and amplitude, the
    acceleration (and so the cart-table ZMP) no longer jumps at the step change.

    * open: ``0`` for ``tau < 1/2``, then ``1 - cos(pi (tau - 1/2))``;
    * recovery: ``sin(pi tau)`` for ``tau < 1/2``, then ``1``;
    * other stages: ``0``.

    With the quintic pelvis (``quintic``) the joined curve is the smoothstep ``S(u)`` of Eq. 17 (Lim et
    al.) over the same span, ``u`` from 0 at ``t0`` of the open stance to 1 at ``t0`` of the recovery:
    ``2 S(tau - 1/2)`` in the open stance and ``2 S(tau + 1/2) - 1`` in the recovery, whose curvature
    is zero where it starts and ends, so the pelvis acceleration does not jump there either.
    """
    opening = profile == SHIFT_OPEN
    recovering = profile == SHIFT_RECOVERY
    late = np.clip(tau - 0.5, 0.0, 0.5)
    early = np.clip(tau, 0.0, 0.5)
    if quintic:  # one smoothstep S(u) from t0 of the open stance (u = 0) to t0 of the recovery (u = 1)
        u = np.where(opening, late, early + 0.5)
        step, step1, step2 = curves.smoothstep5(u)
        active = (opening & (tau >= 0.5)) | (recovering & (tau < 0.5))
        value = np.where(opening, 2.0 * step, np.where(recovering, 2.0 * step - 1.0, 0.0))
        return value, np.where(active, 2.0 * step1, 0.0), np.where(active, 2.0 * step2, 0.0)
    value = np.where(opening, 1.0 - np.cos(np.pi * late), np.where(recovering, np.sin(np.pi * early), 0.0))
    rate = np.where(opening & (tau >= 0.5), np.pi * np.sin(np.pi * late),
                    np.where(recovering & (tau < 0.5), np.pi * np.cos(np.pi * early), 0.0))
    curvature = np.where(opening & (tau >= 0.5), np.pi**2 * np.cos(np.pi * late),
                         np.where(recovering & (tau < 0.5), -np.pi**2 * np.sin(np.pi * early), 0.0))
    return value, rate, curvature




class StageLike(Protocol):
    """What a :class:`StageTable` reads of a stage: :class:`zmpwalk.patterns.stages.Stage` (not imported
    here: that module builds on this one). Positions [m], times [s], slopes per unit normalised time [m]."""

    @property
    def plan(self) -> StagePlan: ...
    @property
    def start(self) -> float: ...
    @property
    def duration(self) -> float: ...
    @property
    def dsp_time(self) -> float: ...
    @property
    def base_start(self) -> tuple[float, float]: ...
    @property
    def base_sagittal(self) -> tuple[float, float]: ...
    @property
    def base_lateral(self) -> tuple[float, float]: ...
    @property
    def lateral_profile(self) -> int: ...
    @property
    def base_slope_start(self) -> tuple[float, float]: ...
    @property
    def base_slope_end(self) -> tuple[float, float]: ...
    @property
    def sway_direction(self) -> tuple[float, float]: ...
    @property
    def sway_amplitude(self) -> float: ...
    @property
    def sway_slope_start(self) -> float: ...
    @property
    def sway_slope_end(self) -> float: ...
    @property
    def sway_out_time(self) -> float: ...
    @property
    def sway_back_time(self) -> float: ...
    @property
    def standing(self) -> bool: ...
    @property
    def grounded(self) -> bool: ...
    @property
    def quintic(self) -> bool: ...
    @property
    def lipm(self) -> LipmPelvis | None: ...


class StageTable:
    """Stages as one-dimensional column arrays, so that many samples evaluate in one vectorised pass."""

    def __init__(self, stages: Sequence[StageLike]) -> None:
        run_to_end(self._fill_in_parts(stages))

    @classmethod
    def in_parts(cls, stages: Sequence[StageLike]) -> Parts[StageTable]:
        """The table of ``stages`` built in parts (:mod:`zmpwalk.slices`): the numbers, the flags and the feet's
        paths, the hyperbolic pelvis's pieces."""
        table = cls.__new__(cls)
        yield from table._fill_in_parts(stages)
        return table

    def _fill_in_parts(self, stages: Sequence[StageLike]) -> Parts[None]:
        self.stages = stages
        # every per-stage number in one array (one numpy call, not one per column), row j = column j
        plans = [s.plan for s in stages]
        numbers = np.array([
            (s.start, s.duration, s.dsp_time, p.support_pose.x, p.support_pose.y, p.support_pose.yaw,
             p.swing_start.x, p.swing_start.y, p.swing_start.yaw, p.swing_end.yaw - p.swing_start.yaw,
             p.swing_end.x - p.swing_start.x, p.swing_end.y - p.swing_start.y,
             0.0 if s.grounded else p.parameters.foot_lift, p.parameters.up_ratio,
             s.base_start[0], s.base_start[1], s.base_sagittal[0], s.base_sagittal[1],
             s.base_lateral[0], s.base_lateral[1], s.base_slope_start[0], s.base_slope_start[1],
             s.base_slope_end[0], s.base_slope_end[1], s.sway_direction[0], s.sway_direction[1],
             s.sway_amplitude, s.sway_slope_start, s.sway_slope_end, s.sway_out_time, s.sway_back_time)
            for s, p in zip(stages, plans, strict=True)], dtype=float).reshape(len(stages), 31).T.copy()
        yield
        (self.start, self.duration, self.dsp, self.support_x, self.support_y, self.support_yaw,
         self.swing_x0, self.swing_y0, self.swing_yaw0, self.swing_dyaw, dx, dy, self.lift, self.up_ratio,
         self.base0_x, self.base0_y, self.sag_x, self.sag_y, self.lat_x, self.lat_y, self.m0_x, self.m0_y,
         self.m1_x, self.m1_y, self.n_x, self.n_y, self.amp, self.w0, self.w1, self.out_time,
         self.back_time) = numbers
        flags = np.array([(p.swing == Side.LEFT, s.standing, s.grounded, s.quintic, s.lipm is not None)
                          for s, p in zip(stages, plans, strict=True)], dtype=bool).reshape(len(stages), 5).T.copy()
        self.swing_left, self.standing, self.grounded, self.quintic, self.hyperbolic = flags
        self.lat_profile = np.array([s.lateral_profile for s in stages])
        hx, hy = np.cos(self.support_yaw), np.sin(self.support_yaw)
        along = dx * hx + dy * hy
        self.along_x, self.along_y = along * hx, along * hy  # [m] cycloid part (Eq. 11)
        self.across_x, self.across_y = dx - self.along_x, dy - self.along_y  # [m] half-cosine part (Eqs. 14-17)
        self.lipm: LipmColumns | None = None  # the hyperbolic pelvises, where a stage has one
        if self.hyperbolic.any():
            yield
            self.lipm = LipmColumns.of([s.lipm for s in stages])

    def index_at(self, time: Array) -> NDArray[np.intp]:
        """Index of the stage each time belongs to (a boundary time opens the next stage)."""
        index = np.searchsorted(self.start, time, side="right") - 1
        return np.clip(index, 0, len(self.stages) - 1)


@dataclass
class Samples:
    """Evaluated pattern at given times, all in world (SI).

    Shapes: ``(n,)`` for scalars, ``(n, 2)`` / ``(n, 3)`` for vectors.
    """

    time: Array  # [s]
    support: NDArray[np.int8]  # SUPPORT_* codes
    pelvis_xy: Array  # [m]
    pelvis_velocity_xy: Array  # [m/s]
    pelvis_acceleration_xy: Array  # [m/s^2]
    pelvis_yaw: Array  # [rad]
    pelvis_yaw_rate: Array  # [rad/s]
    left_position: Array  # [m], ankle
    left_velocity: Array  # [m/s]
    left_yaw: Array  # [rad]
    left_yaw_rate: Array  # [rad/s]
    right_position: Array  # [m], ankle
    right_velocity: Array  # [m/s]
    right_yaw: Array  # [rad]
    right_yaw_rate: Array  # [rad/s]
    zmp_xy: Array  # [m], cart-table ZMP of Eqs. 1-2

    @classmethod
    def joined(cls, pieces: Sequence[Samples]) -> Samples:
        """The samples of consecutive ``pieces``, one after the other."""
        return cls(**{f.name: np.concatenate([getattr(piece, f.name) for piece in pieces])
                      for f in fields(cls)})


def evaluate_in_parts(table: StageTable, time: Array, robot: RobotModel,
                      index: NDArray[np.intp] | None = None) -> Parts[Samples]:
    """Evaluate the stages at ``time`` (each sample in stage ``index``, default: its own stage).
    In parts of a few numpy calls each (the stage lookup, the swinging ankle, the pelvis base and side shift,
    the sway, the feet, the ZMP; :mod:`zmpwalk.slices`); :func:`evaluate` runs it whole.

    Works on one-dimensional component arrays throughout (numpy broadcasting
    over a trailing axis of 2 or 3 is many times slower than plain vector ops).
    """
    t = np.asarray(time, dtype=float)
    k = table.index_at(t) if index is None else index
    yield
    T = table.duration[k]
    d = table.dsp[k]
    elapsed = t - table.start[k]
    tau = elapsed / T
    yield
    swing = yield from _swing_in_parts(table, k, elapsed, T, d, robot)
    yield
    quintic = table.quintic[k] if table.quintic.any() else None  # per sample, None: all cubic
    components = yield from _base_in_parts(table, k, tau, quintic)
    yield
    pelvis_x, pelvis_y, pelvis_vx, pelvis_vy, pelvis_ax, pelvis_ay = yield from _sway_in_parts(
        table, k, elapsed, T, quintic, components)
    yield
    support, (left_position, left_velocity, left_yaw, left_rate), (right_position, right_velocity, right_yaw,
                                                                   right_rate) = yield from _feet_in_parts(
        table, k, len(t), swing, robot)
    yield
    if table.lipm is not None:  # the pendulum's pelvis in place of the curves, where a stage has one
        pelvis_x, pelvis_y, pelvis_vx, pelvis_vy, pelvis_ax, pelvis_ay = yield from table.lipm.pelvis_at_in_parts(
            table.hyperbolic[k], k, elapsed, robot, (pelvis_x, pelvis_y, pelvis_vx, pelvis_vy, pelvis_ax, pelvis_ay))
        yield
    l_over_g = robot.pendulum_length / robot.gravity
    zmp = np.column_stack([pelvis_x - l_over_g * pelvis_ax, pelvis_y - l_over_g * pelvis_ay])  # Eqs. 1-2
    yield
    return Samples(
        time=t, support=support.astype(np.int8), pelvis_xy=np.column_stack([pelvis_x, pelvis_y]),
        pelvis_velocity_xy=np.column_stack([pelvis_vx, pelvis_vy]),
        pelvis_acceleration_xy=np.column_stack([pelvis_ax, pelvis_ay]), pelvis_yaw=0.5 * (left_yaw + right_yaw),
        pelvis_yaw_rate=0.5 * (left_rate + right_rate), left_position=left_position,
        left_velocity=left_velocity, left_yaw=left_yaw, left_yaw_rate=left_rate,
        right_position=right_position, right_velocity=right_velocity, right_yaw=right_yaw,
        right_yaw_rate=right_rate, zmp_xy=zmp,
    )


evaluate = whole(evaluate_in_parts, "evaluate")  # the same, run whole


def _swing_in_parts(table: StageTable, k: NDArray[np.intp], elapsed: Array, T: Array, d: Array,
                    robot: RobotModel) -> Parts[tuple[NDArray[Any], ...]]:
    """The swinging ankle: Eq. 11 (cycloid) along, Eqs. 14-17 (half cosine) across, Fig. 12 height. Whether each
    sample is in the swing, then x, y, z, their rates, the yaw and its rate."""
    swing_span = T - d
    raw = (elapsed - 0.5 * d) / swing_span
    in_swing = (raw > 0.0) & (raw < 1.0) & ~table.grounded[k]
    s = np.clip(raw, 0.0, 1.0)
    rate = in_swing / swing_span
    yield
    b, b1, c, c1 = _blend_and_cycloid(s)
    yield
    h, h1, _ = curves.lift_profile(s, table.up_ratio[k])
    yield
    b1 *= rate
    c1 *= rate
    ax, ay = table.along_x[k], table.along_y[k]
    cx, cy = table.across_x[k], table.across_y[k]
    swing_x = table.swing_x0[k] + ax * c + cx * b
    swing_y = table.swing_y0[k] + ay * c + cy * b
    swing_vx = ax * c1 + cx * b1
    swing_vy = ay * c1 + cy * b1
    lift = table.lift[k]
    swing_z = robot.ankle_height + lift * h
    swing_vz = lift * h1 * rate
    dyaw = table.swing_dyaw[k]
    swing_yaw = table.swing_yaw0[k] + dyaw * b
    swing_yaw_rate = dyaw * b1
    return in_swing, swing_x, swing_y, swing_z, swing_vx, swing_vy, swing_vz, swing_yaw, swing_yaw_rate


def _base_in_parts(table: StageTable, k: NDArray[np.intp], tau: Array, quintic: NDArray[np.bool_] | None
                   ) -> Parts[list[list[Array]]]:
    """The pelvis base: Eqs. 12-13 cubic (Hermite form of Eq. 4) plus the side-walking shift of Eqs. 15-16; for x
    then y, the position, slope and curvature per unit tau and the stage's lateral shift."""
    h10, h01, h11, g10, g01, g11, k10, k01, k11 = yield from _mixed_in_parts(_cubic_basis, _quintic_basis, quintic,
                                                                             tau)
    yield
    components = []
    for base0, sag, m0, m1, lat in (
        (table.base0_x, table.sag_x, table.m0_x, table.m1_x, table.lat_x),
        (table.base0_y, table.sag_y, table.m0_y, table.m1_y, table.lat_y),
    ):
        m0k, m1k, sagk = m0[k], m1[k], sag[k]
        position = base0[k] + h10 * m0k + h01 * sagk + h11 * m1k
        slope = g10 * m0k + g01 * sagk + g11 * m1k
        curvature = k10 * m0k + k01 * sagk + k11 * m1k
        components.append([position, slope, curvature, lat])
        yield
    if np.any(table.lat_profile != SHIFT_NONE):
        q, q1, q2 = yield from _mixed_in_parts(lambda t, p: side_shift_profile(t, p, False),
                                               lambda t, p: side_shift_profile(t, p, True),
                                               quintic, tau, table.lat_profile[k])
        yield
        for component in components:
            lat_k = component[3][k]
            component[0] = component[0] + lat_k * q
            component[1] = component[1] + lat_k * q1
            component[2] = component[2] + lat_k * q2
            yield
    return components


def _sway_in_parts(table: StageTable, k: NDArray[np.intp], elapsed: Array, T: Array,
                   quintic: NDArray[np.bool_] | None, components: list[list[Array]]) -> Parts[tuple[Array, ...]]:
    """The pelvis sway (Eqs. 18-20 on the modified time t_bar: sigma = 2 t_bar, or 2 t_bar - 1) added to the
    base ``components``: the pelvis x, y, their rates and accelerations in world."""
    amp = table.amp[k]
    out_time, back_time = table.out_time[k], table.back_time[k]
    back_start = T - back_time
    first_half = elapsed < out_time
    second_half = (elapsed >= back_start) & ~first_half  # exclusive also where rounding makes them touch
    sigma = np.where(first_half, elapsed / out_time, np.where(second_half, (elapsed - back_start) / back_time, 0.0))
    p_start = np.where(first_half, 0.0, amp)
    m_start = np.where(first_half, table.w0[k], 0.0)
    p_end = np.where(second_half, 0.0, amp)
    m_end = np.where(second_half, table.w1[k], 0.0)
    yield
    sway, sway1, sway2 = yield from _mixed_in_parts(curves.hermite_cubic, curves.hermite_quintic, quintic,
                                                    p_start, m_start, p_end, m_end, sigma)
    yield
    scale = np.where(first_half, 1.0 / out_time, np.where(second_half, 1.0 / back_time, 0.0))  # d sigma/dt
    sway = np.where(first_half | second_half, sway, amp)
    sway1 = sway1 * scale
    sway2 = sway2 * scale * scale
    yield
    inv_T = 1.0 / T
    inv_T2 = inv_T * inv_T
    nx, ny = table.n_x[k], table.n_y[k]
    (px, vx, accx, _), (py, vy, accy, _) = components
    return (px + sway * nx, py + sway * ny, vx * inv_T + sway1 * nx, vy * inv_T + sway1 * ny,
            accx * inv_T2 + sway2 * nx, accy * inv_T2 + sway2 * ny)


def _feet_in_parts(table: StageTable, k: NDArray[np.intp], n: int, swing: tuple[NDArray[Any], ...],
                   robot: RobotModel) -> Parts[tuple[NDArray[Any], tuple[Array, ...], tuple[Array, ...]]]:
    """The support code, and for the left then the right foot its ankle position, velocity, yaw and yaw rate
    (the pelvis yaw is their mean, Eq. 23)."""
    in_swing, swing_x, swing_y, swing_z, swing_vx, swing_vy, swing_vz, swing_yaw, swing_yaw_rate = swing
    left_swings = table.swing_left[k]
    right_swings = ~left_swings
    support_x, support_y = table.support_x[k], table.support_y[k]
    ankle = np.full(n, robot.ankle_height)
    left_position = np.column_stack([
        np.where(left_swings, swing_x, support_x), np.where(left_swings, swing_y, support_y),
        np.where(left_swings, swing_z, ankle)])
    yield
    right_position = np.column_stack([
        np.where(left_swings, support_x, swing_x), np.where(left_swings, support_y, swing_y),
        np.where(left_swings, ankle, swing_z)])
    yield
    left_velocity = np.column_stack([swing_vx * left_swings, swing_vy * left_swings, swing_vz * left_swings])
    right_velocity = np.column_stack([swing_vx * right_swings, swing_vy * right_swings, swing_vz * right_swings])
    yield
    support_yaw = table.support_yaw[k]
    left_yaw = np.where(left_swings, swing_yaw, support_yaw)
    right_yaw = np.where(left_swings, support_yaw, swing_yaw)
    left_rate = swing_yaw_rate * left_swings
    right_rate = swing_yaw_rate * right_swings
    support = np.where(in_swing, np.where(left_swings, Support.RIGHT, Support.LEFT), Support.DOUBLE)
    return support, (left_position, left_velocity, left_yaw, left_rate), (right_position, right_velocity,
                                                                          right_yaw, right_rate)


def _cubic_basis(tau: Array) -> tuple[Array, ...]:
    """Hermite cubic basis (Eqs. 4 and 12): slope-0, end-value and slope-1 functions and their derivatives."""
    s2 = tau * tau
    s3 = s2 * tau
    return (s3 - 2 * s2 + tau, 3 * s2 - 2 * s3, s3 - s2,
            3 * s2 - 4 * tau + 1, 6 * tau - 6 * s2, 3 * s2 - 2 * tau,
            6 * tau - 4, 6 - 12 * tau, 6 * tau - 2)


def _quintic_basis(tau: Array) -> tuple[Array, ...]:
    """The same for :func:`zmpwalk.curves.hermite_quintic` (zero curvature at both ends)."""
    s2 = tau * tau
    s3 = s2 * tau
    s4 = s2 * s2
    rise, rise1, rise2 = curves.smoothstep5(tau)
    return (tau - 6 * s3 + 8 * s4 - 3 * s4 * tau, rise, -4 * s3 + 7 * s4 - 3 * s4 * tau,
            1 - 18 * s2 + 32 * s3 - 15 * s4, rise1, -12 * s2 + 28 * s3 - 15 * s4,
            -36 * tau + 96 * s2 - 60 * s3, rise2, -24 * tau + 84 * s2 - 60 * s3)


def _mixed_in_parts(cubic: Callable[..., tuple[Array, ...]], quintic: Callable[..., tuple[Array, ...]],
                    mask: NDArray[np.bool_] | None, *args: Array) -> Parts[tuple[Array, ...]]:
    """``cubic(*args)`` or ``quintic(*args)`` per sample as ``mask`` (None: every sample cubic); where both
    occur in parts (each, then the choice)."""
    if mask is None:
        return cubic(*args)
    if mask.all():
        return quintic(*args)
    cubics = cubic(*args)
    yield
    quintics = quintic(*args)
    yield
    return tuple(np.where(mask, q, c) for c, q in zip(cubics, quintics, strict=True))


def _blend_and_cycloid(s: Array) -> tuple[Array, Array, Array, Array]:
    """Half cosine (Eqs. 14-17, 21-22) and cycloid (Eq. 11) with their slopes, sharing one sin/cos pair."""
    angle = np.pi * s
    sine, cosine = np.sin(angle), np.cos(angle)
    blend = 0.5 * (1.0 - cosine)
    blend_slope = 0.5 * np.pi * sine
    sin2 = 2.0 * sine * cosine  # sin(2 pi s)
    cos2 = 1.0 - 2.0 * sine * sine  # cos(2 pi s)
    return blend, blend_slope, s - sin2 / curves.TWO_PI, 1.0 - cos2

