"""The hyperbolic (linear inverted pendulum) pelvis of one stage: Lim et al.'s pattern, online, in 2-D.

The online walker plans one *stage* (one swing, see :mod:`zmpwalk.patterns.stages`) at a time
from the pelvis state it inherits. With the pelvis (the centre of mass) at constant height ``z_b``
the ZMP equation of Lim et al. (Eq. 4) holds for each horizontal axis on its own:

.. math:: \\ddot p - a^2 p = -a^2 p_{ZMP}, \\qquad a = \\sqrt{g / z_b}

in *any* fixed horizontal frame, because the two axes do not couple. A stage is therefore solved in
the frame of its supporting foot (``u`` along the foot's heading, ``w`` to its left), which is fixed
while the foot stands: that is how turning enters, and why it is exact. Each axis is a sequence
of pieces, each either

* *constant ZMP* ``c``: the hyperbolic motion of Eq. 5, ``p = (p_0 - c) cosh(a t) + (v_0/a) sinh(a t) + c``;
* *coasting*: the ZMP under the body, zero acceleration, constant speed (Eq. 7b's double support).

**A walking stage** (duration ``T``, double support ``d``; a half of the double support at each end)
is the steady step of Fig. 3 laid on the stage:

* along ``u``: coast ``d/2``; interval I (ZMP ``u_1``) ``t_1``; interval II (coast) ``t_2``;
  interval III (ZMP ``u_2``) ``t_3``; coast ``d/2``. The times are those of the steady step of
  this stage's stride, step time and double support (:func:`~zmpwalk.patterns.pendulum.solve_step`,
  Eq. 11).
* across ``w``: coast ``d/2``; ZMP ``w_1`` over the first half of the single support, ``w_2`` over
  the second; coast ``d/2``. In steady walking ``w_1 = w_2 = y_ZMP`` (Eq. 10: one lateral ZMP).

The stage ends with the *divergent component of motion* ``xi = p + p'/a`` (the part of the
pendulum's state that grows; ``xi' = a (xi - p_ZMP)``) of its own command's *steady state* in the
middle of the next double support: along, ``d/2`` short of ``x0`` of the new supporting foot at the
speed ``v_xD`` (Eqs. 11a-d, ``x_s = 2 f``); across, midway between the soles at the sway speed
``v_y`` (Eqs. 11e-f) towards the new support, plus the sideways drift of a side step (the middle of
the feet moves ``A/2`` per stage). The two ZMPs of an axis are its *nominal* ones (along, the
steady step's ``x_ZMP1``, ``x_ZMP2``; across, the sole centre: Eq. 10) moved by one common amount,
found in closed form (``xi`` at the end is affine in it, Eq. 5), that puts ``xi`` there. The other
component, ``p - p'/a``, converges by itself (by ``exp(-a T)`` per stage), so a step like the one
before it converges to the paper's steady step, and each stage starts from the state the last one
ended in (position and velocity continuous at every boundary), whatever it was. A change of stride,
step time or direction moves the ZMPs within the stage, as far as it has to and no further.

One departure from the paper: Lim et al. put the body above the supporting ankle when the single
support begins (``x0``), so their ZMPs ``x0 + x_s/8`` and ``x0 + x_s/4`` both lie ahead of it and
the heel half of the sole is never used. Here ``x0`` is set back so that the two ZMPs straddle the
sole centre (``x0 = c - (x_ZMP1 + x_ZMP2 - 2 x0) / 2``): the same step (Eq. 11), half the excursion
towards the toe. On HUBO this takes random walks (10 commands, strides up to 0.3 m) from 24 of 50
feasible to 50 of 50.

**Starting and stopping** (Eqs. 12-15 generalised): from standstill the *start* stage (both feet
down) holds one ZMP, just off the middle of the feet, that gives the pendulum the ``xi`` the first
swing's steady state has (Eq. 15 solves the paper's version of this with two ZMPs for the full
state). The closing swing holds one ZMP per axis over its single support that ends with ``xi`` on
the middle of the ankles: the state from which the pendulum can come to rest there; the *settle*
stage (both feet down) holds two ZMPs, one per half, that bring it to rest exactly (the full state,
solved as a 2x2 system: :func:`~zmpwalk.patterns.pendulum.solve_zmps`).

**Feasibility.** The ZMP is the pattern's own input here, so it is checked, not assumed: at every
piece boundary (the ZMP is constant or moves with the body on a straight line between them, so the
boundaries bound it) it must lie in the support polygon of the moment: both soles' hull in double
support, the supporting sole in single support. A stage that would need the ZMP outside raises
:class:`~zmpwalk.errors.InfeasiblePatternError` with the point, the time and the distance.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InfeasiblePatternError, InvalidParameterError
from zmpwalk.footsteps import Pose2D, StagePlan, foot_corners
from zmpwalk.patterns.pendulum import COAST, Piece, propagate, run_pieces, solve_step, solve_zmps
from zmpwalk.patterns.result import PHASE_TIME_TOL
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import ALONE, Parts, whole
from zmpwalk.zmp import convex_hull, point_margin

Array = NDArray[np.float64]

PIECES = 5  # pieces per axis of a stage (unused trailing pieces last 0 s)
GROUNDED_KINDS = ("start", "settle")  # stages with both feet down
ZMP_TOLERANCE = 1e-9  # [m] how far outside its polygon a ZMP may be from rounding alone

@dataclass(frozen=True)
class LipmAxis:
    """One axis of a stage's pelvis in the supporting foot's frame: :data:`PIECES` pieces.

    Attributes:
        starts: Start of each piece from the stage start [s].
        position: Pelvis coordinate at each piece's start [m].
        velocity: Its rate [m/s].
        zmp: The piece's constant ZMP [m], NaN where the piece coasts.
    """

    starts: tuple[float, ...]  # [s]
    position: tuple[float, ...]  # [m]
    velocity: tuple[float, ...]  # [m/s]
    zmp: tuple[float, ...]  # [m], NaN: coasting


@dataclass(frozen=True)
class LipmPelvis:
    """The hyperbolic pelvis of one stage.

    Attributes:
        yaw: Heading of the stage's frame (the supporting foot's yaw) in world [rad]; ``u`` along it,
            ``w`` to its left.
        along, across: The ``u`` and ``w`` axes.
        zmp_margin: Smallest distance of the stage's ZMP inside its support polygon [m].
    """

    yaw: float  # [rad]
    along: LipmAxis
    across: LipmAxis
    zmp_margin: float  # [m]


def dcm_zmps(a: float, position: float, velocity: float, pieces: list[Piece], nominal: tuple[float, float],
             dcm: float) -> tuple[float, float]:
    """The ``nominal`` ZMPs (slots 0 and 1), both moved by one amount, that end the pieces with the
    divergent component of motion at ``dcm``.

    .. math:: \\xi = p + \\dot p / a, \\qquad \\dot \\xi = a (\\xi - p_{ZMP})

    Only ``xi`` diverges; the other component, ``p - \\dot p / a``, converges by itself. One common
    shift is the smallest largest move of the two ZMPs that sets ``xi`` (both push it the same way).
    """

    def end_dcm(shift: float) -> float:
        end = run_pieces(a, position, velocity, pieces, (nominal[0] + shift, nominal[1] + shift))
        return end[0] + end[1] / a

    base = end_dcm(0.0)
    shift = (dcm - base) / (end_dcm(1.0) - base)  # xi at the end is affine in the shift (Eq. 5)
    return nominal[0] + shift, nominal[1] + shift


def _axis(a: float, position: float, velocity: float, pieces: list[Piece], zmps: tuple[float, float]
          ) -> tuple[LipmAxis, tuple[float, float]]:
    """The axis through its pieces, padded to :data:`PIECES`, and its end state."""
    starts, positions, velocities, values = [], [], [], []
    t = 0.0
    for duration, slot in pieces:
        starts.append(t)
        positions.append(position)
        velocities.append(velocity)
        zmp = None if slot == COAST else zmps[slot]
        values.append(math.nan if zmp is None else zmp)
        position, velocity = propagate(a, position, velocity, duration, zmp)
        t += duration
    while len(starts) < PIECES:  # empty coasting pieces at the end
        starts.append(t)
        positions.append(position)
        velocities.append(velocity)
        values.append(math.nan)
    return LipmAxis(tuple(starts), tuple(positions), tuple(velocities), tuple(values)), (position, velocity)


def _heading(yaw: float) -> tuple[Array, Array]:
    return np.array([math.cos(yaw), math.sin(yaw)]), np.array([-math.sin(yaw), math.cos(yaw)])


def _xy(pose: Pose2D) -> Array:
    return np.array([pose.x, pose.y])


def sole_centre(pose: Pose2D, foot: int, robot: RobotModel) -> Array:
    """Centre of a foot's sole in world [m], shape (2,)."""
    centre = pose.compose(robot.sole_center_x, foot * robot.sole_center_y)
    return np.array([centre.x, centre.y])


