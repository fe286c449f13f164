# mypy: disallow-untyped-decorators=False
r"""The compiled inverse kinematics of an imported robot, sample by sample (numba, cached on disk): the base placed
under the pattern's centre of mass, both legs' angles there, and their rates.

An imported robot's pattern moves its whole-body CoM (Eqs. 1-2 of Park et al. move one mass), so each sample's
base is found with its legs (:func:`zmpwalk.kinematics.joint_trajectory_in_parts`). Per sample ``k``, one
iteration, repeated until the CoM and both legs are within tolerance at the same angles and base:

1. both legs' frames at their angles (the compiled leg, :mod:`zmpwalk.stabilizer.leg`: the chain
   :class:`~zmpwalk.leg_chain.LegChain` writes as a product of exponentials), and the whole-body CoM there;
2. the base moved horizontally by the CoM's remaining error times a gain, ``p_base += g (c_pattern - c(p_base,
   q))_xy``, until that error is below :data:`~zmpwalk.whole_body.COM_TOLERANCE`. With the feet fixed, moving the
   base by ``d`` moves the CoM by about ``d (1 - m_feet / M)``: ``g = 1`` contracts the error by ``m_feet / M`` (TALOS:
   about 0.15) a move; each axis's ``g`` is learned from the last move (a secant, :func:`_secant_gain`; TALOS:
   1.17), which contracts it by about ``10^-3``;
3. each leg's step towards its ankle and sole as seen from the moved base, by damped least squares:

   .. math:: \Delta q = J^T (J J^T + \lambda^2 I)^{-1} e

   ``e`` the ankle's position error and the rotation vector of the sole's orientation error, at most
   :data:`~zmpwalk.leg_chain.numeric.IK_MAX_STEP` on a joint (the numeric IK of :mod:`zmpwalk.leg_chain.numeric`,
   one sample at a time), until every component is within :data:`~zmpwalk.leg_chain.numeric.IK_TOLERANCE`.

Each sample starts from the angles and base offset extrapolated from the last three samples by the parabola
through them, so the legs stay on the branch they stand in (the reference posture's, at the first sample). At 1 kHz
the guess is then within about a micrometre, and a sample ends at the second iteration (2 forward kinematics and 1
step a leg) in 68 % of TALOS's samples of a 3-step walk and at the third in the rest, where the straight line
through the last two samples needed three in 96 %; the same iteration on whole arrays in numpy cost 58 us a
sample. A sample that does not converge (or is not finite) is reported in ``excess``, and the next one starts from
the last one that did.

Arrays (all float64): ``params`` and ``chain`` of :mod:`zmpwalk.stabilizer.leg` (the parameters read: the robot's
mass, the rest of the body's mass moment, each leg's ankle offset); ``sole_back`` (2, 3, 3) each leg's sole frame
transposed, ``R_s^T`` (the chain's own rotation is the sole's times it); ``start`` (:data:`START_SIZE`,), carried
from one sample (and one call) to the next: the angles of the last sample (12, role-ordered columns) [rad], its
base's offset from the CoM in the base frame (2) [m], the base's gains (2) [-], the sample before's angles and
offset (14), how many samples have been solved (at most 3), and the angles and offset of the sample before that
(14).
"""

from __future__ import annotations

import math
import sys

import numpy as np
from numba import njit

from zmpwalk.leg_chain.numeric import IK_DAMPING, IK_MAX_ITERATIONS, IK_MAX_STEP, IK_TOLERANCE
from zmpwalk.stabilizer import leg as compiled_leg
from zmpwalk.stabilizer.freshness import BUILD_KEY, renew_stale
from zmpwalk.stabilizer.leg import (
    FIRST,
    SECOND,
    ankle_in_base,
    com_in_base,
    leg_jacobian,
    leg_kinematics,
    lu6,
    lu_solve6,
)

