r"""Kinematics of any 6-DoF leg: forward, Jacobian, closed-form inverse where the axes allow, numeric otherwise.

A leg imported from a robot's model is a chain of six revolute joints from the
pelvis (the floating base) to the foot, in any order and with any axes. It is
written as a product of exponentials in the **pelvis frame** (the base body's
frame; x forward, y left, z up) at the model's zero configuration:

.. math::
    T_{foot}(q) = e^{\hat\xi_1 q_1} e^{\hat\xi_2 q_2} \cdots e^{\hat\xi_6 q_6} M,
    \qquad \xi_i = (\omega_i, r_i)

with ``omega_i`` the unit axis of joint ``i`` and ``r_i`` a point on it, both at
``q = 0``, and ``M = (R_s, A_0)`` the **foot frame** at ``q = 0``: its origin
``A_0`` is the ankle point (where the two ankle axes meet, or the last joint's
anchor), its axes the **sole frame** ``R_s`` (:attr:`LegChain.sole_rotation`:
x forward along the sole, z its normal), which is level when the sole is flat
on the floor. A model whose sole is tilted at zero angles (a foot box pitched
10 degrees, level in the keyframe) has ``R_s = R_y(10 deg)``
(:func:`zmpwalk.robots.collision.foot_sole`): the inverse kinematics is asked
for the sole's pose, so a walking pattern's flat foot is a flat sole. Angles
are the model's own (its signs and zeros).

**Five-joint legs** (hip yaw, roll and pitch, knee, ankle pitch: Unitree H1)
are a six-joint chain whose ankle roll is **virtual** (:attr:`LegChain.virtual`):
an axis along the sole's x axis, ``a = R_s e_x``, through the sole's centre line
on the floor (:mod:`zmpwalk.robots.legs`), which no motor turns. The chain is
solved as any six-joint leg; the virtual angle it returns is the sole's roll
that the five joints cannot give. It leaves the sole's x axis where the target
puts it: with ``R_{1..5}`` the rotation of the five real joints,

.. math:: R_{foot} e_x = R_{1..5}\, e^{\hat a q_6} R_s e_x = R_{1..5}\, e^{\hat a q_6} a = R_{1..5}\, a,

and every point of the axis where the target puts it (a rotation fixes its
axis): the five real joints meet the sole's centre line on the floor and the
sole's heading and pitch exactly, and the virtual angle is the sole's
**residual roll** about that line: what the foot rolls on the floor when the
real joints are sent alone (``tests/test_five_joint_legs.py``).

**Closed form** (:meth:`LegChain.solve`), wherever the three hip axes meet in
one point ``H`` and the two ankle axes meet in one point ``A_0`` (any axis order:
yaw-roll-pitch as HUBO and TALOS, pitch-roll-yaw, ...). With the target
``g = T_d M^{-1}``, three subproblems of Paden and Kahan (Murray, Li and
Sastry, *A Mathematical Introduction to Robotic Manipulation*, 1994, Sec. 3.3):

1. the knee (subproblem 3): the hip joints turn about ``H`` and the ankle joints
   fix ``A_0``, so ``|e^{\hat\xi_4 q_4} A_0 - H| = |g A_0 - H|``;
2. the ankle (subproblem 2, two intersecting axes):
   ``e^{\hat\xi_5 q_5} e^{\hat\xi_6 q_6} (g^{-1} H) = e^{-\hat\xi_4 q_4} H``;
3. the hip (subproblem 2 on the third hip axis, then subproblem 1):
   ``e^{\hat\xi_1 q_1} e^{\hat\xi_2 q_2} e^{\hat\xi_3 q_3} = g\,(e^{\hat\xi_4 q_4} e^{\hat\xi_5 q_5}
   e^{\hat\xi_6 q_6})^{-1}``.

Each subproblem has up to two solutions; zmpwalk takes, at each, the one
nearest the leg's reference angles (the ready posture), so the knee keeps the
branch it stands in.

**Numeric** (damped least squares, warm-started from the reference angles and
iterated on every sample at once) where the axes do not meet, such as Booster
T1's hip (pitch, roll and yaw axes 2 cm and 8.2 cm apart):

.. math:: \Delta q = J^T (J J^T + \lambda^2 I)^{-1} e

with ``e`` the foot's position error and the rotation vector of its
orientation error. It stops when every sample is within :data:`IK_TOLERANCE`;
a sample that does not converge is reported with its remaining error as the
``excess`` of :meth:`LegChain.solve`, and a joint trajectory then raises
:class:`~zmpwalk.errors.UnreachableError` naming the leg and the time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

IK_TOLERANCE = 1e-10  # [m] and [rad]: convergence of the numeric IK
IK_MAX_ITERATIONS = 100
IK_DAMPING = 1e-6  # lambda of the damped least squares [-]
IK_MAX_STEP = 0.3  # [rad] largest joint change of one iteration (keeps far targets from overshooting)
AXES_MEET_TOLERANCE = 1e-6  # [m] axes closer than this meet (closed form applies)


def _rodrigues(axis: Array, angle: Array) -> Array:  # the IK's few rotations; transforms() has its own
    """Rotation matrices about a fixed unit ``axis`` (3,) by ``angle`` (n,), shape (n, 3, 3)."""
    x, y, z = axis
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.asarray(np.eye(3) + s * k + (1.0 - c) * (k @ k), dtype=np.float64)


def cross3(a: Array, b: Array) -> Array:
    """Cross products along the last axis of 3-vectors (``np.cross`` without its axis handling, which
    dominates on the small arrays of one control tick)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