def steady_state(support: Pose2D, support_foot: int, other: Pose2D, forward: float, step_time: float,
                 dsp_time: float, drift: Array, robot: RobotModel) -> tuple[Array, Array]:
    """The pelvis state [m], [m/s] (world) in the middle of the double support before ``support`` carries
    the robot, in steady walking of stride ``forward`` [m] and step time ``step_time`` [s].

    Along the supporting foot's heading: ``d/2`` short of its sole centre, at the steady step's
    ``v_xD`` (Eqs. 11a-d, with ``x_s = 2 forward``); across it: midway between the soles at the
    steady sway speed ``v_y`` towards it (Eqs. 11e-f, ``y_ZMP`` half the soles' distance across),
    plus ``drift`` [m/s] (world).

    Raises:
        InfeasiblePatternError: No steady step has this stride, step time and double support.
    """
    a = math.sqrt(robot.gravity / robot.pendulum_length)
    heading, left = _heading(support.yaw)
    centre = sole_centre(support, support_foot, robot)
    middle = 0.5 * (centre + sole_centre(other, -support_foot, robot))
    across = float((centre - middle) @ left)
    step = solve_step(a, 2.0 * forward, step_time, dsp_time, abs(across))
    start = float((centre - middle) @ heading) - 0.5 * (step.zmp1 + step.zmp2)  # x0
    position = middle + (start - step.v_double * dsp_time / 2) * heading
    velocity = step.v_double * heading + math.copysign(step.v_y, across) * left + drift
    return position, velocity


