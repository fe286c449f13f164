"""ZMP check of the tuned conditions (walk each row of the parameter tables and measure the margin), and what to
change where a plan's ZMP leaves the support polygon."""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.footsteps import Stance
from zmpwalk.patterns.polynomial import (
    Boundary,
    Stage,
    StageTable,
    closing_command,
    evaluate,
    generate,
    plan_next,
    stage_support_phases,
)
from zmpwalk.patterns.result import SupportPhase
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import SWAY_RULE, Schedule
from zmpwalk.sides import SUPPORT_LABELS, Support


@dataclass(frozen=True)
class ConditionMargin:
    """Smallest ZMP margin of one tabulated condition walked for ``steps`` steps.

    Attributes:
        mode: ``"forward"`` or ``"side"``.
        duration: Step time [s].
        stride: Forward stride or side step [m].
        steps: Commands walked.
        min_margin: Smallest signed distance of the cart-table ZMP to the support polygon [m].
        time: When it occurs [s].
        support: Support phase then (``"double"``, ``"left"``, ``"right"``).
    """

    mode: str
    duration: float  # [s]
    stride: float  # [m]
    steps: int
    min_margin: float  # [m]
    time: float  # [s]
    support: str


def condition_margins(
    robot: RobotModel, schedule: Schedule | None = None, steps: int = 10, rate: float = 1000.0,
    pelvis: str = "cubic",
) -> list[ConditionMargin]:
    """Walk ``steps`` commands of every tabulated condition and report the smallest ZMP margin of each
    (``pelvis``: the cubic or quintic pelvis curves of :func:`zmpwalk.patterns.polynomial.plan_walk`)."""
    schedule = schedule or Schedule.hubo()
    results = []
    for mode, duration, stride in schedule.conditions():
        if mode == "forward":
            command = StepCommand(duration=duration, forward=stride)
        else:
            command = StepCommand(duration=duration, side=stride)
        pattern = generate(robot, [command] * steps, rate=rate, schedule=schedule, pelvis=pelvis)
        margin = pattern.zmp_margin()
        index = int(np.nanargmin(margin))
        results.append(ConditionMargin(mode, duration, stride, steps, float(margin[index]),
                                       float(pattern.time[index]), SUPPORT_LABELS[int(pattern.support[index])]))
    return results


def margins_markdown(results: list[ConditionMargin]) -> str:
    """The margins as a Markdown table (mm and s)."""
    lines = ["| mode | step time [s] | stride [m] | min ZMP margin [mm] | at t [s] | support |",
             "|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r.mode} | {r.duration:.2f} | {r.stride:.2f} | {r.min_margin * 1e3:+.1f} | "
                     f"{r.time:.3f} | {r.support} |")
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# What to change where a plan's ZMP leaves the support polygon (zmpwalk plan's exit status 3)
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Change:
    """One parameter of one command that, changed alone to ``limit``, brings the ZMP back onto the polygon's edge
    (the other values as they are; to first order where the term is not linear in it).

    Attributes:
        label: The command, as errors name it (``[[steps]] 2``, ``step 3``, ``the closing stop after step 4``).
        parameter: The steps file's field (``lateral_velocity``, ``sway``, ``duration``, ``forward``).
        value: What the step takes now [SI].
        limit: The bound [SI]: at most for a lowering, at least for a raising.
        lower: True where the value must go down to ``limit``.
    """

    label: str
    parameter: str
    value: float
    limit: float
    lower: bool

    def words(self) -> str:
        name = {"lateral_velocity": "lateral_velocity (V_y)", "sway": "sway (S_y)", "duration": "step time (duration)",
                "forward": "stride (forward)"}[self.parameter]
        unit = "s" if self.parameter == "duration" else "m"
        return (f"{'lower' if self.lower else 'raise'} {name} of {self.label} from {self.value:.4g} to "
                f"{'at most' if self.lower else 'at least'} {self.limit:.4g} {unit}")


@dataclass(frozen=True)
class ZmpAdvice:
    """Where the cart-table ZMP of a plan leaves the support polygon, the term of the pattern that takes it out,
    and what to change.

    Attributes:
        time: When [s].
        margin: The signed margin there [m] (< 0: outside).
        cause: ``"crossing"`` (the sway crossing the middle of the stance in double support, Eq. 20's
            ``(l/g)(4 alpha1 V_y - 6 beta1 S_y)/tau^2``), ``"sway"`` (elsewhere on a sway cubic), ``"stay"`` (the
            pelvis staying at ``beta1 S_y``) or ``"sagittal"`` (beyond a sole's toe or heel).
        label: The command whose stage it is.
        changes: Each change that alone brings the ZMP back to the edge.
        text: One line saying all of it.
    """

    time: float  # [s]
    margin: float  # [m]
    cause: str
    label: str
    changes: tuple[Change, ...]
    text: str


