"""An MJCF model of a robot, generated from its data file.

The torso is a floating body (free joint) at the pelvis centre; each leg is
the yaw-roll-pitch-pitch-pitch-roll chain of :mod:`zmpwalk.kinematics` with
the link boxes and masses of the robot file's ``[bodies]``. The hip yaw, hip
roll and ankle pitch links carry no mass of their own in the robot file; they
get 0.1 % of the thigh's mass so that every moving body has an inertia, and
that mass is taken from the thigh and the foot so the total stays the robot's.

Every joint has a position servo (``[servos]``: ``kp``, ``kv``, armature). Only
the soles (and the torso, to detect falls) collide with the ground.

Ground contact (Eq. 16 of Lim et al.): the paper's normal force
``k x^1.5 + c x'`` is a Hertz-like spring; MuJoCo's soft contact is a linear
spring-damper in the constraint space. zmpwalk linearises the spring at the
static penetration of one foot carrying half the weight,

.. math:: x_0 = \\left(\\frac{M g}{2 k}\\right)^{1/e}, \\qquad K = e\\,k\\,x_0^{e-1},

and gives MuJoCo the stiffness ``K`` and the paper's damping ``c`` per unit of the
carried mass (``solref = (-K / m, -c / m)``, ``m = M / 2``), so a foot under half the
weight sinks ``x_0`` and rings with the natural frequency and damping ratio of the
paper's law at that load. What differs: the spring is linear (stiffer than the
paper's under light loads, softer under heavy ones), and MuJoCo's friction has
one coefficient; the dynamic one (``mu_d = 0.7``) is used, since MuJoCo's soft
contact lets a loaded foot creep slowly rather than stick (no ``mu_s`` at rest).

The paper's damping ``c = 10 N s/mm`` is far beyond critical (17 times for the
small biped at its static load). MuJoCo's constraint damping is integrated
explicitly in the reference acceleration and makes the foot bounce when
``(c / m) * timestep > 1``; there it is capped at that value, still
several times critical (the foot neither bounces nor rings), and
:attr:`ContactMapping.paper_damping` keeps the file's value for the reports.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from zmpwalk.errors import InvalidParameterError
from zmpwalk.robots.model import JOINT_NAMES, RobotModel

TIMESTEP = 0.0005  # [s] simulation step (two per servo period)
SMALL_FRACTION = 1e-3  # mass of the joint-only links, as a fraction of the thigh's
DAMPING_STEP_LIMIT = 1.0  # largest (damping / carried mass) * timestep MuJoCo integrates without bouncing


@dataclass(frozen=True)
class ContactMapping:
    """Eq. 16 linearised for MuJoCo (see the module docstring).

    Attributes:
        penetration: Static penetration of a foot under half the weight [m].
        stiffness: Linearised stiffness ``K`` [N/m].
        damping: ``c`` [N s/m], capped where MuJoCo's step could not integrate it (see the module docstring).
        carried_mass: ``M / 2`` [kg].
        friction: The friction coefficient given to MuJoCo [-].
    """

    penetration: float  # [m]
    stiffness: float  # [N/m]
    damping: float  # [N s/m]
    carried_mass: float  # [kg]
    friction: float  # [-]
    paper_damping: float = 0.0  # [N s/m] c of the robot file, before the stability cap

    @property
    def damping_ratio(self) -> float:
        """Damping of the linearised contact relative to critical [-]."""
        return self.damping / (2 * math.sqrt(self.stiffness * self.carried_mass))

    @property
    def solref(self) -> tuple[float, float]:
        """MuJoCo's direct ``solref`` = (-stiffness, -damping) per unit mass."""
        return -self.stiffness / self.carried_mass, -self.damping / self.carried_mass


def contact_mapping(robot: RobotModel) -> ContactMapping:
    """Eq. 16 of the robot file linearised at the static load of one foot."""
    contact = robot.contact
    if contact is None:
        raise InvalidParameterError("robot", robot.name, "a robot file with a [contact] table")
    mass = robot.link_mass or robot.mass
    half_weight = mass * robot.gravity / 2
    penetration = (half_weight / contact.stiffness) ** (1 / contact.exponent)
    stiffness = contact.exponent * contact.stiffness * penetration ** (contact.exponent - 1)
    carried = mass / 2
    damping = min(contact.damping, DAMPING_STEP_LIMIT * carried / TIMESTEP)
    return ContactMapping(penetration, stiffness, damping, carried, contact.friction_dynamic, contact.damping)