def _drift(plan: StagePlan) -> Array:
    """The sideways speed [m/s] (world) of the feet's middle over a stage (a side step's ``A/2`` per stage)."""
    before = 0.5 * (_xy(plan.support_pose) + _xy(plan.swing_start))
    after = 0.5 * (_xy(plan.support_pose) + _xy(plan.swing_end))
    _, left = _heading(plan.swing_end.yaw)
    return float((after - before) @ left) / plan.duration * left


def lipm_pelvis_in_parts(plan: StagePlan, position: tuple[float, float], velocity: tuple[float, float],
                         robot: RobotModel, next_plan: StagePlan | None = None
                         ) -> Parts[tuple[LipmPelvis, tuple[float, float], tuple[float, float]]]:
    """The hyperbolic pelvis of one stage from the inherited state (see the module docstring).
    In parts (the targets, each axis of the pendulum, then the ZMP check span by span; :mod:`zmpwalk.slices`);
    :func:`lipm_pelvis` runs it whole.

    Args:
        plan: The stage's footsteps and timing.
        position, velocity: Pelvis state at the stage start, world [m], [m/s].
        robot: The robot (``pendulum_length`` is ``z_b``).
        next_plan: For a *start* stage, the first swing's plan (its steady state is the target).

    Returns:
        The pelvis, and its end position [m] and velocity [m/s] in world.

    Raises:
        InfeasiblePatternError: No steady step for the stage's timing, or a ZMP outside its polygon.
    """
    a = math.sqrt(robot.gravity / robot.pendulum_length)
    yaw = plan.support_pose.yaw
    heading, left = _heading(yaw)
    p0, v0 = np.array(position), np.array(velocity)
    T, d = plan.duration, plan.parameters.dsp_time
    ankles_middle = 0.5 * (_xy(plan.support_pose) + _xy(plan.swing_end))
    sole = sole_centre(plan.support_pose, -plan.swing, robot)
    along_nominal = across_nominal = (0.0, 0.0)  # offsets of the nominal ZMPs from the sole centre [m]
    if plan.kind == "settle":  # both feet down, to rest above the middle of the ankles
        along_pieces = across_pieces = [(T / 2, 0), (T / 2, 1)]
        rest: Array | None = ankles_middle
    else:
        rest = None
        if plan.kind == "start":  # both feet down, one ZMP, to the first swing's steady state
            if next_plan is None:
                raise InvalidParameterError("next_plan", next_plan, "the first swing's plan for a start stage")
            along_pieces = across_pieces = [(T, 0)]
            sole = 0.5 * (_xy(plan.support_pose) + _xy(plan.swing_start))
            target_p, target_v = steady_state(
                next_plan.support_pose, -next_plan.swing, next_plan.swing_start, next_plan.forward,
                next_plan.duration, next_plan.parameters.dsp_time, _drift(next_plan), robot)
        elif plan.kind == "stop":  # one ZMP, to the middle of the ankles
            along_pieces = across_pieces = [(d / 2, COAST), (T - d, 0), (d / 2, COAST)]
            target_p, target_v = ankles_middle, np.zeros(2)
        else:  # a steady step of Fig. 3 towards this command's steady state
            steady = solve_step(a, 2.0 * plan.forward, T, d, robot.hip_spacing / 2)
            yield ALONE  # the steady step, then the target's: a long part each
            along_pieces = [(d / 2, COAST), (steady.t1, 0), (steady.t2, COAST), (steady.t3, 1), (d / 2, COAST)]
            across_pieces = [(d / 2, COAST), ((T - d) / 2, 0), ((T - d) / 2, 1), (d / 2, COAST)]
            centring = 0.5 * (steady.zmp1 + steady.zmp2)
            along_nominal = (steady.zmp1 - centring, steady.zmp2 - centring)  # Eqs. 11: x_ZMP1 - x0, x_ZMP2 - x0
            target_p, target_v = steady_state(plan.swing_end, plan.swing, plan.support_pose, plan.forward, T, d,
                                              _drift(plan), robot)
        target_dcm = target_p + target_v / a
    yield
    axes = []
    for direction, pieces, nominal in ((heading, along_pieces, along_nominal), (left, across_pieces, across_nominal)):
        x, v = float(p0 @ direction), float(v0 @ direction)
        if rest is not None:
            zmps = solve_zmps(a, x, v, pieces, (float(rest @ direction), 0.0))
        else:
            centre = float(sole @ direction)
            zmps = dcm_zmps(a, x, v, pieces, (centre + nominal[0], centre + nominal[1]), float(target_dcm @ direction))
        axes.append(_axis(a, x, v, pieces, zmps))
        yield
    (along, (u_end, du_end)), (across, (w_end, dw_end)) = axes
    end_position = u_end * heading + w_end * left
    end_velocity = du_end * heading + dw_end * left
    yield
    margin = yield from _zmp_margin(plan, along, across, robot)
    pelvis = LipmPelvis(yaw, along, across, margin)
    return pelvis, (float(end_position[0]), float(end_position[1])), (float(end_velocity[0]), float(end_velocity[1]))


