"""Preview control of the ZMP (Kajita et al. 2003): the baseline generator on zmpwalk's own footsteps.

Kajita, Kanehiro, Kaneko, Fujiwara, Harada, Yokoi, Hirukawa, "Biped walking pattern generation by
using preview control of zero-moment point", ICRA 2003 (cited by both papers). The cart-table model
(Eqs. 1-2 of Park et al.) with the CoM jerk as input, sampled at ``T = 1 / rate``:

.. math::
    x_{k+1} = A x_k + B u_k, \\quad
    A = \\begin{bmatrix} 1 & T & T^2/2 \\\\ 0 & 1 & T \\\\ 0 & 0 & 1 \\end{bmatrix}, \\quad
    B = \\begin{bmatrix} T^3/6 \\\\ T^2/2 \\\\ T \\end{bmatrix}, \\quad
    p_k = C x_k, \\quad C = \\begin{bmatrix} 1 & 0 & -z_c/g \\end{bmatrix}

with ``x = (c, c', c'')`` the CoM along one axis and ``p`` its ZMP. The servo form with the integral
of the tracking error (Katayama et al. 1985) minimises
:math:`\\sum Q_e e_k^2 + \\Delta x_k^T Q_x \\Delta x_k + R \\Delta u_k^2`; with the solution ``P`` of its
discrete algebraic Riccati equation

.. math::
    u_k = -G_i \\sum_{i \\le k} (p_i - p^{ref}_i) - G_x x_k - \\sum_{j=1}^{N} G_d(j)\\, p^{ref}_{k+j}

(the gains below, :func:`preview_gains`). The footsteps, the swing feet, the yaw and the support
phases are those of the polynomial generator for the same commands; only the pelvis (the point above
the CoM) comes from the preview controller, tracking a ZMP reference that sits at the supporting
sole's centre in single support and moves linearly between the soles in double support.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.sides import Support

Array = NDArray[np.float64]

PREVIEW_TIME = 1.6  # [s] preview horizon (Kajita et al. 2003 use 1.6 s)
TRACKING_WEIGHT = 1.0  # Q_e [1/m^2]
JERK_WEIGHT = 1e-6  # R at a 5 ms period (Kajita et al. 2003); scaled with the period in preview_gains
RICCATI_TOLERANCE = 1e-11  # relative change of P at which the doubling iteration stops
RICCATI_ITERATIONS = 80


@dataclass(frozen=True)
class PreviewGains:
    """The preview controller of one sampling period and CoM height.

    Attributes:
        period: ``T`` [s].
        integral: ``G_i`` (on the summed ZMP error).
        state: ``G_x``, shape (3,) (on CoM position, velocity, acceleration).
        preview: ``G_d(j)``, j = 1..N, shape (N,) (on the future ZMP reference).
        a, b, c: The discrete cart-table model.
    """

    period: float  # [s]
    integral: float
    state: Array
    preview: Array
    a: Array
    b: Array
    c: Array


def solve_dare(a: Array, b: Array, q: Array, r: float) -> Array:
    """The stabilising solution ``P`` of :math:`P = A^T P A - A^T P B (R + B^T P B)^{-1} B^T P A + Q`
    (single input), by the structure-preserving doubling algorithm (quadratic convergence).

    Raises:
        InvalidParameterError: No convergence (not stabilisable or detectable).
    """
    n = a.shape[0]
    ak, gk, hk = a.copy(), np.outer(b, b) / r, q.copy()
    identity = np.eye(n)
    for _ in range(RICCATI_ITERATIONS):
        w = np.linalg.solve(identity + gk @ hk, identity)
        a_next = ak @ w @ ak
        g_next = gk + ak @ w @ gk @ ak.T
        h_next = hk + ak.T @ hk @ w @ ak
        if np.max(np.abs(h_next - hk)) <= RICCATI_TOLERANCE * max(1.0, float(np.max(np.abs(h_next)))):
            return np.asarray(0.5 * (h_next + h_next.T), dtype=np.float64)
        ak, gk, hk = a_next, g_next, h_next
    raise InvalidParameterError("preview gains", "no convergence", "a stabilisable cart-table model")


def preview_gains(period: float, com_height: float, gravity: float = 9.81,
                  preview_time: float = PREVIEW_TIME) -> PreviewGains:
    """Gains of Kajita's preview controller for a sampling ``period`` [s] and CoM height [m].

    The jerk weight is :data:`JERK_WEIGHT` at 5 ms and scales with ``(T / 5 ms)^-2``, which keeps the
    continuous-time trade-off for any rate: the cost weighs the jerk increments ``du ~ T u'``, so
    :math:`\\sum R\\,du^2 \approx R T \\int \\dot u^2 dt` against :math:`\\sum Q_e e^2 \approx (Q_e / T) \\int e^2 dt`,
    and the ratio :math:`R T^2 / Q_e` is what must stay.
    """
    t = period
    a = np.array([[1.0, t, t * t / 2], [0.0, 1.0, t], [0.0, 0.0, 1.0]])
    b = np.array([t**3 / 6, t * t / 2, t])
    c = np.array([1.0, 0.0, -com_height / gravity])
    # the servo system on (e, dx): e_{k+1} = e_k + C A dx_k + C B du_k
    a_tilde = np.zeros((4, 4))
    a_tilde[0, 0] = 1.0
    a_tilde[0, 1:] = c @ a
    a_tilde[1:, 1:] = a
    b_tilde = np.concatenate([[c @ b], b])
    q_tilde = np.zeros((4, 4))
    q_tilde[0, 0] = TRACKING_WEIGHT
    r = JERK_WEIGHT * (0.005 / t) ** 2
    p = solve_dare(a_tilde, b_tilde, q_tilde, r)
    gain_scale = 1.0 / (r + b_tilde @ p @ b_tilde)
    k = gain_scale * (b_tilde @ p @ a_tilde)  # (4,)
    closed = a_tilde - np.outer(b_tilde, k)
    steps = max(1, round(preview_time / t))
    preview = np.empty(steps)
    preview[0] = -k[0]
    x = -closed.T @ p @ np.array([1.0, 0.0, 0.0, 0.0])
    for j in range(1, steps):
        preview[j] = gain_scale * (b_tilde @ x)
        x = closed.T @ x
    return PreviewGains(t, float(k[0]), k[1:].copy(), preview, a, b, c)


def track(gains: PreviewGains, reference: Array, start: Array) -> tuple[Array, Array]:
    """Run the preview controller along a ZMP reference of one axis.

    Args:
        gains: From :func:`preview_gains`.
        reference: ``p_ref`` [m] at every sample, shape (n,); held at its last value beyond the end.
        start: CoM state ``(c, c', c'')`` at the first sample [m, m/s, m/s^2].

    Returns:
        The CoM states (n, 3) and the model's ZMP ``C x`` (n,).
    """
    n = len(reference)
    steps = len(gains.preview)
    padded = np.concatenate([reference, np.full(steps, reference[-1])])
    # the preview term of every sample at once: sum_j G_d(j) p_ref(k + j), j = 1..N
    future = np.correlate(padded[1:], gains.preview, mode="valid")[:n]
    gx0, gx1, gx2 = (float(v) for v in gains.state)
    gi = gains.integral
    x0, x1, x2 = (float(v) for v in start)
    t = gains.period
    t2, t3 = t * t / 2, t**3 / 6
    cz = float(gains.c[2])
    error_sum = 0.0
    states: list[tuple[float, float, float]] = []
    zmp: list[float] = []
    # the recursion is sequential: plain floats and lists, no numpy scalar in the loop
    for reference_k, future_k in zip(reference.tolist(), future.tolist(), strict=True):
        states.append((x0, x1, x2))
        p = x0 + cz * x2
        zmp.append(p)
        error_sum += p - reference_k
        u = -gi * error_sum - (gx0 * x0 + gx1 * x1 + gx2 * x2) - future_k
        x0, x1, x2 = x0 + t * x1 + t2 * x2 + t3 * u, x1 + t * x2 + t2 * u, x2 + t * u
    return np.array(states).reshape(n, 3), np.array(zmp)


def zmp_reference(pattern: WalkingPattern, hold: float = 0.0) -> Array:
    """The ZMP reference of a pattern's footsteps, (n, 2) [m]: the supporting sole's centre in single
    support, a straight line from one sole centre to the next in double support, the middle of the soles
    when standing at the start (until ``hold`` [s] at least) and at the end."""
    robot = pattern.robot
    anchors_t: list[float] = []
    anchors_p: list[tuple[float, float]] = []

    def sole_centre(pose: object, side: int) -> tuple[float, float]:
        x, y, yaw = pose.x, pose.y, pose.yaw  # type: ignore[attr-defined]
        cx, cy = robot.sole_center_x, side * robot.sole_center_y
        return x + math.cos(yaw) * cx - math.sin(yaw) * cy, y + math.sin(yaw) * cx + math.cos(yaw) * cy

    def middle(feet: tuple[tuple[object, int], ...]) -> tuple[float, float]:
        points = [sole_centre(pose, side) for pose, side in feet]
        return (sum(p[0] for p in points) / len(points), sum(p[1] for p in points) / len(points))

    phases = pattern.support_phases
    first, last = phases[0], phases[-1]
    anchors_t += [float(pattern.time[0]), max(float(pattern.time[0]), hold)]
    anchors_p += [middle(first.feet), middle(first.feet)]
    for phase in phases:
        if phase.support == Support.DOUBLE:
            continue
        pose, side = phase.feet[0]
        centre = sole_centre(pose, side)
        anchors_t += [phase.begin, phase.end]
        anchors_p += [centre, centre]
    end = float(pattern.time[-1])
    settle = min(last.begin, end)  # the last double support: at rest between the soles from its start
    if settle > anchors_t[-1]:
        anchors_t.append(settle)
        anchors_p.append(middle(last.feet))
    anchors_t.append(max(end, anchors_t[-1]))
    anchors_p.append(middle(last.feet))
    times = np.array(anchors_t)
    points = np.array(anchors_p)
    return np.column_stack([np.interp(pattern.time, times, points[:, 0]),
                            np.interp(pattern.time, times, points[:, 1])])


def _standing_around(pattern: WalkingPattern, seconds: float) -> WalkingPattern:
    """The pattern with ``seconds`` of standing still added before and after it (feet and pelvis held)."""
    pad = round(seconds * pattern.rate)
    n = len(pattern.time)
    index = np.concatenate([np.zeros(pad, dtype=np.intp), np.arange(n), np.full(pad, n - 1, dtype=np.intp)])
    moving = np.zeros(len(index), dtype=bool)
    moving[pad:pad + n] = True
    shift = pad / pattern.rate

    def held(values: Array) -> Array:
        return np.asarray(values[index], dtype=np.float64)

    def rates(values: Array) -> Array:
        out = held(values)
        out[~moving] = 0.0
        return out

    phases = [replace(phase, begin=phase.begin + shift, end=phase.end + shift) for phase in pattern.support_phases]
    phases[0] = replace(phases[0], begin=0.0)
    steps = [replace(step, start=step.start + shift) for step in pattern.steps]
    return replace(
        pattern, time=np.arange(len(index)) / pattern.rate, support=pattern.support[index],
        position_pelvis_in_world=held(pattern.position_pelvis_in_world),
        velocity_pelvis_in_world=rates(pattern.velocity_pelvis_in_world),
        yaw_pelvis_in_world=held(pattern.yaw_pelvis_in_world), yaw_rate_pelvis=rates(pattern.yaw_rate_pelvis),
        position_left_ankle_in_world=held(pattern.position_left_ankle_in_world),
        velocity_left_ankle_in_world=rates(pattern.velocity_left_ankle_in_world),
        yaw_left_foot_in_world=held(pattern.yaw_left_foot_in_world),
        yaw_rate_left_foot=rates(pattern.yaw_rate_left_foot),
        position_right_ankle_in_world=held(pattern.position_right_ankle_in_world),
        velocity_right_ankle_in_world=rates(pattern.velocity_right_ankle_in_world),
        yaw_right_foot_in_world=held(pattern.yaw_right_foot_in_world),
        yaw_rate_right_foot=rates(pattern.yaw_rate_right_foot),
        zmp_in_world=held(pattern.zmp_in_world), steps=steps, support_phases=phases,
    )


def generate_preview(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    rate: float = 100.0,
    schedule: Schedule | None = None,
    labels: Sequence[str] | None = None,
) -> WalkingPattern:
    """The walking pattern of preview control of the ZMP on the polynomial generator's footsteps.

    Args:
        robot: The robot (``pendulum_length`` is the CoM height ``z_c``).
        commands: Step commands, as for :func:`zmpwalk.patterns.polynomial.generate`.
        rate: Samples per second [Hz]; also the controller's rate.
        schedule: Parameter tables (timing, double support, foot lift of the footsteps).
        labels: How an error names each command.

    Returns:
        A :class:`WalkingPattern` whose pelvis follows the preview controller's CoM and whose ZMP is that
        CoM's cart-table ZMP (Eqs. 1-2), not the reference. The footsteps begin :data:`PREVIEW_TIME` later
        than the polynomial generator's and the pattern stands that long after them: the controller
        moves the CoM ahead of the reference by up to its preview time, which it cannot do before t = 0,
        and settles after the last change of the reference.
    """
    footsteps = _standing_around(generate(robot, commands, rate=rate, schedule=schedule, labels=labels),
                                 PREVIEW_TIME)
    gains = preview_gains(1.0 / rate, robot.pendulum_length, robot.gravity)
    reference = zmp_reference(footsteps, hold=PREVIEW_TIME)
    position = footsteps.position_pelvis_in_world.copy()
    velocity = footsteps.velocity_pelvis_in_world.copy()
    zmp = np.empty_like(footsteps.zmp_in_world)
    for axis in (0, 1):
        start = np.array([reference[0, axis], 0.0, 0.0])
        states, zmp[:, axis] = track(gains, reference[:, axis], start)
        position[:, axis] = states[:, 0]
        velocity[:, axis] = states[:, 1]
    return replace(footsteps, generator="preview", position_pelvis_in_world=position,
                   velocity_pelvis_in_world=velocity, zmp_in_world=zmp)


__all__ = ["PreviewGains", "generate_preview", "preview_gains", "solve_dare", "track", "zmp_reference"]