CAUSE_WORDS = {
    "crossing": "where the sway crosses the middle of the stance in double support (the ZMP at "
                "(l/g)(4 alpha1 V_y - 6 beta1 S_y)/tau^2 = {offset:.1f} mm from the middle, Eqs. 1-2 and 20)",
    "sway": "on a sway cubic of Eq. 20 (the ZMP y - (l/g) y'' of Eqs. 1-2 {offset:+.1f} mm from the middle of the "
            "stance, positive towards the supporting foot)",
    "stay": "where the pelvis stays at beta1 S_y = {offset:.1f} mm from the middle of the stance",
    "sagittal": "beyond a sole's toe or heel ({offset:.1f} mm from the ankle along the foot)",
}


def zmp_advice(robot: RobotModel, commands: Sequence[StepCommand], time: float, margin: float,
               schedule: Schedule | None = None, labels: Sequence[str] | None = None) -> ZmpAdvice:
    """What takes the cubic pattern's cart-table ZMP (Eqs. 1-2) out of the support polygon at ``time`` [s], where
    its margin is ``margin`` [m] < 0, and which parameter of which command to change, by how much.

    The walk is planned again (as :func:`~zmpwalk.patterns.polynomial.plan_walk` plans it) to find the stage at
    ``time`` and its command; the direction in which the ZMP leaves the polygon, against the supporting foot's
    heading, and the part of the stage tell the term: the sway's crossing, its turn-around or its stay
    (sideways), or the sagittal motion. Each term is linear in ``V_y`` and ``S_y``, and its acceleration part goes
    as ``1 / T^2``, so each limit is the value that moves the ZMP there by ``-margin``: the other values as they
    are, and at that point of the walk (another point may then bind).
    """
    schedule = schedule or Schedule.hubo()
    walk = _owned_stages(robot, commands, schedule, labels)
    stages = walk.stages
    k = min(max(bisect.bisect_right([s.start for s in stages], time) - 1, 0), len(stages) - 1)
    zmp = evaluate(StageTable(stages), np.array([time]), robot).zmp_xy[0]
    normal, support = _outward_normal(stages[k], time, zmp, robot)
    yaw = stages[k].plan.support_pose.yaw
    heading, across = np.array([math.cos(yaw), math.sin(yaw)]), np.array([-math.sin(yaw), math.cos(yaw)])
    if abs(float(normal @ heading)) > abs(float(normal @ across)):
        cause, offset, changes = _sagittal(stages[k], time, zmp, margin, walk.label(k), support)
    else:
        cause, offset, changes = _sway(walk, k, time, margin, robot, (normal, support), schedule)
    changes = [c for c in changes if c.parameter == "forward" or c.limit > 0.0]  # S_y, V_y, T cannot go below 0
    where = CAUSE_WORDS[cause].format(offset=offset * 1e3) + _rule_words(stages[k])
    text = (f"the ZMP leaves the support polygon by {-margin * 1e3:.1f} mm at t = {time:.3f} s in {walk.label(k)}"
            + (f", {where}" if where else "") + ": " + ("; or ".join(c.words() for c in changes) if changes else
                                                         "no single parameter of that term brings it back"))
    return ZmpAdvice(time, margin, cause, walk.label(k), tuple(changes), text)


def _rule_words(stage: Stage) -> str:
    """A note where the stage's sway breaks the paper's rule ``1.5 beta1 S_y < alpha1 V_y < 3 beta1 S_y``."""
    p = stage.plan.parameters
    low, high = (factor * p.beta1 * p.sway for factor in SWAY_RULE)
    if p.lateral_velocity <= 0.0 or stage.plan.stop or low < p.alpha1 * p.lateral_velocity < high:
        return ""
    return (f"; alpha1 V_y = {p.alpha1 * p.lateral_velocity:.4g} m is outside the rule 1.5-3 beta1 S_y = "
            f"{low:.4g}-{high:.4g} m (docs/hubo-pattern.md)")


@dataclass(frozen=True)
class _OwnedStages:
    """A walk's stages, each with the command it comes from (the given ones, then the closing stop)."""

    stages: list[Stage]
    owners: list[int]  # each stage's command, an index into commands
    commands: list[StepCommand]
    names: list[str]  # each command as errors name it

    def label(self, k: int) -> str:
        return self.names[self.owners[k]]

    def duration(self, k: int) -> float:
        """Step time [s] of stage ``k``'s command (a start or settle stage lasts longer than its step)."""
        return self.commands[self.owners[k]].duration