lipm_pelvis = whole(lipm_pelvis_in_parts, "lipm_pelvis")  # the same, run whole


def axis_at_in_parts(a: float, axis_starts: Array, position: Array, velocity: Array, zmp: Array, elapsed: Array
                     ) -> Parts[tuple[Array, Array, Array]]:
    """Position [m], velocity [m/s] and acceleration [m/s^2] of axes at ``elapsed`` [s] from their stage start.
    In parts (each sample's piece, its start state, then the pendulum; :mod:`zmpwalk.slices`).

    Args:
        a: ``sqrt(g / z_b)`` [1/s].
        axis_starts, position, velocity, zmp: Each sample's axis, shape (n, :data:`PIECES`).
        elapsed: Shape (n,).
    """
    # a sample at a piece's start (to PHASE_TIME_TOL, whatever the rounding) is in that piece, as the support
    # phases count it (WalkingPattern.zmp_margin): the ZMP jumps there, and the sample shows the new one
    index = np.clip(np.sum(elapsed[:, None] >= axis_starts - PHASE_TIME_TOL, axis=1) - 1, 0, PIECES - 1)
    yield
    rows = np.arange(len(elapsed))
    tau = elapsed - axis_starts[rows, index]
    x0, v0, c = position[rows, index], velocity[rows, index], zmp[rows, index]
    coasting = np.isnan(c)
    c = np.where(coasting, 0.0, c)
    yield
    ch, sh = np.cosh(a * tau), np.sinh(a * tau)
    hyper_x = (x0 - c) * ch + v0 / a * sh + c  # Eq. 5
    hyper_v = (x0 - c) * a * sh + v0 * ch
    x = np.where(coasting, x0 + v0 * tau, hyper_x)
    v = np.where(coasting, v0, hyper_v)
    acceleration = np.where(coasting, 0.0, a * a * (hyper_x - c))  # Eq. 4
    return x, v, acceleration


