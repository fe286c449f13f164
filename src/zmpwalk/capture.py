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
   (``c' = omega (xi - c)``, integrated with RK4 at the pattern's rate).

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

from zmpwalk.curves import smoothstep5
from zmpwalk.errors import InfeasiblePatternError, InvalidParameterError, UnreachableError
from zmpwalk.footsteps import Pose2D
from zmpwalk.kinematics import hip_positions_in_world, leg_reach_excess
from zmpwalk.patterns.result import (
    SUPPORT_DOUBLE,
    SUPPORT_LEFT,
    SUPPORT_RIGHT,
    StepRecord,
    SupportPhase,
    WalkingPattern,
    check_rate,
)
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]

SWING_GRID = 0.01  # [s] the capture swing's duration is searched on this grid
REACH_MARGIN = 0.01  # [m] the landing keeps this much of the leg's reach in hand
REACH_SHRINK = 0.9  # [-] a landing out of reach is pulled towards the stance foot by this factor, then checked
REACH_TRIES = 12  # pulls before the landing is given up as out of reach
CROUCH_LEAST_TIME = 0.1  # [s] the CoM point is lowered for the legs' reach over at least this time
SETTLE_TRIES = 3  # the settle is doubled up to this many times to keep the ZMP in the feet
ZMP_TOLERANCE = 1e-9  # [m]
LEAST_REPLANNED_SWING = 0.08  # [s] a capture step re-planned during its swing lands at least this much later


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

    def __post_init__(self) -> None:
        for name, value in vars(self).items():
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value)
                                                                                       and value >= 0):
                raise InvalidParameterError(f"capture.{name}", value, "a finite number >= 0")
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


