"""Hyperbolic walking of the linear inverted pendulum: Lim, Kim, Son, Kang, Section 3.

With the body at constant height ``z_b`` the ZMP equation reduces to (Eq. 4)

.. math:: \\ddot x_b - a^2 x_b = -a^2 x_{ZMP}, \\qquad a = \\sqrt{g / z_b}

and a piecewise-constant ZMP gives hyperbolic body motion in closed form (Eq. 5).
A steady step (Fig. 3) is a double support of ``t4`` at constant speed
``v_xD`` followed by a single support of ``t5 = t1 + t2 + t3``: ZMP at
``x_ZMP1`` (``t1``, decelerating), ZMP under the body (``t2``, constant speed
``v_xS``), ZMP at ``x_ZMP2`` (``t3``, accelerating); laterally one ZMP
``y_ZMP`` for the whole single support. Eq. 11 gives the times and speeds;
Eqs. 12-15 the start from standstill.

zmpwalk goes past the paper in three ways, each reducing to it when nothing changes:

* **Any sequence of strides and step times.** Each step is solved on its own
  (:func:`solve_step`): its step time ``T`` and double-support time ``d`` fix
  ``t4 = d`` and ``t5 = T - d``, the single-support ZMPs keep the paper's ratio
  ``x_ZMP2 - x0 = 2 (x_ZMP1 - x0)``, and ``x_ZMP1`` and ``v_xD`` are solved so
  that the step takes ``T`` (the paper's example is the solution with
  ``x_ZMP1 = x_s/8``). Between two different steps the double support is a cubic
  joining their end and start states (a straight line, the paper's constant
  speed, when they are equal).
* **Stopping** is the start transient reversed in time: the LIPM is
  time-reversible, so Eq. 15 with the end state ``(x_f - x_a, -v_a)`` gives
  the ZMPs of a last single support and a last double support that bring the
  body to rest above the middle of the feet.
* **Feasibility** is checked, not left to the user: the conditions of Eq. 11
  (``v_xD > a (x_ZMP1 - x0)``, positive logarithm arguments, ``t4 > 0``) and the
  transient ZMPs inside the support polygon (which the paper leaves to check)
  raise :class:`~zmpwalk.errors.InfeasiblePatternError` naming the condition
  and the numbers.

Feet: straight walking, the swinging ankle goes to its landing point with the
quintic of Eq. 17 over the single support and rises and lands with it over
each half. In the world frame x is forward, y left; a step of stride ``x_s`` (the
paper's steady stride, two steps) advances each foot by ``x_s`` and the body by
``x_s / 2`` per step, so ``forward = x_s / 2`` in a
:class:`~zmpwalk.commands.StepCommand`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk import curves
from zmpwalk.errors import InfeasiblePatternError
from zmpwalk.footsteps import Pose2D, foot_corners
from zmpwalk.patterns.pendulum import COAST as COAST  # the pendulum's pieces, where the paper's walk is
from zmpwalk.patterns.pendulum import Piece as Piece
from zmpwalk.patterns.pendulum import SteadyStep as SteadyStep
from zmpwalk.patterns.pendulum import lateral_sway as lateral_sway
from zmpwalk.patterns.pendulum import propagate as propagate
from zmpwalk.patterns.pendulum import run_pieces as run_pieces
from zmpwalk.patterns.pendulum import single_support_zmps as single_support_zmps
from zmpwalk.patterns.pendulum import solve_step as solve_step
from zmpwalk.patterns.pendulum import solve_zmps as solve_zmps
from zmpwalk.patterns.pendulum import steady_step as steady_step
from zmpwalk.patterns.pendulum import transient_zmps as transient_zmps
from zmpwalk.patterns.result import (
    StepRecord,
    SupportPhase,
    WalkingPattern,
    sample_times,
)
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Side, Support
from zmpwalk.zmp import convex_hull, signed_margin

Array = NDArray[np.float64]



# ---------------------------------------------------------------------------------------- the walk

@dataclass(frozen=True)
class HyperbolicGait:
    """Inputs of the paper's walking example, in SI units (defaults: the paper's example).

    Attributes:
        body_height: ``z_b`` [m].
        stride: ``x_s`` [m].
        zmp1_fraction: ``(x_ZMP1 - x0) / x_s``.
        zmp2_fraction: ``(x_ZMP2 - x0) / x_s``.
        y_zmp: ``y_ZMP`` [m].
        v_double: ``v_xD`` [m/s].
        t_star: Start double support ``t*`` [s].
        tau_star: Start single support ``tau*`` [s].
        gravity: ``g`` [m/s^2].
    """

    body_height: float = 0.395  # [m]
    stride: float = 0.100  # [m]
    zmp1_fraction: float = 1 / 8
    zmp2_fraction: float = 1 / 4
    y_zmp: float = 0.068  # [m]
    v_double: float = 0.100  # [m/s]
    t_star: float = 0.2  # [s]
    tau_star: float = 0.3  # [s]
    gravity: float = 9.8  # [m/s^2]

    @property
    def a(self) -> float:
        """``sqrt(g / z_b)`` [1/s] (Eq. 4)."""
        return math.sqrt(self.gravity / self.body_height)

    def steady(self) -> SteadyStep:
        """Eq. 11 for these inputs."""
        return steady_step(self.a, self.stride, self.zmp1_fraction * self.stride, self.zmp2_fraction * self.stride,
                           self.v_double, self.y_zmp)

    def start_zmps(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Eq. 15 sagittally with end state ``(x', v_xD)`` and laterally with ``(y0, -v_y)``.

        Returns ``((x_ZMP0D, y_ZMP0D), (x_ZMP0S, y_ZMP0S))`` [m].
        """
        step = self.steady()
        xd, xs = transient_zmps(self.a, self.t_star, self.tau_star, step.end, step.v_double)
        yd, ys = transient_zmps(self.a, self.t_star, self.tau_star, step.y0, -step.v_y)
        return (xd, yd), (xs, ys)


