r"""Leg kinematics of a yaw-roll-pitch-pitch-pitch-roll leg: forward, closed-form inverse, reach.

The leg of both papers (Lim et al., Fig. 1; HUBO): hip yaw ``q1`` (about z),
hip roll ``q2`` (x), hip pitch ``q3`` (y), knee ``q4`` (y), ankle pitch ``q5``
(y), ankle roll ``q6`` (x). The three hip axes meet at the hip joint centre,
the two ankle axes at the ankle joint centre. Rotations are right-handed
about the pelvis frame's axes (x forward, y left, z up), so a positive knee
angle bends the knee forwards, a negative hip pitch swings the thigh forwards.
With every angle zero the leg hangs straight down. In the pelvis frame:

.. math::
    R_{foot} = R_z(q_1) R_x(q_2) R_y(q_3 + q_4 + q_5) R_x(q_6), \qquad
    p_{ankle} = p_{hip} + R_z(q_1) R_x(q_2) \left[R_y(q_3) (0, 0, -a)^T + R_y(q_3 + q_4)(0, 0, -b)^T\right]

with ``a`` the thigh and ``b`` the shank length. The hip rotation
``R_z R_x R_y`` is the matrix printed in Lim et al. (``1/2 R``).

Eq. 2 of Lim et al. solves this leg only for straight walking (``q1 = 0``,
foot parallel to the torso). :func:`leg_ik` solves the general case: any
ankle position and any foot orientation relative to the pelvis. Work from the
ankle: the hip seen from the ankle in the foot frame, ``r = R^T (p_hip - p_ankle)``,
depends on ``q4, q5, q6`` only:

.. math::
    r = R_x(-q_6) R_y(-q_5) \left[(-a \sin q_4, 0, a \cos q_4 + b)^T\right]

so ``|r|`` gives the knee (law of cosines), ``atan2(r_y, r_z)`` the ankle roll,
the angle of ``r`` in the leg plane the ankle pitch, and the remaining hip
rotation ``R R_x(-q_6) R_y(-q_4 - q_5) = R_z(q_1) R_x(q_2) R_y(q_3)`` gives the
three hip angles. The knee branch is ``q4 >= 0`` (forwards, default) or ``q4 <= 0``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError, UnreachableError
from zmpwalk.joint_limits import (  # re-exported (__all__): the columns and their checks live there
    JOINT_COLUMNS,
    LEG_JOINTS,
    JointLimitError,
    check_joint_limits,
    check_sole_roll,
    joint_bounds,
    virtual_columns,
)
from zmpwalk.leg_chain import LegChain
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import Parts, whole

Array = NDArray[np.float64]


class SampledMotion(Protocol):
    """What the IK needs of a pattern (:class:`zmpwalk.patterns.result.WalkingPattern` is one), in world, SI:
    times [s] (n,), the pelvis and both ankles' positions [m] (n, 3) and velocities [m/s] (n, 3), the pelvis'
    and feet's yaws [rad] (n,) and yaw rates [rad/s] (n,), and the robot."""

    time: Array
    position_pelvis_in_world: Array
    velocity_pelvis_in_world: Array
    yaw_pelvis_in_world: Array
    yaw_rate_pelvis: Array
    position_left_ankle_in_world: Array
    velocity_left_ankle_in_world: Array
    yaw_left_foot_in_world: Array
    yaw_rate_left_foot: Array
    position_right_ankle_in_world: Array
    velocity_right_ankle_in_world: Array
    yaw_right_foot_in_world: Array
    yaw_rate_right_foot: Array
    robot: RobotModel

def rot_x(angle: Array) -> Array:
    """Rotation matrices about x, shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def rot_y(angle: Array) -> Array:
    """Rotation matrices about y, shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def rot_z(angle: Array) -> Array:
    """Rotation matrices about z, shape (n, 3, 3)."""
    c, s = np.cos(angle), np.sin(angle)
    o, z = np.ones_like(c), np.zeros_like(c)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


@dataclass(frozen=True)
class Leg:
    """Geometry of one leg in the pelvis frame.

    Attributes:
        side: +1 left, -1 right.
        hip: Hip joint centre in the pelvis frame [m], (3,).
        thigh: Hip pitch axis to knee axis ``a`` [m].
        shank: Knee axis to ankle axes ``b`` [m].
    """

    side: int
    hip: tuple[float, float, float]  # [m]
    thigh: float  # [m]
    shank: float  # [m]

    @classmethod
    def of(cls, robot: RobotModel, side: int) -> Leg:
        """The left (``side = +1``) or right (``-1``) leg of ``robot``."""
        return cls(side, robot.hip_in_pelvis(side), robot.thigh_length, robot.shank_length)