def _rotate(vector: Array, yaw: float) -> Array:
    """``vector`` (2,) turned by ``yaw`` [rad]."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]])


def quintic_from_rest(start: Array, velocity: Array, end: Array, duration: float, s: Array) -> tuple[Array, Array]:
    r"""Value and rate of the quintic from ``start`` with ``velocity`` and no acceleration to ``end`` at rest
    (zero velocity and acceleration) after ``duration``, at times ``s`` in ``[0, duration]``.

    .. math:: x(s) = x_0 + v_0 s + c_3 s^3 + c_4 s^4 + c_5 s^5

    with ``c3, c4, c5`` from the three end conditions.

    Args:
        start, velocity, end: (k,) each [m], [m/s], [m].
        duration: [s] (> 0).
        s: (n,) [s].

    Returns:
        Positions (n, k) [m] and velocities (n, k) [m/s].
    """
    t = duration
    gap = end - start - velocity * t
    matrix = np.array([[t**3, t**4, t**5], [3 * t**2, 4 * t**3, 5 * t**4], [6 * t, 12 * t**2, 20 * t**3]])
    coefficients = np.linalg.solve(matrix, np.vstack([gap, -velocity, np.zeros_like(gap)]))  # (3, k)
    s = s[:, None]
    value = start + velocity * s + s**3 * coefficients[0] + s**4 * coefficients[1] + s**5 * coefficients[2]
    rate = velocity + 3 * s**2 * coefficients[0] + 4 * s**3 * coefficients[1] + 5 * s**4 * coefficients[2]
    return value, rate


def capture_step(
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
) -> tuple[WalkingPattern, CapturePlan]:
    """The rest of a walk as one capture step and a stop, from the state at ``time`` (see the module docstring).

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
    omega = math.sqrt(robot.gravity / robot.pendulum_length)
    st = 0 if stance == "left" else 1
    sw = 1 - st
    st_side, sw_side = (1, -1) if st == 0 else (-1, 1)
    st_yaw = float(foot_yaws[st])
    half = np.array([robot.foot_length / 2, robot.foot_width / 2])
    st_center_local = np.array([robot.sole_center_x, st_side * robot.sole_center_y])
    sw_center_local = np.array([robot.sole_center_x, sw_side * robot.sole_center_y])
    st_ankle = ankles[st][:2]
    # 1. the stance ZMP: the stance sole's point nearest to the DCM, inside its edges
    local = _rotate(dcm - st_ankle, -st_yaw) - st_center_local
    inside = np.clip(local, -(half - settings.zmp_inset), half - settings.zmp_inset)
    p1 = st_ankle + _rotate(st_center_local + inside, st_yaw)
    # 2. the landing, for each swing time on the grid
    gap_least = 2 * half[1] - 2 * robot.sole_center_y + settings.feet_clearance  # ankle gap across the stance

    def off_the_stance(landing: Array) -> Array:
        """``landing`` moved out across the stance foot until the soles' inner edges keep the clearance."""
        across = _rotate(landing - st_ankle, -st_yaw)
        if sw_side * across[1] >= gap_least:
            return landing
        across[1] = sw_side * gap_least
        return st_ankle + _rotate(across, st_yaw)

    def landing_after(duration: float) -> tuple[float, Array, Array]:
        """How far the foot misses the way at the foot speed [m] (<= 0: it makes it), xi(T) and the landing."""
        dcm_touchdown = p1 + (dcm - p1) * math.exp(omega * duration)
        ahead = dcm_touchdown - p1
        norm = float(np.linalg.norm(ahead))
        sole_center = dcm_touchdown + (settings.landing_inset * ahead / norm if norm > 0 else 0.0)
        landing = off_the_stance(sole_center - _rotate(sw_center_local, st_yaw))
        return float(np.linalg.norm(landing - ankles[sw][:2])) - settings.foot_speed * duration, dcm_touchdown, landing

    shortest = settings.shortest_swing if touchdown is None else max(touchdown - time, LEAST_REPLANNED_SWING)
    first = round(shortest / SWING_GRID)
    durations = np.arange(first, max(round(settings.longest_swing / SWING_GRID), first) + 1) * SWING_GRID
    candidates = [(float(duration), *landing_after(float(duration))) for duration in durations]
    fitting = [c for c in candidates if c[1] <= 0.0]
    # the shortest swing that makes its way at the foot speed, else the one that misses it least
    swing_time, _, dcm_touchdown, landing = fitting[0] if fitting else min(candidates, key=lambda c: c[1])
    n = max(math.ceil((max(end, time + swing_time + settings.settle + 1.0 / omega) - time) * rate - 1e-9), 1) + 1
    reached = True
    for attempt in range(REACH_TRIES + 1):
        pattern, rest, settle, margin = _settled(robot, time, rate, n, settings, omega, st, com, dcm, p1, swing_time,
                                                 landing, st_yaw, float(yaw_pelvis_in_world), ankles, velocities,
                                                 foot_yaws)
        excess = leg_reach_excess(pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
                                  pattern.position_left_ankle_in_world, pattern.position_right_ankle_in_world, robot)
        worst = int(np.argmax([excess[0].max(), excess[1].max()]))
        if float(excess[worst].max()) <= -REACH_MARGIN:
            break
        if attempt == REACH_TRIES:
            out = int(np.argmax(excess[worst] > -REACH_MARGIN))
            raise UnreachableError(("left", "right")[worst], float(pattern.time[out]),
                                   float(excess[worst].max()) + REACH_MARGIN,
                                   f"capture step, after {REACH_TRIES} landings pulled towards the stance foot")
        reached = False
        landing = off_the_stance(st_ankle + REACH_SHRINK * (landing - st_ankle))
    if margin < -ZMP_TOLERANCE:
        pulled = ", pulled in for the legs' reach," if not reached else ""
        raise InfeasiblePatternError(
            f"capture step: the DCM at touchdown {np.round(dcm_touchdown, 3).tolist()} m lies outside the feet"
            f"{pulled} (its ZMP leaves them by {-margin * 1e3:.1f} mm on the way to rest, settle {settle:g} s): "
            "no single step catches it")
    plan = CapturePlan(time=time, swing=("left", "right")[sw], swing_time=swing_time, zmp_stance=p1, dcm_start=dcm,
                       dcm_touchdown=dcm_touchdown, landing=(float(landing[0]), float(landing[1]), st_yaw), rest=rest,
                       reached=reached)
    return pattern, plan


def _settled(robot: RobotModel, time: float, rate: float, n: int, settings: CaptureSettings, omega: float, st: int,
             com: Array, dcm: Array, p1: Array, swing_time: float, landing: Array, st_yaw: float, pelvis_yaw: float,
             ankles: list[Array], velocities: list[Array],
             foot_yaws: tuple[float, float]) -> tuple[WalkingPattern, Array, float, float]:
    """:func:`_build` with the settle doubled (up to :data:`SETTLE_TRIES` times) until the ZMP stays in the feet:
    the pattern, the rest point, the settle [s] and the least ZMP margin [m] (< 0: it leaves them)."""
    settle = settings.settle
    for tries in range(SETTLE_TRIES + 1):
        samples = max(n, math.ceil((swing_time + settle + 1.0 / omega) * rate) + 1)
        pattern, rest = _build(robot, time, rate, np.arange(samples) / rate, settings, settle, omega, st, com, dcm,
                               p1, swing_time, landing, st_yaw, pelvis_yaw, ankles, velocities, foot_yaws)
        margin = float(pattern.zmp_margin().min())
        if margin >= -ZMP_TOLERANCE or tries == SETTLE_TRIES:
            break
        settle *= 2.0
    return pattern, rest, settle, margin


