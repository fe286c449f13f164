"""The robot as data: lengths, foot, posture, walking defaults, joint ranges.

Frames used throughout zmpwalk (documented once, here):

* **world**: x forward along the robot's initial heading, y to its left, z up;
  origin on the ground midway between the ankles of the ready posture.
* **pelvis**: origin at the pelvis centre, x forward along the pelvis heading,
  y left, z up (the paper's x, y frame of Figs. 4-5).
* **foot** (left or right ankle): origin at the ankle joint, x along the foot
  heading, y left, z up. A foot's yaw is the heading of its x axis in world.

All quantities are SI: m, s, rad, kg.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

from zmpwalk.errors import FileFormatError, InvalidParameterError, UnknownNameError
from zmpwalk.stabilizer_gains import StabilizerGains

if TYPE_CHECKING:
    from zmpwalk.leg_chain import LegChain
    from zmpwalk.robots.description import ModelPlant

JOINT_NAMES = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
JOINT_COLUMNS = tuple(f"{side}_{joint}" for side in ("left", "right") for joint in JOINT_NAMES)  # the 12 columns
HUBO_PENDULUM = 0.62  # [m] pendulum length the HUBO tables were tuned for (robots/data/hubo.toml)
HUBO_HIP_SPACING = 0.17  # [m] HUBO's hip spacing (robots/data/hubo.toml)
HUBO_LEG_LENGTH = 0.60  # [m] HUBO's thigh plus shank (robots/data/hubo.toml)
LINK_NAMES = ("torso", "thigh", "shank", "foot")
FOOT_SPEED_FROUDE = 1.6  # [-] default swing-foot speed limit over sqrt(g l)
FOOT_ACCELERATION_G = 5.0  # [-] default swing-foot acceleration limit over g
# The pattern generators by name, kept here below zmpwalk.patterns (which must not be imported from robots/) so that a
# robot file's choice is checked where it is read; zmpwalk.patterns.GENERATORS holds the same names (tested).
GENERATOR_NAMES = ("polynomial", "hyperbolic", "preview")
BOX_MODEL_GENERATOR = "polynomial"  # the papers' pattern, for the built-in box models and box robot files
OWN_MODEL_GENERATOR = "hyperbolic"  # a robot built from its own MJCF/URDF: of the generators measured on TALOS (servos,
# motors), Booster T1 and Fourier N1, the one that passes the most walks with its joints in range and runs online
# (bench/bench_defaults.py, docs/design-log/defaults.md)


@dataclass(frozen=True)
class Link:
    """Mass properties of one rigid link, a uniform box.

    Attributes:
        mass: [kg].
        size: Box edge lengths along the link's x, y, z [m].
        com: Centre of mass in the link's frame [m] (torso: pelvis frame; thigh: hip frame,
            shank: knee frame, foot: ankle frame; the leg's defaults are set by the loader).
    """

    mass: float  # [kg]
    size: tuple[float, float, float]  # [m]
    com: tuple[float, float, float]  # [m]

    @property
    def inertia(self) -> tuple[float, float, float]:
        """Principal moments of inertia about the centre of mass [kg m^2] (uniform box)."""
        x, y, z = self.size
        m = self.mass / 12.0
        return m * (y * y + z * z), m * (x * x + z * z), m * (x * x + y * y)


@dataclass(frozen=True)
class Servos:
    """Position servos of the simulated joints: torque ``kp (q_ref - q) - kv q'``.

    Attributes:
        kp: Stiffness [N m/rad].
        kv: Damping [N m s/rad].
        armature: Reflected rotor inertia [kg m^2].
    """

    kp: float  # [N m/rad]
    kv: float  # [N m s/rad]
    armature: float  # [kg m^2]


@dataclass(frozen=True)
class Contact:
    """Ground contact of Eq. 16 (Lim et al.): normal force ``k x^e + c x'``, Coulomb friction.

    Attributes:
        stiffness: ``k`` [N/m^e].
        exponent: ``e`` [-].
        damping: ``c`` [N s/m].
        friction_static: ``mu_s`` [-].
        friction_dynamic: ``mu_d`` [-].
    """

    stiffness: float  # [N/m^e]
    exponent: float  # [-]
    damping: float  # [N s/m]
    friction_static: float  # [-]
    friction_dynamic: float  # [-]


@dataclass(frozen=True)
class RobotModel:
    """A biped's geometry and walking defaults, in SI units.

    Attributes:
        name: Short name used on the command line.
        description: One line for humans.
        mass: Total mass [kg].
        height: Standing height [m].
        hip_spacing: Lateral distance between the hip joints, also the ankle
            spacing of the ready posture [m].
        hip_drop: Hip joints below the pelvis centre [m].
        thigh_length: Hip pitch axis to knee axis [m].
        shank_length: Knee axis to ankle pitch axis [m].
        ankle_height: Ankle axes above the sole [m].
        foot_length: Sole length along the foot x axis [m].
        foot_width: Sole width [m].
        sole_center_x: Sole centre ahead of the ankle [m].
        sole_center_y: Sole centre left of the left ankle (mirrored on the right) [m].
        pelvis_height: Pelvis centre above the ground in the ready posture [m].
        pendulum_length: ``l`` of Eqs. 1-2 (Park 2008), centre-of-mass height [m].
        min_knee: Least knee bend while walking [rad].
        dsp_time: Default double-support time ``d`` [s].
        foot_lift: Default swing apex height [m].
        lateral_velocity: Default ``V_y`` of Eq. 20 [m per unit of ``2 t_bar``].
        joint_limits: Joint role (``"knee"``: both legs) or column (``"left_knee"``: one leg) ->
            (lower, upper) [rad]; a column's entry wins over its role's.
        gravity: Gravitational acceleration [m/s^2].
        hip_x: Hip joint centres ahead of the pelvis origin [m] (TALOS: -0.02).
        com_offset: Centre of mass of the ready posture ahead of and left of the pelvis origin [m]. The
            pattern's pelvis point is the point above the CoM: the pelvis origin is this far behind it.
        legs: The two leg chains (left, right) of an imported model, in the pelvis frame and the model's
            angles; None for the built-in yaw-roll-pitch-pitch-pitch-roll leg of the robot file.
        plant: The model file and what the simulation needs to run it (imported robots), or None.
        schedule_scale: Factors (time, stride, lateral) [-] mapping this robot's steps onto the HUBO
            tables: times with ``sqrt(l / l_HUBO)``, strides and foot lift with the leg length
            ``L / L_HUBO`` (thigh plus shank), sway with the hip spacing (``zmpwalk.schedule``).
        foot_speed_limit: Fastest the swinging ankle may move [m/s]; None: :attr:`max_foot_speed`'s
            size-scaled default.
        foot_acceleration_limit: Largest acceleration of the swinging ankle [m/s^2]; None: 5 g.
        stabilizer_gains: The robot file's own ``[stabilizer]`` gains, (name, value) pairs.
        generator: The pattern generator a robot file chose (``[walking] generator``, one of
            :data:`GENERATOR_NAMES`); None: the default of the robot's kind (:attr:`default_generator`).
    """

    name: str
    description: str
    mass: float  # [kg]
    height: float  # [m]
    hip_spacing: float  # [m]
    hip_drop: float  # [m]
    thigh_length: float  # [m]
    shank_length: float  # [m]
    ankle_height: float  # [m]
    foot_length: float  # [m]
    foot_width: float  # [m]
    sole_center_x: float  # [m]
    sole_center_y: float  # [m]
    pelvis_height: float  # [m]
    pendulum_length: float  # [m]
    min_knee: float  # [rad]
    dsp_time: float  # [s]
    foot_lift: float  # [m]
    lateral_velocity: float  # [m per unit 2*t_bar]
    joint_limits: dict[str, tuple[float, float]] = field(default_factory=dict)  # [rad]
    gravity: float = 9.81  # [m/s^2]
    links: dict[str, Link] = field(default_factory=dict)  # torso, thigh, shank, foot (one leg's)
    servos: Servos | None = None
    contact: Contact | None = None
    hip_x: float = 0.0  # [m]
    com_offset: tuple[float, float] = (0.0, 0.0)  # [m]
    legs: tuple[LegChain, LegChain] | None = None
    plant: ModelPlant | None = None
    schedule_scale: tuple[float, float, float] = (1.0, 1.0, 1.0)  # [-] time, stride, lateral
    foot_speed_limit: float | None = None  # [m/s]
    foot_acceleration_limit: float | None = None  # [m/s^2]
    stabilizer_gains: tuple[tuple[str, float], ...] = ()  # the robot's own [stabilizer] gains (name, value)
    generator: str | None = None  # the robot file's [walking] generator; None: default_generator's rule

    @property
    def own_model(self) -> bool:
        """Whether the robot is its own MJCF/URDF model (:func:`zmpwalk.robots.imported.import_robot`: the
        simulation drives that model, its :attr:`legs` are chains found in it, the pattern's point is its
        whole-body centre of mass) rather than a box model generated from a robot file's data (the pattern's
        point is the pelvis, the legs the straight closed form of its link lengths)."""
        return self.plant is not None

    @property
    def default_generator(self) -> str:
        """The pattern generator this robot walks with where none is named (``zmpwalk plan``, ``simulate``,
        ``report``, ``demo``, ``sweep`` without ``--generator``): the robot file's ``[walking] generator``,
        else :data:`OWN_MODEL_GENERATOR` for a robot built from its own model (:attr:`own_model`),
        else :data:`BOX_MODEL_GENERATOR`."""
        if self.generator is not None:
            return self.generator
        return OWN_MODEL_GENERATOR if self.own_model else BOX_MODEL_GENERATOR

    def hip_in_pelvis(self, side: int) -> tuple[float, float, float]:
        """Hip joint centre of the left (``side = +1``) or right (-1) leg relative to the pattern's pelvis
        point (the pelvis origin shifted by :attr:`com_offset`) [m]."""
        return (self.hip_x - self.com_offset[0], side * self.hip_spacing / 2 - self.com_offset[1], -self.hip_drop)

    def limits_of(self, column: str) -> tuple[float, float]:
        """Range of a joint column such as ``"left_knee"`` [rad] (unlimited where the robot gives none)."""
        if column in self.joint_limits:
            return self.joint_limits[column]
        role = column.split("_", 1)[1]
        return self.joint_limits.get(role, (-math.inf, math.inf))

    @property
    def link_mass(self) -> float:
        """Mass of the torso and both legs from :attr:`links` [kg] (0 without links)."""
        if not self.links:
            return 0.0
        return self.links["torso"].mass + 2 * sum(self.links[n].mass for n in ("thigh", "shank", "foot"))

    @property
    def max_leg_reach(self) -> float:
        """Largest hip-to-ankle distance, at the least knee bend [m]."""
        a, b = self.thigh_length, self.shank_length
        return math.sqrt(a * a + b * b + 2 * a * b * math.cos(self.min_knee))

    @property
    def max_foot_speed(self) -> float:
        """Fastest the swinging ankle may move [m/s]: :attr:`foot_speed_limit`, by default
        ``1.6 sqrt(g l)`` (4 m/s for HUBO's l = 0.62 m: dynamically similar robots, equal Froude number)."""
        if self.foot_speed_limit is not None:
            return self.foot_speed_limit
        return FOOT_SPEED_FROUDE * math.sqrt(self.gravity * self.pendulum_length)

    @property
    def max_foot_acceleration(self) -> float:
        """Largest acceleration of the swinging ankle [m/s^2]: :attr:`foot_acceleration_limit`, by default
        5 g (equal for dynamically similar robots)."""
        if self.foot_acceleration_limit is not None:
            return self.foot_acceleration_limit
        return FOOT_ACCELERATION_G * self.gravity

    @property
    def max_foot_lift(self) -> float:
        """Highest swing apex above the ankle's ground height [m]: half the hip's height above the ankle,
        so the swinging ankle stays well below the hip."""
        return 0.5 * (self.hip_height - self.ankle_height)

    @property
    def hip_height(self) -> float:
        """Hip joints above the ground in the ready posture [m]."""
        return self.pelvis_height - self.hip_drop


_SECTIONS: dict[str, dict[str, str]] = {
    "": {"name": "name", "description": "description", "mass": "mass", "height": "height",
         "gravity": "gravity"},
    "legs": {"hip_spacing": "hip_spacing", "hip_drop": "hip_drop", "hip_x": "hip_x", "thigh_length": "thigh_length",
             "shank_length": "shank_length", "ankle_height": "ankle_height"},
    "foot": {"length": "foot_length", "width": "foot_width", "sole_center_x": "sole_center_x",
             "sole_center_y": "sole_center_y"},
    "posture": {"pelvis_height": "pelvis_height", "pendulum_length": "pendulum_length",
                "min_knee": "min_knee"},
    "walking": {"dsp_time": "dsp_time", "foot_lift": "foot_lift",
                "lateral_velocity": "lateral_velocity", "scale_schedule": "scale_schedule",
                "foot_speed_limit": "foot_speed_limit", "foot_acceleration_limit": "foot_acceleration_limit",
                "generator": "generator"},
}
_OPTIONAL = {"gravity", "hip_x", "scale_schedule", "foot_speed_limit", "foot_acceleration_limit", "generator"}
_POSITIVE = {"mass", "height", "hip_spacing", "thigh_length", "shank_length", "ankle_height",
             "foot_length", "foot_width", "pelvis_height", "pendulum_length", "gravity",
             "dsp_time", "lateral_velocity", "foot_speed_limit", "foot_acceleration_limit"}
# Sections a later part of zmpwalk reads (bodies, servos); kept as raw tables.
_EXTRA_SECTIONS = {"limits", "bodies", "servos", "contact", "stabilizer"}  # read by their own parsers


def schedule_scale(pendulum_length: float, leg_length: float, hip_spacing: float) -> tuple[float, float, float]:
    r"""Factors (time, stride, lateral) [-] that map a robot's steps onto the HUBO tables.

    The cart-table model ``p = x - (l / g) x''`` (Eqs. 1-2) is linear in length: if HUBO's pelvis
    ``x_H(t)`` has the ZMP ``p_H(t)``, then ``lambda x_H(t / s_t)`` has the ZMP ``lambda p_H(t / s_t)`` on a
    robot of pendulum length ``l`` for **any** length factor ``lambda``, provided the time factor is

    .. math:: s_t = \sqrt{l / l_{HUBO}}

    (``x'' / s_t^2`` times ``l / g`` is HUBO's ``l_HUBO / g``). Time is fixed by the pendulum; length is
    free. zmpwalk takes the leg length ``L`` (thigh plus shank) for strides and foot lift,
    ``lambda = L / L_HUBO``: the legs then sweep HUBO's angles, so a table row asks of every robot what it
    asks of HUBO's legs (a top-heavy robot has a long pendulum on short legs: TALOS, ``l / l_HUBO`` = 1.47
    but ``L / L_HUBO`` = 1.17, would otherwise be asked for 44 cm strides that its legs cannot reach). The
    sideways sway scales with the hip spacing, the distance it must cover.

    Args:
        pendulum_length: ``l`` [m].
        leg_length: ``L`` [m].
        hip_spacing: [m].
    """
    return (math.sqrt(pendulum_length / HUBO_PENDULUM), leg_length / HUBO_LEG_LENGTH, hip_spacing / HUBO_HIP_SPACING)


def checked_generator(value: object, source: str) -> str:
    """A robot file's ``[walking] generator``: one of :data:`GENERATOR_NAMES`.

    Raises:
        FileFormatError: Not a string, or not a generator's name (lists the known ones).
    """
    if not isinstance(value, str) or value not in GENERATOR_NAMES:
        raise FileFormatError(source, f"[walking] {UnknownNameError('generator', str(value), GENERATOR_NAMES)}")
    return value


def _table(kind: type[Any], table: object, name: str, source: str) -> Any:
    """A table of positive numbers into the dataclass ``kind`` (None when the table is absent)."""
    if table is None:
        return None
    names = [f.name for f in fields(kind)]
    if not isinstance(table, dict) or set(table) != set(names):
        raise FileFormatError(source, f"[{name}] needs exactly: {', '.join(names)}")
    values = {}
    for key in names:
        value = table[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
            raise FileFormatError(source, f"[{name}] {key} = {value!r} must be a number > 0")
        values[key] = float(value)
    return kind(**values)


def stabilizer_gains(table: object, source: str) -> tuple[tuple[str, float], ...]:
    """The [stabilizer] table: gains of :class:`zmpwalk.stabilizer_gains.StabilizerGains` tuned for this robot
    (the others keep their defaults), checked as the gains check them."""
    if table is None:
        return ()

    known = [f.name for f in fields(StabilizerGains)]
    if not isinstance(table, dict):
        raise FileFormatError(source, "[stabilizer] must be a table of gains")
    for key in table:
        if key not in known:
            raise FileFormatError(source, f"[stabilizer] unknown gain {key!r}; known: {', '.join(known)}")
    try:
        StabilizerGains(**table)
    except (InvalidParameterError, TypeError) as error:
        raise FileFormatError(source, f"[stabilizer] {error}") from None
    return tuple((key, float(value)) for key, value in table.items())


def _links(table: object, values: dict[str, Any], source: str) -> dict[str, Link]:
    """The [bodies] table: mass and box per link; leg centres of mass default to the segment middles."""
    if table is None:
        return {}
    if not isinstance(table, dict) or set(table) != set(LINK_NAMES):
        raise FileFormatError(source, f"[bodies] needs exactly: {', '.join(LINK_NAMES)}")
    defaults = {
        "torso": (0.0, 0.0, 0.0),
        "thigh": (0.0, 0.0, -values["thigh_length"] / 2),
        "shank": (0.0, 0.0, -values["shank_length"] / 2),
        "foot": (values["sole_center_x"], 0.0, -values["ankle_height"]),
    }
    links = {}
    for name in LINK_NAMES:
        entry = table[name]
        try:
            mass = float(entry["mass"])
            size = tuple(float(v) for v in entry["size"])
            com = tuple(float(v) for v in entry.get("com", defaults[name]))
        except (KeyError, TypeError, ValueError):
            raise FileFormatError(source, f"[bodies] {name} needs mass [kg] and size [x, y, z] [m]") from None
        if mass <= 0 or len(size) != 3 or min(size) <= 0 or len(com) != 3:
            raise FileFormatError(source, f"[bodies] {name}: mass > 0, three sizes > 0 and a 3-vector com")
        if name == "foot" and "com" not in entry:
            com = (com[0], com[1], com[2] + size[2] / 2)  # the box rests on the ground
        links[name] = Link(mass, (size[0], size[1], size[2]), (com[0], com[1], com[2]))
    return links


def robot_from_dict(data: dict[str, Any], source: str = "<robot>") -> RobotModel:
    """Build a :class:`RobotModel` from the tables of a robot file."""
    values: dict[str, Any] = {}
    for section, section_fields in _SECTIONS.items():
        table = data if section == "" else data.get(section)
        if not isinstance(table, dict):
            raise FileFormatError(source, f"missing table [{section}]")
        known = set(section_fields)
        if section == "":
            known |= (set(_SECTIONS) - {""}) | _EXTRA_SECTIONS
        for key in table:
            if key not in known:
                where = f"[{section}] " if section else ""
                names = ", ".join(sorted(section_fields))
                raise FileFormatError(source, f"{where}unknown field {key!r}; known: {names}")
        for key, attribute in section_fields.items():
            if key not in table:
                if attribute in _OPTIONAL:
                    continue
                raise FileFormatError(source, f"[{section}] missing field {key!r}")
            value = table[key]
            if attribute in ("name", "description"):
                if not isinstance(value, str):
                    raise FileFormatError(source, f"{key} must be a string")
            elif attribute == "generator":
                value = checked_generator(value, source)
            elif attribute == "scale_schedule":
                if not isinstance(value, bool):
                    raise FileFormatError(source, f"[{section}] {key} = {value!r} must be true or false")
            else:
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    raise FileFormatError(source, f"[{section}] {key} = {value!r} must be a finite number")
                value = float(value)
                if attribute in _POSITIVE and value <= 0:
                    raise FileFormatError(source, f"[{section}] {key} = {value:g} must be > 0")
            values[attribute] = value
    limits: dict[str, tuple[float, float]] = {}
    columns = list(JOINT_COLUMNS)
    for joint, bounds in data.get("limits", {}).items():
        if joint not in JOINT_NAMES and joint not in columns:
            raise FileFormatError(source, f"[limits] unknown joint {joint!r}; known: {', '.join(JOINT_NAMES)} "
                                  "(both legs) or one leg's, e.g. left_knee")
        if (not isinstance(bounds, list) or len(bounds) != 2
                or not all(isinstance(b, (int, float)) for b in bounds) or bounds[0] >= bounds[1]):
            raise FileFormatError(source, f"[limits] {joint} must be [lower, upper] with lower < upper")
        limits[joint] = (float(bounds[0]), float(bounds[1]))
    values["joint_limits"] = limits
    values["links"] = _links(data.get("bodies"), values, source)
    values["servos"] = _table(Servos, data.get("servos"), "servos", source)
    values["contact"] = _table(Contact, data.get("contact"), "contact", source)
    values["stabilizer_gains"] = stabilizer_gains(data.get("stabilizer"), source)
    if values.pop("scale_schedule", True):
        values["schedule_scale"] = schedule_scale(values["pendulum_length"], values["thigh_length"]
                                                  + values["shank_length"], values["hip_spacing"])
    robot = RobotModel(**values)
    if robot.hip_height - robot.ankle_height >= robot.max_leg_reach:
        raise FileFormatError(source, "[posture] pelvis_height leaves the legs straighter than min_knee allows")
    return robot