def _fmt(*values: float) -> str:
    return " ".join(f"{v:.9g}" for v in values)


def _box(size: tuple[float, float, float]) -> str:
    return _fmt(size[0] / 2, size[1] / 2, size[2] / 2)


def _inertial(mass: float, com: tuple[float, float, float], size: tuple[float, float, float]) -> str:
    x, y, z = size
    m = mass / 12.0
    return (f'<inertial pos="{_fmt(*com)}" mass="{mass:.9g}" '
            f'diaginertia="{_fmt(m * (y * y + z * z), m * (x * x + z * z), m * (x * x + y * y))}"/>')


def robot_mjcf(robot: RobotModel, mass_scale: float = 1.0) -> str:
    """The MJCF XML of ``robot`` standing on a flat floor.

    Args:
        robot: A robot file with ``[bodies]``, ``[servos]`` and ``[contact]``.
        mass_scale: Multiply every mass and inertia (the mass study of Lim et al.); the servo gains
            and rotor inertias are multiplied too, so the joints track equally well, as the prescribed
            joint motions of the paper's ADAMS model do whatever the masses.

    Raises:
        InvalidParameterError: The robot file lacks one of those tables.
    """
    if not robot.links or robot.servos is None:
        raise InvalidParameterError("robot", robot.name, "a robot file with [bodies], [servos] and [contact]")
    scaled = RobotModel(**{**vars(robot), "links": {
        name: type(link)(link.mass * mass_scale, link.size, link.com) for name, link in robot.links.items()}})
    mapping = contact_mapping(scaled)
    servos = robot.servos
    servos = type(servos)(servos.kp * mass_scale, servos.kv * mass_scale, servos.armature * mass_scale)
    torso = scaled.links["torso"]
    legs = "".join(_leg(scaled, side, label, mapping) for side, label in ((1, "left"), (-1, "right")))
    touch_size = _box((1.05 * torso.size[0], 1.05 * torso.size[1], 1.05 * torso.size[2]))
    solref = _fmt(*mapping.solref)
    return f"""<mujoco model="{robot.name}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{TIMESTEP}" integrator="implicitfast" cone="elliptic" gravity="0 0 {-robot.gravity:.9g}"/>
  <default>
    <joint armature="{servos.armature:.9g}" damping="0"/>
    <geom solref="{solref}" solimp="0.95 0.99 0.0001" condim="3"/>
  </default>
  <visual><global offwidth="640" offheight="480"/></visual>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1=".85 .85 .85" rgb2=".7 .7 .7" width="512" height="512"/>
    <material name="grid" texture="grid" texrepeat="8 8" reflectance="0.1"/>
  </asset>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1" directional="true"/>
    <geom name="floor" type="plane" size="0 0 0.05" material="grid" friction="{mapping.friction:.9g} 0.005 0.0001"/>
    <body name="torso" pos="0 0 {robot.pelvis_height:.9g}">
      <freejoint name="root"/>
      {_inertial(torso.mass, torso.com, torso.size)}
      <geom name="torso" type="box" size="{_box(torso.size)}" pos="{_fmt(*torso.com)}" rgba="0.8 0.45 0.2 1"/>
      <site name="pelvis" pos="0 0 0" size="0.01"/>
      <site name="torso_touch" type="box" size="{touch_size}" pos="{_fmt(*torso.com)}"
            rgba="0 0 0 0"/>{legs}
    </body>
  </worldbody>
  <actuator>
{_servos(servos.kp, servos.kv)}
  </actuator>
  <sensor>
{_sensors()}
  </sensor>
</mujoco>
"""