def _crouch(robot: RobotModel, s: Array, pelvis: Array, pelvis_velocity: Array, pelvis_yaw: float,
            feet: list[Array]) -> None:
    """Lower the CoM point (in place) where a leg would otherwise be out of reach: a capture step can carry the
    body further from the stance foot than the walk's height allows. The least lowering that keeps each hip
    within the leg's reach less :data:`REACH_MARGIN` of its ankle, ``dz <= sqrt(r^2 - h^2)`` with ``h`` the
    horizontal distance, is reached along a quintic by the first sample that needs it, and then held."""
    reach = robot.max_leg_reach - REACH_MARGIN
    hips = hip_positions_in_world(pelvis, np.full(len(s), pelvis_yaw), robot)
    needed = np.zeros(len(s))
    for hip, ankle in zip(hips, feet, strict=True):
        horizontal = np.linalg.norm(hip[:, :2] - ankle[:, :2], axis=1)
        allowed = np.sqrt(np.maximum(reach**2 - horizontal**2, 0.0))
        needed = np.maximum(needed, (hip[:, 2] - ankle[:, 2]) - allowed)
    if needed.max() <= 0.0:
        return
    drop = float(needed.max())
    first = float(s[int(np.argmax(needed > 0.0))])
    ramp = max(first, CROUCH_LEAST_TIME)
    blend, slope, _ = smoothstep5(np.clip(s / ramp, 0.0, 1.0))
    pelvis[:, 2] -= drop * blend
    pelvis_velocity[:, 2] -= drop * slope / ramp