def leg_fk(leg: Leg, q: Array) -> tuple[Array, Array]:
    """Forward kinematics: ankle position [m] (n, 3) and foot rotation (n, 3, 3) in the pelvis frame.

    Args:
        leg: The leg.
        q: Joint angles [rad], (n, 6) in the order of :data:`LEG_JOINTS`.
    """
    q = np.atleast_2d(q)
    hip_rotation = rot_z(q[:, 0]) @ rot_x(q[:, 1])
    pitch_thigh = q[:, 2]
    pitch_shank = q[:, 2] + q[:, 3]
    leg_vector = np.stack([
        -leg.thigh * np.sin(pitch_thigh) - leg.shank * np.sin(pitch_shank),
        np.zeros(len(q)),
        -leg.thigh * np.cos(pitch_thigh) - leg.shank * np.cos(pitch_shank),
    ], axis=-1)
    ankle = np.asarray(leg.hip) + np.einsum("nij,nj->ni", hip_rotation, leg_vector)
    foot = hip_rotation @ rot_y(q[:, 2] + q[:, 3] + q[:, 4]) @ rot_x(q[:, 5])
    return ankle, foot


@dataclass(frozen=True)
class LegSolution:
    """Closed-form IK result for many poses.

    Attributes:
        angles: (n, 6) [rad], order of :data:`LEG_JOINTS`.
        excess: Hip-to-ankle distance beyond the leg's reach [m], (n,); > 0 where unreachable
            (the angles there are those of the stretched leg pointing at the target).
    """

    angles: Array
    excess: Array

    @property
    def reachable(self) -> NDArray[np.bool_]:
        return self.excess <= 0.0


def leg_ik(leg: Leg, position_ankle_in_pelvis: Array, rotation_foot_in_pelvis: Array,
           knee_forward: bool = True) -> LegSolution:
    """Closed-form inverse kinematics, vectorised (see the module docstring for the derivation).

    Args:
        leg: The leg.
        position_ankle_in_pelvis: Ankle joint centre [m], (n, 3).
        rotation_foot_in_pelvis: Foot orientation, (n, 3, 3).
        knee_forward: The knee branch: ``q4 >= 0`` (True) or ``q4 <= 0``.

    Returns:
        The angles and, per pose, how far it is out of reach.
    """
    p = np.atleast_2d(position_ankle_in_pelvis)
    R = rotation_foot_in_pelvis.reshape(-1, 3, 3)
    d = np.asarray(leg.hip) - p
    r = np.einsum("nji,nj->ni", R, d)  # R^T (hip - ankle): the hip seen from the ankle, foot frame
    a, b = leg.thigh, leg.shank
    distance = np.sqrt(np.einsum("ni,ni->n", r, r))
    excess = np.maximum(distance - (a + b), (abs(a - b) - distance))
    cos_knee = np.clip((distance**2 - a * a - b * b) / (2 * a * b), -1.0, 1.0)
    q4 = np.arccos(cos_knee) * (1.0 if knee_forward else -1.0)
    q6 = np.arctan2(r[:, 1], r[:, 2])
    u_z = np.hypot(r[:, 1], r[:, 2])
    q5 = np.arctan2(-a * np.sin(q4), a * np.cos(q4) + b) - np.arctan2(r[:, 0], u_z)
    hip = R @ rot_x(-q6) @ rot_y(-(q4 + q5))  # = Rz(q1) Rx(q2) Ry(q3)
    q1 = np.arctan2(-hip[:, 0, 1], hip[:, 1, 1])
    q2 = np.arctan2(hip[:, 2, 1], np.hypot(hip[:, 0, 1], hip[:, 1, 1]))
    q3 = np.arctan2(-hip[:, 2, 0], hip[:, 2, 2])
    return LegSolution(np.stack([q1, q2, q3, q4, q5, q6], axis=1), excess)


def leg_ik_yaw(leg: Leg, position_ankle_in_pelvis: Array, yaw_foot_in_pelvis: Array,
               knee_forward: bool = True) -> LegSolution:
    """:func:`leg_ik` for a flat foot (rotation ``Rz(yaw)``), written component-wise for speed.

    Args:
        leg: The leg.
        position_ankle_in_pelvis: Ankle joint centre [m], (n, 3).
        yaw_foot_in_pelvis: Foot yaw relative to the pelvis (the hip yaw of the paper's Eq. 21) [rad], (n,).
        knee_forward: Knee branch.
    """
    return leg_ik_yaw_rates(leg, position_ankle_in_pelvis, yaw_foot_in_pelvis, None, None, knee_forward)[0]