_EYE = np.eye(3)


def _wrap(angle: Array) -> Array:
    return np.asarray((angle + np.pi) % (2 * np.pi) - np.pi, dtype=np.float64)


def _nearest(candidates: list[Array], reference: float) -> Array:
    """Per sample, the candidate angle (each (n,)) nearest ``reference`` (wrap-aware)."""
    stacked = np.stack(candidates)
    distance = np.abs(_wrap(stacked - reference))
    return np.asarray(stacked[np.argmin(distance, axis=0), np.arange(stacked.shape[1])], dtype=np.float64)


def _subproblem1(axis: Array, u: Array, v: Array) -> Array:
    """Angle about ``axis`` (3,) taking vectors ``u`` to ``v`` (n, 3) (Paden-Kahan 1; projections)."""
    up = u - np.outer(u @ axis, axis)
    vp = v - np.outer(v @ axis, axis)
    return np.asarray(np.arctan2(np.einsum("ni,ni->n", np.cross(up, vp), np.broadcast_to(axis, up.shape)),
                                 np.einsum("ni,ni->n", up, vp)), dtype=np.float64)


def _subproblem2(axis1: Array, axis2: Array, u: Array, v: Array) -> tuple[list[tuple[Array, Array]], Array]:
    """``exp(axis1 t1) exp(axis2 t2) u = v`` for vectors (n, 3) about axes through one point (Paden-Kahan 2).

    Returns:
        The two solutions ``(t1, t2)`` and ``gamma^2`` (< 0 where none exists; the nearest is taken there).
    """
    w12 = float(axis1 @ axis2)
    cross = np.cross(axis1, axis2)
    denominator = w12 * w12 - 1.0
    a = (w12 * (u @ axis2) - v @ axis1) / denominator
    b = (w12 * (v @ axis1) - u @ axis2) / denominator
    gamma2 = (np.einsum("ni,ni->n", u, u) - a * a - b * b - 2 * a * b * w12) / float(cross @ cross)
    gamma = np.sqrt(np.maximum(gamma2, 0.0))
    solutions = []
    for sign in (1.0, -1.0):
        z = np.outer(a, axis1) + np.outer(b, axis2) + np.outer(sign * gamma, cross)
        solutions.append((_subproblem1(axis1, z, v), _subproblem1(axis2, u, z)))
    return solutions, np.asarray(gamma2, dtype=np.float64)