Pair = tuple[np.ndarray, np.ndarray]  # the left and the right foot's array (numba: a homogeneous tuple)
UNCONVERGED = 1e3 * IK_TOLERANCE  # [m] or [rad]: a sample whose residual is larger did not converge
START_SIZE = 45  # the carried state of a fill (module docstring)
SECANT_MOVE = 1e-10  # [m] a smaller move of the base does not tell its gain (the CoM is computed to about 1e-13)
SECANT_RANGE = (0.5, 2.0)  # [-] gains outside are not learned: the CoM moves by 0.5-2 times the base's move


@njit(cache=True, nogil=True)
def _orientation_error(target: np.ndarray, frame: np.ndarray, error: np.ndarray) -> None:
    """``error[3:6]`` <- the rotation vector of ``target frame^T`` (axis times angle, up to pi), ``frame`` the
    rotation of a leg's last frame (row-major, ``frame[0:9]``)."""
    def entry(i: int, j: int) -> float:
        return float(target[i, 0] * frame[3 * j] + target[i, 1] * frame[3 * j + 1] + target[i, 2] * frame[3 * j + 2])

    cosine = min(max((entry(0, 0) + entry(1, 1) + entry(2, 2) - 1.0) / 2.0, -1.0), 1.0)
    angle = math.acos(cosine)
    sine = math.sin(angle)
    scale = angle / sine if sine > 1e-9 else 1.0 + angle * angle / 6.0
    error[3] = 0.5 * (entry(2, 1) - entry(1, 2)) * scale
    error[4] = 0.5 * (entry(0, 2) - entry(2, 0)) * scale
    error[5] = 0.5 * (entry(1, 0) - entry(0, 1)) * scale


@njit(cache=True, nogil=True)
def base_under_com(params: np.ndarray, chain: np.ndarray, sole_back: np.ndarray, com: np.ndarray, yaw: np.ndarray,
                   feet: Pair, feet_yaw: Pair, first: int, last: int, start: np.ndarray,
                   tolerance: float, base: np.ndarray, angles: np.ndarray, excess: np.ndarray) -> None:
    """Samples ``first:last``: the base (n, 3) [m] whose whole-body CoM is the pattern's ``com`` (n, 3) [m]
    within ``tolerance`` [m], the legs' angles there (n, 12) [rad], and per leg and sample the IK's residual
    where it did not converge (> 0), else -1 (``excess`` (2, n)); ``yaw`` (n,) the base's heading [rad], ``feet``
    (left, right) each (n, 3) the ankles and ``feet_yaw`` each (n,) the soles' headings in world. ``start``
    (:data:`START_SIZE`,) carries the last samples' angles, base offsets and gains (module docstring).

    One iteration: both legs' frames at their angles, the CoM's error there and the base's move (step 2 of the
    module docstring), then each leg's error from the moved base and its step (step 1); it ends when the CoM and
    both legs are within tolerance at the same angles and base."""
    work = np.zeros((4, 7, 12))
    scratch = np.empty((3, 6, 6))
    errors = np.empty((2, 6))
    target = np.empty(3)
    rotation = np.empty((3, 3))
    columns = start[:12]
    for k in range(first, last):
        _extrapolate(start)
        c, s = math.cos(yaw[k]), math.sin(yaw[k])
        bx = com[k, 0] + c * start[12] - s * start[13]
        by = com[k, 1] + s * start[12] + c * start[13]
        bz = com[k, 2]
        sx = sy = 0.0  # the base's last move [m]
        residuals = (math.inf, math.inf)
        placed = converged = False
        ex = ey = 0.0  # the CoM's error [m]
        for _ in range(IK_MAX_ITERATIONS):
            leg_kinematics(chain, FIRST, columns, work[0])
            leg_kinematics(chain, SECOND, columns, work[2])
            mx, my, _ = com_in_base(params, chain, work, 0)
            ex = com[k, 0] - (bx + c * mx - s * my)
            ey = com[k, 1] - (by + s * mx + c * my)
            placed = max(abs(ex), abs(ey)) < tolerance
            if placed:
                sx = sy = 0.0
            else:
                start[14] = _secant_gain(start[14], sx, ex)
                start[15] = _secant_gain(start[15], sy, ey)
                sx, sy = start[14] * ex, start[15] * ey
                bx += sx
                by += sy
            for leg in range(2):
                _leg_target(feet, feet_yaw, sole_back, k, leg, yaw[k], c, s, bx, by, bz, target, rotation)
                _leg_error(params, leg, work[2 * leg], target, rotation, errors[leg])
            residuals = (_largest(errors[0]), _largest(errors[1]))
            if placed and residuals[0] <= IK_TOLERANCE and residuals[1] <= IK_TOLERANCE:
                converged = True
                break
            for leg in range(2):
                if residuals[leg] > IK_TOLERANCE:
                    _newton_step(params, chain, leg, work[2 * leg], columns, errors[leg], scratch)
        base[k, 0], base[k, 1], base[k, 2] = bx, by, bz
        for m in range(12):
            angles[k, m] = _wrap(columns[m])
        misplaced = 0.0 if converged or placed else max(abs(ex), abs(ey))  # a CoM not placed: both legs say so
        for leg in range(2):
            residual = misplaced if residuals[leg] <= misplaced else residuals[leg]  # (NaN kept)
            excess[leg, k] = -1.0 if converged or residual <= UNCONVERGED else residual  # (NaN: reported)
        dx, dy = bx - com[k, 0], by - com[k, 1]
        start[12], start[13] = c * dx + s * dy, -s * dx + c * dy
        if not converged:
            _restart(start)  # the next sample starts from the last good one, not from a leg stretched towards this


