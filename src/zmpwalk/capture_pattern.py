r"""The capture step's pattern for one landing: the DCM, the CoM and the feet of the three phases.

:func:`capture_pattern_parts` builds the pattern :func:`zmpwalk.capture.capture_step` chose a landing for (its
module docstring's three phases): the DCM runs away from the stance ZMP until touchdown, moves to the midpoint of
the soles along a quintic over the settle and rests there; the CoM follows it (``c' = omega (xi - c)``, in closed
form); the swinging foot moves along quintics to the landing, lifted on the way, turning to the stance foot's yaw;
the CoM point is lowered where a leg would otherwise be out of reach.

Axes: world, x forward at the walk's start, y left, z up (docs/frames-and-units.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.curves import smoothstep5
from zmpwalk.footsteps import Pose2D
from zmpwalk.kinematics import hip_positions_in_world
from zmpwalk.patterns.result import (
    StepRecord,
    SupportPhase,
    WalkingPattern,
)
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import Support
from zmpwalk.slices import Parts
from zmpwalk.zmp import point_margin

Array = NDArray[np.float64]

REACH_MARGIN = 0.01  # [m] the landing keeps this much of the leg's reach in hand
CROUCH_LEAST_TIME = 0.1  # [s] the CoM point is lowered for the legs' reach over at least this time


def turned(vector: Array, yaw: float) -> Array:
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


@dataclass(frozen=True)
class CaptureState:
    """What a capture pattern is built from, but its landing and settle: the state at the capture and the
    choices of steps 1 and 2 (:mod:`zmpwalk.capture`).

    Attributes:
        st: The stance foot (0 left, 1 right); ``ankles``, ``velocities`` and ``foot_yaws`` are left, right.
    """

    robot: RobotModel
    time: float  # [s]
    rate: float  # [Hz]
    lift: float  # [m] least height of the swinging ankle above its landing height
    omega: float  # [1/s]
    st: int
    com: Array  # [m]
    dcm: Array  # [m]
    p1: Array  # [m]
    swing_time: float  # [s]
    st_yaw: float  # [rad]
    pelvis_yaw: float  # [rad]
    ankles: list[Array]  # [m]
    velocities: list[Array]  # [m/s]
    foot_yaws: tuple[float, float]  # [rad]


def capture_pattern_parts(plan: CaptureState, s: Array, settle: float,
                          landing: Array) -> Parts[tuple[WalkingPattern, Array]]:
    """The capture pattern for one landing (the module docstring's three phases) at times ``s`` [s] after the
    capture, and the rest point [m], in parts (:mod:`zmpwalk.slices`: a few vectorised operations over every
    sample each, about 0.1 ms for 2 000 samples)."""
    robot, st, omega = plan.robot, plan.st, plan.omega
    rest = rest_point(plan, landing)
    xi, xi_rate = _dcm_at(plan, rest, settle, s)
    yield
    zmp = xi - xi_rate / omega  # p = xi - xi' / omega
    c = yield from _com_path(plan, rest, settle, s)
    yield
    n = len(s)
    pelvis = np.column_stack([c, np.full(n, plan.com[2])])
    pelvis_velocity = np.column_stack([omega * (xi - c), np.zeros(n)])
    yield
    foot_position, foot_velocity = yield from _feet(plan, s, landing)
    yield
    yaws, yaw_rates = _foot_yaws(plan, s)
    yield
    yield from _crouch(robot, s, pelvis, pelvis_velocity, plan.pelvis_yaw, foot_position)
    yield
    support = np.where(s < plan.swing_time, Support.LEFT if st == 0 else Support.RIGHT,
                       Support.DOUBLE).astype(np.int8)
    steps, phases = _record(plan, landing, settle, int(support[0]))
    pattern = WalkingPattern(
        robot=robot, rate=plan.rate, generator="capture", time=plan.time + s, support=support,
        position_pelvis_in_world=pelvis, velocity_pelvis_in_world=pelvis_velocity,
        yaw_pelvis_in_world=np.full(n, plan.pelvis_yaw), yaw_rate_pelvis=np.zeros(n),
        position_left_ankle_in_world=foot_position[0], velocity_left_ankle_in_world=foot_velocity[0],
        yaw_left_foot_in_world=yaws[0], yaw_rate_left_foot=yaw_rates[0],
        position_right_ankle_in_world=foot_position[1], velocity_right_ankle_in_world=foot_velocity[1],
        yaw_right_foot_in_world=yaws[1], yaw_rate_right_foot=yaw_rates[1],
        zmp_in_world=zmp, steps=steps, support_phases=phases)
    return pattern, rest



def rest_point(plan: CaptureState, landing: Array) -> Array:
    """Where the capture's DCM comes to rest [m], (2,): the midpoint of the stance sole's and the landed sole's
    centres."""
    robot, st, yaw = plan.robot, plan.st, plan.st_yaw
    st_side = 1 if st == 0 else -1
    stance_centre = plan.ankles[st][:2] + turned(np.array([robot.sole_center_x, st_side * robot.sole_center_y]), yaw)
    landed_centre = landing + turned(np.array([robot.sole_center_x, -st_side * robot.sole_center_y]), yaw)
    return np.asarray((stance_centre + landed_centre) / 2, dtype=np.float64)


def zmp_margin_of_capture(plan: CaptureState, landing: Array, settle: float) -> float:
    r"""The least margin [m] of the capture pattern's ZMP to its support polygon (> 0 inside), over the whole
    pattern, in closed form: no sample is made.

    - Single support: the ZMP is ``p1`` (:func:`_dcm_at`: ``p = xi - xi' / omega = p1``), in the stance sole.
    - The settle and after, both soles: with ``xi = m + D (1 - b(tau))``, ``D = xi(T) - m``,
      ``xi' = -D b'(tau) / settle``, the ZMP is :math:`p = m + D\,g(\tau)`,
      :math:`g = 1 - b + b' / (\omega\,\mathrm{settle})`, one line through the rest point ``m`` (``g = 0`` at rest).
      A point's margin to a convex polygon is concave along a line, so its least value over the path is at the
      extremes of ``g`` on ``[0, 1]``: the ends, or where :math:`g' = -b' + b'' / (\omega\,\mathrm{settle}) = 0`,
      i.e. (with ``b' = 30 tau^2 (1 - tau)^2``, ``b'' = 60 tau (1 - tau)(1 - 2 tau)``, divided by ``30 tau (1 - tau)``)
      :math:`-\tau(1 - \tau) + 2 k (1 - 2\tau) = 0`, ``k = 1 / (omega settle)``: :math:`\tau^2 - (1 + 4k)\tau +
      2k = 0`.

    Checked against the margin of the sampled pattern in the tests.
    """
    rest = rest_point(plan, landing)
    dcm_touchdown = plan.p1 + (plan.dcm - plan.p1) * math.exp(plan.omega * plan.swing_time)
    k = 1.0 / (plan.omega * settle)
    half_sum = (1.0 + 4.0 * k) / 2.0
    root = 2.0 * k / (half_sum + math.sqrt(half_sum**2 - 2.0 * k))  # the root in (0, 1) (the other is > 1)
    taus = [0.0, 1.0] + ([root] if 0.0 < root < 1.0 else [])
    single, double = (phase.polygon(plan.robot).tolist() for phase in _record(plan, landing, settle, Support.LEFT)[1])
    margin = point_margin(float(plan.p1[0]), float(plan.p1[1]), single)
    for tau in taus:
        b, slope, _ = smoothstep5(np.array(tau))
        g = 1.0 - float(b) + k * float(slope)
        point = rest + (dcm_touchdown - rest) * g
        margin = min(margin, point_margin(float(point[0]), float(point[1]), double))
    return margin


def _dcm_at(plan: CaptureState, rest: Array, settle: float, t: Array) -> tuple[Array, Array]:
    """The planned DCM [m] and its rate [m/s] at times ``t`` (n,) after the capture: running away from ``p1``
    until touchdown, then along the quintic to ``rest`` over ``settle`` [s], then at rest."""
    p1, dcm, omega, swing_time = plan.p1, plan.dcm, plan.omega, plan.swing_time
    dcm_touchdown = p1 + (dcm - p1) * math.exp(omega * swing_time)
    t = np.asarray(t, dtype=float)
    xi, rate_xi = np.empty((len(t), 2)), np.empty((len(t), 2))
    single = t < swing_time - 1e-12
    grow = np.exp(omega * t[single])[:, None]
    xi[single], rate_xi[single] = p1 + (dcm - p1) * grow, omega * (dcm - p1) * grow
    later = ~single
    blend, slope, _ = smoothstep5(np.clip((t[later] - swing_time) / settle, 0.0, 1.0))
    xi[later] = rest + (dcm_touchdown - rest) * (1.0 - blend)[:, None]
    rate_xi[later] = -(dcm_touchdown - rest) * (slope / settle)[:, None]
    return xi, rate_xi


def _com_path(plan: CaptureState, rest: Array, settle: float, s: Array) -> Parts[Array]:
    r"""The CoM's horizontal path [m] (n, 2) at ``s``: the solution of ``c' = omega (xi - c)`` from the plan's CoM
    point, in closed form for each phase of :func:`_dcm_at`'s DCM:

    - single support, ``xi = p1 + A e^{omega t}``, ``A = xi_0 - p1``:
      :math:`c = p_1 + \tfrac{A}{2} e^{\omega t} + (c_0 - p_1 - \tfrac{A}{2}) e^{-\omega t}`;
    - the settle, ``xi = m + D (1 - b(tau))``, ``b`` the quintic smoothstep, ``tau = (t - T) / settle``: the
      particular solution of a polynomial DCM is :math:`\sum_{k=0}^{5} (-1/\omega)^k \xi^{(k)}`, so
      :math:`c = m + D\,(1 - \sum_{k=0}^{5} u^k b^{(k)}(\tau)) + (c_T - c_p(T)) e^{-\omega (t - T)}`,
      ``u = -1 / (omega settle)``;
    - at rest, ``xi = m``: :math:`c = m + (c_E - m) e^{-\omega (t - T - settle)}`.

    Each is checked against a fine numerical integration in the tests. Bounded work: no loop over the samples; a
    part per phase.
    """
    omega, swing_time, p1 = plan.omega, plan.swing_time, plan.p1
    c0, a = plan.com[:2], plan.dcm - plan.p1

    def single(time: Array | float) -> Array:
        return np.asarray(p1 + a / 2 * np.exp(omega * time) + (c0 - p1 - a / 2) * np.exp(-omega * time))

    dcm_touchdown = p1 + a * math.exp(omega * swing_time)
    gap = dcm_touchdown - rest
    u = -1.0 / (omega * settle)

    def particular(tau: Array | float) -> Array:
        tau = np.asarray(tau, dtype=float)
        derivatives = (*smoothstep5(tau), 60.0 - 360.0 * tau + 360.0 * tau**2, -360.0 + 720.0 * tau,
                       np.full_like(tau, 720.0))  # b and its first five derivatives
        series = sum(u**k * d for k, d in enumerate(derivatives))
        return np.asarray(rest + gap * (1.0 - series))

    c_touchdown = single(swing_time)
    start_offset = c_touchdown - particular(0.0)

    def settling(time: Array | float) -> Array:
        return particular((time - swing_time) / settle) + start_offset * np.exp(-omega * (time - swing_time))

    c_end = settling(swing_time + settle)
    end = swing_time + settle
    t = np.asarray(s, dtype=float)
    c = np.empty((len(t), 2))
    single_mask = t < swing_time - 1e-12
    resting = t > end
    settle_mask = ~single_mask & ~resting
    c[single_mask] = single(t[single_mask][:, None])
    yield
    c[settle_mask] = settling(t[settle_mask][:, None])
    yield
    c[resting] = rest + (c_end - rest) * np.exp(-omega * (t[resting][:, None] - end))
    return c


def _feet(plan: CaptureState, s: Array, landing: Array) -> Parts[tuple[list[Array], list[Array]]]:
    """The ankles' positions [m] and velocities [m/s] at ``s``, left and right, (n, 3) each: the stance one stays,
    the swinging one moves along quintics to ``landing``, lifted :attr:`CaptureSettings.lift` on the way (in two
    parts)."""
    st, swing_time, ankles, velocities = plan.st, plan.swing_time, plan.ankles, plan.velocities
    sw, n = 1 - st, len(s)
    foot_position = [np.repeat(ankles[f][None], n, axis=0) for f in range(2)]
    foot_velocity = [np.zeros((n, 3)) for _ in range(2)]
    swing = s < swing_time
    ground = float(ankles[st][2])
    way, way_rate = quintic_from_rest(ankles[sw][:2], velocities[sw][:2], landing, swing_time, s[swing])
    foot_position[sw][swing, :2], foot_velocity[sw][swing, :2] = way, way_rate
    foot_position[sw][~swing, :2] = landing
    yield
    top = max(float(ankles[sw][2]), ground + plan.lift)
    first = s < swing_time / 2
    up, up_rate = quintic_from_rest(ankles[sw][2:], velocities[sw][2:], np.array([top]), swing_time / 2, s[first])
    down, down_rate = quintic_from_rest(np.array([top]), np.zeros(1), np.array([ground]), swing_time / 2,
                                        s[swing & ~first] - swing_time / 2)
    foot_position[sw][first, 2], foot_velocity[sw][first, 2] = up[:, 0], up_rate[:, 0]
    foot_position[sw][swing & ~first, 2], foot_velocity[sw][swing & ~first, 2] = down[:, 0], down_rate[:, 0]
    foot_position[sw][~swing, 2] = ground
    return foot_position, foot_velocity


def _foot_yaws(plan: CaptureState, s: Array) -> tuple[list[Array], list[Array]]:
    """The feet's yaws [rad] and yaw rates [rad/s] at ``s``, left and right: the swinging foot turns to the stance
    foot's yaw during the swing."""
    sw, n, swing_time = 1 - plan.st, len(s), plan.swing_time
    yaw_blend, yaw_slope, _ = smoothstep5(np.clip(s / swing_time, 0.0, 1.0))
    start_yaw = float(plan.foot_yaws[sw])
    yaws = [np.full(n, float(plan.foot_yaws[f])) for f in range(2)]
    yaw_rates = [np.zeros(n), np.zeros(n)]
    yaws[sw] = start_yaw + (plan.st_yaw - start_yaw) * yaw_blend
    yaw_rates[sw] = (plan.st_yaw - start_yaw) * yaw_slope / swing_time
    return yaws, yaw_rates


def _record(plan: CaptureState, landing: Array, settle: float,
            single: int) -> tuple[list[StepRecord], list[SupportPhase]]:
    """The capture pattern's step (one ``"capture"`` step) and its support phases (the single support ``single``
    until touchdown, double after)."""
    st, time, swing_time, st_yaw = plan.st, plan.time, plan.swing_time, plan.st_yaw
    sw = 1 - st
    st_pose = Pose2D(float(plan.ankles[st][0]), float(plan.ankles[st][1]), st_yaw)
    sw_pose = Pose2D(float(landing[0]), float(landing[1]), st_yaw)
    sides = (1, -1)
    both = ((st_pose, sides[st]), (sw_pose, sides[sw])) if st == 0 else ((sw_pose, sides[sw]), (st_pose, sides[st]))
    phases = [SupportPhase(time, time + swing_time, single, ((st_pose, sides[st]),)),
              SupportPhase(time + swing_time, math.inf, Support.DOUBLE, both)]
    step = StepRecord(start=time, duration=swing_time, swing=("left", "right")[sw], kind="capture",
                      landing=(float(landing[0]), float(landing[1]), st_yaw),
                      parameters={"swing_time": swing_time, "settle": settle})
    return [step], phases



def _crouch(robot: RobotModel, s: Array, pelvis: Array, pelvis_velocity: Array, pelvis_yaw: float,
            feet: list[Array]) -> Parts[None]:
    """Lower the CoM point (in place) where a leg would otherwise be out of reach: a capture step can carry the
    body further from the stance foot than the walk's height allows. The least lowering that keeps each hip
    within the leg's reach less :data:`REACH_MARGIN` of its ankle, ``dz <= sqrt(r^2 - h^2)`` with ``h`` the
    horizontal distance, is reached along a quintic by the first sample that needs it, and then held (a part per
    leg)."""
    reach = robot.max_leg_reach - REACH_MARGIN
    hips = hip_positions_in_world(pelvis, np.full(len(s), pelvis_yaw), robot)
    needed = np.zeros(len(s))
    for hip, ankle in zip(hips, feet, strict=True):
        yield
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