def leg_ik_yaw_rates(leg: Leg, position_ankle_in_pelvis: Array, yaw_foot_in_pelvis: Array,
                     velocity_ankle_in_pelvis: Array | None, yaw_rate_foot_in_pelvis: Array | None,
                     knee_forward: bool = True) -> tuple[LegSolution, Array | None]:
    r""":func:`leg_ik_yaw` and, given the ankle's velocity and the foot's yaw rate relative to the pelvis, the
    joint rates [rad/s] (n, 6) as the time derivative of the same closed form (no linear solve).

    With :math:`r = R_z(\psi)^T (h - p)`, :math:`D = |r|`, :math:`u = \sqrt{r_y^2 + r_z^2}`:

    .. math::
        \dot r = R_z(\psi)^T (-\dot p) + \dot\psi\,(r_y, -r_x, 0), \quad
        \dot q_4 = -\frac{D \dot D}{a b \sin q_4}, \quad
        \dot q_6 = \frac{r_z \dot r_y - r_y \dot r_z}{u^2}, \quad
        \dot q_3 = -(\dot q_4 + \dot q_5)

    and :math:`\dot q_5, \dot q_1, \dot q_2` from the derivative of ``atan2(y, x)``,
    :math:`(x \dot y - y \dot x) / (x^2 + y^2)`, of their own arguments. This equals
    :math:`J^{-1}` times the ankle twist wherever the leg is not stretched (``tests/test_kinematics.py``).
    """
    p = np.atleast_2d(position_ankle_in_pelvis)
    n = len(p)
    angles = np.empty((6, n))
    rates: Array | None = None
    velocity: tuple[Array, Array, Array, Array] | None = None
    if velocity_ankle_in_pelvis is not None and yaw_rate_foot_in_pelvis is not None:
        rates = np.empty((6, n))
        v = np.atleast_2d(velocity_ankle_in_pelvis)
        velocity = (v[:, 0], v[:, 1], v[:, 2], np.asarray(yaw_rate_foot_in_pelvis))
    excess = _leg_ik_yaw_rates(leg, p[:, 0], p[:, 1], p[:, 2], np.asarray(yaw_foot_in_pelvis), velocity,
                               knee_forward, angles, rates)
    return LegSolution(angles.T, excess), (None if rates is None else rates.T)