def _owned_stages(robot: RobotModel, commands: Sequence[StepCommand], schedule: Schedule,
                  labels: Sequence[str] | None) -> _OwnedStages:
    """The walk's stages as :func:`plan_walk` plans them (cubic pelvis), with their commands."""
    sequence = list(commands)
    names = [labels[i] if labels is not None and i < len(labels) else f"step {i + 1}" for i in range(len(sequence))]
    if sequence and not sequence[-1].stop:
        sequence.append(closing_command(sequence[-1]))
        names.append(f"the closing stop after {names[-1]}")
    stance, boundary = Stance.ready(robot), Boundary(0.0)
    stages: list[Stage] = []
    owners: list[int] = []
    for index, command in enumerate(sequence):
        new, stance, boundary = plan_next(robot, schedule, stance, boundary, command, reach=False)
        stages.extend(new)
        owners.extend([index] * len(new))
    return _OwnedStages(stages, owners, sequence, names)


def _outward_normal(stage: Stage, time: float, zmp: NDArray[np.float64], robot: RobotModel
                    ) -> tuple[NDArray[np.float64], int]:
    """Unit vector from the support polygon's nearest boundary point to the ZMP outside it, and the support code."""
    phases = stage_support_phases(stage)
    begin, end, code, poses = next((p for p in phases if p[0] <= time < p[1]), phases[-1])
    feet = [(stage.plan.support_pose, -stage.plan.swing)]
    if len(poses) == 2:
        feet.append((poses[1], stage.plan.swing))
    polygon = SupportPhase(begin, end, code, tuple(feet)).polygon(robot)
    best, nearest = math.inf, polygon[0]
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0), strict=True):
        edge = b - a
        share = float(np.clip((zmp - a) @ edge / max(float(edge @ edge), 1e-18), 0.0, 1.0))
        point = a + share * edge
        if float(np.linalg.norm(zmp - point)) < best:
            best, nearest = float(np.linalg.norm(zmp - point)), point
    direction = zmp - nearest
    return direction / max(float(np.linalg.norm(direction)), 1e-12), code


def _change(label: str, parameter: str, value: float, delta: float) -> Change:
    return Change(label, parameter, value, value + delta, delta < 0.0)


def _cubic(s: float, outgoing: bool) -> tuple[tuple[float, float], tuple[float, float]]:
    """Hermite basis of a sway cubic at ``s`` in [0, 1]: (value, second derivative) of the amplitude's and of the
    slope's basis function. Outgoing: from the middle at the slope to the amplitude at rest (``h10``, ``h01``);
    returning: from the amplitude at rest to the middle at the slope (``h00``, ``h11``)."""
    if outgoing:
        return (-2 * s**3 + 3 * s**2, -12 * s + 6), (s**3 - 2 * s**2 + s, 6 * s - 4)
    return (2 * s**3 - 3 * s**2 + 1, 12 * s - 6), (s**3 - s**2, 6 * s - 2)


def _sway(walk: _OwnedStages, k: int, time: float, margin: float, robot: RobotModel,
          where: tuple[NDArray[np.float64], int], schedule: Schedule) -> tuple[str, float, list[Change]]:
    """Sideways: the sway of Eq. 20 at ``time``. Across the supporting foot (``u``, positive towards it) the pelvis
    follows a cubic Hermite curve in units of its own time tau (outgoing: 0 at slope ``m`` to ``A = beta1 S_y`` at
    rest; then the stay at ``A``; returning: back to 0 at slope ``m``, ``m`` being ``alpha1 V_y`` per unit of the
    returning cubic's time), so the ZMP ``u - (l/g) u''/tau^2`` (Eqs. 1-2) is linear in ``A`` and ``m``: each
    limit moves it by ``-margin`` across the edge it passed. At the crossing (``s`` = 0 or 1 in double support) it
    is ``(l/g)(4 m - 6 A)/tau^2``, :func:`zmpwalk.schedule.sway_crossing_zmp`."""
    stage = walk.stages[k]
    normal, support = where  # the ZMP's way out of the polygon, and the support phase
    l_g = robot.pendulum_length / robot.gravity  # [s^2]
    toward = -stage.plan.swing  # +1: the supporting foot is the left one, the sway goes towards it
    yaw = stage.plan.support_pose.yaw
    push = margin / float(normal @ (toward * np.array([-math.sin(yaw), math.cos(yaw)])))  # [m] along u
    amplitude = stage.sway_amplitude * toward  # [m] A
    elapsed = time - stage.start
    sway = stage.plan.parameters.sway
    if stage.sway_out_time <= elapsed < stage.duration - stage.sway_back_time:  # the stay: the ZMP is the pelvis
        return "stay", amplitude, [_change(walk.label(k), "sway", sway, push * sway / amplitude)]
    outgoing = elapsed < stage.sway_out_time
    tau = stage.sway_out_time if outgoing else stage.sway_back_time
    s = elapsed / tau if outgoing else (elapsed - stage.duration + tau) / tau
    (a, a2), (b, b2) = _cubic(min(max(s, 0.0), 1.0), outgoing)
    slope = (stage.sway_slope_start if outgoing else stage.sway_slope_end) * toward  # [m] per unit of tau
    zmp = amplitude * (a - l_g * a2 / tau**2) + slope * (b - l_g * b2 / tau**2)  # [m] along u
    source = k - 1 if outgoing and k > 0 else k  # an outgoing cubic's slope is the stage before's speed
    velocity = walk.stages[source].plan.parameters.lateral_velocity
    changes = []
    per_velocity = slope / velocity * (b - l_g * b2 / tau**2) if velocity > 0.0 else 0.0  # [-] dz/dV_y
    if abs(per_velocity) > 1e-9:
        changes.append(_change(walk.label(source), "lateral_velocity", velocity, push / per_velocity))
    per_sway = amplitude / sway * (a - l_g * a2 / tau**2)  # [-] dz/dS_y
    if abs(per_sway) > 1e-9:
        changes.append(_change(walk.label(k), "sway", sway, push / per_sway))
    changes.extend(_step_time(walk, k, schedule, robot, (zmp, push), (a, a2, b, b2, tau, slope)))
    crossing = support == Support.DOUBLE and (s < 0.5) == outgoing  # the pelvis near the middle, both feet down
    return "crossing" if crossing else "sway", zmp, changes


