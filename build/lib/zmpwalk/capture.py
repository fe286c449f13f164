r"""The capture step: a walk's remainder re-planned from the measured state after a push.

A push in single support moves the body's divergent component of motion (DCM) ``xi = c + c' / omega``
away from the plan faster than the stabilizer's offsets of a planned step can follow (docs/balance.md:
re-planning only the steps after the pushed one survives none of the pushes that fell, because the fall is
decided within the pushed step). :func:`capture_step` replaces the rest of the walk, from the tick it is
called, by one step whose place and timing come from the measured DCM, and a CoM plan that comes to rest
between the feet:

1. **Single support, until touchdown after** ``T``: the ZMP stays at ``p1``, the point of the stance sole
   nearest to the DCM (:attr:`CaptureSettings.zmp_inset` inside its edges). The linear inverted pendulum's
   DCM then runs away from it as

   .. math:: \xi(t) = p_1 + (\xi_0 - p_1)\, e^{\omega t}

   (from :math:`\dot\xi = \omega(\xi - p)`, Englsberger et al. 2015; the CoM of Eqs. 4-5 of Lim et al. in
   closed form, :math:`c(t) = p_1 + A e^{\omega t} + B e^{-\omega t}`).
2. **The landing**: the swinging sole lands so that the DCM at touchdown, ``xi(T)``, lies
   :attr:`CaptureSettings.landing_inset` inside it, on the side of the stance foot (the capture point of
   Pratt et al. 2006, where a ZMP stops the DCM); never across the stance foot (the soles' inner edges keep
   :attr:`CaptureSettings.feet_clearance` between them), within the leg's reach. ``T`` is the shortest time
   on a 10 ms grid in ``[shortest_swing, longest_swing]`` at which the swinging foot covers its way at
   :attr:`CaptureSettings.foot_speed` on average (the DCM runs away with ``T``, the foot closes in on it).
3. **Double support for** :attr:`CaptureSettings.settle`: the DCM moves from ``xi(T)`` to the midpoint ``m``
   of the soles along a quintic, ``xi = m + (xi(T) - m)(1 - s(tau))``, whose ZMP is
   ``p = xi - xi' / omega``; then it stays at ``m`` with the ZMP, and the CoM converges to it
   (``c' = omega (xi - c)``, in closed form: :func:`zmpwalk.capture_pattern._com_path`).

The CoM plan starts where the pattern's CoM point is (its joint references are continuous) with the measured
DCM: the stabilizer's DCM error is then zero, and what is left of the push is in the plan. The swinging foot
starts where it is aimed (its planned place plus the stabilizer's landing correction), with its planned
velocity, and moves along quintics in each axis. Heights and yaws: the CoM point's height is held, the
pelvis yaw held, the swinging foot turns to the stance foot's yaw.

Axes: world, x forward at the walk's start, y left, z up (docs/frames-and-units.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.capture_pattern import (
    REACH_MARGIN,
    CaptureState,
    capture_pattern_parts,
    quintic_from_rest,
    turned,
    zmp_margin_of_capture,
)
from zmpwalk.errors import InfeasiblePatternError, InvalidParameterError, UnreachableError
from zmpwalk.kinematics import leg_reach_excess
from zmpwalk.patterns.result import WalkingPattern, check_rate
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import Parts, whole

Array = NDArray[np.float64]

SWING_GRID = 0.01  # [s] the capture swing's duration is searched on this grid
REACH_SHRINK = 0.9  # [-] a landing out of reach is pulled towards the stance foot by this factor, then checked
REACH_TRIES = 12  # pulls before the landing is given up as out of reach
CAPTURE_INTERVAL = 0.02  # [s] least time between two capture steps planned in one single support
SETTLE_TRIES = 3  # the settle is doubled up to this many times to keep the ZMP in the feet
ZMP_TOLERANCE = 1e-9  # [m]
LEAST_REPLANNED_SWING = 0.08  # [s] a capture step re-planned during its swing lands at least this much later


def capture_wanted(dcm_error: Array, trigger: float, swing_force: float, load_threshold: float) -> bool:
    """Whether the DCM error asks for a capture step in a single support: longer than ``trigger`` [m] while the
    swinging sole carries no load (its measured normal force ``swing_force`` at most ``load_threshold`` [N]). A
    swinging sole already loaded has landed: the step is taken, and a plan made then would lift a loaded foot, on
    a DCM estimate that jumps as the legs' odometry moves its anchor to the landing foot."""
    return bool(swing_force <= load_threshold and math.hypot(float(dcm_error[0]), float(dcm_error[1])) > trigger)


