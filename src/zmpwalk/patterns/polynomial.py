"""The online walking pattern of KHR-3 (HUBO): Park, Kim and Oh (2008), Section 3.

One *stage* is one swing of one foot from ``t1`` to ``t2 = t1 + T``. All its
trajectories are fixed at the stage start from boundary conditions, so the
next stage's parameters (step time, stride, mode) can change freely:

* **Pelvis, sagittal** (Eqs. 12-13): a cubic in normalised time from the
  middle of the ankles at ``t1`` to the middle at ``t2``. The end velocity is
  ``alpha f`` per unit normalised time (``alpha f / T`` in m/s). The start
  velocity is the previous stage's end velocity, which is the paper's
  ``alpha b`` when step time and ``alpha`` stay the same, and keeps the velocity
  continuous when they change.
* **Pelvis, lateral sway** (Eqs. 18-20): two cubics on the modified time
  ``t_bar`` with staying ratio ``d1``: from the ankles' middle towards the
  supporting foot by ``beta1 S_y`` and back. ``V_y`` is a slope per unit of
  each cubic's own normalised time ``2 t_bar`` (Fig. 16: ``V_y = 100`` mm with
  ``S_y = 40`` mm: the range ``1.5 S_y < alpha1 V_y < 3 S_y`` is where the sway
  cubic has neither the inflection of too small an ``alpha1`` nor the reverse
  action of too large an ``alpha1 V_y``, as the paper describes). The start
  slope is inherited from the previous stage, the end slope is
  ``alpha1 V_y`` towards the next supporting foot, 0 at a stop.
* **Pelvis, side walking** (Eqs. 15-16): when the ankles' middle moves
  sideways, the pelvis follows with a half cosine in the half of the step
  whose sway goes the same way (second half of the open stance, first half of
  the recovery).
* **Swing ankle** (Eq. 11): cycloid along the supporting foot's heading and
  half cosine across it (Eqs. 14-17), both on the swing interval
  ``[t1 + d/2, t2 - d/2]`` so that a foot in double support stays still.
* **Foot height** (Fig. 12): quintic rise over ``u`` of the swing, fall over the rest.
* **Turning** (Eqs. 21-23): the swinging foot's yaw follows a half cosine on
  the swing interval and the pelvis yaw is the mean of the feet's yaws, so the
  hip yaws are ``+-(theta/4)(1 -+ cos)`` exactly as in Eqs. 21-23.

The pelvis height is constant (the paper's assumption) and the ZMP is the
cart-table ZMP of Eqs. 1-2, ``p - (l/g) p''``, computed in closed form.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from zmpwalk import curves
from zmpwalk.commands import MAX_STRIDE, MAX_TURN, StepCommand
from zmpwalk.errors import (
    InfeasibleCommandError,
    InfeasiblePatternError,
    InvalidParameterError,
    UnreachableError,
    ZmpwalkError,
)
from zmpwalk.footsteps import GROUNDED_STRETCH, LEFT, Pose2D, StagePlan, Stance, grounded_stage, plan_command
from zmpwalk.kinematics import JointLimitError, check_leg_reach
from zmpwalk.patterns.lipm_stage import PIECES, LipmPelvis, axis_at_in_parts, lipm_pelvis_in_parts
from zmpwalk.patterns.result import (
    SUPPORT_DOUBLE,
    SUPPORT_LEFT,
    SUPPORT_RIGHT,
    StepRecord,
    SupportPhase,
    WalkingPattern,
    check_rate,
    sample_times,
)
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.slices import Parts, whole

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
# the pelvis option: the paper's cubics, jerk-continuous quintics, or the pendulum's own hyperbolic motion
PELVIS_CURVES = ("cubic", "quintic", "hyperbolic")


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




@dataclass(frozen=True)
class Boundary:
    """Continuity state handed from one stage to the next.

    Attributes:
        time: Stage boundary time [s].
        pelvis_velocity: Horizontal pelvis velocity in world [m/s], shape (2,).
        sway_velocity: The sway part of it, in world [m/s], shape (2,).
        at_rest: The robot stands still (the pelvis above the middle of the ankles).
        pelvis_position: Horizontal pelvis position in world [m] where it is not the middle of the ankles
            (the hyperbolic pelvis), else None.
    """

    time: float  # [s]
    pelvis_velocity: tuple[float, float] = (0.0, 0.0)  # [m/s]
    sway_velocity: tuple[float, float] = (0.0, 0.0)  # [m/s]
    at_rest: bool = True
    pelvis_position: tuple[float, float] | None = None  # [m] where the pelvis is (hyperbolic pelvis only)


@dataclass(frozen=True)
class Stage:
    """Everything needed to evaluate one stage at any time; see the module docstring.

    Positions in world [m], velocities in world [m/s], slopes per unit of the
    curve's own normalised time [m].
    """

    plan: StagePlan
    start: float  # [s] t1
    duration: float  # [s] T
    dsp_time: float  # [s] d
    base_start: tuple[float, float]  # [m] ankles' middle at t1
    base_sagittal: tuple[float, float]  # [m] part of the middle's motion done by the cubic
    base_lateral: tuple[float, float]  # [m] part done by the side-walking shift (Eqs. 15-16)
    lateral_profile: int  # SHIFT_* code
    base_slope_start: tuple[float, float]  # [m] per unit tau
    base_slope_end: tuple[float, float]  # [m] per unit tau
    sway_direction: tuple[float, float]  # unit vector, left of the supporting foot
    sway_amplitude: float  # [m] signed, along sway_direction
    sway_slope_start: float  # [m] per unit 2*t_bar
    sway_slope_end: float  # [m] per unit 2*t_bar
    sway_out_time: float  # [s] length of the outgoing sway cubic, (1 - d1) T / 2 in Eq. 18
    sway_back_time: float  # [s] length of the returning sway cubic
    standing: bool = False
    grounded: bool = False  # no foot leaves the ground (standing, start)
    end: Boundary = field(default_factory=lambda: Boundary(0.0))
    quintic: bool = False  # jerk-continuous pelvis curves (zero acceleration at every curve's ends)
    lipm: LipmPelvis | None = None  # the hyperbolic pelvis, in place of the curves above

    @property
    def stop_time(self) -> float:
        return self.start + self.duration


def build_stage(plan: StagePlan, boundary: Boundary, quintic: bool = False) -> Stage:
    """Fix a stage's trajectories from its plan and the inherited boundary state (``quintic``: the
    jerk-continuous pelvis curves, same boundary positions and velocities)."""
    # plain floats throughout (a stage is planned in a control loop's tick: numpy's per-call cost on 2-vectors
    # would be most of it)
    p = plan.parameters
    T = plan.duration
    support = plan.support_pose
    nx, ny = -math.sin(support.yaw), math.cos(support.yaw)  # unit vector across the support foot
    toward_support = 1.0 if plan.swing != LEFT else -1.0  # support is left when the right foot swings
    out_time, back_time = sway_times(plan)
    half_time_scale = back_time  # [s] per unit of 2*t_bar of the returning cubic
    v_prev_x, v_prev_y = boundary.pelvis_velocity
    w0 = boundary.sway_velocity[0] * nx + boundary.sway_velocity[1] * ny  # [m/s] sway speed along n
    if plan.stop:
        w1 = 0.0
        v1x = v1y = 0.0
    else:
        w1 = -toward_support * p.alpha1 * p.lateral_velocity / half_time_scale  # [m/s], Eq. 20
        yaw_end = 0.5 * (support.yaw + plan.swing_end.yaw)
        speed = p.alpha * plan.forward / T  # Eq. 13
        v1x, v1y = speed * math.cos(yaw_end), speed * math.sin(yaw_end)
    middle_start = (0.5 * (support.x + plan.swing_start.x), 0.5 * (support.y + plan.swing_start.y))
    middle_end_x, middle_end_y = 0.5 * (support.x + plan.swing_end.x), 0.5 * (support.y + plan.swing_end.y)
    shift_x, shift_y = middle_end_x - middle_start[0], middle_end_y - middle_start[1]
    profile = SHIFT_PROFILES.get(plan.kind, SHIFT_NONE)
    across = shift_x * nx + shift_y * ny if profile != SHIFT_NONE else 0.0
    lateral = (across * nx, across * ny)
    sagittal = (shift_x - lateral[0], shift_y - lateral[1])
    lateral_rate_start, lateral_rate_end = (QUINTIC_SHIFT_END_RATES if quintic else SHIFT_END_RATES)[profile]
    v0_base = (v_prev_x - w0 * nx - lateral[0] * lateral_rate_start / T,
               v_prev_y - w0 * ny - lateral[1] * lateral_rate_start / T)
    v_end = (v1x + lateral[0] * lateral_rate_end / T + w1 * nx,
             v1y + lateral[1] * lateral_rate_end / T + w1 * ny)  # total pelvis velocity at t2
    end = Boundary(
        time=boundary.time + T,
        pelvis_velocity=v_end,
        sway_velocity=(w1 * nx, w1 * ny),
        at_rest=plan.stop,
    )
    return Stage(
        plan=plan,
        start=boundary.time,
        duration=T,
        dsp_time=p.dsp_time,
        base_start=middle_start,
        base_sagittal=sagittal,
        base_lateral=lateral,
        lateral_profile=profile,
        base_slope_start=(v0_base[0] * T, v0_base[1] * T),
        base_slope_end=(v1x * T, v1y * T),
        sway_direction=(nx, ny),
        sway_amplitude=toward_support * p.beta1 * p.sway,
        sway_slope_start=w0 * out_time,
        sway_slope_end=w1 * back_time,
        sway_out_time=out_time,
        sway_back_time=back_time,
        grounded=plan.kind in ("start", "settle"),
        end=end,
        quintic=quintic,
    )


def sway_times(plan: StagePlan) -> tuple[float, float]:
    """Lengths [s] of the outgoing and returning sway cubics of a stage.

    A walking stage follows Eq. 18: each cubic lasts ``(1 - d1) T / 2`` and the
    pelvis stays for ``d1 T`` in between. The sway cubic from rest (start) or
    to rest (settle) has no inherited speed to shape it, and done in
    ``(1 - d1) T / 2`` it throws the cart-table ZMP outside the feet; it lasts
    one step time instead, and the other cubic keeps the regular length so
    that the walking stage next to it meets the speed of Eq. 20.
    """
    d1 = plan.parameters.d1
    if plan.kind in ("start", "settle"):
        step_time = plan.duration / (GROUNDED_STRETCH + (1.0 - d1) / 2.0)
        slow, regular = GROUNDED_STRETCH * step_time, (1.0 - d1) * step_time / 2.0
        return (slow, regular) if plan.kind == "start" else (regular, slow)
    half = (1.0 - d1) * plan.duration / 2.0
    return half, half


def standing_stage(plan: StagePlan, start: float) -> Stage:
    """A stage in which nothing moves: the robot stands in double support from ``start`` on."""
    middle = 0.5 * (np.array([plan.support_pose.x, plan.support_pose.y])
                    + [plan.swing_start.x, plan.swing_start.y])
    zero = (0.0, 0.0)
    return Stage(
        plan=plan, start=start, duration=1.0, dsp_time=0.0, base_start=_pair(middle), base_sagittal=zero,
        base_lateral=zero, lateral_profile=SHIFT_NONE, base_slope_start=zero, base_slope_end=zero,
        sway_direction=(0.0, 1.0), sway_amplitude=0.0, sway_slope_start=0.0, sway_slope_end=0.0,
        sway_out_time=0.5, sway_back_time=0.5,
        standing=True, grounded=True, end=Boundary(math.inf),
    )


def _pair(vector: Array) -> tuple[float, float]:
    return float(vector[0]), float(vector[1])


class StageTable:
    """Stages as one-dimensional column arrays, so that many samples evaluate in one vectorised pass."""

    def __init__(self, stages: list[Stage]) -> None:
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
        (self.start, self.duration, self.dsp, self.support_x, self.support_y, self.support_yaw,
         self.swing_x0, self.swing_y0, self.swing_yaw0, self.swing_dyaw, dx, dy, self.lift, self.up_ratio,
         self.base0_x, self.base0_y, self.sag_x, self.sag_y, self.lat_x, self.lat_y, self.m0_x, self.m0_y,
         self.m1_x, self.m1_y, self.n_x, self.n_y, self.amp, self.w0, self.w1, self.out_time,
         self.back_time) = numbers
        flags = np.array([(p.swing == LEFT, s.standing, s.grounded, s.quintic, s.lipm is not None)
                          for s, p in zip(stages, plans, strict=True)], dtype=bool).reshape(len(stages), 5).T.copy()
        self.swing_left, self.standing, self.grounded, self.quintic, self.hyperbolic = flags
        self.lat_profile = np.array([s.lateral_profile for s in stages])
        hx, hy = np.cos(self.support_yaw), np.sin(self.support_yaw)
        along = dx * hx + dy * hy
        self.along_x, self.along_y = along * hx, along * hy  # [m] cycloid part (Eq. 11)
        self.across_x, self.across_y = dx - self.along_x, dy - self.along_y  # [m] half-cosine part (Eqs. 14-17)
        if self.hyperbolic.any():  # the pieces of each axis of the hyperbolic pelvis, (stages, PIECES)
            unused = np.full(PIECES, np.nan)
            pelvises = [s.lipm for s in stages]
            self.lipm_yaw = np.array([p.yaw if p else 0.0 for p in pelvises])
            self.lipm_axes = [
                [np.array([getattr(getattr(p, axis), name) if p else unused for p in pelvises], dtype=float)
                 for name in ("starts", "position", "velocity", "zmp")]
                for axis in ("along", "across")]

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


def evaluate_in_parts(table: StageTable, time: Array, robot: RobotModel,
                      index: NDArray[np.intp] | None = None) -> Parts[Samples]:
    """Evaluate the stages at ``time`` (each sample in stage ``index``, default: its own stage).
    In parts of about equal cost (swing ankle, pelvis base, sway, feet, the rest; :mod:`zmpwalk.slices`);
    :func:`evaluate` runs it whole.

    Works on one-dimensional component arrays throughout (numpy broadcasting
    over a trailing axis of 2 or 3 is many times slower than plain vector ops).
    """
    t = np.asarray(time, dtype=float)
    k = table.index_at(t) if index is None else index
    n = len(t)
    T = table.duration[k]
    d = table.dsp[k]
    elapsed = t - table.start[k]
    tau = elapsed / T
    yield
    # --- swing ankle: Eq. 11 (cycloid) along, Eqs. 14-17 (half cosine) across, Fig. 12 height
    swing_span = T - d
    raw = (elapsed - 0.5 * d) / swing_span
    in_swing = (raw > 0.0) & (raw < 1.0) & ~table.grounded[k]
    s = np.clip(raw, 0.0, 1.0)
    rate = in_swing / swing_span
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
    yield
    # --- pelvis base: Eqs. 12-13 cubic (Hermite form of Eq. 4) plus the side-walking shift of Eqs. 15-16
    quintic = table.quintic[k] if table.quintic.any() else None  # per sample, None: all cubic
    h10, h01, h11, g10, g01, g11, k10, k01, k11 = _mixed(_cubic_basis, _quintic_basis, quintic, tau)
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
        q, q1, q2 = _mixed(lambda t, p: side_shift_profile(t, p, False), lambda t, p: side_shift_profile(t, p, True),
                           quintic, tau, table.lat_profile[k])
        yield
        for component in components:
            lat_k = component[3][k]
            component[0] = component[0] + lat_k * q
            component[1] = component[1] + lat_k * q1
            component[2] = component[2] + lat_k * q2
            yield
    yield
    # --- pelvis sway: Eqs. 18-20 on the modified time t_bar (sigma = 2 t_bar, or 2 t_bar - 1)
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
    sway, sway1, sway2 = _mixed(curves.hermite_cubic, curves.hermite_quintic, quintic,
                                p_start, m_start, p_end, m_end, sigma)
    scale = np.where(first_half, 1.0 / out_time, np.where(second_half, 1.0 / back_time, 0.0))  # d sigma/dt
    sway = np.where(first_half | second_half, sway, amp)
    sway1 = sway1 * scale
    sway2 = sway2 * scale * scale
    yield
    inv_T = 1.0 / T
    inv_T2 = inv_T * inv_T
    nx, ny = table.n_x[k], table.n_y[k]
    (px, vx, accx, _), (py, vy, accy, _) = components
    pelvis_x = px + sway * nx
    pelvis_y = py + sway * ny
    pelvis_vx = vx * inv_T + sway1 * nx
    pelvis_vy = vy * inv_T + sway1 * ny
    pelvis_ax = accx * inv_T2 + sway2 * nx
    pelvis_ay = accy * inv_T2 + sway2 * ny
    yield
    # --- feet to left/right, pelvis yaw as the mean of the feet (Eq. 23)
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
    left_velocity = np.column_stack([swing_vx * left_swings, swing_vy * left_swings, swing_vz * left_swings])
    right_velocity = np.column_stack([swing_vx * right_swings, swing_vy * right_swings, swing_vz * right_swings])
    yield
    support_yaw = table.support_yaw[k]
    left_yaw = np.where(left_swings, swing_yaw, support_yaw)
    right_yaw = np.where(left_swings, support_yaw, swing_yaw)
    left_rate = swing_yaw_rate * left_swings
    right_rate = swing_yaw_rate * right_swings
    support = np.where(in_swing, np.where(left_swings, SUPPORT_RIGHT, SUPPORT_LEFT), SUPPORT_DOUBLE)
    yield
    if table.hyperbolic.any():
        pelvis_x, pelvis_y, pelvis_vx, pelvis_vy, pelvis_ax, pelvis_ay = yield from _hyperbolic_pelvis(
            table, k, elapsed, robot, (pelvis_x, pelvis_y, pelvis_vx, pelvis_vy, pelvis_ax, pelvis_ay))
        yield
    l_over_g = robot.pendulum_length / robot.gravity
    zmp = np.column_stack([pelvis_x - l_over_g * pelvis_ax, pelvis_y - l_over_g * pelvis_ay])  # Eqs. 1-2
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


def _hyperbolic_pelvis(table: StageTable, k: NDArray[np.intp], elapsed: Array, robot: RobotModel,
                       curves_xy: tuple[Array, ...]) -> Parts[tuple[Array, ...]]:
    """Pelvis x, y, their rates and accelerations: the hyperbolic pelvis where a stage has one, else ``curves_xy``.
    In parts (each axis, then the turn to world)."""
    a = math.sqrt(robot.gravity / robot.pendulum_length)
    axes = []
    for starts, position, velocity, zmp in table.lipm_axes:
        axes.append((yield from axis_at_in_parts(a, starts[k], position[k], velocity[k], zmp[k], elapsed)))
        yield
    (u, du, ddu), (w, dw, ddw) = axes
    c, s = np.cos(table.lipm_yaw[k]), np.sin(table.lipm_yaw[k])  # the supporting foot's frame to world
    hyperbolic = table.hyperbolic[k]
    world = (u * c - w * s, u * s + w * c, du * c - dw * s, du * s + dw * c, ddu * c - ddw * s, ddu * s + ddw * c)
    return tuple(np.where(hyperbolic, value, other) for value, other in zip(world, curves_xy, strict=True))


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


def _mixed(cubic: Callable[..., tuple[Array, ...]], quintic: Callable[..., tuple[Array, ...]],
           mask: NDArray[np.bool_] | None, *args: Array) -> tuple[Array, ...]:
    """``cubic(*args)`` or ``quintic(*args)`` per sample as ``mask`` (None: every sample cubic)."""
    if mask is None:
        return cubic(*args)
    if mask.all():
        return quintic(*args)
    return tuple(np.where(mask, q, c) for c, q in zip(cubic(*args), quintic(*args), strict=True))


def _blend_and_cycloid(s: Array) -> tuple[Array, Array, Array, Array]:
    """Half cosine (Eqs. 14-17, 21-22) and cycloid (Eq. 11) with their slopes, sharing one sin/cos pair."""
    angle = np.pi * s
    sine, cosine = np.sin(angle), np.cos(angle)
    blend = 0.5 * (1.0 - cosine)
    blend_slope = 0.5 * np.pi * sine
    sin2 = 2.0 * sine * cosine  # sin(2 pi s)
    cos2 = 1.0 - 2.0 * sine * sine  # cos(2 pi s)
    return blend, blend_slope, s - sin2 / curves.TWO_PI, 1.0 - cos2


def stage_support_phases(stage: Stage) -> list[tuple[float, float, int, tuple[Pose2D, ...]]]:
    """Support phases of a stage: (begin [s], end [s], support code, feet on the ground with their sides).

    The feet are given as poses; the caller pairs them with sides for the soles.
    """
    plan = stage.plan
    if stage.grounded:
        end = math.inf if stage.standing else stage.stop_time
        return [(stage.start, end, SUPPORT_DOUBLE, (plan.support_pose, plan.swing_start))]
    t1 = stage.start
    half = stage.dsp_time / 2
    single = SUPPORT_RIGHT if plan.swing == LEFT else SUPPORT_LEFT
    return [
        (t1, t1 + half, SUPPORT_DOUBLE, (plan.support_pose, plan.swing_start)),
        (t1 + half, stage.stop_time - half, single, (plan.support_pose,)),
        (stage.stop_time - half, stage.stop_time, SUPPORT_DOUBLE, (plan.support_pose, plan.swing_end)),
    ]


# ---------------------------------------------------------------------------
# Whole walks: commands -> stages -> WalkingPattern
# ---------------------------------------------------------------------------

REACH_CHECK_POINTS = 25  # samples per stage at which the leg reach is checked
CHUNK_STAGES = 1000  # stages evaluated in one vectorised pass on long walks (bounds the memory)


def check_reach(stages: Sequence[Stage], robot: RobotModel) -> None:
    """Raise :class:`~zmpwalk.errors.UnreachableError` if a leg cannot follow the stages.

    The hip-to-ankle distance is checked at :data:`REACH_CHECK_POINTS` times of
    every stage (both ends included), in one vectorised pass. The error has the
    attribute ``stage`` (index into ``stages``).
    """
    fraction = np.linspace(0.0, 1.0, REACH_CHECK_POINTS)
    for first in range(0, len(stages), CHUNK_STAGES):  # bounded memory on long walks
        chunk = list(stages[first:first + CHUNK_STAGES])
        table = StageTable(chunk)
        index = np.repeat(np.arange(len(chunk)), REACH_CHECK_POINTS)
        times = table.start[index] + np.tile(fraction, len(chunk)) * table.duration[index]
        samples = evaluate(table, times, robot, index)
        pelvis = np.column_stack([samples.pelvis_xy, np.full(len(times), robot.pelvis_height)])
        try:
            check_leg_reach(times, pelvis, samples.pelvis_yaw, samples.left_position, samples.right_position, robot)
        except UnreachableError as error:
            error.stage = first + int(index[error.sample])
            raise


def plan_next_in_parts(
    robot: RobotModel, schedule: Schedule, stance: Stance, boundary: Boundary, command: StepCommand,
    reach: bool = True, pelvis: str = "cubic",
) -> Parts[tuple[list[Stage], Stance, Boundary]]:
    """Stages of one command from a stance and boundary state; nothing is changed on error.
    In parts (the footsteps, then each stage; :mod:`zmpwalk.slices`); :func:`plan_next` runs it whole.

    From standstill a walk begins with a *start* stage: one step time in double
    support in which the pelvis sways towards the first swinging foot and comes
    back through the middle at the sway speed ``alpha1 V_y`` of Eq. 20, so that
    the first swing starts like every other one. A stop command at standstill
    does nothing.

    Args:
        reach: Check the legs' reach here (a caller that checks many commands at
            once with :func:`check_reach` passes False).
        pelvis: ``"cubic"`` (the paper's curves), ``"quintic"`` (jerk-continuous) or ``"hyperbolic"``
            (the pendulum's own motion under a piecewise-constant ZMP: :mod:`zmpwalk.patterns.lipm_stage`).

    Raises:
        ZmpwalkError: The command is infeasible for this robot (reach, overlap, timing, and for the
            hyperbolic pelvis a ZMP outside the feet).
    """
    check_pelvis(pelvis)
    if boundary.at_rest and command.stop:
        return [], stance, boundary
    plans, next_stance = plan_command(stance, command, robot, schedule)
    if boundary.at_rest:
        first = plans[0]
        plans = [grounded_stage(stance, first.swing, command.duration, first.parameters, "start"), *plans]
    stages: list[Stage] = []
    start = boundary
    for plan in plans:
        yield
        stage = build_stage(plan, boundary, pelvis == "quintic")
        stages.append(stage)
        boundary = stage.end
    if pelvis == "hyperbolic":
        stages = yield from hyperbolic_stages(stages, start, robot)
        boundary = stages[-1].end
    if reach:
        check_reach(stages, robot)
    if command.stop:
        next_stance = Stance(next_stance.left, next_stance.right, 0)
    return stages, next_stance, boundary


plan_next = whole(plan_next_in_parts, "plan_next")  # the same, run whole


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
        position = _pair(0.5 * (np.array([plan.support_pose.x, plan.support_pose.y])
                                + [plan.swing_start.x, plan.swing_start.y]))
    pelvis, end_position, end_velocity = yield from lipm_pelvis_in_parts(plan, position, boundary.pelvis_velocity,
                                                                         robot, next_plan)
    end = Boundary(time=boundary.time + plan.duration, pelvis_velocity=end_velocity, at_rest=plan.stop,
                   pelvis_position=end_position)
    return replace(stage, lipm=pelvis, end=end)


STRIDE_FIELDS = ("forward", "side", "turn")
STRIDE_BISECTIONS = 10  # halvings of the stride scale when looking for the largest that fits (0.1 %)
# the rejections that name the largest stride that fits: the legs, or (hyperbolic) the ZMP leaving the feet
STRIDE_CAUSES = (UnreachableError, JointLimitError, InfeasiblePatternError)
# [s] the step times at which a command rejected for its step time (or another parameter) is tried, to tell
# whether its stride fits at any: MIN_DURATION to MAX_DURATION of StepCommand, denser where robots walk
STEP_TIME_PROBES = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.95, 1.2, 1.6, 2.2, 3.0, 5.0)


def names_stride(error: ZmpwalkError) -> bool:
    """Whether ``error`` is about a command's stride: the legs or the ZMP (:data:`STRIDE_CAUSES`), or a stride
    field named (feet that would overlap, the largest stride that fits)."""
    return isinstance(error, STRIDE_CAUSES) or (
        isinstance(error, InvalidParameterError) and error.parameter in STRIDE_FIELDS)


def step_time_rejection(command: StepCommand, error: ZmpwalkError,
                        feasible: Callable[[StepCommand], object]) -> ZmpwalkError:
    """The rejection of ``command``, refused with ``error`` for its step time or another parameter than its
    stride: it names first the parameter that cannot be met at any setting of the others, reach before step time.

    When the stride fits at none of :data:`STEP_TIME_PROBES` (with the command's shape factors, and with the
    schedule's), no step time (or shape factor) would make it fit: the rejection names the stride, with the
    largest that fits (:func:`infeasible_command`, ``every_step_time``). Else (or for a command without a stride,
    or an error about the stride already) ``error`` itself. ``feasible`` raises
    :class:`~zmpwalk.errors.ZmpwalkError` for a command that does not fit from the same place.
    """
    if names_stride(error) or not any(getattr(command, name) for name in STRIDE_FIELDS):
        return error
    cause: ZmpwalkError | None = None
    for candidate in _step_time_probes(command):
        try:
            feasible(candidate)
        except ZmpwalkError as failure:
            if cause is None and names_stride(failure):
                cause = failure  # at the step time nearest the command's
            continue
        return error  # the stride fits at this step time: the step time (or the other parameter) is the fix
    if cause is None:  # no step time tried is for the stride: nothing to say of it
        return error
    return infeasible_command(command, cause, feasible, every_step_time=True)


def _step_time_probes(command: StepCommand) -> Iterator[StepCommand]:
    """``command`` at each of :data:`STEP_TIME_PROBES`, nearest its own step time first, with its shape factors
    and (where it overrides any) with the schedule's."""
    plain = StepCommand(command.duration, command.forward, command.side, command.turn)
    for duration in sorted(STEP_TIME_PROBES, key=lambda probe: abs(probe - command.duration)):
        for base in dict.fromkeys((command, plain)):
            try:
                yield replace(base, duration=duration)
            except InvalidParameterError:  # an override that does not fit this step time (dsp_time)
                continue


def infeasible_command(command: StepCommand, cause: ZmpwalkError, feasible: Callable[[StepCommand], object],
                       every_step_time: bool = False) -> InfeasibleCommandError:
    """The error for a command whose legs cannot follow it, with the largest stride that fits.

    The stride (``forward``, ``side``, ``turn`` together, so the direction is kept) is scaled by
    bisection on ``feasible``, which raises :class:`~zmpwalk.errors.ZmpwalkError` for a command
    that does not fit from the same place. ``every_step_time``: the stride fits at no step time (the
    command was refused first for its step time); where not even a step in place fits at the command's own
    step time, the largest stride is searched at the nearest of :data:`STEP_TIME_PROBES` where one does.
    """
    def fits(candidate: StepCommand, scale: float) -> bool:
        try:
            feasible(_scaled(candidate, scale))
        except ZmpwalkError:
            return False
        return True

    moving = [name for name in STRIDE_FIELDS if getattr(command, name) != 0.0]
    if not moving:
        return InfeasibleCommandError("foot_lift", command.foot_lift, {}, cause)
    # the field that is largest against its own limit names the error
    limits = {"forward": MAX_STRIDE, "side": MAX_STRIDE, "turn": MAX_TURN}
    name = max(moving, key=lambda n: abs(getattr(command, n)) / limits[n])
    base = command
    if every_step_time and not fits(command, 0.0):
        base = next((probe for probe in _step_time_probes(command) if fits(probe, 0.0)), command)
    step_time = base.duration if base is not command else None
    if not fits(base, 0.0):
        return InfeasibleCommandError(name, getattr(command, name), {}, cause, None, every_step_time)
    low, high = 0.0, 1.0
    for _ in range(STRIDE_BISECTIONS):
        middle = 0.5 * (low + high)
        if fits(base, middle):
            low = middle
        else:
            high = middle
    if low == 0.0:  # only the step in place fits: the stride's direction is not the cause
        return InfeasibleCommandError(name, getattr(command, name), {}, cause, None, every_step_time)
    largest = _scaled(base, low)
    return InfeasibleCommandError(name, getattr(command, name), {n: getattr(largest, n) for n in moving}, cause,
                                  step_time, every_step_time)


def largest_command(command: StepCommand, error: InfeasibleCommandError) -> StepCommand:
    """``command`` with the largest stride that fits of ``error`` (and its step time, where it names one)."""
    largest = error.largest
    return replace(command, duration=command.duration if error.step_time is None else error.step_time,
                   forward=largest.get("forward", 0.0), side=largest.get("side", 0.0), turn=largest.get("turn", 0.0))


def _scaled(command: StepCommand, scale: float) -> StepCommand:
    return replace(command, **{name: getattr(command, name) * scale for name in STRIDE_FIELDS})


def check_pelvis(pelvis: str) -> str:
    """``pelvis`` if it is one of :data:`PELVIS_CURVES`.

    Raises:
        InvalidParameterError: Any other value (the message lists them).
    """
    if pelvis not in PELVIS_CURVES:
        raise InvalidParameterError("pelvis", pelvis, f"one of {', '.join(PELVIS_CURVES)}")
    return pelvis


def closing_command(last: StepCommand) -> StepCommand:
    """The stop added after ``last``: same step time and shape-factor overrides, no motion."""
    return replace(last, forward=0.0, side=0.0, turn=0.0, stop=True)


def plan_walk(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
    pelvis: str = "cubic",
) -> tuple[list[Stage], Stance]:
    """Stages of a whole walk from the ready posture, closed by a stop and a standing stage.

    A walk whose last command is not a stop gets a closing stop step of the
    last step time and shape factors (:func:`closing_command`), so every
    pattern ends standing in the ready posture.

    Args:
        robot: The robot.
        commands: The step commands.
        schedule: Parameter tables.
        labels: How an error names each command (default ``step N``, 1-based).
        pelvis: ``"cubic"`` (the paper's curves) or ``"quintic"`` (jerk-continuous, zero acceleration at
            every curve's ends: the cart-table ZMP is continuous; the parameters keep their meaning).

    Raises:
        ZmpwalkError: With the command's label in front, for the first command that fails.
    """
    check_pelvis(pelvis)
    schedule = schedule or Schedule.hubo()
    stance = Stance.ready(robot)
    boundary = Boundary(0.0)
    stages: list[Stage] = []
    sequence = list(commands)
    if sequence and not sequence[-1].stop:
        sequence.append(closing_command(sequence[-1]))
    walk = _Walk(robot, schedule, pelvis, sequence, labels, len(commands))
    for number, command in enumerate(sequence, start=1):
        walk.starts.append((stance, boundary))
        try:
            new, stance, boundary = plan_next(robot, schedule, stance, boundary, command, reach=False,
                                              pelvis=pelvis)
        except ZmpwalkError as error:
            walk.check_reach(stages)  # a step before it beyond the legs' reach is named first
            if not isinstance(error, STRIDE_CAUSES):  # the stride before the step time (the ZMP: the step)
                error = step_time_rejection(command, error, walk.feasible(number))
            raise error.in_context(walk.label(number)) from None
        stages.extend(new)
        walk.numbers.extend([number] * len(new))
    walk.check_reach(stages)
    stages.append(standing_stage(_standing_plan(stance, robot, schedule), boundary.time))
    return stages, stance


@dataclass
class _Walk:
    """What :func:`plan_walk` knows of a walk to name a rejection: the commands, their labels, where each starts."""

    robot: RobotModel
    schedule: Schedule
    pelvis: str
    sequence: list[StepCommand]  # the commands and the closing stop
    labels: Sequence[str] | None
    given: int  # commands given (the closing stop follows them)
    starts: list[tuple[Stance, Boundary]] = field(default_factory=list)  # where each command starts from
    numbers: list[int] = field(default_factory=list)  # each stage's command, 1-based

    def check_reach(self, stages: list[Stage]) -> None:
        """Raise for the first stage of ``stages`` beyond the legs' reach, naming its command's stride."""
        try:
            check_reach(stages, self.robot)
        except UnreachableError as error:
            number = self.numbers[error.stage]
            if number > 1 and self.sequence[number - 1].stop:
                number -= 1  # a stop fails for the stride before it
            raise infeasible_command(self.sequence[number - 1], error, self.feasible(number)).in_context(
                self.label(number)) from None

    def feasible(self, number: int) -> Callable[[StepCommand], None]:
        """Raises for a command that does not fit in place of command ``number`` (1-based), or its stop."""
        stance, boundary = self.starts[number - 1]

        def feasible(candidate: StepCommand) -> None:  # the command, and the stop after it
            _, after, after_boundary = plan_next(self.robot, self.schedule, stance, boundary, candidate,
                                                 pelvis=self.pelvis)
            if not candidate.stop:
                plan_next(self.robot, self.schedule, after, after_boundary, closing_command(candidate),
                          pelvis=self.pelvis)

        return feasible

    def label(self, number: int) -> str:
        """How error messages name command ``number`` (1-based): its label (default ``step N``, N counted from 1),
        or for the closing stop added after the last, ``the closing stop after`` the last one's."""
        if number > self.given:
            return f"the closing stop after {self.label(self.given)}"
        if self.labels is None or number > len(self.labels):
            return f"step {number}"
        return self.labels[number - 1]


def _standing_plan(stance: Stance, robot: RobotModel, schedule: Schedule) -> StagePlan:
    parameters, _ = schedule.stage_parameters(StepCommand(duration=1.0), robot)
    return StagePlan(LEFT, stance.right, stance.left, stance.left, 0.0, 1.0, parameters, True, "stand")


def generate(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    rate: float = 100.0,
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
    pelvis: str = "cubic",
) -> WalkingPattern:
    """The HUBO walking pattern of a command sequence, sampled at ``rate`` [Hz].

    Args:
        robot: The robot.
        commands: Step commands in order; a closing stop is added if missing.
        rate: Samples per second (HUBO's reference rate is 100 Hz).
        schedule: Parameter tables; Tables 2-3 of the paper by default.
        labels: How an error names each command (default ``step N``).
        pelvis: ``"cubic"`` or ``"quintic"`` (:func:`plan_walk`).

    Returns:
        The pattern from the ready posture at t = 0 to standing after the last step.
    """
    check_rate(rate)
    stages, _ = plan_walk(robot, commands, schedule, labels, pelvis)
    return _sampled(stages, robot, rate, sample_times(stages[-1].start, rate), generator_name(pelvis))


def generate_chunks(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    rate: float = 100.0,
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
    chunk_stages: int = CHUNK_STAGES,
    pelvis: str = "cubic",
) -> Iterator[WalkingPattern]:
    """The pattern of :func:`generate` in consecutive pieces, for walks too long to hold at once.

    The whole walk is planned and its reach checked first (so an infeasible command raises
    before any piece is returned); then each piece of ``chunk_stages`` stages is sampled,
    in memory that does not grow with the walk. The pieces' samples, joined, are those of
    :func:`generate`; each piece carries the steps and support phases of its own stages.

    Raises:
        InvalidParameterError: ``chunk_stages`` < 1.
    """
    check_rate(rate)
    if isinstance(chunk_stages, bool) or not isinstance(chunk_stages, int) or chunk_stages < 1:
        raise InvalidParameterError("chunk_stages", chunk_stages, "an integer >= 1")
    stages, _ = plan_walk(robot, commands, schedule, labels, pelvis)
    return _chunks(stages, robot, rate, chunk_stages, generator_name(pelvis))


def generator_name(pelvis: str) -> str:
    """The name a pattern of these pelvis curves carries: ``"hyperbolic"`` for the pendulum's, else ``"polynomial"``."""
    return "hyperbolic" if pelvis == "hyperbolic" else "polynomial"


def _chunks(stages: list[Stage], robot: RobotModel, rate: float, chunk_stages: int, generator: str
            ) -> Iterator[WalkingPattern]:
    end = stages[-1].start  # the first sample of standing still closes the walk
    for first in range(0, len(stages), chunk_stages):
        chunk = stages[first:first + chunk_stages]
        last = first + len(chunk) >= len(stages)
        begin_index = first_sample_at(chunk[0].start, rate)
        stop_time = stages[min(first + len(chunk), len(stages) - 1)].start
        # the last piece ends where sample_times ends the whole walk
        stop_index = math.ceil(end * rate - 1e-9) + 1 if last else first_sample_at(stop_time, rate)
        if stop_index > begin_index:
            yield _sampled(chunk, robot, rate, np.arange(begin_index, stop_index) / rate, generator)


def first_sample_at(time: float, rate: float) -> int:
    """Index of the first sample ``k / rate`` at or after ``time`` [s], compared exactly as the sampled times are
    (the sample that :meth:`StageTable.index_at` puts in the stage starting at ``time``)."""
    index = math.ceil(time * rate - 1e-9)
    while index / rate < time:
        index += 1
    while index > 0 and (index - 1) / rate >= time:
        index -= 1
    return index


def _sampled(stages: list[Stage], robot: RobotModel, rate: float, times: Array,
             generator: str = "polynomial") -> WalkingPattern:
    return pattern_from_samples(evaluate(StageTable(stages), times, robot), stages, robot, rate, generator)


def pattern_from_samples(
    samples: Samples, stages: list[Stage], robot: RobotModel, rate: float, generator: str
) -> WalkingPattern:
    """Wrap evaluated samples and their stages into a :class:`WalkingPattern`."""
    n = len(samples.time)
    height = np.full(n, robot.pelvis_height)
    phases: list[SupportPhase] = []
    steps: list[StepRecord] = []
    for stage in stages:
        for begin, end, code, poses in stage_support_phases(stage):
            if end <= begin:
                continue
            feet = [(stage.plan.support_pose, -stage.plan.swing)]
            if len(poses) == 2:
                feet.append((poses[1], stage.plan.swing))
            phases.append(SupportPhase(begin, end, code, tuple(feet)))
        if not stage.standing:
            plan = stage.plan
            parameters: dict[str, float | str] = dict(vars(plan.parameters))
            steps.append(StepRecord(
                start=stage.start, duration=stage.duration, swing="left" if plan.swing == LEFT else "right",
                kind=plan.kind, landing=(plan.swing_end.x, plan.swing_end.y, plan.swing_end.yaw),
                parameters=parameters,
            ))
    return WalkingPattern(
        robot=robot, rate=rate, generator=generator, time=samples.time, support=samples.support,
        position_pelvis_in_world=np.column_stack([samples.pelvis_xy, height]),
        velocity_pelvis_in_world=np.column_stack([samples.pelvis_velocity_xy, np.zeros(n)]),
        yaw_pelvis_in_world=samples.pelvis_yaw, yaw_rate_pelvis=samples.pelvis_yaw_rate,
        position_left_ankle_in_world=samples.left_position, velocity_left_ankle_in_world=samples.left_velocity,
        yaw_left_foot_in_world=samples.left_yaw, yaw_rate_left_foot=samples.left_yaw_rate,
        position_right_ankle_in_world=samples.right_position,
        velocity_right_ankle_in_world=samples.right_velocity,
        yaw_right_foot_in_world=samples.right_yaw, yaw_rate_right_foot=samples.right_yaw_rate,
        zmp_in_world=samples.zmp_xy, steps=steps, support_phases=phases,
    )