def _leg_ik_yaw_rates_in_parts(leg: Leg, px: Array, py: Array, pz: Array, yaw: Array,
                               velocity: tuple[Array, Array, Array, Array] | None, knee_forward: bool,
                               angles: Array, rates: Array | None) -> Parts[Array]:
    """:func:`leg_ik_yaw_rates` on component arrays (n,), writing the rows of ``angles`` and ``rates`` (6, n);
    returns the reach excess [m] (n,). In parts of tens of microseconds, the angles then the rates
    (:mod:`zmpwalk.slices`); :func:`_leg_ik_yaw_rates` runs it whole."""
    c, s = np.cos(yaw), np.sin(yaw)
    dx, dy, dz = leg.hip[0] - px, leg.hip[1] - py, leg.hip[2] - pz
    rx, ry, rz = c * dx + s * dy, c * dy - s * dx, dz
    yield
    a, b = leg.thigh, leg.shank
    distance = np.sqrt(rx * rx + ry * ry + rz * rz)
    excess = np.maximum(distance - (a + b), abs(a - b) - distance)
    cos4 = np.clip((distance * distance - a * a - b * b) / (2 * a * b), -1.0, 1.0)
    q4 = np.arccos(cos4)
    sin4 = np.sqrt(1.0 - cos4 * cos4)  # sin(arccos k) without trigonometry
    yield
    if not knee_forward:
        q4, sin4 = -q4, -sin4
    q6 = np.arctan2(ry, rz)
    u_squared = ry * ry + rz * rz
    u_z = np.sqrt(u_squared)
    big_y, big_x = -a * sin4, a * cos4 + b
    q5 = np.arctan2(big_y, big_x) - np.arctan2(rx, u_z)
    yield
    # The hip rotation Rz(q1) Rx(q2) Ry(q3) = Rz(yaw) Rx(-q6) Ry(-(q4 + q5)) of a flat foot, in closed form
    # (Eq. 2 of Lim et al.): with the ankle below the hip (r_z > 0) q1 = yaw, q2 = -q6, q3 = -(q4 + q5);
    # above it (r_z < 0, not a walking posture) both q1 and q3 turn by pi and q2 = atan2(-r_y, |r_z|).
    flipped = rz < 0.0
    q1, q2, q3 = yaw.copy(), -q6, -(q4 + q5)
    if np.any(flipped):
        q1, q3 = q1 + np.pi * flipped, q3 + np.pi * flipped
        q2 = np.where(flipped, np.arctan2(-ry, -rz), q2)
    for angle in (q1, q3):  # into (-pi, pi], as atan2 returns them
        outside = np.abs(angle) > np.pi
        if np.any(outside):
            angle[outside] = np.arctan2(np.sin(angle[outside]), np.cos(angle[outside]))
    angles[0], angles[1], angles[2], angles[3], angles[4], angles[5] = q1, q2, q3, q4, q5, q6
    if velocity is None or rates is None:
        return excess
    yield
    vx, vy, vz, w = velocity
    drx = -(c * vx + s * vy) + w * ry
    dry = -(c * vy - s * vx) - w * rx
    drz = -vz
    d_distance = (rx * drx + ry * dry + rz * drz) / distance
    yield
    with np.errstate(divide="ignore", invalid="ignore"):  # a stretched leg has no joint rates (J singular;
        dq4 = -distance * d_distance / (a * b * sin4)  # such a sample is beyond reach, which the caller rejects)
        du = (ry * dry + rz * drz) / u_z
        dq6 = (rz * dry - ry * drz) / u_squared
    yield  # (not inside the errstate: the caller runs between the parts)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_big_y, d_big_x = -a * cos4 * dq4, -a * sin4 * dq4
        dq5 = ((big_x * d_big_y - big_y * d_big_x) / (big_x * big_x + big_y * big_y)
               - (u_z * drx - rx * du) / (rx * rx + u_squared))
    yield
    dq1 = w
    dq2 = np.where(flipped, dq6, -dq6)
    dq3 = -(dq4 + dq5)
    rates[0], rates[1], rates[2], rates[3], rates[4], rates[5] = dq1, dq2, dq3, dq4, dq5, dq6
    return excess


_leg_ik_yaw_rates = whole(_leg_ik_yaw_rates_in_parts, "_leg_ik_yaw_rates")  # the same, run whole


def leg_ik_scalar(leg: Leg, ankle: tuple[float, float, float], foot_yaw: float,
                  knee_forward: bool = True) -> tuple[float, ...]:
    """The same closed form for one pose with a flat foot of yaw ``foot_yaw`` [rad] (pelvis frame).

    Plain ``math`` for a controller that solves one leg per tick.

    Raises:
        UnreachableError: The ankle is out of the leg's reach (``time`` is nan).
    """
    c, s = math.cos(foot_yaw), math.sin(foot_yaw)
    dx, dy, dz = leg.hip[0] - ankle[0], leg.hip[1] - ankle[1], leg.hip[2] - ankle[2]
    rx, ry, rz = c * dx + s * dy, -s * dx + c * dy, dz  # Rz(yaw)^T (hip - ankle)
    a, b = leg.thigh, leg.shank
    distance = math.sqrt(rx * rx + ry * ry + rz * rz)
    if distance > a + b or distance < abs(a - b):
        excess = max(distance - a - b, abs(a - b) - distance)
        raise UnreachableError("left" if leg.side > 0 else "right", math.nan, excess)
    q4 = math.acos(max(-1.0, min(1.0, (distance * distance - a * a - b * b) / (2 * a * b))))
    if not knee_forward:
        q4 = -q4
    q6 = math.atan2(ry, rz)
    q5 = math.atan2(-a * math.sin(q4), a * math.cos(q4) + b) - math.atan2(rx, math.hypot(ry, rz))
    # hip rotation = Rz(yaw) Rx(-q6) Ry(-(q4 + q5)); only the entries needed for q1, q2, q3
    p = -(q4 + q5)
    cp, sp = math.cos(p), math.sin(p)
    c6, s6 = math.cos(-q6), math.sin(-q6)
    # Rx(-q6) Ry(p) = [[cp, 0, sp], [s6*sp, c6, -s6*cp], [-c6*sp, s6, c6*cp]]
    m01 = -s * c6
    m11 = c * c6
    m20, m21, m22 = -c6 * sp, s6, c6 * cp
    q1 = math.atan2(-m01, m11)
    q2 = math.atan2(m21, math.hypot(m01, m11))
    q3 = math.atan2(-m20, m22)
    return q1, q2, q3, q4, q5, q6