def _build(robot: RobotModel, time: float, rate: float, s: Array, settings: CaptureSettings, settle: float,
           omega: float, st: int, com: Array, dcm: Array, p1: Array, swing_time: float, landing: Array, st_yaw: float,
           pelvis_yaw: float, ankles: list[Array], velocities: list[Array],
           foot_yaws: tuple[float, float]) -> tuple[WalkingPattern, Array]:
    """The capture pattern for one landing (the module docstring's three phases)."""
    sw = 1 - st
    n = len(s)
    st_side, sw_side = (1, -1) if st == 0 else (-1, 1)
    centers = [ankles[st][:2] + _rotate(np.array([robot.sole_center_x, st_side * robot.sole_center_y]), st_yaw),
               landing + _rotate(np.array([robot.sole_center_x, sw_side * robot.sole_center_y]), st_yaw)]
    rest = (centers[0] + centers[1]) / 2
    dcm_touchdown = p1 + (dcm - p1) * math.exp(omega * swing_time)

    def dcm_at(t: Array) -> tuple[Array, Array]:
        """The planned DCM [m] and its rate [m/s] at times ``t`` (n,) after the capture."""
        t = np.asarray(t, dtype=float)
        single = t < swing_time - 1e-12
        grow = np.exp(omega * np.minimum(t, swing_time))[:, None]
        xi = np.where(single[:, None], p1 + (dcm - p1) * grow, 0.0)
        rate_xi = np.where(single[:, None], omega * (dcm - p1) * grow, 0.0)
        tau = np.clip((t - swing_time) / settle, 0.0, 1.0)
        blend, slope, _ = smoothstep5(tau)
        moving = rest + (dcm_touchdown - rest) * (1.0 - blend)[:, None]
        moving_rate = -(dcm_touchdown - rest) * (slope / settle)[:, None]
        xi = np.where(single[:, None], xi, moving)
        rate_xi = np.where(single[:, None], rate_xi, moving_rate)
        return xi, rate_xi

    xi, xi_rate = dcm_at(s)
    zmp = xi - xi_rate / omega  # p = xi - xi' / omega
    # the CoM: c' = omega (xi - c), RK4 at the pattern's rate from the plan's CoM point
    dt = 1.0 / rate
    c = np.empty((n, 2))
    c[0] = com[:2]
    half_xi, _ = dcm_at(s[:-1] + dt / 2)
    for k in range(n - 1):
        a = omega * (xi[k] - c[k])
        b = omega * (half_xi[k] - (c[k] + dt / 2 * a))
        d = omega * (half_xi[k] - (c[k] + dt / 2 * b))
        e = omega * (xi[k + 1] - (c[k] + dt * d))
        c[k + 1] = c[k] + dt / 6 * (a + 2 * b + 2 * d + e)
    pelvis = np.column_stack([c, np.full(n, com[2])])
    pelvis_velocity = np.column_stack([omega * (xi - c), np.zeros(n)])
    # the feet: the stance one stays, the swinging one moves along quintics to the landing
    foot_position = [np.repeat(ankles[f][None], n, axis=0) for f in range(2)]
    foot_velocity = [np.zeros((n, 3)) for _ in range(2)]
    swing = s < swing_time
    ground = float(ankles[st][2])
    way, way_rate = quintic_from_rest(ankles[sw][:2], velocities[sw][:2], landing, swing_time, s[swing])
    foot_position[sw][swing, :2], foot_velocity[sw][swing, :2] = way, way_rate
    foot_position[sw][~swing, :2] = landing
    top = max(float(ankles[sw][2]), ground + settings.lift)
    first = s < swing_time / 2
    up, up_rate = quintic_from_rest(ankles[sw][2:], velocities[sw][2:], np.array([top]), swing_time / 2, s[first])
    down, down_rate = quintic_from_rest(np.array([top]), np.zeros(1), np.array([ground]), swing_time / 2,
                                        s[swing & ~first] - swing_time / 2)
    foot_position[sw][first, 2], foot_velocity[sw][first, 2] = up[:, 0], up_rate[:, 0]
    foot_position[sw][swing & ~first, 2], foot_velocity[sw][swing & ~first, 2] = down[:, 0], down_rate[:, 0]
    foot_position[sw][~swing, 2] = ground
    yaw_blend, yaw_slope, _ = smoothstep5(np.clip(s / swing_time, 0.0, 1.0))
    start_yaw = float(foot_yaws[sw])
    yaws = [np.full(n, float(foot_yaws[f])) for f in range(2)]
    yaw_rates = [np.zeros(n), np.zeros(n)]
    yaws[sw] = start_yaw + (st_yaw - start_yaw) * yaw_blend
    yaw_rates[sw] = (st_yaw - start_yaw) * yaw_slope / swing_time
    _crouch(robot, s, pelvis, pelvis_velocity, pelvis_yaw, foot_position)
    support = np.where(swing, SUPPORT_LEFT if st == 0 else SUPPORT_RIGHT, SUPPORT_DOUBLE).astype(np.int8)
    st_pose = Pose2D(float(ankles[st][0]), float(ankles[st][1]), st_yaw)
    sw_pose = Pose2D(float(landing[0]), float(landing[1]), st_yaw)
    sides = (1, -1)
    both = ((st_pose, sides[st]), (sw_pose, sides[sw])) if st == 0 else ((sw_pose, sides[sw]), (st_pose, sides[st]))
    phases = [SupportPhase(time, time + swing_time, int(support[0]), ((st_pose, sides[st]),)),
              SupportPhase(time + swing_time, math.inf, SUPPORT_DOUBLE, both)]
    step = StepRecord(start=time, duration=swing_time, swing=("left", "right")[sw], kind="capture",
                      landing=(float(landing[0]), float(landing[1]), st_yaw),
                      parameters={"swing_time": swing_time, "settle": settle})
    pattern = WalkingPattern(
        robot=robot, rate=rate, generator="capture", time=time + s, support=support,
        position_pelvis_in_world=pelvis, velocity_pelvis_in_world=pelvis_velocity,
        yaw_pelvis_in_world=np.full(n, pelvis_yaw), yaw_rate_pelvis=np.zeros(n),
        position_left_ankle_in_world=foot_position[0], velocity_left_ankle_in_world=foot_velocity[0],
        yaw_left_foot_in_world=yaws[0], yaw_rate_left_foot=yaw_rates[0],
        position_right_ankle_in_world=foot_position[1], velocity_right_ankle_in_world=foot_velocity[1],
        yaw_right_foot_in_world=yaws[1], yaw_rate_right_foot=yaw_rates[1],
        zmp_in_world=zmp, steps=[step], support_phases=phases)
    return pattern, rest


__all__ = ["CapturePlan", "CaptureSettings", "capture_step", "quintic_from_rest"]