STEP_TIME_SEARCH = (1.005, 200)  # [-] step-time factor and number of its powers tried: up to 2.7 times


def _step_time(walk: _OwnedStages, k: int, schedule: Schedule, robot: RobotModel, target: tuple[float, float],
               cubic: tuple[float, ...]) -> list[Change]:
    """The shortest longer step time of stage ``k``'s command whose schedule values (:meth:`Schedule.stage_parameters`,
    overrides kept) move the sway's ZMP at the same point of its cubic by ``push`` (``target = (zmp, push)`` [m]),
    the steps around it taking the same step time (the slope an outgoing cubic inherits scales with
    ``alpha1 V_y``); ``cubic = (a, a2, b, b2, tau, slope)`` as in :func:`_sway`. None within 2.7 times."""
    zmp, push = target
    a, a2, b, b2, tau, slope = cubic
    command = walk.commands[walk.owners[k]]
    now = walk.stages[k].plan.parameters
    l_g = robot.pendulum_length / robot.gravity  # [s^2]
    factor, count = STEP_TIME_SEARCH
    for n in range(1, count + 1):
        duration = command.duration * factor**n
        first, second = schedule.stage_parameters(replace(command, duration=duration), robot)
        p = second if walk.stages[k].plan.kind == "recovery" else first
        tau_new = tau * (1.0 - p.d1) / (1.0 - now.d1) * duration / command.duration  # [s]
        inherited = now.alpha1 * now.lateral_velocity  # [m]: 0 (no V_y) leaves no slope to scale
        slope_new = slope * p.alpha1 * p.lateral_velocity / inherited if inherited else slope  # [m] per unit tau
        moved = p.beta1 * p.sway * (a - l_g * a2 / tau_new**2) + slope_new * (b - l_g * b2 / tau_new**2) - zmp
        if moved / push >= 1.0:
            return [_change(walk.label(k), "duration", command.duration, duration - command.duration)]
    return []


def _sagittal(stage: Stage, time: float, zmp: NDArray[np.float64], margin: float, label: str, support: int
              ) -> tuple[str, float, list[Change]]:
    """Beyond a toe or heel: the pelvis cubics of Eqs. 12-13 and the feet are linear in the strides, and so is
    the ZMP's distance along the foot from the supporting ankle (from the middle of both in double support):
    scaling the stride by ``(d + margin) / d`` brings it back (to first order: the soles do not scale)."""
    plan = stage.plan
    reference = np.array([plan.support_pose.x, plan.support_pose.y])
    if support == Support.DOUBLE:
        other = plan.swing_start if time < stage.start + stage.dsp_time / 2 else plan.swing_end
        reference = (reference + np.array([other.x, other.y])) / 2.0
    yaw = plan.support_pose.yaw
    distance = abs(float((zmp - reference) @ np.array([math.cos(yaw), math.sin(yaw)])))  # [m]
    if plan.forward == 0.0 or distance <= -margin:
        return "sagittal", distance, []
    return "sagittal", distance, [_change(label, "forward", plan.forward, plan.forward * margin / distance)]