def hip_positions_in_world(
    position_pelvis_in_world: Array, yaw_pelvis_in_world: Array, robot: RobotModel
) -> tuple[Array, Array]:
    """Left and right hip joint centres in world [m], each (n, 3)."""
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    result = []
    for side in (1, -1):
        x, y, z = robot.hip_in_pelvis(side)
        result.append(position_pelvis_in_world + np.column_stack([c * x - s * y, s * x + c * y, np.full_like(c, z)]))
    return result[0], result[1]


def leg_reach_excess(
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    position_left_ankle_in_world: Array,
    position_right_ankle_in_world: Array,
    robot: RobotModel,
) -> tuple[Array, Array]:
    """Hip-to-ankle distance minus the leg's reach at its least knee bend [m], left and right, each (n,).

    Positive values are out of reach.
    """
    hip_left, hip_right = hip_positions_in_world(position_pelvis_in_world, yaw_pelvis_in_world, robot)
    reach = robot.max_leg_reach
    return (np.linalg.norm(position_left_ankle_in_world - hip_left, axis=1) - reach,
            np.linalg.norm(position_right_ankle_in_world - hip_right, axis=1) - reach)


def check_leg_reach(
    time: Array,
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    position_left_ankle_in_world: Array,
    position_right_ankle_in_world: Array,
    robot: RobotModel,
) -> None:
    """Raise if a hip-to-ankle distance exceeds the leg's reach at its least knee bend.

    Raises:
        UnreachableError: Names the leg, the first time it is out of reach and
            the largest excess [m]; ``error.sample`` is the first sample index.
    """
    excesses = leg_reach_excess(position_pelvis_in_world, yaw_pelvis_in_world, position_left_ankle_in_world,
                                position_right_ankle_in_world, robot)
    firsts = [int(np.argmax(e > 0)) if np.any(e > 0) else len(time) for e in excesses]
    if min(firsts) == len(time):
        return
    side = 0 if firsts[0] <= firsts[1] else 1
    first = firsts[side]
    excess = excesses[side]
    error = UnreachableError(
        ("left", "right")[side], float(time[first]), float(excess.max()),
        f"hip-to-ankle distance up to {float(excess.max()) + robot.max_leg_reach:.3f} m, "
        f"reach {robot.max_leg_reach:.3f} m",
    )
    error.sample = first
    raise error


def leg_jacobian(leg: Leg, q: Array) -> Array:
    """Geometric Jacobian of the ankle in the pelvis frame, (n, 6, 6): rows (v, omega), columns joints."""
    q = np.atleast_2d(q)
    n = len(q)
    hip = np.broadcast_to(np.asarray(leg.hip), (n, 3))
    yaw = rot_z(q[:, 0])
    yaw_roll = yaw @ rot_x(q[:, 1])
    ex, ey, ez = np.eye(3)
    z1 = np.broadcast_to(ez, (n, 3))
    z2 = yaw @ ex
    z3 = yaw_roll @ ey
    thigh = np.stack([-leg.thigh * np.sin(q[:, 2]), np.zeros(n), -leg.thigh * np.cos(q[:, 2])], -1)
    knee = hip + np.einsum("nij,nj->ni", yaw_roll, thigh)
    ankle, _ = leg_fk(leg, q)
    z6 = (yaw_roll @ rot_y(q[:, 2] + q[:, 3] + q[:, 4])) @ ex
    axes = [z1, z2, z3, z3, z3, z6]
    origins = [hip, hip, hip, knee, ankle, ankle]
    jacobian = np.empty((n, 6, 6))
    for column, (axis, origin) in enumerate(zip(axes, origins, strict=True)):
        jacobian[:, :3, column] = np.cross(axis, ankle - origin)
        jacobian[:, 3:, column] = axis
    return jacobian


@dataclass
class JointTrajectory:
    """The 12 leg joint angles and velocities along a walking pattern.

    Attributes:
        time: [s], (n,).
        angles: [rad], (n, 12), columns :data:`JOINT_COLUMNS` (left leg, then right leg).
        velocities: [rad/s], (n, 12).
        position_base_in_world: For an imported robot, the base origin that puts the whole-body CoM on the
            pattern's point [m], (n, 3); None for the robot-file legs (their pelvis is the pattern's).
    """

    time: Array
    angles: Array
    velocities: Array
    names: tuple[str, ...] = JOINT_COLUMNS
    position_base_in_world: Array | None = None

    def columns(self) -> dict[str, Array]:
        """Angles by column name, for the CSV of ``zmpwalk plan --joints``."""
        return {name: self.angles[:, i] for i, name in enumerate(self.names)}