@dataclass(frozen=True)
class LipmColumns:
    """The hyperbolic pelvises of a table's stages as column arrays, so that many samples evaluate in one pass.

    Attributes:
        yaw: Each stage's frame heading in world [rad], 0 where a stage has none.
        axes: For the ``along`` then the ``across`` axis, the pieces' starts [s], positions [m], velocities [m/s]
            and ZMPs [m] (NaN: coasting), each shape (stages, :data:`PIECES`), NaN where a stage has none.
    """

    yaw: Array  # [rad]
    axes: list[list[Array]]

    @classmethod
    def of(cls, pelvises: Sequence[LipmPelvis | None]) -> LipmColumns:
        """The columns of ``pelvises`` (None: a stage without one)."""
        unused = np.full(PIECES, np.nan)
        yaw = np.array([p.yaw if p else 0.0 for p in pelvises])
        axes = [
            [np.array([getattr(getattr(p, axis), name) if p else unused for p in pelvises], dtype=float)
             for name in ("starts", "position", "velocity", "zmp")]
            for axis in ("along", "across")]
        return cls(yaw, axes)

    def pelvis_at_in_parts(self, hyperbolic: NDArray[np.bool_], k: NDArray[np.intp], elapsed: Array,
                           robot: RobotModel, curves_xy: tuple[Array, ...]) -> Parts[tuple[Array, ...]]:
        """Pelvis x, y, their rates and accelerations in world: the hyperbolic pelvis where ``hyperbolic`` (per
        sample), else ``curves_xy``. In parts (each axis, then the turn to world).

        Args:
            hyperbolic: Whether each sample's stage has a hyperbolic pelvis, shape (n,).
            k: Each sample's stage, shape (n,).
            elapsed: Each sample's time from its stage start [s], shape (n,).
            robot: The robot (``pendulum_length`` is ``z_b``).
            curves_xy: The pelvis of the curves: x, y [m], their rates [m/s] and accelerations [m/s^2].
        """
        a = math.sqrt(robot.gravity / robot.pendulum_length)
        axes = []
        for starts, position, velocity, zmp in self.axes:
            sample_starts, sample_positions = starts[k], position[k]  # each sample's stage's pieces, (n, PIECES)
            yield
            sample_velocities, sample_zmps = velocity[k], zmp[k]
            yield
            axes.append((yield from axis_at_in_parts(a, sample_starts, sample_positions, sample_velocities,
                                                     sample_zmps, elapsed)))
            yield
        (u, du, ddu), (w, dw, ddw) = axes
        c, s = np.cos(self.yaw[k]), np.sin(self.yaw[k])  # the supporting foot's frame to world
        world = (u * c - w * s, u * s + w * c, du * c - dw * s, du * s + dw * c, ddu * c - ddw * s,
                 ddu * s + ddw * c)
        return tuple(np.where(hyperbolic, value, other) for value, other in zip(world, curves_xy, strict=True))


def _zmp_margin(plan: StagePlan, along: LipmAxis, across: LipmAxis, robot: RobotModel) -> Parts[float]:
    """Smallest margin of the stage's ZMP in its support polygons [m]; raises where it is outside (a part per
    span of constant or linear ZMP)."""
    T, d = plan.duration, plan.parameters.dsp_time
    grounded = plan.kind in GROUNDED_KINDS
    support = foot_corners(plan.support_pose, -plan.swing, robot)
    polygons = [support]
    for swing in (plan.swing_start, plan.swing_end):  # the double supports' polygons, a part each
        yield
        polygons.append(convex_hull(np.vstack([support, foot_corners(swing, plan.swing, robot)])))
    yield
    single, before, after = ([(float(x), float(y)) for x, y in polygon] for polygon in polygons)
    breaks = sorted(t for t in {*along.starts, *across.starts, T} if t <= T + 1e-12)
    c, s = math.cos(plan.support_pose.yaw), math.sin(plan.support_pose.yaw)
    worst, where = math.inf, (0.0, 0.0, 0.0)
    for t0, t1 in itertools.pairwise(breaks):
        if t1 - t0 <= 1e-12:
            continue
        middle = 0.5 * (t0 + t1)
        polygon = before if grounded or middle < d / 2 else after if middle > T - d / 2 else single
        for t in (t0, t1):  # inside a span the ZMP is constant or moves on a straight line: its ends bound it
            u, w = _zmp_at(along, t, middle), _zmp_at(across, t, middle)
            x, y = u * c - w * s, u * s + w * c
            margin = point_margin(x, y, polygon)
            if margin < worst:
                worst, where = margin, (t, x, y)
        yield
    if worst < -ZMP_TOLERANCE:
        t, x, y = where
        raise InfeasiblePatternError(
            f"the hyperbolic pattern needs its ZMP at ({x:.4f}, {y:.4f}) m, {-worst * 1e3:.1f} mm "
            f"outside the support polygon, {t:.3f} s into this {plan.kind} stage (a shorter stride or a longer "
            f"step or double-support time fits)")
    return worst


def _zmp_at(axis: LipmAxis, t: float, inside: float) -> float:
    """The ZMP [m] on one axis at ``t`` [s] of the piece that contains ``inside`` [s] (its value at that end)."""
    k = max(sum(1 for start in axis.starts if inside >= start) - 1, 0)
    zmp = axis.zmp[k]
    if math.isnan(zmp):  # coasting: the ZMP is the body
        return axis.position[k] + axis.velocity[k] * (t - axis.starts[k])
    return zmp
