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
from zmpwalk.patterns.evaluation import (
    QUINTIC_SHIFT_END_RATES,
    SHIFT_END_RATES,
    SHIFT_NONE,
    SHIFT_PROFILES,
)
from zmpwalk.patterns.evaluation import Samples as Samples  # re-exported: other modules import these here
from zmpwalk.patterns.evaluation import StageTable as StageTable
from zmpwalk.patterns.evaluation import evaluate as evaluate
from zmpwalk.patterns.evaluation import side_shift_profile as side_shift_profile  # docs/equations.md
from zmpwalk.patterns.lipm_stage import LipmPelvis, lipm_pelvis_in_parts
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
from zmpwalk.slices import ALONE, Parts, whole

Array = NDArray[np.float64]

# the pelvis option: the paper's cubics, jerk-continuous quintics, or the pendulum's own hyperbolic motion
PELVIS_CURVES = ("cubic", "quintic", "hyperbolic")


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
    yield ALONE
    schedule.stage_parameters(command, robot)  # the tables' lookups, kept by the schedule: parts of their own
    if command.is_two_stage and stance.next_swing not in (0, command.leading_side):  # a plain step inserted
        yield ALONE
        schedule.stage_parameters(replace(command, side=0.0, turn=0.0), robot)
    yield ALONE
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
    yield ALONE  # the pendulum's targets (a steady step solved): a long part
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