def joint_trajectory_in_parts(
    time: Array,
    position_pelvis_in_world: Array,
    yaw_pelvis_in_world: Array,
    velocity_pelvis_in_world: Array,
    yaw_rate_pelvis: Array,
    feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]],
    robot: RobotModel,
    knee_forward: bool = True,
    check_limits: bool = True,
) -> Parts[JointTrajectory]:
    """Joint angles (closed-form IK) and velocities (Jacobian) of both legs with an upright pelvis, in parts
    (:mod:`zmpwalk.slices`: with closed-form legs, each leg's angles and rates, then the joint ranges; an
    imported robot's legs in one part). :func:`joint_trajectory` runs it whole.

    Args:
        time: [s], (n,).
        position_pelvis_in_world, yaw_pelvis_in_world, velocity_pelvis_in_world, yaw_rate_pelvis:
            the pelvis [m], [rad], [m/s], [rad/s].
        feet: For the left then the right foot: ankle position [m] (n, 3), foot yaw [rad] (n,),
            ankle velocity [m/s] (n, 3) and foot yaw rate [rad/s] (n,), all in world.
        robot: The robot (leg lengths, hip positions, joint ranges).
        knee_forward: Knee branch.
        check_limits: Raise :class:`JointLimitError` when an angle leaves the robot's range.

    Raises:
        UnreachableError: First time an ankle is out of reach, with the largest excess.
        JointLimitError: First joint to leave its range (when ``check_limits``).
    """
    n = len(time)
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    angles, velocities = np.empty((n, 12)), np.empty((n, 12))
    base: Array | None = None
    solutions: list[tuple[Array, Array]] = []
    if robot.legs is not None:
        # An imported robot: the pattern moves the whole-body centre of mass; find the base that puts it there.
        base, solutions = _base_under_com(position_pelvis_in_world, yaw_pelvis_in_world,
                                          [(f[0], f[1]) for f in feet], robot)
        if n > 1:
            velocity_pelvis_in_world = velocity_pelvis_in_world + np.gradient(base - position_pelvis_in_world,
                                                                              time, axis=0)
        position_pelvis_in_world = base
    if robot.legs is None:  # closed form, written row by row into (12, n) and returned transposed
        angles, velocities = yield from _closed_form_legs_in_parts(
            time, position_pelvis_in_world, (c, s), yaw_pelvis_in_world, velocity_pelvis_in_world, yaw_rate_pelvis,
            feet, robot, knee_forward)
    else:  # an imported robot's legs: angles from _base_under_com, rates from J q' = twist
        for index, (side, (position, _, velocity, yaw_rate)) in enumerate(zip((1, -1), feet, strict=True)):
            rel = position - position_pelvis_in_world
            v = velocity - velocity_pelvis_in_world  # relative velocity in the (rotating) pelvis frame
            v[:, 0] += yaw_rate_pelvis * rel[:, 1]
            v[:, 1] -= yaw_rate_pelvis * rel[:, 0]
            twist = np.column_stack([c * v[:, 0] + s * v[:, 1], -s * v[:, 0] + c * v[:, 1], v[:, 2],
                                     np.zeros(n), np.zeros(n), yaw_rate - yaw_rate_pelvis])
            chain = robot.legs[index]
            leg_angles, excess = solutions[index]
            _check_reach(excess, time, "left" if side > 0 else "right",
                         "inverse kinematics, " + ("closed form" if chain.closed_form else "numeric"))
            rates = np.linalg.solve(chain.jacobian(leg_angles), twist[..., None])[..., 0]
            order = list(chain.role_order)
            angles[:, 6 * index:6 * index + 6] = leg_angles[:, order]
            velocities[:, 6 * index:6 * index + 6] = rates[:, order]
    if check_limits:  # the joint ranges: parts of their own, each half of the samples (the first sample out
        half = (n + 1) // 2  # of range is the first of the first half that has one, else of the second)
        yield
        check_sole_roll(time, angles, robot)  # a five-joint leg's sole roll over the whole walk (none: no work)
        check_joint_limits(time[:half], angles[:half], robot)
        yield
        check_joint_limits(time[half:], angles[half:], robot)
    return JointTrajectory(time, angles, velocities, position_base_in_world=base)


joint_trajectory = whole(joint_trajectory_in_parts, "joint_trajectory")  # the same, run whole