@dataclass(frozen=True)
class CaptureSettings:
    """When a capture step is taken and how it is shaped.

    Attributes:
        trigger: The DCM error's length in single support above which the rest of the walk is replaced by a
            capture step (:func:`zmpwalk.sim.simulate`'s loop reads the stabilizer's estimate) [m]. Above the
            stabilizer's stepping deadband (30 mm), so that nominal walks are not touched.
        shortest_swing: Least time from the capture to touchdown [s].
        longest_swing: Most time from the capture to touchdown [s].
        foot_speed: Mean horizontal speed of the swinging foot on its way to the landing [m/s].
        lift: Least height of the swinging ankle above its landing height on the way [m].
        zmp_inset: The stance ZMP ``p1`` is kept this far inside the stance sole's edges [m].
        landing_inset: The DCM at touchdown lies this far inside the landing sole [m].
        feet_clearance: Least gap between the soles' inner edges across the stance foot [m].
        settle: Double support in which the DCM moves to the midpoint of the soles [s].
        lead: The walking controller plans a capture step over this long before the step takes over from the walk
            [s] (:mod:`zmpwalk.control.capture`: a few parts of the plan per tick, from the state predicted at the
            take-over; whole ticks, at least one: 0 plans it within the triggering tick, as the batch loop does).
    """

    trigger: float = 0.08  # [m]
    shortest_swing: float = 0.2  # [s]
    longest_swing: float = 0.6  # [s]
    foot_speed: float = 1.2  # [m/s]
    lift: float = 0.03  # [m]
    zmp_inset: float = 0.02  # [m]
    landing_inset: float = 0.03  # [m]
    feet_clearance: float = 0.02  # [m]
    settle: float = 1.0  # [s]
    lead: float = 0.04  # [s]

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value)
                                                                                       and value >= 0):
                raise InvalidParameterError(f"capture.{name}", value, "a finite number >= 0")
        if self.lead > 0.2:
            raise InvalidParameterError("capture.lead", self.lead, "at most 0.2 s")
        if not 0.05 <= self.shortest_swing <= self.longest_swing <= 2.0:
            raise InvalidParameterError("capture.shortest_swing", (self.shortest_swing, self.longest_swing),
                                        "0.05 s <= shortest_swing <= longest_swing <= 2 s")
        for name in ("foot_speed", "settle"):
            if getattr(self, name) <= 0:
                raise InvalidParameterError(f"capture.{name}", getattr(self, name), "a value > 0")


@dataclass(frozen=True)
class CapturePlan:
    """The capture step chosen (what :func:`capture_step`'s pattern does, in numbers).

    Attributes:
        time: When it was planned [s].
        swing: ``"left"`` or ``"right"``.
        swing_time: Time to touchdown ``T`` [s].
        zmp_stance: ``p1`` in world [m], (2,).
        dcm_start: The measured DCM it starts from [m], (2,).
        dcm_touchdown: ``xi(T)`` [m], (2,).
        landing: Landing pose of the swinging ankle ``(x [m], y [m], yaw [rad])``.
        rest: Where the DCM comes to rest, the midpoint of the soles [m], (2,).
        reached: False when the landing was pulled in for the leg's reach (the DCM at touchdown may then lie
            outside the landing sole).
    """

    time: float  # [s]
    swing: str
    swing_time: float  # [s]
    zmp_stance: Array  # [m]
    dcm_start: Array  # [m]
    dcm_touchdown: Array  # [m]
    landing: tuple[float, float, float]
    rest: Array  # [m]
    reached: bool


