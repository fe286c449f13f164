r"""Static joint torques of the ready posture, on both feet and on one foot: a builder's first motor check.

Before any walk, a leg motor must hold the robot still where every walk passes: standing on both feet,
and standing on one foot with the centre of mass over its sole (the moment a foot lifts in a slow walk).
Both follow from the model alone. On one foot, a stance-leg joint carries the moment of everything above
it (the foot is the root of the chain):

.. math:: \tau_k = a_k \cdot \sum_{b \notin \mathrm{sub}(k)} (x_b - o_k) \times m_b\, g

with ``a_k`` and ``o_k`` the joint's axis and anchor and ``sub(k)`` the bodies between the joint and the
foot; with an upright torso it depends on the posture only, not on where the feet are. The posture is the
ready posture's (the pattern's point at the base height, the legs' reference bend); on one foot the other foot
is raised by the robot's foot lift (the apex of a step in place), so that a leg that cannot reach the floor
beside a base moved over the other sole still has a posture. Booster T1, for one, needs 33.1 N m at the stance
hip roll (of a 30 N m limit) and 14.2 N m at its hip yaw (its pitch-roll-yaw hip shares the sideways moment
between them) to hold the centre of mass over one sole: a walk's sway keeps it inside the sole's centre.

The torques come from the same inverse dynamics as the simulation's feedforward
(:func:`zmpwalk.sim.plant.servo_torques`, ``dynamic=False``): gravity minus the planned ground
reaction, all weight on the stance sole at the point under the centre of mass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JOINT_COLUMNS, joint_trajectory
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]


@dataclass(frozen=True)
class StaticTorques:
    """Leg joint torques [N m] holding the ready posture still, each (12,) in the leg-column order
    (:data:`zmpwalk.kinematics.JOINT_COLUMNS`).

    Attributes:
        both_feet: Standing on both feet, the centre of mass midway between the soles' centres.
        on_left: All weight on the left sole, the centre of mass over its centre, the right foot raised by the
            foot lift.
        on_right: The same on the right foot.
        limits: Each joint's actuator torque limit [N m] (inf where unlimited).
        poses: The model's ``qpos`` of the three postures (both feet, on the left, on the right), (3, nq).
    """

    both_feet: Array
    on_left: Array
    on_right: Array
    limits: Array
    poses: Array

    @property
    def one_foot(self) -> Array:
        """Each joint's larger |torque| of the two single supports [N m], (12,)."""
        return np.maximum(np.abs(self.on_left), np.abs(self.on_right))

    @property
    def over_limit(self) -> list[str]:
        """Columns whose static torque (both feet or one foot) exceeds the actuator's limit."""
        need = np.maximum(self.one_foot, np.abs(self.both_feet))
        return [column for column, value, limit in zip(JOINT_COLUMNS, need, self.limits, strict=True)
                if value > limit]


def static_torques(robot: RobotModel) -> StaticTorques:
    """The torques of :class:`StaticTorques` for an imported robot (its own model and actuators).

    The posture is the ready posture of the pattern (feet at the hip spacing, base height and knee bend of
    the robot), the base moved horizontally until the whole-body centre of mass is over the point named
    (both soles' midpoint, or one sole's centre) within 1e-6 m.

    Raises:
        InvalidParameterError: ``robot`` is a box model (no model of its own to hold).
    """
    from zmpwalk.sim.plant import FEEDFORWARD_PERIOD, build_plant, servo_torques
    from zmpwalk.sim.poses import plant_qpos

    if robot.plant is None or robot.legs is None:
        raise InvalidParameterError("robot", robot.name, "a robot imported from its MJCF or URDF model")
    plant = build_plant(robot)
    half = robot.hip_spacing / 2
    ankles = [np.array([[0.0, side * half, robot.ankle_height]] * 3) for side in (1, -1)]
    ankles[1][1, 2] += robot.foot_lift  # [m] on the left sole the right foot is raised, and the other way round
    ankles[0][2, 2] += robot.foot_lift
    sole = np.array([robot.sole_center_x, half + robot.sole_center_y])
    # rows: both feet, on the left sole, on the right sole
    com_xy = np.array([[robot.sole_center_x, 0.0], sole, sole * (1.0, -1.0)])
    com = np.column_stack([com_xy, np.full(3, robot.pelvis_height)])  # the pattern's point: the base's height
    zero, still = np.zeros(3), np.zeros((3, 3))
    legs = joint_trajectory(np.arange(3.0), com, zero, still, zero,
                            ((ankles[0], zero, still, zero), (ankles[1], zero, still, zero)),
                            robot, check_limits=False)
    if legs.position_base_in_world is None:  # pragma: no cover - imported robots always place the base
        raise InvalidParameterError("robot", robot.name, "a robot imported from its MJCF or URDF model")
    qpos = plant_qpos(plant, legs.position_base_in_world, zero, legs.angles)
    torques = servo_torques(plant, qpos, com_xy, np.array([0, 1, 2]), (ankles[0], ankles[1]),
                            1.0 / FEEDFORWARD_PERIOD,  # every row a key row, none interpolated
                            dynamic=False)[:, plant.leg_actuators]
    limits = np.array([np.inf if joint.actuator is None else joint.actuator.force_limit
                       for joint in robot.plant.joints])
    return StaticTorques(torques[0], torques[1], torques[2], limits, qpos)