def _closed_form_legs_in_parts(
    time: Array, position_pelvis_in_world: Array, heading: tuple[Array, Array], yaw_pelvis_in_world: Array,
    velocity_pelvis_in_world: Array, yaw_rate_pelvis: Array,
    feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]], robot: RobotModel,
    knee_forward: bool,
) -> Parts[tuple[Array, Array]]:
    """The closed-form legs of :func:`joint_trajectory_in_parts` (``heading``: cos and sin of the pelvis yaw),
    each leg in parts: its ankle in the pelvis frame, the angles, the rates. Angles and rates, (n, 12) each."""
    c, s = heading
    n = len(time)
    rows_angles, rows_rates = np.empty((12, n)), np.empty((12, n))
    for index, (side, (position, yaw, velocity, yaw_rate)) in enumerate(zip((1, -1), feet, strict=True)):
        yield
        rx, ry = position[:, 0] - position_pelvis_in_world[:, 0], position[:, 1] - position_pelvis_in_world[:, 1]
        vx = velocity[:, 0] - velocity_pelvis_in_world[:, 0] + yaw_rate_pelvis * ry  # in the rotating frame
        vy = velocity[:, 1] - velocity_pelvis_in_world[:, 1] - yaw_rate_pelvis * rx
        rows = slice(6 * index, 6 * index + 6)
        yield
        ankle = (c * rx + s * ry, c * ry - s * rx, position[:, 2] - position_pelvis_in_world[:, 2],
                 yaw - yaw_pelvis_in_world)
        ankle_rates = (c * vx + s * vy, c * vy - s * vx, velocity[:, 2] - velocity_pelvis_in_world[:, 2],
                       yaw_rate - yaw_rate_pelvis)
        yield
        excess = yield from _leg_ik_yaw_rates_in_parts(Leg.of(robot, side), *ankle, ankle_rates, knee_forward,
                                                       rows_angles[rows], rows_rates[rows])
        _check_reach(excess, time, "left" if side > 0 else "right", "inverse kinematics")
    return rows_angles.T, rows_rates.T


def _check_reach(excess: Array, time: Array, label: str, detail: str) -> None:
    if np.any(excess > 0):
        first = int(np.argmax(excess > 0))
        raise UnreachableError(label, float(time[first]), float(excess.max()), detail)


COM_TOLERANCE = 1e-6  # [m] the base is placed until the whole-body CoM is this close to the pattern's
COM_ITERATIONS = 12


def _base_under_com(position_com_in_world: Array, yaw_pelvis_in_world: Array, feet: list[tuple[Array, Array]],
                    robot: RobotModel) -> tuple[Array, list[tuple[Array, Array]]]:
    r"""Base positions (n, 3) [m] that put the whole-body CoM of an imported robot on the pattern's point, and
    the leg solutions there.

    The pattern (Eqs. 1-2 of Park et al.) moves one mass; a real robot's legs carry part of it (TALOS: 17 %
    each), so a swinging leg moves the CoM away from where the pattern put it. With the feet fixed in world,
    the base is moved horizontally by the remaining CoM error until it is below :data:`COM_TOLERANCE`:

    .. math:: p_{base}^{k+1} = p_{base}^k + (c_{pattern} - c(p_{base}^k, q^k))_{xy}

    (a contraction: moving the base by ``d`` moves the CoM by about ``d (1 - m_{feet} / M)``).
    The CoM height stays the pattern's (its vertical motion is what the pattern neglects too).
    """
    legs, plant = robot.legs, robot.plant
    if legs is None or plant is None:
        raise InvalidParameterError("robot", robot.name, "an imported robot (leg chains and masses)")
    n = len(yaw_pelvis_in_world)
    c, s = np.cos(yaw_pelvis_in_world), np.sin(yaw_pelvis_in_world)
    rotation = rot_z(yaw_pelvis_in_world)
    offset = np.array([robot.com_offset[0], robot.com_offset[1], 0.0])
    base = position_com_in_world - np.einsum("nij,j->ni", rotation, offset)
    total = plant.rest_mass + sum(float(leg.link_masses.sum()) for leg in legs)
    starts: list[Array | None] = [None, None]
    solutions: list[tuple[Array, Array]] = []
    for _ in range(COM_ITERATIONS):
        solutions = []
        com_in_base = plant.rest_mass * np.asarray(plant.rest_com)
        com_in_base = np.broadcast_to(com_in_base, (n, 3)).copy()
        for index, (chain, (position, yaw)) in enumerate(zip(legs, feet, strict=True)):
            rel = position - base
            ankle_in_base = np.column_stack([c * rel[:, 0] + s * rel[:, 1], -s * rel[:, 0] + c * rel[:, 1], rel[:, 2]])
            solution = chain.solve(ankle_in_base, rot_z(yaw - yaw_pelvis_in_world), start=starts[index])
            solutions.append(solution)
            starts[index] = solution[0]
            com_in_base += np.einsum("k,nki->ni", chain.link_masses, chain.link_com_positions(solution[0]))
        com = base + np.einsum("nij,nj->ni", rotation, com_in_base / total)
        error = position_com_in_world[:, :2] - com[:, :2]
        base[:, :2] += error
        if np.max(np.abs(error)) < COM_TOLERANCE:
            break
    return base, solutions


