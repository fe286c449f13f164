r"""Closed form of the straight leg: yaw-roll-pitch hip, pitch knee, pitch-roll ankle on one vertical line.

The leg of both papers (Lim et al., Fig. 1; HUBO): hip yaw ``q1`` (about z),
hip roll ``q2`` (x), hip pitch ``q3`` (y), knee ``q4`` (y), ankle pitch ``q5``
(y), ankle roll ``q6`` (x). The three hip axes meet at the hip joint centre,
the two ankle axes at the ankle joint centre, and with every angle zero the leg
hangs straight down: knee and ankle directly below the hip. Rotations are
right-handed about the pelvis frame's axes (x forward, y left, z up), so a
positive knee angle bends the knee forwards, a negative hip pitch swings the
thigh forwards. In the pelvis frame:

.. math::
    R_{foot} = R_z(q_1) R_x(q_2) R_y(q_3 + q_4 + q_5) R_x(q_6), \qquad
    p_{ankle} = p_{hip} + R_z(q_1) R_x(q_2) \left[R_y(q_3) (0, 0, -a)^T + R_y(q_3 + q_4)(0, 0, -b)^T\right]

with ``a`` the thigh and ``b`` the shank length. The hip rotation
``R_z R_x R_y`` is the matrix printed in Lim et al. (``1/2 R``).

Eq. 2 of Lim et al. solves this leg only for straight walking (``q1 = 0``,
foot parallel to the torso). :func:`solve` solves the general case: any
ankle position and any foot orientation relative to the pelvis. Work from the
ankle: the hip seen from the ankle in the foot frame, ``r = R^T (p_hip - p_ankle)``,
depends on ``q4, q5, q6`` only:

.. math::
    r = R_x(-q_6) R_y(-q_5) \left[(-a \sin q_4, 0, a \cos q_4 + b)^T\right]

so ``|r|`` gives the knee (law of cosines), ``atan2(r_y, r_z)`` the ankle roll,
the angle of ``r`` in the leg plane the ankle pitch, and the remaining hip
rotation ``R R_x(-q_6) R_y(-q_4 - q_5) = R_z(q_1) R_x(q_2) R_y(q_3)`` gives the
three hip angles. The knee branch is ``q4 >= 0`` (forwards, default) or ``q4 <= 0``.

For a flat foot (``R = R_z(psi)``, a walking pattern's foot) :func:`solve_flat_in_parts`
writes the same closed form component-wise, with the joint rates as its time
derivative, for whole trajectories; :func:`solve_flat_one` with ``math`` for one
pose per control tick. A :class:`~zmpwalk.leg_chain.LegChain` built from link
lengths (a robot file's leg) takes this closed form (:func:`recognise`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from zmpwalk.errors import InvalidParameterError, UnreachableError
from zmpwalk.leg_chain.geometry import ChainGeometry
from zmpwalk.leg_chain.rotations import Array, rot_x, rot_y
from zmpwalk.sides import Side
from zmpwalk.slices import Parts

_EX, _EY, _EZ = np.eye(3)
STRAIGHT_AXES = np.array([_EZ, _EX, _EY, _EY, _EY, _EX])  # hip yaw, roll, pitch, knee, ankle pitch, roll
AXIS_TOLERANCE = 1e-12  # [-] of a unit axis: axes this close to STRAIGHT_AXES are those of the straight leg
POINT_TOLERANCE = 1e-6  # [m] joint points this close to where the link lengths put them are there


class StraightLeg(NamedTuple):
    """What the straight leg's closed form needs of its chain.

    Attributes:
        hip: Hip joint centre in the pelvis frame [m].
        thigh: Hip pitch axis to knee axis ``a`` [m].
        shank: Knee axis to ankle axes ``b`` [m].
    """

    hip: tuple[float, float, float]  # [m]
    thigh: float  # [m]
    shank: float  # [m]


def recognise(chain: ChainGeometry) -> StraightLeg | None:
    """The straight leg's parameters of a chain built from its link lengths (its
    :attr:`~zmpwalk.leg_chain.LegChain.link_lengths` set, :meth:`~zmpwalk.leg_chain.LegChain.from_lengths`),
    else None.

    Only such a chain takes this closed form: an imported model's chain of the same structure (TALOS) takes
    Paden and Kahan's, which chooses each branch nearest its reference angles where this one fixes them.

    Raises:
        InvalidParameterError: The chain's axes and points are not those of a straight leg of these lengths
            (axes :data:`STRAIGHT_AXES` in role order, knee ``thigh`` and ankle ``thigh + shank`` directly
            below the hip at zero angles, a level sole, no virtual joint).
    """
    if chain.link_lengths is None:
        return None
    thigh, shank = chain.link_lengths
    points, foot = chain.points, chain.ankle
    hip = (float(points[0][0]), float(points[0][1]), float(points[1][2]))  # on the yaw axis, at the roll axis
    knee_z, ankle_z = float(points[3][2]), float(points[4][2])
    # each pitch axis (along y) fixes x and z, each roll axis (along x) y and z, the yaw axis x and y
    deviations = [points[2][0] - hip[0], points[2][2] - hip[2], points[1][1] - hip[1], points[3][0] - hip[0],
                  points[4][0] - hip[0], points[5][1] - hip[1], points[5][2] - ankle_z,
                  foot[0] - hip[0], foot[1] - hip[1], foot[2] - ankle_z,
                  hip[2] - knee_z - thigh, knee_z - ankle_z - shank]
    if (chain.virtual is not None or tuple(chain.role_order) != tuple(range(6))
            or np.max(np.abs(chain.axes - STRAIGHT_AXES)) > AXIS_TOLERANCE
            or np.max(np.abs(chain.sole_rotation - np.eye(3))) > AXIS_TOLERANCE
            or max(abs(float(d)) for d in deviations) > POINT_TOLERANCE or thigh <= 0.0 or shank <= 0.0):
        raise InvalidParameterError("link_lengths", chain.link_lengths,
                                    "None, or the thigh and shank of a straight leg's axes and points")
    return StraightLeg(hip, float(thigh), float(shank))


def solve(leg: StraightLeg, position_ankle_in_pelvis: Array, rotation_foot_in_pelvis: Array,
          knee_forward: bool = True) -> tuple[Array, Array]:
    """Closed-form inverse kinematics, vectorised (see the module docstring for the derivation).

    Args:
        leg: The leg.
        position_ankle_in_pelvis: Ankle joint centre [m], (n, 3).
        rotation_foot_in_pelvis: Foot orientation, (n, 3, 3).
        knee_forward: The knee branch: ``q4 >= 0`` (True) or ``q4 <= 0``.

    Returns:
        The angles (n, 6) [rad] and, per pose, the hip-to-ankle distance beyond the leg's reach [m] (n,); > 0
        where unreachable (the angles there are those of the stretched leg pointing at the target).
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
    return np.stack([q1, q2, q3, q4, q5, q6], axis=1), excess