def _closest_point_to_lines(points: Array, axes: Array) -> tuple[Array, float]:
    """The point nearest to several lines (least squares) and the largest distance of it to one of them [m]."""
    a = np.zeros((3, 3))
    b = np.zeros(3)
    for point, axis in zip(points, axes, strict=True):
        projector = np.eye(3) - np.outer(axis, axis)
        a += projector
        b += projector @ point
    centre = np.linalg.lstsq(a, b, rcond=None)[0]
    distances = [float(np.linalg.norm((np.eye(3) - np.outer(w, w)) @ (centre - p))) for p, w in zip(points, axes,
                                                                                                       strict=True)]
    return np.asarray(centre, dtype=np.float64), max(distances)


@dataclass(frozen=True, eq=False)
class LegChain:
    """One leg as six revolute joints in the pelvis frame (see the module docstring).

    Attributes:
        side: +1 left, -1 right.
        joint_names: The model's joint names, hip to ankle.
        axes: Unit joint axes at ``q = 0`` in the pelvis frame, (6, 3).
        points: A point on each axis at ``q = 0`` (the joint's anchor) [m], (6, 3).
        ankle: Origin of the foot frame at ``q = 0`` [m], (3,).
        reference: Angles that choose the IK branch (the ready posture) [rad], (6,).
        lower, upper: Joint ranges [rad], (6,) (``-inf``/``inf`` where unlimited).
        link_masses: Mass of each segment (what joint ``i`` moves up to the next joint) [kg], (6,).
        link_coms: Its centre of mass at ``q = 0`` in the pelvis frame [m], (6, 3).
        role_order: Chain index of each role (hip yaw, hip roll, hip pitch, knee, ankle pitch, ankle
            roll): ``angles[:, role_order]`` lists a solution in the role order of zmpwalk's joint columns.
        sole_rotation: The sole frame in the pelvis frame at ``q = 0`` (the rotation of ``M``), (3, 3).
        virtual: Chain index of the virtual joint of a five-joint leg (its ankle roll, which no motor turns;
            see the module docstring), or None.
        sole_tilt_reference: The (roll, pitch) of the sole's lowest points' plane in the model's reference
            posture, relative to level [rad] (:class:`zmpwalk.robots.collision.Sole`; for reading).
    """

    side: int
    joint_names: tuple[str, ...]
    axes: Array
    points: Array
    ankle: Array
    reference: Array = field(default_factory=lambda: np.zeros(6))
    lower: Array = field(default_factory=lambda: np.full(6, -np.inf))
    upper: Array = field(default_factory=lambda: np.full(6, np.inf))
    role_order: tuple[int, ...] = (0, 1, 2, 3, 4, 5)
    link_masses: Array = field(default_factory=lambda: np.zeros(6))
    link_coms: Array = field(default_factory=lambda: np.zeros((6, 3)))
    sole_rotation: Array = field(default_factory=lambda: np.eye(3))
    virtual: int | None = None
    sole_tilt_reference: tuple[float, float] = (0.0, 0.0)  # [rad]

    @property
    def virtual_column(self) -> int | None:
        """The virtual joint's place among the leg's six role-ordered columns (5: the ankle roll), or None."""
        return None if self.virtual is None else list(self.role_order).index(self.virtual)

    def residual_roll(self, q: Array) -> Array:
        """The sole's roll about its own x axis that the real joints cannot give [rad], (n,): the virtual joint's
        angle of a five-joint leg (zeros for a six-joint leg)."""
        q = np.atleast_2d(q)
        return np.asarray(q[:, self.virtual] if self.virtual is not None else np.zeros(len(q)), dtype=np.float64)

    def link_com_positions(self, q: Array, transforms: tuple[Array, Array] | None = None) -> Array:
        """Centres of mass of the six moving segments in the pelvis frame [m], (n, 6, 3).

        Segment ``i`` is everything joint ``i`` moves up to the next joint; :attr:`link_coms` holds its
        centre of mass at ``q = 0``.
        """
        rotations, translations = self.transforms(q) if transforms is None else transforms
        return np.asarray((rotations[:, 1:] @ self.link_coms[:, :, None])[..., 0] + translations[:, 1:])

    @property
    def label(self) -> str:
        return "left" if self.side > 0 else "right"

    @property
    def hip(self) -> Array:
        """Hip centre: the point nearest the three hip axes [m], (3,)."""
        return _closest_point_to_lines(self.points[:3], self.axes[:3])[0]

    @property
    def hip_axes_offset(self) -> float:
        """Largest distance of the hip centre from a hip axis [m] (0 where they meet)."""
        return _closest_point_to_lines(self.points[:3], self.axes[:3])[1]

    @property
    def ankle_axes_offset(self) -> float:
        """Distance between the two ankle axes at the ankle point [m] (0 where they meet)."""
        return _closest_point_to_lines(self.points[4:], self.axes[4:])[1]

    @property
    def closed_form(self) -> bool:
        """True where the hip axes meet in a point and the ankle axes meet (Paden-Kahan closed form)."""
        return self.hip_axes_offset < AXES_MEET_TOLERANCE and self.ankle_axes_offset < AXES_MEET_TOLERANCE

    @property
    def knee_point(self) -> Array:
        """Point of the knee axis nearest the hip centre [m], (3,)."""
        w, r = self.axes[3], self.points[3]
        return np.asarray(r + w * float(w @ (self.hip - r)), dtype=np.float64)

    @property
    def ankle_point(self) -> Array:
        """Point nearest both ankle axes (the ankle centre) [m], (3,)."""
        return _closest_point_to_lines(self.points[4:], self.axes[4:])[0]

    # --- forward kinematics -------------------------------------------------------------------------------
    def __post_init__(self) -> None:
        skews = np.array([[[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]] for w in self.axes])
        object.__setattr__(self, "_skews", skews)
        object.__setattr__(self, "_skews2", skews @ skews)

    def transforms(self, q: Array) -> tuple[Array, Array]:
        """Cumulative rotations (n, 7, 3, 3) and translations (n, 7, 3): ``prod_{j<i} exp(xi_j q_j)``, i = 0..6."""
        q = np.atleast_2d(q)
        n = len(q)
        rotations = np.empty((n, 7, 3, 3))
        translations = np.empty((n, 7, 3))
        rotations[:, 0] = _EYE
        translations[:, 0] = 0.0
        sines, cosines = np.sin(q), 1.0 - np.cos(q)
        skews, skews2 = self._skews, self._skews2  # type: ignore[attr-defined]
        points = self.points
        for i in range(6):
            r_i = _EYE + sines[:, i, None, None] * skews[i] + cosines[:, i, None, None] * skews2[i]
            t_i = points[i] - r_i @ points[i]  # exp(xi q): x -> R x + (I - R) r
            translations[:, i + 1] = translations[:, i] + (rotations[:, i] @ t_i[..., None])[..., 0]
            rotations[:, i + 1] = rotations[:, i] @ r_i
        return rotations, translations

    def fk(self, q: Array, transforms: tuple[Array, Array] | None = None) -> tuple[Array, Array]:
        """Ankle position [m] (n, 3) and sole rotation (n, 3, 3) in the pelvis frame for angles (n, 6) [rad]."""
        position, rotation = self._fk_chain(q, transforms)
        return position, np.asarray(rotation @ self.sole_rotation, dtype=np.float64)

    def _fk_chain(self, q: Array, transforms: tuple[Array, Array] | None = None) -> tuple[Array, Array]:
        """Ankle position and the chain's rotation ``prod exp(xi_i q_i)`` (the sole's, without ``R_s``)."""
        rotations, translations = self.transforms(q) if transforms is None else transforms
        rotation, translation = rotations[:, 6], translations[:, 6]
        return translation + rotation @ self.ankle, rotation

    def jacobian(self, q: Array, transforms: tuple[Array, Array] | None = None) -> Array:
        """Geometric Jacobian of the ankle point in the pelvis frame, (n, 6, 6): rows (v, omega)."""
        rotations, translations = self.transforms(q) if transforms is None else transforms
        ankle = translations[:, 6] + rotations[:, 6] @ self.ankle
        axes = (rotations[:, :6] @ self.axes[:, :, None])[..., 0]  # (n, 6, 3)
        origins = (rotations[:, :6] @ self.points[:, :, None])[..., 0] + translations[:, :6]
        jacobian = np.empty((len(ankle), 6, 6))
        jacobian[:, :3, :] = np.swapaxes(cross3(axes, ankle[:, None, :] - origins), 1, 2)
        jacobian[:, 3:, :] = np.swapaxes(axes, 1, 2)
        return jacobian

    # --- inverse kinematics -------------------------------------------------------------------------------
    def solve(self, position_ankle_in_pelvis: Array, rotation_foot_in_pelvis: Array,
              numeric: bool | None = None, start: Array | None = None) -> tuple[Array, Array]:
        """Joint angles (n, 6) [rad] for ankle positions (n, 3) [m] and sole rotations (n, 3, 3) (the sole frame's,
        :attr:`sole_rotation`; a flat sole of yaw ``psi`` is ``R_z(psi)``).

        Args:
            numeric: Force the numeric IK (True) or the closed form (False); None picks the closed form
                where :attr:`closed_form` holds.
            start: Warm start of the numeric IK (n, 6) [rad] (default: :attr:`reference`).

        Returns:
            The angles and, per sample, how far the target is out of reach [m] (> 0 unreachable; the
            numeric IK reports its remaining error there).
        """
        p = np.atleast_2d(position_ankle_in_pelvis)
        # the chain's own rotation g = T_d M^-1: the sole's target turned back by R_s
        rotation = np.asarray(rotation_foot_in_pelvis).reshape(-1, 3, 3) @ self.sole_rotation.T
        if numeric is None:
            numeric = not self.closed_form
        if numeric:
            return self._solve_numeric(p, rotation, start)
        return self._solve_closed(p, rotation)

    def _solve_closed(self, p: Array, rotation: Array) -> tuple[Array, Array]:
        n = len(p)
        w, r = self.axes, self.points
        hip = self.hip
        ankle0 = self.ankle_point
        reference = self.reference

        def g_point(x: Array) -> Array:  # g = T_d M^-1 applied to points (3,) or (n, 3)
            return np.asarray(np.einsum("nij,nj->ni", rotation, np.broadcast_to(x - self.ankle, (n, 3))) + p)

        # 1. knee: |exp(xi4 q4) A0 - H| = delta (subproblem 3)
        delta = np.linalg.norm(g_point(ankle0) - hip, axis=1)
        u = ankle0 - r[3]
        v = hip - r[3]
        up, vp = u - w[3] * (w[3] @ u), v - w[3] * (w[3] @ v)
        along = float(w[3] @ (ankle0 - hip))
        delta_p2 = delta * delta - along * along
        delta_p = np.sqrt(np.maximum(delta_p2, 0.0))
        lu, lv = float(np.linalg.norm(up)), float(np.linalg.norm(vp))
        excess = np.maximum(delta_p - (lu + lv), abs(lu - lv) - delta_p)
        theta0 = math.atan2(float(w[3] @ np.cross(up, vp)), float(up @ vp))
        phi = np.arccos(np.clip((lu * lu + lv * lv - delta_p2) / (2 * lu * lv), -1.0, 1.0))
        q4 = _nearest([_wrap(theta0 + phi), _wrap(theta0 - phi)], reference[3])
        # 2. ankle: exp(xi5 q5) exp(xi6 q6) (g^-1 H) = exp(-xi4 q4) H (subproblem 2 about A0)
        h_seen = np.einsum("nji,nj->ni", rotation, hip - p) + self.ankle  # g^-1 H
        knee_back = np.einsum("nij,j->ni", _rodrigues(w[3], -q4), hip - r[3]) + r[3]
        solutions, _ = _subproblem2(w[4], w[5], h_seen - ankle0, knee_back - ankle0)
        choice = _pick(solutions, reference[4], reference[5])
        q5, q6 = choice
        # 3. hip: R1 R2 R3 = R_d (R4 R5 R6)^T (subproblem 2 on axis 3, then subproblem 1)
        lower = _rodrigues(w[3], q4) @ _rodrigues(w[4], q5) @ _rodrigues(w[5], q6)
        hip_rotation = rotation @ np.swapaxes(lower, 1, 2)
        target = hip_rotation @ w[2]
        solutions, _ = _subproblem2(w[0], w[1], np.broadcast_to(w[2], (n, 3)), target)
        q1, q2 = _pick(solutions, reference[0], reference[1])
        perpendicular = np.cross(w[2], np.eye(3)[int(np.argmin(np.abs(w[2])))])
        perpendicular /= np.linalg.norm(perpendicular)
        upper = _rodrigues(w[0], q1) @ _rodrigues(w[1], q2)
        seen = np.einsum("nji,njk,k->ni", upper, hip_rotation, perpendicular)  # (R1 R2)^T R_hip x
        q3 = _subproblem1(w[2], np.broadcast_to(perpendicular, (n, 3)), seen)
        angles = np.column_stack([q1, q2, q3, q4, q5, q6])
        # Where the ankle cannot turn the foot as asked (no exact solution), report the residual.
        position, _ = self._fk_chain(angles)
        residual = np.linalg.norm(position - p, axis=1)
        excess = np.where(excess > 0, excess, np.where(residual > 1e-6, residual, excess))
        return angles, excess

    def _solve_numeric(self, p: Array, rotation: Array, start: Array | None = None) -> tuple[Array, Array]:
        n = len(p)
        q = np.broadcast_to(self.reference, (n, 6)).copy() if start is None else start.copy()
        eye = np.eye(6)
        error = np.zeros((n, 6))
        for _ in range(IK_MAX_ITERATIONS):
            position, current = self._fk_chain(q)
            error[:, :3] = p - position
            error[:, 3:] = _rotation_vector(rotation @ np.swapaxes(current, 1, 2))
            norm = np.max(np.abs(error), axis=1)
            active = norm > IK_TOLERANCE
            if not active.any():
                break
            jacobian = self.jacobian(q[active])
            jjt = jacobian @ np.swapaxes(jacobian, 1, 2) + IK_DAMPING**2 * eye
            step = np.einsum("nji,nj->ni", jacobian, np.linalg.solve(jjt, error[active][..., None])[..., 0])
            largest = np.max(np.abs(step), axis=1, keepdims=True)
            q[active] += step * np.minimum(1.0, IK_MAX_STEP / np.maximum(largest, 1e-300))
        position, current = self._fk_chain(q)
        residual = np.linalg.norm(p - position, axis=1)
        residual = np.maximum(residual, np.linalg.norm(_rotation_vector(rotation @ np.swapaxes(current, 1, 2)),
                                                       axis=1))
        excess = np.where(residual > 1e3 * IK_TOLERANCE, residual, -1.0)
        return _wrap(q), excess


def _pick(solutions: list[tuple[Array, Array]], reference1: float, reference2: float) -> tuple[Array, Array]:
    """The solution pair nearest the reference angles, per sample."""
    cost = np.stack([np.abs(_wrap(a - reference1)) + np.abs(_wrap(b - reference2)) for a, b in solutions])
    best = np.argmin(cost, axis=0)
    first = np.where(best == 0, solutions[0][0], solutions[1][0])
    second = np.where(best == 0, solutions[0][1], solutions[1][1])
    return first, second


def _rotation_vector(rotation: Array) -> Array:
    """Axis times angle of rotations (n, 3, 3), (n, 3) (accurate near the identity and up to pi)."""
    cos = np.clip((np.trace(rotation, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    vee = 0.5 * np.stack([rotation[:, 2, 1] - rotation[:, 1, 2], rotation[:, 0, 2] - rotation[:, 2, 0],
                          rotation[:, 1, 0] - rotation[:, 0, 1]], axis=-1)
    sin = np.sin(angle)
    scale = np.where(sin > 1e-9, angle / np.where(sin > 1e-9, sin, 1.0), 1.0 + angle * angle / 6.0)
    return np.asarray(vee * scale[:, None], dtype=np.float64)


__all__ = ["LegChain", "cross3"]