def capture_step_parts(
    robot: RobotModel,
    *,
    time: float,
    rate: float,
    end: float,
    stance: str,
    position_com_in_world: Array,
    dcm_in_world: Array,
    yaw_pelvis_in_world: float,
    ankles_in_world: tuple[Array, Array],
    ankle_velocities_in_world: tuple[Array, Array],
    foot_yaws: tuple[float, float],
    settings: CaptureSettings | None = None,
    touchdown: float | None = None,
) -> Parts[tuple[WalkingPattern, CapturePlan]]:
    """The rest of a walk as one capture step and a stop, from the state at ``time`` (see the module docstring),
    in parts (:mod:`zmpwalk.slices`: the landing search, then the pattern's parts and its reach check for each
    landing tried; a controller runs them over the ticks before the step takes over); :func:`capture_step` runs it
    whole.

    Args:
        robot: The robot (soles, legs, pendulum length).
        time: The tick it starts at [s]: its first sample is this one.
        rate: Samples per second [Hz].
        end: The pattern lasts at least until this time [s] (and at least until the DCM has come to rest).
        stance: The foot on the ground, ``"left"`` or ``"right"``.
        position_com_in_world: The pattern's CoM point at ``time`` (the plan's; the references stay
            continuous) [m], (3,).
        dcm_in_world: The measured DCM [m], (2,): the plan's DCM plus the stabilizer's DCM error.
        yaw_pelvis_in_world: [rad], held.
        ankles_in_world: Left and right ankles at ``time`` [m], (3,) each: the stance ankle where it stands, the
            swinging one where it is aimed.
        ankle_velocities_in_world: Their velocities [m/s], (3,) each.
        foot_yaws: Left and right foot yaws [rad].
        settings: :class:`CaptureSettings` (default ones).
        touchdown: When the capture step under way (one planned earlier in this single support) lands [s]: the
            new one lands no later than needed to cover its way at the foot speed, searched from then on (at
            least :data:`LEAST_REPLANNED_SWING` after ``time``), instead of from ``shortest_swing`` (a push still
            acting moves the DCM on, and re-planning from the shortest swing each time would never land).

    Returns:
        The pattern (its ``steps`` one ``"capture"`` step, the support single until touchdown and double after)
        and the plan's figures.

    Raises:
        InvalidParameterError: ``stance`` not ``"left"`` or ``"right"``, a bad rate, ``end`` before ``time``, or
            an input with the wrong number of values.
        InfeasiblePatternError: The DCM at touchdown lies where no ZMP in the feet brings it to rest (a fall
            towards the stance side, which a step of the other foot would have to catch).
        UnreachableError: No landing pulled towards the stance foot, nor lowering the CoM point, keeps both legs
            within reach (:data:`REACH_MARGIN` in hand): the body is already too far from the stance foot.
    """
    settings = settings or CaptureSettings()
    com, dcm, ankles, velocities = _checked_state(time, rate, end, stance, position_com_in_world, dcm_in_world,
                                                  ankles_in_world, ankle_velocities_in_world)
    omega = math.sqrt(robot.gravity / robot.pendulum_length)
    st = 0 if stance == "left" else 1
    stance_foot = _StanceFoot(robot, settings, st, float(foot_yaws[st]), ankles, dcm, omega)
    swing_time, dcm_touchdown, landing = stance_foot.swing(time, touchdown)
    yield
    n = max(math.ceil((max(end, time + swing_time + settings.settle + 1.0 / omega) - time) * rate - 1e-9), 1) + 1
    plan = CaptureState(robot, time, rate, settings.lift, omega, st, com, dcm, stance_foot.p1, swing_time,
                        stance_foot.st_yaw, float(yaw_pelvis_in_world), ankles, velocities, foot_yaws)
    pattern, rest, settle, margin, landing, reached = yield from _within_reach(plan, n, landing, stance_foot,
                                                                               settings.settle)
    if margin < -ZMP_TOLERANCE:
        pulled = ", pulled in for the legs' reach," if not reached else ""
        raise InfeasiblePatternError(
            f"capture step: the DCM at touchdown {np.round(dcm_touchdown, 3).tolist()} m lies outside the feet"
            f"{pulled} (its ZMP leaves them by {-margin * 1e3:.1f} mm on the way to rest, settle {settle:g} s): "
            "no single step catches it")
    return pattern, CapturePlan(time=time, swing=("left", "right")[1 - st], swing_time=swing_time,
                                zmp_stance=stance_foot.p1, dcm_start=dcm, dcm_touchdown=dcm_touchdown,
                                landing=(float(landing[0]), float(landing[1]), stance_foot.st_yaw), rest=rest,
                                reached=reached)


capture_step = whole(capture_step_parts, "capture_step")


