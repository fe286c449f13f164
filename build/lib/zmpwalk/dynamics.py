"""The multibody ZMP of Eq. 3 (Lim et al.; Eqs. 1-2 of Park et al. before simplification).

.. math::
    x_{ZMP} = \\frac{\\sum m_i (\\ddot z_i + g) x_i - \\sum m_i \\ddot x_i z_i - \\sum \\dot L_{iy}}
                   {\\sum m_i (\\ddot z_i + g)}, \\qquad
    y_{ZMP} = \\frac{\\sum m_i (\\ddot z_i + g) y_i - \\sum m_i \\ddot y_i z_i + \\sum \\dot L_{ix}}
                   {\\sum m_i (\\ddot z_i + g)}

with ``L_i = R_i I_i R_i^T omega_i`` the angular momentum of link ``i`` about its
centre of mass (the papers write ``I Omega-dot``; the time derivative of the
angular momentum is the general form, and for ``y`` the moment about x enters
with a plus sign in a right-handed frame). Unlike the cart-table ZMP of the
patterns it includes the legs' masses, vertical motion and rotation: the
difference of the two is the error that Park et al. name as their method's
limitation.

The links (torso and, per leg, thigh, shank and foot) are uniform boxes from
the robot file's ``[bodies]``; their motion comes from the pattern and the
joint angles, and the accelerations are second-order central differences of
the sampled motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JointTrajectory, pattern_joint_trajectory, rot_x, rot_y, rot_z
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]


@dataclass
class LinkMotion:
    """Centres of mass and orientations of the links over time, in world.

    Attributes:
        names: Link names (``torso``, ``left_thigh``, ...).
        masses: [kg], (k,).
        inertias: Principal moments about the centre of mass in the link frame [kg m^2], (k, 3).
        positions: Centres of mass [m], (n, k, 3).
        rotations: Link orientations, (n, k, 3, 3).
    """

    names: tuple[str, ...]
    masses: Array
    inertias: Array
    positions: Array
    rotations: Array


def link_motion(pattern: WalkingPattern, joints: JointTrajectory) -> LinkMotion:
    """Forward kinematics of every link along a pattern and its joint trajectory (upright pelvis)."""
    robot = pattern.robot
    if not robot.links:
        raise InvalidParameterError("robot", robot.name, "a robot file with a [bodies] table (link masses)")
    pelvis_rotation = rot_z(pattern.yaw_pelvis_in_world)
    pelvis = pattern.position_pelvis_in_world
    names = ["torso"]
    positions = [pelvis + np.einsum("nij,j->ni", pelvis_rotation, np.array(robot.links["torso"].com))]
    rotations = [pelvis_rotation]
    masses = [robot.links["torso"].mass]
    inertias = [robot.links["torso"].inertia]
    for index, (side, label) in enumerate(((1, "left"), (-1, "right"))):
        q = joints.angles[:, 6 * index:6 * index + 6]
        hip = pelvis + np.einsum("nij,j->ni", pelvis_rotation,
                                 np.array([0.0, side * robot.hip_spacing / 2, -robot.hip_drop]))
        thigh = pelvis_rotation @ rot_z(q[:, 0]) @ rot_x(q[:, 1]) @ rot_y(q[:, 2])
        knee = hip + thigh[:, :, 2] * -robot.thigh_length
        shank = thigh @ rot_y(q[:, 3])
        ankle = knee + shank[:, :, 2] * -robot.shank_length
        foot = shank @ rot_y(q[:, 4]) @ rot_x(q[:, 5])
        for name, origin, rotation in (("thigh", hip, thigh), ("shank", knee, shank), ("foot", ankle, foot)):
            link = robot.links[name]
            com = np.array(link.com) * np.array([1.0, side, 1.0])
            names.append(f"{label}_{name}")
            positions.append(origin + np.einsum("nij,j->ni", rotation, com))
            rotations.append(rotation)
            masses.append(link.mass)
            inertias.append(link.inertia)
    return LinkMotion(tuple(names), np.array(masses), np.array(inertias), np.stack(positions, axis=1),
                      np.stack(rotations, axis=1))


def angular_momenta(time: Array, rotations: Array, inertias: Array) -> Array:
    """Angular momentum of each link about its centre of mass, in world [kg m^2/s], (n, k, 3).

    ``omega`` from ``skew(omega) = R' R^T`` by central differences.
    """
    derivative = np.gradient(rotations, time, axis=0, edge_order=2)
    skew = derivative @ np.swapaxes(rotations, -1, -2)
    omega = 0.5 * np.stack([skew[..., 2, 1] - skew[..., 1, 2], skew[..., 0, 2] - skew[..., 2, 0],
                            skew[..., 1, 0] - skew[..., 0, 1]], axis=-1)
    body = np.einsum("nkji,nkj->nki", rotations, omega) * inertias[None, :, :]  # I (R^T omega)
    return np.asarray(np.einsum("nkij,nkj->nki", rotations, body), dtype=np.float64)


def multibody_zmp(time: Array, masses: Array, positions: Array, momenta: Array, gravity: float) -> Array:
    """Eq. 3 from link centres of mass [m] (n, k, 3) and angular momenta [kg m^2/s] (n, k, 3); (n, 2) [m]."""
    acceleration = np.gradient(np.gradient(positions, time, axis=0, edge_order=2), time, axis=0, edge_order=2)
    momentum_rate = np.gradient(momenta, time, axis=0, edge_order=2)
    x, y, z = positions[..., 0], positions[..., 1], positions[..., 2]
    vertical = masses * (acceleration[..., 2] + gravity)  # m_i (z_i'' + g)
    total = vertical.sum(axis=1)
    zmp_x = ((vertical * x).sum(axis=1) - (masses * acceleration[..., 0] * z).sum(axis=1)
             - momentum_rate[..., 1].sum(axis=1)) / total  # Eq. 3a
    zmp_y = ((vertical * y).sum(axis=1) - (masses * acceleration[..., 1] * z).sum(axis=1)
             + momentum_rate[..., 0].sum(axis=1)) / total  # Eq. 3b
    return np.column_stack([zmp_x, zmp_y])


@dataclass
class ZmpComparison:
    """The multibody ZMP of a pattern against its cart-table ZMP.

    Attributes:
        time: [s], (n,).
        multibody: Eq. 3 ZMP [m], (n, 2).
        cart_table: The pattern's ZMP (Eqs. 1-2 / Eq. 4) [m], (n, 2).
        difference: multibody - cart_table [m], (n, 2).
        center_of_mass: Whole-body centre of mass [m], (n, 3).
    """

    time: Array
    multibody: Array
    cart_table: Array
    difference: Array
    center_of_mass: Array

    @property
    def rms(self) -> float:
        """RMS of the difference's length [m]."""
        return float(np.sqrt(np.mean(np.sum(self.difference**2, axis=1))))

    @property
    def max(self) -> float:
        """Largest difference [m]."""
        return float(np.max(np.linalg.norm(self.difference, axis=1)))


def compare_zmp(pattern: WalkingPattern, joints: JointTrajectory | None = None) -> ZmpComparison:
    """Multibody ZMP (Eq. 3) along ``pattern`` with the robot's link masses, and its difference from the
    pattern's own (cart-table) ZMP.

    The pattern must be sampled uniformly (any :class:`WalkingPattern` is).
    """
    joints = joints if joints is not None else pattern_joint_trajectory(pattern, check_limits=False)
    motion = link_motion(pattern, joints)
    momenta = angular_momenta(pattern.time, motion.rotations, motion.inertias)
    robot: RobotModel = pattern.robot
    zmp = multibody_zmp(pattern.time, motion.masses, motion.positions, momenta, robot.gravity)
    com = np.einsum("k,nki->ni", motion.masses, motion.positions) / motion.masses.sum()
    return ZmpComparison(pattern.time, zmp, pattern.zmp_in_world, zmp - pattern.zmp_in_world, com)
