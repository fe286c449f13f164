"""The linear inverted pendulum of Lim, Kim, Son and Kang, Section 3: its steady step and its pieces.

With the body at constant height ``z_b`` the ZMP equation reduces, on each horizontal axis, to (Eq. 4)

.. math:: \\ddot x_b - a^2 x_b = -a^2 x_{ZMP}, \\qquad a = \\sqrt{g / z_b}

and a piecewise-constant ZMP gives hyperbolic body motion in closed form (Eq. 5). A steady step (Fig. 3)
is a double support of ``t4`` at constant speed ``v_xD`` followed by a single support of ``t5 = t1 + t2 + t3``
(:class:`SteadyStep`, Eq. 11: :func:`steady_step` from the paper's inputs, :func:`solve_step` from a step time).
An axis is a sequence of *pieces*, each holding one constant ZMP or coasting (:func:`propagate`,
:func:`run_pieces`); the ZMPs that take a state to another are solved in closed form (:func:`solve_zmps`;
the start from standstill: :func:`transient_zmps`, Eq. 15).

The paper's straight walk (:mod:`zmpwalk.patterns.hyperbolic`) and the online stages of the hyperbolic pelvis
(:mod:`zmpwalk.patterns.lipm_stage`) both build on these.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from zmpwalk.errors import InfeasiblePatternError

# ---------------------------------------------------------------------------------------- steady step

@dataclass(frozen=True)
class SteadyStep:
    """One steady step of Fig. 3, relative to the body position ``x0`` at the start of its single support.

    Attributes:
        stride: ``x_s`` [m] (each step advances the body by ``x_s / 2``).
        zmp1: ``x_ZMP1 - x0`` [m].
        zmp2: ``x_ZMP2 - x0`` [m].
        v_double: ``v_xD`` [m/s], body speed in double support and at the single support's ends.
        v_single: ``v_xS`` [m/s], body speed in interval II (Eq. 11b).
        end: ``x' - x0`` [m], body at the end of the single support (Eq. 11c).
        t1, t2, t3: Intervals I-III of the single support [s] (Eqs. 11a, 11h; t3 = t1).
        t4: Double support [s] (Eq. 11d).
        t5: Single support ``t1 + t2 + t3`` [s].
        y_zmp: Lateral ZMP, the supporting foot [m] (magnitude).
        y0: Lateral body position at the single support's ends [m] (Eq. 11e, magnitude).
        v_y: Lateral body speed in double support [m/s] (Eq. 11f, magnitude).
    """

    stride: float  # [m]
    zmp1: float  # [m]
    zmp2: float  # [m]
    v_double: float  # [m/s]
    v_single: float  # [m/s]
    end: float  # [m]
    t1: float  # [s]
    t2: float  # [s]
    t3: float  # [s]
    t4: float  # [s]
    t5: float  # [s]
    y_zmp: float  # [m]
    y0: float  # [m]
    v_y: float  # [m/s]

    @property
    def period(self) -> float:
        """Step time ``t4 + t5`` [s]."""
        return self.t4 + self.t5


def steady_step(a: float, stride: float, zmp1: float, zmp2: float, v_double: float, y_zmp: float,
                x0: float = 0.0) -> SteadyStep:
    """Eq. 11: times and speeds of the steady step from the paper's inputs.

    Args:
        a: ``sqrt(g / z_b)`` [1/s].
        stride: ``x_s`` [m].
        zmp1, zmp2: ``x_ZMP1``, ``x_ZMP2`` [m] (same origin as ``x0``).
        v_double: ``v_xD`` [m/s].
        y_zmp: ``y_ZMP`` [m].
        x0: Body at the start of the single support [m].

    Raises:
        InfeasiblePatternError: A condition of Eq. 11 fails; the message names it with the numbers.
    """
    lag = x0 - zmp1
    if not v_double > a * (zmp1 - x0):
        raise InfeasiblePatternError(
            f"v_xD > a (x_ZMP1 - x0) fails: v_xD = {v_double:g} m/s, a (x_ZMP1 - x0) = {a * (zmp1 - x0):g} m/s")
    numerator, denominator = v_double - a * lag, v_double + a * lag
    if numerator <= 0 or denominator <= 0:
        raise InfeasiblePatternError(
            f"Eq. 11a needs positive logarithm arguments: v_xD -+ a (x0 - x_ZMP1) = {numerator:g}, {denominator:g} m/s")
    t1 = math.log(numerator / denominator) / (2 * a)  # Eq. 11a
    v_single = a * lag * math.sinh(a * t1) + v_double * math.cosh(a * t1)  # Eq. 11b
    end = zmp1 + zmp2 - x0  # Eq. 11c
    t4 = ((x0 + stride / 2) - end) / v_double  # Eq. 11d (without the printed stray factor a)
    if t4 <= 0:
        raise InfeasiblePatternError(
            f"Eq. 11d needs x0 + x_s/2 > x' : x0 + x_s/2 = {x0 + stride / 2:g} m, x' = {end:g} m")
    if zmp2 < zmp1 or v_single <= 0:
        raise InfeasiblePatternError(
            f"Eq. 11h needs x_ZMP2 >= x_ZMP1 and v_xS > 0: x_ZMP1 = {zmp1:g}, x_ZMP2 = {zmp2:g} m, "
            f"v_xS = {v_single:g} m/s")
    t2 = (zmp2 - zmp1) / v_single  # Eq. 11h
    t3 = t1  # intervals I and III travel the same distance (Eq. 6)
    t5 = t1 + t2 + t3
    y0, v_y = lateral_sway(a, t4, t5, y_zmp)
    return SteadyStep(stride, zmp1 - x0, zmp2 - x0, v_double, v_single, end - x0, t1, t2, t3, t4, t5, y_zmp, y0,
                      v_y)


def lateral_sway(a: float, t4: float, t5: float, y_zmp: float) -> tuple[float, float]:
    """Eqs. 11e-11g: lateral body position at the single support's ends and double-support speed.

    ``q = exp(a t5)`` (READING-NOTES: the printed q of Eq. 11e equals this).

    Raises:
        InfeasiblePatternError: Eq. 11g's logarithm argument is not positive (no periodic sway).
    """
    q = math.exp(a * t5)
    y0 = a * t4 * y_zmp * (1 - q) / ((1 - q) * a * t4 - 2 * (1 + q))  # Eq. 11e
    v_y = 2 * y0 / t4 if t4 > 0 else 0.0  # Eq. 11f
    if y_zmp != 0 and t4 > 0:
        top, bottom = -v_y + a * (y0 - y_zmp), v_y + a * (y0 - y_zmp)
        if not top / bottom > 0:
            raise InfeasiblePatternError(f"Eq. 11g needs a positive logarithm argument: {top:g} / {bottom:g}")
    return y0, v_y


@functools.lru_cache(maxsize=1024)  # the online walker solves the same few steps at every stage
def solve_step(a: float, stride: float, step_time: float, dsp_time: float, y_zmp: float) -> SteadyStep:
    """A steady step that takes ``step_time`` with a double support of ``dsp_time``.

    ``t4 = dsp_time``; ``x_ZMP1 - x0 = rho x_s``, ``x_ZMP2 - x0 = 2 rho x_s`` (the paper's ratio) and
    ``v_xD = x_s (1/2 - 3 rho) / t4`` (Eq. 11d); ``rho`` is found by bisection so that
    ``t5 = t1 + t2 + t3 = step_time - dsp_time``. ``t5`` rises monotonically from 0 (``rho -> 0``) to
    infinity (``v_xD -> a (x_ZMP1 - x0)``, the limit of Eq. 11a), so the root is unique.

    Raises:
        InfeasiblePatternError: ``dsp_time`` not inside ``(0, step_time)``.
    """
    if not 0 < dsp_time < step_time:
        raise InfeasiblePatternError(
            f"the double support must be shorter than the step: d = {dsp_time:g} s, T = {step_time:g} s")
    single = step_time - dsp_time
    if abs(stride) < 1e-9:  # [m] stepping on the spot: no sagittal motion
        y0, v_y = lateral_sway(a, dsp_time, single, y_zmp)
        return SteadyStep(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, single / 2, 0.0, single / 2, dsp_time, single, y_zmp,
                          y0, v_y)
    sign = 1.0 if stride > 0 else -1.0
    s = abs(stride)

    def single_time(rho: float) -> float:
        v = s * (0.5 - 3 * rho) / dsp_time
        t1 = math.log((v + a * rho * s) / (v - a * rho * s)) / (2 * a)
        v_single = -a * rho * s * math.sinh(a * t1) + v * math.cosh(a * t1)
        return 2 * t1 + rho * s / v_single

    low, high = 0.0, 0.5 / (a * dsp_time + 3)  # v_xD = a (x_ZMP1 - x0) at the upper end
    for _ in range(200):
        middle = 0.5 * (low + high)
        if single_time(middle) < single:
            low = middle
        else:
            high = middle
        if high - low < 1e-15:
            break
    rho = 0.5 * (low + high)
    step = steady_step(a, s, rho * s, 2 * rho * s, s * (0.5 - 3 * rho) / dsp_time, y_zmp)
    if sign > 0:
        return step
    return SteadyStep(stride, -step.zmp1, -step.zmp2, -step.v_double, -step.v_single, -step.end, step.t1,
                      step.t2, step.t3, step.t4, step.t5, step.y_zmp, step.y0, step.v_y)


# A piece of an axis: (duration [s], slot): slot 0 or 1 is the unknown ZMP it holds, COAST none.
COAST = -1
Piece = tuple[float, int]


def propagate(a: float, position: float, velocity: float, duration: float, zmp: float | None
              ) -> tuple[float, float]:
    """State after ``duration`` [s] of one piece: constant ``zmp`` (Eq. 5) or coasting (None)."""
    if zmp is None:
        return position + velocity * duration, velocity
    c, s = math.cosh(a * duration), math.sinh(a * duration)
    return (position - zmp) * c + velocity / a * s + zmp, (position - zmp) * a * s + velocity * c  # Eq. 5


def run_pieces(a: float, position: float, velocity: float, pieces: list[Piece], zmps: tuple[float, float]
               ) -> tuple[float, float]:
    """The state after ``pieces``, each holding ZMP ``zmps[slot]`` or coasting."""
    for duration, slot in pieces:
        position, velocity = propagate(a, position, velocity, duration, None if slot == COAST else zmps[slot])
    return position, velocity


def solve_zmps(a: float, position: float, velocity: float, pieces: list[Piece], target: tuple[float, float]
               ) -> tuple[float, float]:
    """The two ZMPs (slots 0 and 1) that take ``(position, velocity)`` to ``target`` through ``pieces``.

    The end state is affine in the ZMPs (Eq. 5 is affine in ``c``), so three runs give the map and
    one 2x2 solve the ZMPs.

    Raises:
        InfeasiblePatternError: The pieces cannot reach every end state (a slot acts too briefly).
    """
    base = np.array(run_pieces(a, position, velocity, pieces, (0.0, 0.0)))
    matrix = np.column_stack([np.array(run_pieces(a, position, velocity, pieces, (1.0, 0.0))) - base,
                              np.array(run_pieces(a, position, velocity, pieces, (0.0, 1.0))) - base])
    if abs(np.linalg.det(matrix)) < 1e-12:
        raise InfeasiblePatternError(
            "the hyperbolic pattern cannot reach its end state: the single support is too short for two ZMPs")
    first, second = np.linalg.solve(matrix, np.array(target) - base)
    return float(first), float(second)


def single_support_zmps(a: float, x: float, v: float, step: SteadyStep, x_end: float, v_end: float
                        ) -> tuple[float, float]:
    """ZMPs of intervals I and III that take the body from ``(x, v)`` to ``(x_end, v_end)`` in ``t5``
    (interval II coasts: the ZMP under the body)."""
    return solve_zmps(a, x, v, [(step.t1, 0), (step.t2, COAST), (step.t3, 1)], (x_end, v_end))


# ---------------------------------------------------------------------------------------- transient

def transient_zmps(a: float, t_star: float, tau_star: float, position: float, velocity: float) -> tuple[float, float]:
    """Eq. 15: ZMPs of the start from standstill (double support ``t*``, then single support ``tau*``).

    The body starts at rest at 0 and must reach ``position`` with ``velocity``
    (Eq. 14) at the end. Returns ``(x_ZMP0D, x_ZMP0S)`` [m]; the same function
    gives the lateral ZMPs with ``y`` for ``x`` (Section 3.2).
    """
    den = a * (-math.sinh(a * t_star) + math.sinh(a * (t_star + tau_star)) - math.sinh(a * tau_star))
    zmp_double = (-a * position * math.sinh(a * tau_star) - velocity * (1 - math.cosh(a * tau_star))) / den  # 15a
    zmp_single = (-a * position * (math.sinh(a * tau_star) - math.sinh(a * (t_star + tau_star)))
                  + velocity * (math.cosh(a * tau_star) - math.cosh(a * (t_star + tau_star)))) / den  # Eq. 15b
    return zmp_double, zmp_single
