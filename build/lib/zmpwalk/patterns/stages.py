"""The stages of a walk: the online walking pattern of KHR-3 (HUBO), Park, Kim and Oh (2008), Section 3.

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
cart-table ZMP of Eqs. 1-2, ``p - (l/g) p''``, computed in closed form
(:mod:`zmpwalk.patterns.evaluation`).

:class:`CurvePelvis` is the pelvis model (:class:`~zmpwalk.patterns.pelvis_model.PelvisModel`) of these
curves, cubic as in the paper or quintic (jerk-continuous); the hyperbolic pelvis of the linear inverted
pendulum is :mod:`zmpwalk.patterns.lipm_pelvis`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from zmpwalk.footsteps import GROUNDED_STRETCH, Pose2D, StagePlan
from zmpwalk.patterns.evaluation import (
    QUINTIC_SHIFT_END_RATES,
    SHIFT_END_RATES,
    SHIFT_NONE,
    SHIFT_PROFILES,
)
from zmpwalk.patterns.lipm_stage import LipmPelvis
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Side, Support
from zmpwalk.slices import Parts

Array = NDArray[np.float64]


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
    toward_support = 1.0 if plan.swing != Side.LEFT else -1.0  # support is left when the right foot swings
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
        plan=plan, start=start, duration=1.0, dsp_time=0.0, base_start=as_pair(middle), base_sagittal=zero,
        base_lateral=zero, lateral_profile=SHIFT_NONE, base_slope_start=zero, base_slope_end=zero,
        sway_direction=(0.0, 1.0), sway_amplitude=0.0, sway_slope_start=0.0, sway_slope_end=0.0,
        sway_out_time=0.5, sway_back_time=0.5,
        standing=True, grounded=True, end=Boundary(math.inf),
    )


def as_pair(vector: Array) -> tuple[float, float]:
    """A horizontal vector [m] or [m/s], shape (2,), as a pair of plain floats."""
    return float(vector[0]), float(vector[1])


def stage_support_phases(stage: Stage) -> list[tuple[float, float, int, tuple[Pose2D, ...]]]:
    """Support phases of a stage: (begin [s], end [s], support code, feet on the ground with their sides).

    The feet are given as poses; the caller pairs them with sides for the soles.
    """
    plan = stage.plan
    if stage.grounded:
        end = math.inf if stage.standing else stage.stop_time
        return [(stage.start, end, Support.DOUBLE, (plan.support_pose, plan.swing_start))]
    t1 = stage.start
    half = stage.dsp_time / 2
    single = Support.RIGHT if plan.swing == Side.LEFT else Support.LEFT
    return [
        (t1, t1 + half, Support.DOUBLE, (plan.support_pose, plan.swing_start)),
        (t1 + half, stage.stop_time - half, single, (plan.support_pose,)),
        (stage.stop_time - half, stage.stop_time, Support.DOUBLE, (plan.support_pose, plan.swing_end)),
    ]


@dataclass(frozen=True)
class CurvePelvis:
    """The pelvis of the paper's curves (module docstring): cubics (Eqs. 12-13, 18-20), or quintics with the
    same boundary positions and velocities and zero acceleration at every curve's ends (``quintic``: the
    cart-table ZMP is continuous; the parameters keep their meaning).

    Attributes:
        name: The pelvis option, ``"cubic"`` or ``"quintic"``.
    """

    name: str

    @property
    def generator(self) -> str:
        """The name a pattern of this pelvis carries."""
        return "polynomial"

    def stages_in_parts(self, plans: Sequence[StagePlan], boundary: Boundary, robot: RobotModel
                        ) -> Parts[list[Stage]]:
        """The stages of ``plans`` from ``boundary`` (:func:`build_stage`, each inheriting the last's end), a part
        each."""
        stages: list[Stage] = []
        for plan in plans:
            yield
            stage = build_stage(plan, boundary, self.name == "quintic")
            stages.append(stage)
            boundary = stage.end
        return stages


CUBIC = CurvePelvis("cubic")
QUINTIC = CurvePelvis("quintic")