def solve_flat_in_parts(leg: StraightLeg, px: Array, py: Array, pz: Array, yaw: Array,
                        velocity: tuple[Array, Array, Array, Array] | None, knee_forward: bool,
                        angles: Array, rates: Array | None) -> Parts[Array]:
    r""":func:`solve` for a flat foot (rotation ``Rz(yaw)``, ``yaw`` the foot's relative to the pelvis, the hip yaw
    of the paper's Eq. 21 [rad]) written component-wise, on component arrays (n,) of the ankle [m]; writes the rows
    of ``angles`` [rad] and, given the ankle's velocity [m/s] and the foot's yaw rate [rad/s] relative to the pelvis
    (``velocity``: x, y, z, yaw rate), of ``rates`` [rad/s] (6, n), as the time derivative of the same closed form
    (no linear solve). Returns the reach excess [m] (n,). In parts of tens of microseconds, the angles then the
    rates (:mod:`zmpwalk.slices`).

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


def solve_flat_one(leg: StraightLeg, ankle: tuple[float, float, float], foot_yaw: float, knee_forward: bool,
                   side: int) -> tuple[float, ...]:
    """The same closed form for one pose with a flat foot of yaw ``foot_yaw`` [rad] (pelvis frame), the ankle
    [m]; the six angles [rad]. Plain ``math`` for a controller that solves one leg per tick.

    Raises:
        UnreachableError: The ankle is out of the leg's reach (``side`` +1 left, -1 right; ``time`` is nan).
    """
    c, s = math.cos(foot_yaw), math.sin(foot_yaw)
    dx, dy, dz = leg.hip[0] - ankle[0], leg.hip[1] - ankle[1], leg.hip[2] - ankle[2]
    rx, ry, rz = c * dx + s * dy, -s * dx + c * dy, dz  # Rz(yaw)^T (hip - ankle)
    a, b = leg.thigh, leg.shank
    distance = math.sqrt(rx * rx + ry * ry + rz * rz)
    if distance > a + b or distance < abs(a - b):
        excess = max(distance - a - b, abs(a - b) - distance)
        raise UnreachableError(Side(side).label, math.nan, excess)
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


__all__ = ["STRAIGHT_AXES", "StraightLeg", "recognise", "solve", "solve_flat_in_parts", "solve_flat_one"]