@njit(cache=True, nogil=True, inline="always")
def _extrapolate(start: np.ndarray) -> None:
    """The next sample's first guess in ``start`` (:data:`START_SIZE`): the angles and base offset extrapolated from
    the last three samples by the parabola through them, ``3 x_k - 3 x_(k-1) + x_(k-2)`` (from the last two by the
    line through them, from the last one alone, before there are three or two), the last two kept."""
    solved = start[30]
    for m in range(14):
        last, before = start[m], start[16 + m]
        if solved >= 3.0:
            start[m] = 3.0 * (last - before) + start[31 + m]
        elif solved >= 2.0:
            start[m] = 2.0 * last - before
        start[31 + m] = before
        start[16 + m] = last
    start[30] = min(solved + 1.0, 3.0)


@njit(cache=True, nogil=True, inline="always")
def _restart(start: np.ndarray) -> None:
    """``start`` back to the sample before's angles and offset (kept by :func:`_extrapolate`), not extrapolated."""
    for m in range(14):
        start[m] = start[16 + m]
    start[30] = 0.0


@njit(cache=True, nogil=True, inline="always")
def _largest(values: np.ndarray) -> float:
    """The largest magnitude of ``values`` (NaN where one is NaN)."""
    largest = 0.0
    for value in values:
        if not abs(value) <= largest:  # NaN too
            largest = abs(value)
    return largest


@njit(cache=True, nogil=True)
def _leg_target(feet: Pair, feet_yaw: Pair, sole_back: np.ndarray, k: int, leg: int, yaw: float,
                c: float, s: float, bx: float, by: float, bz: float, target: np.ndarray, rotation: np.ndarray) -> None:
    """Sample ``k``'s ankle of ``leg`` (``target`` (3,) [m]) and the chain's own rotation (``rotation`` (3, 3):
    the sole's turned back by ``R_s``) seen from the base at ``(bx, by, bz)`` [m] with heading ``yaw`` [rad]
    (its cosine ``c`` and sine ``s``)."""
    rx, ry = feet[leg][k, 0] - bx, feet[leg][k, 1] - by
    target[0], target[1], target[2] = c * rx + s * ry, -s * rx + c * ry, feet[leg][k, 2] - bz
    turn = feet_yaw[leg][k] - yaw
    ct, st = math.cos(turn), math.sin(turn)
    for j in range(3):  # R_z(turn) R_s^T
        rotation[0, j] = ct * sole_back[leg, 0, j] - st * sole_back[leg, 1, j]
        rotation[1, j] = st * sole_back[leg, 0, j] + ct * sole_back[leg, 1, j]
        rotation[2, j] = sole_back[leg, 2, j]