def _leg(robot: RobotModel, side: int, label: str, mapping: ContactMapping) -> str:
    """The bodies of one leg (``side`` 1 left, -1 right; ``label`` its name) with the masses of ``robot``'s
    ``[bodies]``, its joints, and its sole, the only geom of the leg that collides (``mapping``'s friction). The
    joint-only links carry :data:`SMALL_FRACTION` of the thigh's mass, taken from the thigh and the foot."""
    links = robot.links
    small = links["thigh"].mass * SMALL_FRACTION
    tiny_size = (0.01, 0.01, 0.01)
    thigh, shank, foot = links["thigh"], links["shank"], links["foot"]
    foot_com = (foot.com[0], side * foot.com[1], foot.com[2])
    return f"""
      <body name="{label}_hip_yaw_link" pos="{_fmt(0.0, side * robot.hip_spacing / 2, -robot.hip_drop)}">
        <joint name="{label}_hip_yaw" axis="0 0 1"/>
        {_inertial(small, (0, 0, 0), tiny_size)}
        <body name="{label}_hip_roll_link">
          <joint name="{label}_hip_roll" axis="1 0 0"/>
          {_inertial(small, (0, 0, 0), tiny_size)}
          <body name="{label}_thigh">
            <joint name="{label}_hip_pitch" axis="0 1 0"/>
            {_inertial(thigh.mass - 2 * small, thigh.com, thigh.size)}
            <geom name="{label}_thigh" type="box" size="{_box(thigh.size)}" pos="{_fmt(*thigh.com)}"
                  contype="0" conaffinity="0" rgba="0.55 0.6 0.7 1"/>
            <body name="{label}_shank" pos="0 0 {-robot.thigh_length:.9g}">
              <joint name="{label}_knee" axis="0 1 0"/>
              {_inertial(shank.mass, shank.com, shank.size)}
              <geom name="{label}_shank" type="box" size="{_box(shank.size)}" pos="{_fmt(*shank.com)}"
                    contype="0" conaffinity="0" rgba="0.55 0.6 0.7 1"/>
              <body name="{label}_ankle_pitch_link" pos="0 0 {-robot.shank_length:.9g}">
                <joint name="{label}_ankle_pitch" axis="0 1 0"/>
                {_inertial(small, (0, 0, 0), tiny_size)}
                <body name="{label}_foot">
                  <joint name="{label}_ankle_roll" axis="1 0 0"/>
                  {_inertial(foot.mass - small, foot_com, foot.size)}
                  <geom name="{label}_sole" type="box" size="{_box(foot.size)}" pos="{_fmt(*foot_com)}"
                        friction="{mapping.friction:.9g} 0.005 0.0001" rgba="0.2 0.25 0.3 1"/>
                  <site name="{label}_ankle" pos="0 0 0" size="0.005"/>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>"""


def _servos(kp: float, kv: float) -> str:
    """A position servo with gains ``kp`` [N m/rad] and ``kv`` [N m s/rad] on every leg joint."""
    return "\n".join(
        f'    <position name="{label}_{joint}" joint="{label}_{joint}" kp="{kp:.9g}" '
        f'kv="{kv:.9g}"/>'
        for label in ("left", "right") for joint in JOINT_NAMES)


def _sensors() -> str:
    """The sensors zmpwalk measures with: the pelvis pose and gyro, the torso's touch of the ground, a
    force-torque sensor and the pose of each ankle, and each joint's angle, rate and actuator torque."""
    sensors = [
        '    <framepos name="pelvis_pos" objtype="site" objname="pelvis"/>',
        '    <framequat name="pelvis_quat" objtype="site" objname="pelvis"/>',
        '    <gyro name="pelvis_gyro" site="pelvis"/>',
        '    <touch name="torso_touch" site="torso_touch"/>',
    ]
    for label in ("left", "right"):
        sensors += [
            f'    <force name="{label}_force" site="{label}_ankle"/>',
            f'    <torque name="{label}_torque" site="{label}_ankle"/>',
            f'    <framepos name="{label}_ankle_pos" objtype="site" objname="{label}_ankle"/>',
            f'    <framequat name="{label}_ankle_quat" objtype="site" objname="{label}_ankle"/>',
        ]
    for label in ("left", "right"):
        for joint in JOINT_NAMES:
            sensors += [f'    <jointpos name="{label}_{joint}_q" joint="{label}_{joint}"/>',
                        f'    <jointvel name="{label}_{joint}_qd" joint="{label}_{joint}"/>',
                        f'    <actuatorfrc name="{label}_{joint}_tau" actuator="{label}_{joint}"/>']
    return "\n".join(sensors)
