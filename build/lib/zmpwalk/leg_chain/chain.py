r"""One leg as a chain of six revolute joints: geometry, forward kinematics, Jacobian, and its inverse kinematics.

A leg is a chain of six revolute joints from the pelvis (the floating base) to
the foot, in any order and with any axes. It is written as a product of
exponentials in the **pelvis frame** (the base body's frame; x forward, y left,
z up) at the zero configuration:

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
are the model's own (its signs and zeros). A robot file's leg (HUBO's) is the
chain of its link lengths (:meth:`LegChain.from_lengths`).

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

**Inverse kinematics** (:meth:`LegChain.solve`), chosen from the geometry:

* a leg whose hip axes meet and whose ankle axes meet: a closed form. The
  straight leg built from its link lengths (:mod:`zmpwalk.leg_chain.straight`:
  yaw-roll-pitch hip, knee and pitch-roll ankle on one vertical line, HUBO) has
  its own, with joint rates as its time derivative for whole trajectories
  (:meth:`LegChain.solve_flat_in_parts`) and a ``math`` path for one control
  tick (:meth:`LegChain.solve_flat_one`); any other, an imported model's, the
  subproblems of Paden and Kahan (:mod:`zmpwalk.leg_chain.paden_kahan`), each
  branch nearest its reference angles;
* otherwise damped least squares (:mod:`zmpwalk.leg_chain.numeric`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from zmpwalk.errors import UnreachableError
from zmpwalk.leg_chain import straight as straight_form
from zmpwalk.leg_chain.numeric import solve_numeric
from zmpwalk.leg_chain.paden_kahan import solve_closed
from zmpwalk.leg_chain.rotations import Array, cross3, rot_z
from zmpwalk.leg_chain.straight import StraightLeg
from zmpwalk.sides import Side
from zmpwalk.slices import Parts, run_to_end

AXES_MEET_TOLERANCE = 1e-6  # [m] axes closer than this meet (closed form applies)
_EYE = np.eye(3)


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
        link_lengths: Thigh and shank [m] of a straight leg built from them (:meth:`from_lengths`), which its
            own closed form uses as given, or None (any other chain).
        straight: Hip centre, thigh and shank of a straight leg built from its link lengths, whose own closed
            form (:mod:`zmpwalk.leg_chain.straight`) :meth:`solve` takes; None for any other chain (an imported
            model's, whatever its axes: :func:`zmpwalk.leg_chain.straight.recognise`). Set from the others.
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
    link_lengths: tuple[float, float] | None = None  # [m]
    straight: StraightLeg | None = field(init=False, repr=False, default=None)

    @classmethod
    def from_lengths(cls, side: int, joint_names: tuple[str, ...], hip: tuple[float, float, float], thigh: float,
                     shank: float, **fields: Any) -> LegChain:
        """The straight leg (:mod:`zmpwalk.leg_chain.straight`) of a robot file: hip yaw, roll and pitch about z, x
        and y meeting at ``hip`` [m] (pelvis frame), the knee (y) ``thigh`` [m] below it, the ankle pitch and roll
        (y, x) ``shank`` [m] below the knee, the foot frame at the ankle with a level sole.

        Args:
            fields: The other attributes (``reference``, ``lower``, ``upper``, ``link_masses``, ``link_coms``).
        """
        ex, ey, ez = np.eye(3)
        hip_point = np.array(hip)
        knee = hip_point + [0.0, 0.0, -thigh]
        ankle = knee + [0.0, 0.0, -shank]
        return cls(side, joint_names, np.array([ez, ex, ey, ey, ey, ex]),
                   np.array([hip_point, hip_point, hip_point, knee, ankle, ankle]), ankle,
                   link_lengths=(thigh, shank), **fields)

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
        return Side(self.side).label

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
        object.__setattr__(self, "straight", straight_form.recognise(self))

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
        position, rotation = self.fk_chain(q, transforms)
        return position, np.asarray(rotation @ self.sole_rotation, dtype=np.float64)

    def fk_chain(self, q: Array, transforms: tuple[Array, Array] | None = None) -> tuple[Array, Array]:
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


    def joint_rates(self, q: Array, twist: Array) -> Array:
        """Joint rates [rad/s] (n, 6) that give the ankle ``twist`` (n, 6) (velocity [m/s], angular velocity
        [rad/s], pelvis frame) at angles ``q`` (n, 6) [rad]: ``J(q)^-1 twist``."""
        return np.asarray(np.linalg.solve(self.jacobian(q), twist[..., None])[..., 0], dtype=np.float64)

    # --- inverse kinematics -------------------------------------------------------------------------------
    def solve(self, position_ankle_in_pelvis: Array, rotation_foot_in_pelvis: Array,
              numeric: bool | None = None, start: Array | None = None) -> tuple[Array, Array]:
        """Joint angles (n, 6) [rad] for ankle positions (n, 3) [m] and sole rotations (n, 3, 3) (the sole frame's,
        :attr:`sole_rotation`; a flat sole of yaw ``psi`` is ``R_z(psi)``).

        Args:
            numeric: Force the numeric IK (True) or the closed form (False): the straight leg's own
                (:attr:`straight`; the knee bent as the reference's), else Paden and Kahan's; None picks the
                closed form where :attr:`closed_form` holds.
            start: Warm start of the numeric IK (n, 6) [rad] (default: :attr:`reference`).

        Returns:
            The angles and, per sample, how far the target is out of reach [m] (> 0 unreachable; the
            numeric IK reports its remaining error there).
        """
        p = np.atleast_2d(position_ankle_in_pelvis)
        # the chain's own rotation g = T_d M^-1: the sole's target turned back by R_s
        rotation = np.asarray(rotation_foot_in_pelvis).reshape(-1, 3, 3)
        if not np.array_equal(self.sole_rotation, np.eye(3)):  # a level sole at zero angles needs no turn
            rotation = rotation @ self.sole_rotation.T
        if numeric is None:
            numeric = not self.closed_form
        if numeric:
            return solve_numeric(self, p, rotation, start)
        if self.straight is not None:
            return straight_form.solve(self.straight, p, rotation, knee_forward=bool(self.reference[3] >= 0.0))
        return solve_closed(self, p, rotation)

    def solve_flat(self, position_ankle_in_pelvis: Array, yaw_foot_in_pelvis: Array,
                   velocity_ankle_in_pelvis: Array | None = None, yaw_rate_foot_in_pelvis: Array | None = None,
                   knee_forward: bool = True) -> tuple[Array, Array, Array | None]:
        """:meth:`solve` for flat soles (``R_z(yaw)``) and, given the ankle's velocity and the foot's yaw rate, the
        joint rates: angles (n, 6) [rad], reach excess (n,) [m] (> 0 unreachable) and rates (n, 6) [rad/s] or None.

        Args:
            position_ankle_in_pelvis: [m], (n, 3).
            yaw_foot_in_pelvis: The sole's yaw relative to the pelvis [rad], (n,).
            velocity_ankle_in_pelvis: [m/s], (n, 3) (relative to the pelvis, in its frame), or None.
            yaw_rate_foot_in_pelvis: [rad/s], (n,), or None.
            knee_forward: The straight leg's knee branch (``q4 >= 0`` or ``<= 0``); any other chain keeps the
                branch of its reference angles.
        """
        p = np.atleast_2d(position_ankle_in_pelvis)
        yaw = np.asarray(yaw_foot_in_pelvis, dtype=np.float64)
        velocity = None
        if velocity_ankle_in_pelvis is not None and yaw_rate_foot_in_pelvis is not None:
            v = np.atleast_2d(velocity_ankle_in_pelvis)
            velocity = (v[:, 0], v[:, 1], v[:, 2], np.asarray(yaw_rate_foot_in_pelvis))
        if self.straight is None:
            angles, excess = self.solve(p, rot_z(yaw))
            if velocity is None:
                return angles, excess, None
            zero = np.zeros(len(p))
            return angles, excess, self.joint_rates(angles, np.column_stack([*velocity[:3], zero, zero, velocity[3]]))
        rows, rates = np.empty((6, len(p))), (None if velocity is None else np.empty((6, len(p))))
        excess = run_to_end(straight_form.solve_flat_in_parts(self.straight, p[:, 0], p[:, 1], p[:, 2], yaw,
                                                               velocity, knee_forward, rows, rates))
        return rows.T, excess, (None if rates is None else rates.T)

    def solve_flat_in_parts(self, position: tuple[Array, Array, Array], yaw: Array,
                            velocity: tuple[Array, Array, Array, Array] | None, knee_forward: bool,
                            angles: Array, rates: Array | None) -> Parts[Array]:
        """:meth:`solve_flat` for a whole trajectory, on component arrays (n,) (ankle x, y, z [m]; ``velocity``:
        its x, y, z [m/s] and the foot's yaw rate [rad/s], or None), writing the rows of ``angles`` [rad] and
        ``rates`` [rad/s] (6, n); returns the reach excess [m] (n,). In parts of tens of microseconds for the
        straight leg (:func:`zmpwalk.leg_chain.straight.solve_flat_in_parts`), in one for any other chain."""
        if self.straight is not None:
            excess: Array = yield from straight_form.solve_flat_in_parts(self.straight, *position, yaw, velocity,
                                                                         knee_forward, angles, rates)
            return excess
        yield
        p = np.column_stack(position)
        if velocity is None or rates is None:
            solved, excess, _ = self.solve_flat(p, yaw, knee_forward=knee_forward)
        else:
            solved, excess, solved_rates = self.solve_flat(p, yaw, np.column_stack(velocity[:3]), velocity[3],
                                                           knee_forward)
            if solved_rates is not None:
                rates[:] = solved_rates.T
        angles[:] = solved.T
        return excess

    def solve_flat_one(self, ankle: tuple[float, float, float], yaw: float,
                       knee_forward: bool = True) -> tuple[float, ...]:
        """The six angles [rad] for one ankle position [m] with a flat sole of yaw ``yaw`` [rad] (pelvis frame):
        plain ``math`` for the straight leg (a controller that solves one leg per tick), :meth:`solve_flat`
        on one sample for any other chain.

        Raises:
            UnreachableError: The ankle is out of the leg's reach (``time`` is nan).
        """
        if self.straight is not None:
            return straight_form.solve_flat_one(self.straight, ankle, yaw, knee_forward, self.side)
        angles, excess, _ = self.solve_flat(np.array([ankle]), np.array([yaw]), knee_forward=knee_forward)
        if excess[0] > 0.0:
            raise UnreachableError(self.label, float("nan"), float(excess[0]))
        return tuple(float(angle) for angle in angles[0])


__all__ = ["AXES_MEET_TOLERANCE", "LegChain"]