@dataclass(frozen=True)
class _Piece:
    """One interval of one body axis: ``hyp`` (constant ZMP ``c``, Eq. 5) or ``cubic`` (Hermite to ``c, v1``)."""

    start: float  # [s]
    duration: float  # [s]
    hyperbolic: bool
    x0: float  # [m]
    v0: float  # [m/s]
    c: float  # [m] ZMP (hyperbolic) or end position (cubic)
    v1: float = 0.0  # [m/s] end velocity (cubic)


class _Axis:
    """The pieces of one body coordinate, appended in time order; tracks the current state."""

    def __init__(self, a: float) -> None:
        self.a = a
        self.pieces: list[_Piece] = []
        self.t, self.x, self.v = 0.0, 0.0, 0.0

    def hold_zmp(self, duration: float, zmp: float) -> None:
        """Constant ZMP for ``duration`` (Eqs. 5, 8-10, 12-13)."""
        self.pieces.append(_Piece(self.t, duration, True, self.x, self.v, zmp))
        self.x, self.v = propagate(self.a, self.x, self.v, duration, zmp)
        self.t += duration

    def cubic_to(self, duration: float, x1: float, v1: float) -> None:
        """Hermite cubic to ``(x1, v1)`` (a straight line at constant speed when it is one)."""
        self.pieces.append(_Piece(self.t, duration, False, self.x, self.v, x1, v1))
        self.x, self.v = x1, v1
        self.t += duration

    def evaluate(self, time: Array) -> tuple[Array, Array, Array]:
        """Position [m], velocity [m/s], acceleration [m/s^2]; before and after the pieces: at rest."""
        a = self.a
        starts = np.array([p.start for p in self.pieces])
        k = np.clip(np.searchsorted(starts, time, side="right") - 1, 0, len(self.pieces) - 1)

        def get(name: str) -> Array:
            return np.array([getattr(p, name) for p in self.pieces], dtype=float)[k]

        duration = get("duration")
        tau = np.clip(time - get("start"), 0.0, duration)
        x0, v0, c, v1 = get("x0"), get("v0"), get("c"), get("v1")
        hyper = get("hyperbolic").astype(bool)
        ch, sh = np.cosh(a * tau), np.sinh(a * tau)
        hx = (x0 - c) * ch + v0 / a * sh + c  # Eq. 5
        hv = (x0 - c) * a * sh + v0 * ch
        ha = a * a * (hx - c)  # Eq. 4
        T = np.where(duration > 0, duration, 1.0)
        s = tau / T
        cx, cs, cc = curves.hermite_cubic(x0, v0 * T, c, v1 * T, s)
        position = np.where(hyper, hx, cx)
        velocity = np.where(hyper, hv, cs / T)
        acceleration = np.where(hyper, ha, cc / (T * T))
        after = time > self.t
        velocity = np.where(after, 0.0, velocity)
        acceleration = np.where(after, 0.0, acceleration)
        return position, velocity, acceleration