@njit(cache=True, nogil=True)
def _leg_error(params: np.ndarray, leg: int, frames: np.ndarray, target: np.ndarray, rotation: np.ndarray,
               error: np.ndarray) -> None:
    """``error`` (6,) <- the leg's ankle error [m] and the rotation vector of its orientation error [rad], from its
    ``frames`` to ``target`` and ``rotation`` (:func:`_leg_target`)."""
    ankle = ankle_in_base(params, leg, frames)
    for i in range(3):
        error[i] = target[i] - ankle[i]
    _orientation_error(rotation, frames[6], error)


@njit(cache=True, nogil=True)
def _newton_step(params: np.ndarray, chain: np.ndarray, leg: int, frames: np.ndarray, columns: np.ndarray,
                 error: np.ndarray, scratch: np.ndarray) -> None:
    """The leg's damped least-squares step ``J^T (J J^T + lambda^2 I)^-1 e`` for its ``error`` (6,) (overwritten)
    at its ``frames``, at most :data:`IK_MAX_STEP` on a joint, added to ``columns`` (12, role-ordered) [rad];
    ``scratch`` (3, 6, 6) holds the Jacobian, ``J J^T`` and the row swaps."""
    jacobian, jjt, swaps = scratch[0], scratch[1], scratch[2, 1]
    leg_jacobian(chain, leg, frames, ankle_in_base(params, leg, frames), jacobian)
    for i in range(6):
        for j in range(6):
            total = IK_DAMPING * IK_DAMPING if i == j else 0.0
            for m in range(6):
                total += jacobian[i, m] * jacobian[j, m]
            jjt[i, j] = total
    lu6(jjt, swaps)
    lu_solve6(jjt, swaps, error)
    largest = 0.0
    for i in range(6):  # the step J^T y, into jjt's first row (no longer needed)
        step = 0.0
        for m in range(6):
            step += jacobian[m, i] * error[m]
        jjt[0, i] = step
        largest = max(largest, abs(step))
    scale = min(1.0, IK_MAX_STEP / max(largest, 1e-300))
    for i in range(6):
        columns[6 * leg + int(chain[leg, i, 10])] += scale * jjt[0, i]


@njit(cache=True, nogil=True, inline="always")
def _secant_gain(gain: float, moved: float, error: float) -> float:
    """The base's move per unit of CoM error along one axis, learned from its last move ``moved`` [m], which
    changed the error by ``moved / gain - error`` [m]: ``moved`` over that change, where the move was large
    enough to tell (:data:`SECANT_MOVE`) and the response is one of a base carrying most of the mass
    (:data:`SECANT_RANGE`); else ``gain`` kept."""
    if abs(moved) < SECANT_MOVE:
        return gain
    change = moved / gain - error
    if change == 0.0:
        return gain
    learned = moved / change
    return learned if SECANT_RANGE[0] <= learned <= SECANT_RANGE[1] else gain