def _checked_state(time: float, rate: float, end: float, stance: str, position_com_in_world: Array,
                   dcm_in_world: Array, ankles_in_world: tuple[Array, Array],
                   ankle_velocities_in_world: tuple[Array, Array]) -> tuple[Array, Array, list[Array], list[Array]]:
    """The state :func:`capture_step` starts from, checked: the CoM point (3,) and the DCM (2,) [m], the ankles
    [m] and their velocities [m/s], (3,) each (the raises of :func:`capture_step`)."""
    check_rate(rate)
    if stance not in ("left", "right"):
        raise InvalidParameterError("stance", stance, '"left" or "right"')
    if not (math.isfinite(end) and math.isfinite(time) and end >= time):
        raise InvalidParameterError("end", end, f"a time >= time = {time} s")
    com = np.asarray(position_com_in_world, dtype=float).reshape(-1)
    dcm = np.asarray(dcm_in_world, dtype=float).reshape(-1)
    if com.size != 3 or dcm.size != 2:
        raise InvalidParameterError("position_com_in_world, dcm_in_world", (com.size, dcm.size), "3 and 2 values")
    ankles = [np.asarray(a, dtype=float).reshape(3) for a in ankles_in_world]
    velocities = [np.asarray(v, dtype=float).reshape(3) for v in ankle_velocities_in_world]
    return com, dcm, ankles, velocities


class _StanceFoot:
    """The stance foot's geometry: the stance ZMP ``p1`` (step 1 of the module docstring) and the landings
    of the swinging foot (step 2)."""

    def __init__(self, robot: RobotModel, settings: CaptureSettings, st: int, st_yaw: float, ankles: list[Array],
                 dcm: Array, omega: float) -> None:
        """The stance foot ``st`` (0 left, 1 right) at yaw ``st_yaw`` [rad], with the ankles [m] and the
        measured DCM [m]; ``omega`` [1/s] of the pendulum."""
        self.settings, self.st_yaw, self.dcm, self.omega = settings, st_yaw, dcm, omega
        self.swing_ankle = ankles[1 - st][:2]
        st_side, self.sw_side = (1, -1) if st == 0 else (-1, 1)
        half = np.array([robot.foot_length / 2, robot.foot_width / 2])
        st_center_local = np.array([robot.sole_center_x, st_side * robot.sole_center_y])
        self.sw_center_local = np.array([robot.sole_center_x, self.sw_side * robot.sole_center_y])
        self.st_ankle = ankles[st][:2]
        # 1. the stance ZMP: the stance sole's point nearest to the DCM, inside its edges
        local = turned(dcm - self.st_ankle, -st_yaw) - st_center_local
        inside = np.clip(local, -(half - settings.zmp_inset), half - settings.zmp_inset)
        self.p1 = self.st_ankle + turned(st_center_local + inside, st_yaw)
        # 2. the landing, for each swing time on the grid
        self.gap_least = 2 * half[1] - 2 * robot.sole_center_y + settings.feet_clearance  # ankle gap across stance

    def off_the_stance(self, landings: Array) -> Array:
        """``landings`` (k, 2) [m], each moved out across the stance foot until the soles' inner edges keep the
        clearance."""
        c, s = math.cos(self.st_yaw), math.sin(self.st_yaw)
        rx, ry = landings[:, 0] - self.st_ankle[0], landings[:, 1] - self.st_ankle[1]
        along, across = c * rx + s * ry, -s * rx + c * ry
        moved = self.sw_side * across < self.gap_least
        across = np.where(moved, self.sw_side * self.gap_least, across)
        out = np.column_stack([self.st_ankle[0] + c * along - s * across, self.st_ankle[1] + s * along + c * across])
        return np.where(moved[:, None], out, landings)

    def landings_after(self, durations: Array) -> tuple[Array, Array, Array]:
        """For each swing time of ``durations`` (k,) [s]: how far the foot misses the way at the foot speed [m]
        (<= 0: it makes it), xi(T) and the landing [m], (k,) and (k, 2) each."""
        p1 = self.p1
        dcm_touchdown = p1 + (self.dcm - p1) * np.exp(self.omega * durations)[:, None]
        ahead = dcm_touchdown - p1
        norm = np.hypot(ahead[:, 0], ahead[:, 1])
        unit = np.divide(ahead, norm[:, None], out=np.zeros_like(ahead), where=norm[:, None] > 0)
        landing = self.off_the_stance(dcm_touchdown + self.settings.landing_inset * unit
                                      - turned(self.sw_center_local, self.st_yaw))
        way = landing - self.swing_ankle
        miss = np.hypot(way[:, 0], way[:, 1]) - self.settings.foot_speed * durations
        return miss, dcm_touchdown, landing

    def swing(self, time: float, touchdown: float | None) -> tuple[float, Array, Array]:
        """The swing time ``T`` [s], ``xi(T)`` [m] and the landing [m] (the module docstring's step 2), for a capture
        at ``time`` [s] (``touchdown``: :func:`capture_step`'s): every swing time of the grid at once."""
        settings = self.settings
        shortest = settings.shortest_swing if touchdown is None else max(touchdown - time, LEAST_REPLANNED_SWING)
        first = round(shortest / SWING_GRID)
        grid = np.arange(first, max(round(settings.longest_swing / SWING_GRID), first) + 1)
        durations = np.asarray(grid * SWING_GRID, dtype=np.float64)
        miss, dcm_touchdown, landing = self.landings_after(durations)
        fitting = np.flatnonzero(miss <= 0.0)
        # the shortest swing that makes its way at the foot speed, else the one that misses it least
        best = int(fitting[0]) if len(fitting) else int(np.argmin(miss))
        return float(durations[best]), dcm_touchdown[best], landing[best]