@dataclass(frozen=True)
class _Swing:
    start: float  # [s]
    duration: float  # [s]
    foot: int
    x_from: float  # [m]
    x_to: float  # [m]


class HyperbolicWalk:
    """A straight walk: start transient, steady steps, and optionally the stop transient.

    Args:
        robot: The robot (``pendulum_length`` is ``z_b``, ``foot_lift`` the swing height).
        steps: One steady step per swing: the first is the target of the start transient (its swing is
            the transient's), the others are walked as steady steps.
        start: ``(t*, tau*)`` of the start transient [s].
        stop: ``(t*, tau*)`` of the stop transient [s], or None to end after the last single support.
        gravity: ``g`` [m/s^2] (default the robot's).
        y_foot: Lateral ankle position [m] (default the first step's ``y_ZMP``).

    Raises:
        InfeasiblePatternError: A transient ZMP outside its support polygon.
    """

    def __init__(self, robot: RobotModel, steps: Sequence[SteadyStep], start: tuple[float, float],
                 stop: tuple[float, float] | None, gravity: float | None = None) -> None:
        self.robot = robot
        self.gravity = robot.gravity if gravity is None else gravity
        self.a = math.sqrt(self.gravity / robot.pendulum_length)
        self.steps = list(steps)
        self.y_foot = self.steps[0].y_zmp
        self.x_axis, self.y_axis = _Axis(self.a), _Axis(self.a)
        self.swings: list[_Swing] = []
        self.records: list[StepRecord] = []
        self.phases: list[SupportPhase] = []
        self.start_zmps: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))
        self.stop_zmps: tuple[tuple[float, float], tuple[float, float]] | None = None
        self._build(start, stop)

    def _pose(self, feet: dict[Side, float], foot: Side) -> tuple[Pose2D, int]:
        return Pose2D(feet[foot], foot * self.y_foot, 0.0), foot

    def _double(self, feet: dict[Side, float], duration: float) -> None:
        t = self.x_axis.t
        self.phases.append(SupportPhase(t, t + duration, Support.DOUBLE,
                                        (self._pose(feet, Side.LEFT), self._pose(feet, Side.RIGHT))))

    def _single(self, feet: dict[Side, float], support: Side, duration: float, landing: float, kind: str) -> None:
        t = self.x_axis.t
        swing = support.other
        self.phases.append(SupportPhase(t, t + duration, support.single_support, (self._pose(feet, support),)))
        self.swings.append(_Swing(t, duration, swing, feet[swing], landing))
        self.records.append(StepRecord(t, duration, swing.label, kind,
                                       (landing, swing * self.y_foot, 0.0), {}))
        feet[swing] = landing

    def _build(self, start: tuple[float, float], stop: tuple[float, float] | None) -> None:
        a, X, Y = self.a, self.x_axis, self.y_axis
        first = self.steps[0]
        feet = {Side.LEFT: 0.0, Side.RIGHT: 0.0}  # ankle x of each foot
        t_star, tau_star = start
        # Start (Eqs. 12-15): shift the body towards the left foot, then swing the right one by x_s/2.
        xd, xs = transient_zmps(a, t_star, tau_star, first.end, first.v_double)
        yd, ys = transient_zmps(a, t_star, tau_star, first.y0, -first.v_y)
        self.start_zmps = ((xd, yd), (xs, ys))
        self._check_zmp("start", "double", (xd, yd), feet, None)
        self._check_zmp("start", "single", (xs, ys), feet, Side.LEFT)
        self._double(feet, t_star)
        X.hold_zmp(t_star, xd)  # Eq. 12
        Y.hold_zmp(t_star, yd)
        self._single(feet, Side.LEFT, tau_star, feet[Side.LEFT] + first.stride / 2, "start")
        X.hold_zmp(tau_star, xs)  # Eq. 13
        Y.hold_zmp(tau_star, ys)
        support = Side.RIGHT
        for step in self.steps[1:]:
            self._steady(step, feet, support)
            support = support.other
        if stop is None:
            return
        # Stop: the start reversed in time; the body comes to rest above the middle of the feet.
        last = self.steps[-1]
        body0 = feet[support]
        self._double(feet, last.t4)
        X.cubic_to(last.t4, body0, last.v_double)
        Y.cubic_to(last.t4, support * last.y0, support * last.v_y)
        t_star, tau_star = stop
        rest_x, rest_y = body0, 0.0
        xd, xs = transient_zmps(a, t_star, tau_star, X.x - rest_x, -X.v)
        yd, ys = transient_zmps(a, t_star, tau_star, Y.x - rest_y, -Y.v)
        zmp_single, zmp_double = (rest_x + xs, rest_y + ys), (rest_x + xd, rest_y + yd)
        self.stop_zmps = (zmp_double, zmp_single)
        self._check_zmp("stop", "single", zmp_single, feet, support)
        self._single(feet, support, tau_star, feet[support], "stop")
        X.hold_zmp(tau_star, zmp_single[0])
        Y.hold_zmp(tau_star, zmp_single[1])
        self._check_zmp("stop", "double", zmp_double, feet, None)
        self._double(feet, t_star)
        X.hold_zmp(t_star, zmp_double[0])
        Y.hold_zmp(t_star, zmp_double[1])

    def _steady(self, step: SteadyStep, feet: dict[Side, float], support: Side) -> None:
        """Double support at constant speed (Eq. 7b), then the single support of Fig. 3.

        The single-support ZMPs of intervals I and III are solved so that the body ends in this
        step's steady end state ``(x', v_xD)`` whatever state it starts in: in steady walking
        that gives the paper's ``x_ZMP1``, ``x_ZMP2``; after a change of stride or step time they
        move to brake or push, which the ZMP margin then judges.
        """
        X, Y = self.x_axis, self.y_axis
        foot = feet[support]
        self._double(feet, step.t4)
        X.cubic_to(step.t4, X.x + X.v * step.t4, X.v)  # constant speed (Eq. 7b)
        Y.cubic_to(step.t4, support * step.y0, support * step.v_y)  # constant speed v_y in steady walking (7c)
        self._single(feet, support, step.t5, foot + step.stride / 2, "step")
        zmp1, zmp2 = single_support_zmps(self.a, X.x, X.v, step, foot + step.end, step.v_double)
        X.hold_zmp(step.t1, zmp1)  # interval I, Eq. 8
        if step.t2 > 0:
            X.cubic_to(step.t2, X.x + X.v * step.t2, X.v)  # interval II: zero acceleration (ZMP under the body)
        X.hold_zmp(step.t3, zmp2)  # interval III, Eq. 9
        Y.hold_zmp(step.t5, support * step.y_zmp)  # Eq. 10

    def _check_zmp(self, which: str, phase: str, point: tuple[float, float], feet: dict[Side, float],
                   support: Side | None) -> None:
        """A transient ZMP must lie in its support polygon (the check the paper leaves to the user)."""
        if support is None:
            polygon = convex_hull(np.vstack([foot_corners(*self._pose(feet, f), self.robot) for f in Side]))
        else:
            polygon = foot_corners(*self._pose(feet, support), self.robot)
        margin = float(signed_margin(np.array([point]), polygon)[0])
        if margin < 0:
            raise InfeasiblePatternError(
                f"the {which} transient's {phase}-support ZMP ({point[0] * 1e3:.2f}, {point[1] * 1e3:.2f}) mm is "
                f"{-margin * 1e3:.2f} mm outside its support polygon (t*, tau* or the stride need changing)")

    @property
    def duration(self) -> float:
        """End of the walk [s]."""
        return self.x_axis.t

    def feet_at(self, time: Array, foot: int) -> tuple[Array, Array]:
        """Ankle position [m] (n, 3) and velocity [m/s] (n, 3) of one foot: Eq. 17 quintics."""
        swings = [s for s in self.swings if s.foot == foot]
        lift = self.robot.foot_lift
        n = len(time)
        x, vx, vz = np.zeros(n), np.zeros(n), np.zeros(n)
        z = np.full(n, self.robot.ankle_height)
        index = np.searchsorted(np.array([s.start for s in swings]), time, side="right") - 1
        for i, swing in enumerate(swings):  # a handful of swings: one vectorised pass each
            mask = index == i
            tau = np.clip((time[mask] - swing.start) / swing.duration, 0.0, 1.0)
            moving = tau < 1.0
            value, slope, _ = curves.smoothstep5(tau)  # Eq. 17
            x[mask] = swing.x_from + (swing.x_to - swing.x_from) * value
            vx[mask] = np.where(moving, (swing.x_to - swing.x_from) * slope / swing.duration, 0.0)
            height, rate, _ = curves.lift_profile(tau, 0.5)  # Eq. 17 up over the first half, down the second
            z[mask] = self.robot.ankle_height + lift * height
            vz[mask] = np.where(moving, lift * rate / swing.duration, 0.0)
        y = np.full(len(time), foot * self.y_foot)
        return np.column_stack([x, y, z]), np.column_stack([vx, np.zeros(len(time)), vz])

    def sample(self, rate: float, generator: str = "hyperbolic") -> WalkingPattern:
        """The walk sampled at ``rate`` [Hz] from 0 to its end, as a :class:`WalkingPattern`."""
        time = sample_times(self.duration, rate)
        x, vx, ax = self.x_axis.evaluate(time)
        y, vy, ay = self.y_axis.evaluate(time)
        n = len(time)
        left, v_left = self.feet_at(time, Side.LEFT)
        right, v_right = self.feet_at(time, Side.RIGHT)
        begins = np.array([p.begin for p in self.phases])
        which = np.clip(np.searchsorted(begins, time, side="right") - 1, 0, len(begins) - 1)
        support = np.array([p.support for p in self.phases], dtype=np.int8)[which]
        support[time >= self.duration] = Support.DOUBLE
        zeros = np.zeros(n)
        a2 = self.a * self.a
        return WalkingPattern(
            robot=self.robot, rate=rate, generator=generator, time=time, support=support,
            position_pelvis_in_world=np.column_stack([x, y, np.full(n, self.robot.pelvis_height)]),
            velocity_pelvis_in_world=np.column_stack([vx, vy, zeros]),
            yaw_pelvis_in_world=zeros, yaw_rate_pelvis=zeros,
            position_left_ankle_in_world=left, velocity_left_ankle_in_world=v_left,
            yaw_left_foot_in_world=zeros, yaw_rate_left_foot=zeros,
            position_right_ankle_in_world=right, velocity_right_ankle_in_world=v_right,
            yaw_right_foot_in_world=zeros, yaw_rate_right_foot=zeros,
            zmp_in_world=np.column_stack([x - ax / a2, y - ay / a2]),  # Eq. 4: x_ZMP = x_b - x_b'' / a^2
            steps=list(self.records), support_phases=list(self.phases),
        )


def paper_walk(robot: RobotModel, gait: HyperbolicGait | None = None, steps: int = 2, stop: bool = True
               ) -> HyperbolicWalk:
    """The paper's example (Section 4): start transient, ``steps`` steady steps, and the stop.

    With the defaults, the start and two steady steps are the "three steps counted from
    the stationary state" of the paper.
    """
    gait = gait or HyperbolicGait(body_height=robot.pendulum_length)
    steady = gait.steady()
    window = (gait.t_star, gait.tau_star)
    return HyperbolicWalk(robot, [steady] * (steps + 1), window, window if stop else None, gait.gravity)