@njit(cache=True, nogil=True)
def joint_rates(params: np.ndarray, chain: np.ndarray, time: np.ndarray, angles: np.ndarray, base: np.ndarray,
                com: np.ndarray, velocity_com: np.ndarray, yaw: np.ndarray, yaw_rate: np.ndarray, feet: Pair,
                feet_velocity: Pair, feet_yaw_rate: Pair, first: int, last: int,
                rates: np.ndarray) -> None:
    """Samples ``first:last`` of the joint rates (n, 12) [rad/s] that give each ankle its velocity relative to the
    base, ``J(q)^-1 twist`` (:meth:`~zmpwalk.leg_chain.LegChain.joint_rates`). The base's velocity is the CoM's,
    ``velocity_com`` (n, 3) [m/s], plus the time derivative of the base's offset from it (:func:`_offset_rate`:
    the base of samples ``first - 1`` to ``last`` is read); ``yaw_rate`` (n,) [rad/s] is the base's,
    ``feet_velocity`` (left, right) each (n, 3) [m/s] and ``feet_yaw_rate`` each (n,) [rad/s] the ankles' and
    soles' in world. A
    singular leg's rates are NaN."""
    frames = np.empty((7, 12))
    jacobian = np.empty((6, 6))
    swaps = np.empty(6)
    twist = np.empty(6)
    for k in range(first, last):
        c, s = math.cos(yaw[k]), math.sin(yaw[k])
        vbx = velocity_com[k, 0] + _offset_rate(time, base, com, k, 0)
        vby = velocity_com[k, 1] + _offset_rate(time, base, com, k, 1)
        vbz = velocity_com[k, 2] + _offset_rate(time, base, com, k, 2)
        for leg in range(2):
            rx, ry = feet[leg][k, 0] - base[k, 0], feet[leg][k, 1] - base[k, 1]
            vx = feet_velocity[leg][k, 0] - vbx + yaw_rate[k] * ry  # in the rotating base frame
            vy = feet_velocity[leg][k, 1] - vby - yaw_rate[k] * rx
            twist[0], twist[1] = c * vx + s * vy, -s * vx + c * vy
            twist[2] = feet_velocity[leg][k, 2] - vbz
            twist[3], twist[4], twist[5] = 0.0, 0.0, feet_yaw_rate[leg][k] - yaw_rate[k]
            leg_kinematics(chain, leg, angles[k], frames)
            leg_jacobian(chain, leg, frames, ankle_in_base(params, leg, frames), jacobian)
            singular = lu6(jacobian, swaps) == 0.0
            if not singular:
                lu_solve6(jacobian, swaps, twist)
            for i in range(6):
                rates[k, 6 * leg + int(chain[leg, i, 10])] = math.nan if singular else twist[i]


@njit(cache=True, nogil=True, inline="always")
def _offset_rate(time: np.ndarray, base: np.ndarray, com: np.ndarray, k: int, axis: int) -> float:
    """The time derivative at sample ``k`` of the base's offset from the CoM along ``axis`` [m/s], as
    ``numpy.gradient`` takes it: one-sided at the ends, second order inside (on uneven steps too); 0 for one
    sample."""
    n = len(time)
    if n < 2:
        return 0.0
    if k == 0 or k == n - 1:
        a, b = (0, 1) if k == 0 else (n - 2, n - 1)
        return float(((base[b, axis] - com[b, axis]) - (base[a, axis] - com[a, axis])) / (time[b] - time[a]))
    h1, h2 = time[k] - time[k - 1], time[k + 1] - time[k]
    before, here, after = (base[k - 1, axis] - com[k - 1, axis], base[k, axis] - com[k, axis],
                           base[k + 1, axis] - com[k + 1, axis])
    return float((h1 * h1 * after - h2 * h2 * before + (h2 * h2 - h1 * h1) * here) / (h1 * h2 * (h1 + h2)))


@njit(cache=True, nogil=True, inline="always")
def _wrap(angle: float) -> float:
    """``angle`` [rad] in [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@njit("int64()", cache=True, nogil=True)
def compiled_key() -> int:
    """:data:`~zmpwalk.stabilizer.freshness.BUILD_KEY` as this module's compiled functions know it."""
    return BUILD_KEY


# this module's cached code holds the compiled leg's: renew both where a module or the layout changed since
renew_stale((compiled_leg, sys.modules[__name__]))

__all__ = ["START_SIZE", "UNCONVERGED", "base_under_com", "joint_rates"]