def pattern_joint_trajectory(pattern: SampledMotion, knee_forward: bool = True,
                             check_limits: bool = True) -> JointTrajectory:
    """Joint angles and velocities of a :class:`~zmpwalk.patterns.result.WalkingPattern` (any generator)."""
    return joint_trajectory(
        pattern.time, pattern.position_pelvis_in_world, pattern.yaw_pelvis_in_world,
        pattern.velocity_pelvis_in_world, pattern.yaw_rate_pelvis,
        ((pattern.position_left_ankle_in_world, pattern.yaw_left_foot_in_world,
          pattern.velocity_left_ankle_in_world, pattern.yaw_rate_left_foot),
         (pattern.position_right_ankle_in_world, pattern.yaw_right_foot_in_world,
          pattern.velocity_right_ankle_in_world, pattern.yaw_rate_right_foot)),
        pattern.robot, knee_forward, check_limits)


def leg_chains(robot: RobotModel) -> tuple[LegChain, LegChain]:
    """Both legs as :class:`~zmpwalk.leg_chain.LegChain` in the pelvis (base) frame, for any robot.

    An imported robot has its own; the robot-file leg (yaw-roll-pitch-pitch-pitch-roll, links along -z)
    becomes the same chain, with the ``[bodies]`` masses of thigh, shank and foot where the file has them.
    """
    if robot.legs is not None:
        return robot.legs
    ex, ey, ez = np.eye(3)
    chains = []
    for side in (1, -1):
        hip = np.array([robot.hip_x, side * robot.hip_spacing / 2, -robot.hip_drop])
        knee = hip + [0.0, 0.0, -robot.thigh_length]
        ankle = knee + [0.0, 0.0, -robot.shank_length]
        masses, coms = np.zeros(6), np.zeros((6, 3))
        if robot.links:
            for index, (name, origin) in enumerate((("thigh", hip), ("shank", knee), ("foot", ankle))):
                link = robot.links[name]
                masses[2 + index + (1 if name == "foot" else 0)] = link.mass
                coms[2 + index + (1 if name == "foot" else 0)] = origin + np.array(link.com) * [1.0, side, 1.0]
        limits = [robot.limits_of(f"{'left' if side > 0 else 'right'}_{joint}") for joint in LEG_JOINTS]
        chains.append(LegChain(
            side, tuple(f"{'left' if side > 0 else 'right'}_{joint}" for joint in LEG_JOINTS),
            np.array([ez, ex, ey, ey, ey, ex]), np.array([hip, hip, hip, knee, ankle, ankle]), ankle,
            reference=np.array([0.0, 0.0, -0.5, 1.0, -0.5, 0.0]),
            lower=np.array([lo for lo, _ in limits]), upper=np.array([hi for _, hi in limits]),
            link_masses=masses, link_coms=coms))
    return chains[0], chains[1]


def rest_mass(robot: RobotModel) -> tuple[float, Array]:
    """Mass [kg] and centre of mass in the pelvis frame [m] of everything but the leg segments."""
    if robot.plant is not None:
        return robot.plant.rest_mass, np.array(robot.plant.rest_com)
    if robot.links:
        return robot.links["torso"].mass, np.array(robot.links["torso"].com)
    return robot.mass, np.zeros(3)


__all__ = ["COM_ITERATIONS", "COM_TOLERANCE", "JOINT_COLUMNS", "LEG_JOINTS", "JointLimitError", "JointTrajectory",
           "Leg", "LegSolution", "SampledMotion", "check_joint_limits", "check_leg_reach",
           "check_sole_roll", "hip_positions_in_world", "joint_bounds", "joint_trajectory",
           "joint_trajectory_in_parts", "leg_chains", "leg_fk", "leg_ik", "leg_ik_scalar", "leg_ik_yaw",
           "leg_ik_yaw_rates", "leg_jacobian", "leg_reach_excess", "pattern_joint_trajectory", "rest_mass", "rot_x",
           "rot_y", "rot_z", "virtual_columns"]