def _within_reach(plan: CaptureState, n: int, landing: Array, stance_foot: _StanceFoot,
                  settle: float) -> Parts[tuple[WalkingPattern, Array, float, float, Array, bool]]:
    """:func:`_settled` (from ``settle`` [s]) for ``landing``, pulled towards the stance foot
    (:data:`REACH_SHRINK`, up to :data:`REACH_TRIES` times) until both legs keep :data:`REACH_MARGIN` of their
    reach, in parts: the pattern, the rest point, the settle [s], the least ZMP margin [m], the landing [m] and
    whether it was not pulled in.

    Raises:
        UnreachableError: Still out of reach after the last pull.
    """
    reached = True
    for attempt in range(REACH_TRIES + 1):
        settled, margin = _settled(plan, landing, settle)
        yield
        samples = max(n, math.ceil((plan.swing_time + settled + 1.0 / plan.omega) * plan.rate) + 1)
        pattern, rest = yield from capture_pattern_parts(plan, np.arange(samples) / plan.rate, settled, landing)
        excess = yield from _reach_excess(pattern)
        worst = int(np.argmax([excess[0].max(), excess[1].max()]))
        if float(excess[worst].max()) <= -REACH_MARGIN:
            break
        if attempt == REACH_TRIES:
            out = int(np.argmax(excess[worst] > -REACH_MARGIN))
            raise UnreachableError(("left", "right")[worst], float(pattern.time[out]),
                                   float(excess[worst].max()) + REACH_MARGIN,
                                   f"capture step, after {REACH_TRIES} landings pulled towards the stance foot")
        reached = False
        pulled = stance_foot.st_ankle + REACH_SHRINK * (landing - stance_foot.st_ankle)
        landing = stance_foot.off_the_stance(pulled[None, :])[0]
        yield
    return pattern, rest, settled, margin, landing, reached


def _reach_excess(pattern: WalkingPattern) -> Parts[tuple[Array, Array]]:
    """:func:`~zmpwalk.kinematics.leg_reach_excess` of every sample of ``pattern``, left and right [m], in two parts
    (each half of the samples)."""
    half = (len(pattern.time) + 1) // 2
    pieces = []
    for rows in (slice(0, half), slice(half, None)):
        yield
        pieces.append(leg_reach_excess(pattern.position_pelvis_in_world[rows], pattern.yaw_pelvis_in_world[rows],
                                       pattern.position_left_ankle_in_world[rows],
                                       pattern.position_right_ankle_in_world[rows], pattern.robot))
    return np.concatenate([pieces[0][0], pieces[1][0]]), np.concatenate([pieces[0][1], pieces[1][1]])


def _settled(plan: CaptureState, landing: Array, settle: float) -> tuple[float, float]:
    """The ``settle`` [s] doubled (up to :data:`SETTLE_TRIES` times) until the ZMP stays in the feet, and the least
    ZMP margin [m] (< 0: it leaves them), in closed form (:func:`~zmpwalk.capture_pattern.zmp_margin_of_capture`:
    no pattern is sampled)."""
    for tries in range(SETTLE_TRIES + 1):
        margin = zmp_margin_of_capture(plan, landing, settle)
        if margin >= -ZMP_TOLERANCE or tries == SETTLE_TRIES:
            break
        settle *= 2.0
    return settle, margin


__all__ = ["REACH_MARGIN", "CapturePlan", "CaptureSettings", "capture_step", "capture_wanted", "quintic_from_rest"]
