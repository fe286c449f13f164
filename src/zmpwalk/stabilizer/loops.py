# mypy: disallow-untyped-decorators=False
r"""The compiled stabilizer's feedback loops (numba, cached on disk), one function each: DCM feedback, CoM
admittance, the force distribution between the soles with the ankle damping control, the foot force difference
control, and the torso attitude.

The laws are those of :mod:`zmpwalk.balance` (its docstring numbers them; ``docs/balance.md`` derives them):
Kajita et al. (2010, *Biped walking stabilization based on linear inverted pendulum tracking*, IROS) in the
divergent-component-of-motion form of Englsberger et al. (2015) and Caron et al. (2019, *Stair climbing
stabilization of the HRP-4 humanoid robot using whole-body admittance control*, ICRA). Each function reads its
gains from ``params`` by name (:data:`zmpwalk.stabilizer.layout.P`, the fields of
:class:`~zmpwalk.stabilizer_gains.StabilizerGains`), and reads and writes only its own entries of ``state``
(:data:`zmpwalk.stabilizer.layout.S`) and ``log`` (:data:`zmpwalk.stabilizer.layout.L`).

Positions are in world [m], x forward, y left, z up; angles in radians. The pattern's support is 0 double, 1 left,
2 right; a sole's centre is given by its point in world (:func:`zmpwalk.stabilizer.estimation.sole_centre`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from zmpwalk.stabilizer.freshness import BUILD_KEY
from zmpwalk.stabilizer.layout import DOUBLE_SUPPORT, LEFT_SUPPORT, RIGHT_SUPPORT, L, P, S
from zmpwalk.stabilizer.leg import SECOND, com_in_base
from zmpwalk.stabilizer.rotations import clip, rotate2

MIN_SHARE = 1e-9  # [-] a sole's share of the desired ZMP below which its CoP is not controlled
Point = tuple[float, float]


@njit(cache=True, nogil=True, inline="always")
def whole_body_rest(params: np.ndarray, chain: np.ndarray, work: np.ndarray, log: np.ndarray, yaw: float) -> Point:
    """The planned whole-body CoM's offset from a pelvis point [m], in world, times the gain ``whole_body_rest``
    (0 unless the CoM point is a pelvis point): the pattern's legs (``work[1]``, ``work[3]``) at their planned
    angles and the rest of the body (:mod:`zmpwalk.balance`, step 2)."""
    whole_x = whole_y = 0.0
    if params[P.whole_body_rest] > 0.0:
        qx, qy, _ = com_in_base(params, chain, work, SECOND)
        whole_x, whole_y = rotate2(params[P.whole_body_rest] * qx, params[P.whole_body_rest] * qy, yaw)
    log[L.whole_body_offset], log[L.whole_body_offset + 1] = whole_x, whole_y
    return whole_x, whole_y


@njit(cache=True, nogil=True, inline="always")
def clamp_zmp(params: np.ndarray, zx: float, zy: float, support: int, c0x: float, c0y: float, c1x: float,
              c1y: float, yaw_left: float, yaw_right: float) -> Point:
    """The ZMP moved into the support polygon shrunk by the gain ``zmp_margin`` (single support: the sole; double:
    the segment between the soles' centres widened by the soles' half widths, a conservative hull). The soles are
    given by their centres ``c0``, ``c1`` in world [m] and yaws [rad]."""
    margin = params[P.zmp_margin]
    lx, ly = max(params[P.half_length] - margin, 0.0), max(params[P.half_width] - margin, 0.0)
    if support in (LEFT_SUPPORT, RIGHT_SUPPORT):
        cx, cy, yaw = (c0x, c0y, yaw_left) if support == LEFT_SUPPORT else (c1x, c1y, yaw_right)
        local_x, local_y = rotate2(zx - cx, zy - cy, -yaw)
        bx, by = rotate2(min(max(local_x, -lx), lx), min(max(local_y, -ly), ly), yaw)
        return cx + bx, cy + by
    sx, sy = c1x - c0x, c1y - c0y
    length = math.hypot(sx, sy)
    if length < 1e-9:
        return zx, zy
    ax, ay = sx / length, sy / length
    rx, ry = zx - c0x, zy - c0y
    along = min(max(rx * ax + ry * ay, 0.0), length)
    across = min(max(-rx * ay + ry * ax, -lx), lx)
    return c0x + along * ax - across * ay, c0y + along * ay + across * ax


@njit(cache=True, nogil=True, inline="always")
def dcm_feedback(params: np.ndarray, state: np.ndarray, log: np.ndarray, com: np.ndarray, velocity: Point,
                 centre: Point, zmp: np.ndarray, support: int, c0: Point, c1: Point, yaw_left: float,
                 yaw_right: float) -> tuple[float, float, float, float]:
    r"""DCM tracking (:mod:`zmpwalk.balance`, step 1; Englsberger et al. 2015): the error ``e = xi - xi_ref`` of the
    divergent component ``xi = c + c' / omega`` (the estimate ``centre`` with the state's filtered velocity, the
    pattern's CoM point ``com`` with its ``velocity``) decays at the gain ``dcm`` (``k_xi``) when the ZMP is

    .. math:: p_d = p_{ref} + (1 + k_\xi / \omega)\, e

    kept inside the support polygon (:func:`clamp_zmp`). Returns ``e`` and ``p_d`` [m]."""
    omega = params[P.omega]
    ex = (centre[0] + state[S.com_velocity] / omega) - (com[0] + velocity[0] / omega)
    ey = (centre[1] + state[S.com_velocity + 1] / omega) - (com[1] + velocity[1] / omega)
    gain = 1.0 + params[P.dcm] / omega
    pdx, pdy = clamp_zmp(params, zmp[0] + gain * ex, zmp[1] + gain * ey, support, c0[0], c0[1], c1[0], c1[1],
                         yaw_left, yaw_right)
    log[L.zmp_desired], log[L.zmp_desired + 1] = pdx, pdy
    log[L.dcm_error], log[L.dcm_error + 1] = ex, ey
    return ex, ey, pdx, pdy


@njit(cache=True, nogil=True, inline="always")
def com_admittance(params: np.ndarray, state: np.ndarray, log: np.ndarray, loaded: bool, zmp_measured: Point,
                   zmp_desired: Point, rest_x: float, rest_y: float, support: int, yaw: float) -> Point:
    r"""CoM admittance (:mod:`zmpwalk.balance`, step 2; Caron et al. 2019): the commanded CoM's offset accelerates
    by

    .. math:: \Delta c'' = A (p_{measured} - p_d) - K_v \Delta c' - K_p (\Delta c - \Delta c_{rest})

    (gains ``com_admittance``, ``com_damping``, ``com_stiffness``; no ZMP term with no sole ``loaded``; at an early
    touchdown the caller gives the stance sole's CoP as ``zmp_measured``), kept within
    ``com_limit``; it rests at ``(rest_x, rest_y)`` (the slope's and the whole-body CoM's offsets). Legs without an
    ankle roll cannot move the CoP across the stance sole in single ``support``: the ZMP term's part across the
    pelvis (yaw ``yaw`` [rad]) is left out there, the sideways balance being the step's. Returns the offset [m]."""
    dt = params[P.dt]
    if loaded:
        ax = params[P.com_admittance] * (zmp_measured[0] - zmp_desired[0])
        ay = params[P.com_admittance] * (zmp_measured[1] - zmp_desired[1])
        if params[P.ankle_roll] == 0.0 and support != DOUBLE_SUPPORT:
            along, _ = rotate2(ax, ay, -yaw)
            ax, ay = rotate2(along, 0.0, yaw)
    else:
        ax = ay = 0.0
    ax -= params[P.com_damping] * state[S.offset_rate] + params[P.com_stiffness] * (state[S.offset] - rest_x)
    ay -= params[P.com_damping] * state[S.offset_rate + 1] + params[P.com_stiffness] * (state[S.offset + 1] - rest_y)
    state[S.offset_rate] += ax * dt
    state[S.offset_rate + 1] += ay * dt
    state[S.offset] += state[S.offset_rate] * dt
    state[S.offset + 1] += state[S.offset_rate + 1] * dt
    com_limit = params[P.com_limit]
    norm = math.hypot(state[S.offset], state[S.offset + 1])
    if norm > com_limit:
        state[S.offset] *= com_limit / norm
        state[S.offset + 1] *= com_limit / norm
        state[S.offset_rate] = state[S.offset_rate + 1] = 0.0
    log[L.com_offset], log[L.com_offset + 1] = state[S.offset], state[S.offset + 1]
    return state[S.offset], state[S.offset + 1]


@njit(cache=True, nogil=True, inline="always")
def distribute(zx: float, zy: float, support: int, c0x: float, c0y: float, c1x: float,
               c1y: float) -> tuple[float, float, float, float, float, float]:
    """Load shares of the feet and each sole's CoP target [m] for a desired ZMP, given the soles' centres in world
    [m]: (share left, share right, target left x, y, target right x, y)."""
    if support == LEFT_SUPPORT:
        return 1.0, 0.0, zx, zy, c1x, c1y
    if support == RIGHT_SUPPORT:
        return 0.0, 1.0, c0x, c0y, zx, zy
    sx, sy = c1x - c0x, c1y - c0y
    ratio = min(max(((zx - c0x) * sx + (zy - c0y) * sy) / max(sx * sx + sy * sy, 1e-12), 0.0), 1.0)
    dx, dy = zx - (c0x + ratio * sx), zy - (c0y + ratio * sy)
    return 1.0 - ratio, ratio, c0x + dx, c0y + dy, c1x + dx, c1y + dy


@njit(cache=True, nogil=True, inline="always")
def ankle_damping(params: np.ndarray, state: np.ndarray, log: np.ndarray, loaded0: bool, loaded1: bool,
                  shares: tuple[float, float, float, float, float, float], cops: tuple[float, float, float, float],
                  yaw_left: float, yaw_right: float) -> None:
    r"""Ankle damping control (:mod:`zmpwalk.balance`, step 3; the damping control of Kajita et al. 2010): each
    loaded sole's CoP (``cops``: left x, y, right x, y) follows its share of ``p_d`` (``shares``,
    :func:`distribute`) by turning the foot, ``delta' = -(tau_d - tau) / D - delta / T``, written per metre of CoP
    error (gains ``ankle_gain``, ``ankle_time_constant``, ``ankle_limit``); the foot turns (roll, pitch) in the
    foot's frame go into the state."""
    dt = params[P.dt]
    share0, share1, t0x, t0y, t1x, t1y = shares
    decay = dt / params[P.ankle_time_constant]
    ankle_limit, ankle_gain = params[P.ankle_limit], params[P.ankle_gain]
    for foot in range(2):
        o = S.ankle + 2 * foot
        loaded = loaded0 if foot == 0 else loaded1
        share = share0 if foot == 0 else share1
        if loaded and share > MIN_SHARE:
            if foot == 0:
                error = rotate2(t0x - cops[0], t0y - cops[1], -yaw_left)
            else:
                error = rotate2(t1x - cops[2], t1y - cops[3], -yaw_right)
            state[o] += dt * (-ankle_gain * error[1])
            state[o + 1] += dt * (ankle_gain * error[0])
        state[o] = clip(state[o] - decay * state[o], ankle_limit)
        state[o + 1] = clip(state[o + 1] - decay * state[o + 1], ankle_limit)
    for i in range(4):
        log[L.ankle_offsets + i] = state[S.ankle + i]


@njit(cache=True, nogil=True, inline="always")
def foot_force_difference(params: np.ndarray, state: np.ndarray, log: np.ndarray, support: int, f0: float,
                          f1: float, loaded0: bool, loaded1: bool, share0: float, share1: float) -> float:
    """Foot force difference control (:mod:`zmpwalk.balance`, step 4; Kajita et al. 2010): in double support the
    feet's heights move apart (gain ``force_gain``) until the measured normal forces ``f0 - f1`` [N] are the
    desired shares' difference; a sole the plan has down that carries no load (a late touchdown, an early lift)
    reads the whole weight as the difference and is lowered at the gain ``touchdown_speed``; in single support a
    swinging sole that carries load (an early touchdown) is raised at that speed. Returns the height difference
    [m] (left lowered, right raised by half of it)."""
    dt = params[P.dt]
    weight = f0 + f1
    if support == DOUBLE_SUPPORT:
        state[S.lifted] = state[S.lifted + 1] = 0.0
    elif support == LEFT_SUPPORT and not loaded1:
        state[S.lifted + 1] = 1.0
    elif support == RIGHT_SUPPORT and not loaded0:
        state[S.lifted] = 1.0
    # the swinging sole touches down early: it carries load after it has lifted (not while it lifts)
    early = ((support == LEFT_SUPPORT and loaded1 and state[S.lifted + 1] > 0.0)
             or (support == RIGHT_SUPPORT and loaded0 and state[S.lifted] > 0.0))
    if (early or (support == DOUBLE_SUPPORT and (loaded0 or loaded1))) and weight > 0:
        wanted = (share0 - share1) * weight
        rate_gain = params[P.force_gain] if loaded0 and loaded1 and not early else params[P.touchdown_speed]
        state[S.height] += dt * rate_gain * (wanted - (f0 - f1)) / weight
    state[S.height] -= dt / params[P.force_time_constant] * state[S.height]
    state[S.height] = clip(state[S.height], params[P.force_limit])
    height: float = state[S.height]
    log[L.height_difference] = height
    return height


@njit(cache=True, nogil=True, inline="always")
def torso_attitude(params: np.ndarray, log: np.ndarray, attitude: np.ndarray, rate: np.ndarray) -> Point:
    """Torso attitude (:mod:`zmpwalk.balance`, step 5): the pelvis turn (roll, pitch) [rad] against the measured
    torso roll and pitch [rad] and their rates [rad/s] (gains ``attitude_gain``, ``attitude_damping``,
    ``attitude_limit``)."""
    gain, damping, limit = params[P.attitude_gain], params[P.attitude_damping], params[P.attitude_limit]
    turn_roll = clip(-gain * attitude[0] - damping * rate[0], limit)
    turn_pitch = clip(-gain * attitude[1] - damping * rate[1], limit)
    log[L.pelvis_turn], log[L.pelvis_turn + 1] = turn_roll, turn_pitch
    return turn_roll, turn_pitch


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY
