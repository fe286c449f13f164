"""The two legs of a robot's own model: which joints they are, each joint's role, the leg chain
(:class:`~zmpwalk.leg_chain.LegChain`) with its sole, and the masses the chain's segments carry.

A leg is the hinge joints from where the two feet's paths part down to a foot: six (hip yaw, roll and pitch in
any order, a pitch knee, an ankle pitch and roll in either order), or five without the ankle roll (Unitree H1).
A five-joint leg's chain gets a **virtual** ankle roll after its ankle pitch, which no motor turns: an axis
along the sole's x axis through the sole's centre line on the floor (the ankle height below the ankle pitch's
anchor, at the sole's mid-width), the line about which a foot that cannot roll at its ankle rolls on the floor
(Unitree H1's foot rests on a heel-to-toe capsule there). The inverse kinematics returns the sole roll the five
joints cannot give as its angle (:mod:`zmpwalk.leg_chain`); the sole's centre line stays where the pattern puts
it, so a foot rolled on it stands where planned. The simulation and the stabilizer send nothing to it. Its joint
column keeps zmpwalk's 12-column layout (left leg then right, role order), its range the sole roll a walk may
leave (:func:`zmpwalk.robots.collision.sole_roll_bound`).

**Why a five-joint leg cannot walk a pattern with a flat sole and an upright pelvis.** With the hip yaw at 0 the
sole's rotation in the pelvis frame is ``R_x(q_2) R_y(q_3 + q_4 + q_5)``: a level sole under an upright pelvis
needs ``q_2 = 0``, and the leg then hangs in its own vertical plane, the ankle a fixed ``d`` beside the hip roll
axis (Unitree H1: 115.4 mm, its ankles 405.7 mm apart). The pelvis cannot move sideways over a sole: what the
walking pattern asks (its CoM over the stance sole, the ZMP in it) needs one of

(a) the pelvis rolled by ``phi``: the hip roll axis, ``h`` below the pelvis origin (H1: 174.2 mm), then moves the
    origin by ``h sin(phi)`` over the fixed leg plane, so a sway ``s`` needs ``sin(phi) = s / h``, four to five
    times the sole roll of (b). On H1's walks (the three example steps files): 0.45-0.50 rad in single support
    with the polynomial generator, up to 0.9 rad with the preview generator, where some samples have none; in
    double support the two legs need rolls up to 0.15-0.36 rad apart, so no pelvis roll keeps both soles flat;
    the hip rolls' range is 0.43 rad. It does not fit;

(b) the sole rolled by ``rho``, the leg inclined across: ``L sin(rho) = s`` with ``L`` the hip-to-sole height
    (about 0.9 m): the inverse kinematics meets the sole's centre line, heading and pitch and leaves that roll, the
    virtual joint's angle. On H1's walks: up to 0.110-0.146 rad (polynomial), 0.216-0.235 rad (preview).

(b) is what zmpwalk computes: it needs the smaller angle and exists at every sample. A rolled sole stands on an
edge, though: a walk is accepted only where the roll stays within the band that makes the sole a sole
(:func:`~zmpwalk.robots.collision.sole_roll_bound`, H1: 0.0333 rad), and a walk beyond it raises
:class:`~zmpwalk.kinematics.JointLimitError` (its ``sole_roll`` set), naming the ankle roll it lacks.

Measured, with the bound lifted: H1 (whose heel-to-toe capsules let it roll on the sole's centre line) sways in
double support with its soles rolled up to 0.2 rad and its torso within 0.003-0.016 rad of upright, and falls in
all six walks once single supports begin: at 3.8-4.2 s with the polynomial generator (whose plan, HUBO's sway
scaled to H1's 406 mm stance, also leaves the soles by 92-102 mm) and at 5.7-9.4 s with the preview generator
(plan inside by 18-21 mm), CoP - ZMP RMS 136-217 mm: on the line it rolls on, its centre of pressure cannot move
sideways, and nothing brakes the sway; a synthetic biped with flat 140 mm box soles keeps them flat and rolls its
torso instead (0.058 rad for a 0.084 rad sole roll), its CoM never reaches the stance sole, and it falls at 4.6 s
(``tests/test_five_joint_legs.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError
from zmpwalk.leg_chain import LegChain
from zmpwalk.robots.collision import Sole, foot_sole
from zmpwalk.robots.description import LegJoint
from zmpwalk.robots.pd import element_name, joint_actuator
from zmpwalk.robots.tree import body_path, joint_path
from zmpwalk.sides import Side

Array = NDArray[np.float64]

ROLES = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
VIRTUAL_PREFIX = "zmpwalk_virtual_"  # name of a five-joint leg's virtual ankle roll: no model joint has it
MIN_SOLE = 0.01  # [m] a sole shorter or narrower than this in the reference posture does not stand flat there


def leg_joint_ids(model: object, base: int, feet: list[int], source: str) -> list[list[int]]:
    """Each leg's hinge joints, hip to foot: those below the point where the two feet's paths part.

    Raises:
        FileFormatError: A leg of other than 5 or 6 joints, or a joint that is not a hinge.
    """
    import mujoco

    m = model
    left_bodies, right_bodies = (body_path(m, base, f) for f in feet)
    shared = [b for b in left_bodies if b in right_bodies]
    legs = []
    for label, foot in zip(("left", "right"), feet, strict=True):
        leg = [j for j in joint_path(m, base, foot) if int(m.jnt_bodyid[j]) not in shared]  # type: ignore[attr-defined]
        names = [element_name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in leg]
        if len(leg) not in (5, 6):
            foot_name = element_name(m, mujoco.mjtObj.mjOBJ_BODY, foot)
            raise FileFormatError(source, f"the {label} leg (to foot body {foot_name!r}) has {len(leg)} joints "
                                  f"({', '.join(names) or 'none'}); zmpwalk walks legs of 6 hinge joints, or of 5 "
                                  "without the ankle roll")
        for j, joint_name in zip(leg, names, strict=True):
            if m.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:  # type: ignore[attr-defined]
                raise FileFormatError(source, f"{label} leg joint {joint_name!r} is not a hinge (revolute) joint")
        legs.append(leg)
    return legs


def joint_roles(axes: Array, names: list[str], label: str, source: str) -> list[str]:
    """Role of each chain joint from its axis at the zero pose (largest component z: yaw, x: roll, y: pitch) and
    its place (hip: the first three, knee: the fourth, ankle: the rest); a five-joint leg's list ends with the
    virtual ``ankle_roll``.

    Raises:
        FileFormatError: The axes do not make a 3-axis hip, a pitch knee and a pitch-roll ankle (or an ankle pitch
            alone).
    """
    kinds = ["yaw" if k == 2 else "roll" if k == 0 else "pitch" for k in np.argmax(np.abs(axes), axis=1)]
    counts = {k: kinds.count(k) for k in ("yaw", "roll", "pitch")}
    described = ", ".join(f"{n} ({k})" for n, k in zip(names, kinds, strict=True))
    ankles = (["pitch", "roll"], ["roll", "pitch"]) if len(kinds) == 6 else (["pitch"],)
    wanted = {"yaw": 1, "roll": 2 if len(kinds) == 6 else 1, "pitch": 3}
    if counts != wanted or kinds[3] != "pitch" or kinds[4:] not in ankles or "yaw" not in kinds[:3]:
        raise FileFormatError(source, f"the {label} leg has {len(kinds)} joints: {described}; zmpwalk walks legs "
                              "with a 3-axis hip (yaw, roll, pitch in any order), a pitch knee and a pitch-roll ankle "
                              "(or, in a 5-joint leg, an ankle pitch alone)")
    roles = [f"hip_{kind}" if index < 3 else "knee" if index == 3 else f"ankle_{kind}"
             for index, kind in enumerate(kinds)]
    return roles if len(roles) == 6 else [*roles, "ankle_roll"]


@dataclass(frozen=True)
class Segments:
    """The masses the legs' segments carry (segment ``i`` of a leg: what its joint ``i`` moves up to the next
    joint) and the rest of the body (base, trunk, arms, head: rigid with the base at the reference pose).

    Attributes:
        mass: [kg], (2, 6), left leg then right.
        com: Their centres of mass in the pelvis frame at zero angles [m], (2, 6, 3).
        rest_mass: [kg].
        rest_com: [m], (3,).
    """

    mass: Array
    com: Array
    rest_mass: float
    rest_com: Array


def segments(model: object, data: object, base: int, legs: list[list[int]],
             in_pelvis: Callable[[Array], Array]) -> Segments:
    """:class:`Segments` from MuJoCo's body masses, ``data`` at the zero pose of the legs (base at the origin)."""
    m = model
    segment_of = {j: (leg_index, k) for leg_index, leg in enumerate(legs) for k, j in enumerate(leg)}
    mass, moment = np.zeros((2, 6)), np.zeros((2, 6, 3))
    rest_mass, rest_moment = 0.0, np.zeros(3)
    for body in range(1, m.nbody):  # type: ignore[attr-defined]
        last = None
        for j in joint_path(m, base, body):
            last = segment_of.get(j, last)
        body_mass = float(m.body_mass[body])  # type: ignore[attr-defined]
        com = in_pelvis(data.xipos[body])  # type: ignore[attr-defined]
        if last is None:
            rest_mass += body_mass
            rest_moment += body_mass * com
        else:
            mass[last] += body_mass
            moment[last] += body_mass * com
    return Segments(mass, moment / np.maximum(mass, 1e-12)[..., None], rest_mass, rest_moment / max(rest_mass, 1e-12))


@dataclass(frozen=True)
class FootAtReference:
    """A foot in the reference posture: its collision points in the foot body's frame [m], (m, 3), and the up of its
    sole's plane in that frame, (3,) (the world's, or a box sole's own bottom face)."""

    points: Array
    up: Array


def build_leg(model: object, data: object, side: int, foot: int, leg: list[int], reference_qpos: Array,
              masses: Segments, foot_reference: FootAtReference, in_pelvis: Callable[[Array], Array],
              base_rotation: Array, source: str) -> tuple[LegChain, list[LegJoint], Sole]:
    """One leg's chain (its reference angles the keyframe's), its joints by role (:data:`ROLES` order) and its sole,
    ``data`` at the zero pose of the legs (base at the origin).

    Raises:
        FileFormatError: Roles that do not make a leg (:func:`joint_roles`), or a foot whose sole does not stand
            flat in the reference posture (shorter or narrower than :data:`MIN_SOLE`).
    """
    import mujoco

    m, d = model, data
    label = Side(side).label
    names = [element_name(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in leg]
    axes = np.array([base_rotation.T @ d.xaxis[j] for j in leg])  # type: ignore[attr-defined]
    points = np.array([in_pelvis(d.xanchor[j]) for j in leg])  # type: ignore[attr-defined]
    roles = joint_roles(axes, names, label, source)
    five = len(leg) == 5
    ankle = points[4] if five else LegChain(side, tuple(names), axes, points, np.zeros(3)).ankle_point
    rotation = base_rotation.T @ d.xmat[foot].reshape(3, 3)  # type: ignore[attr-defined]
    sole = foot_sole(foot_reference.points, foot_reference.up, rotation, in_pelvis(d.xpos[foot]), ankle)  # type: ignore[attr-defined]
    length, width = sole.extent
    if length < MIN_SOLE or width < MIN_SOLE:
        foot_name = element_name(m, mujoco.mjtObj.mjOBJ_BODY, foot)
        raise FileFormatError(source, f"the {label} foot {foot_name!r} touches the floor with a {length * 1e3:.1f} x "
                              f"{width * 1e3:.1f} mm sole in the reference posture: it does not stand flat there; "
                              "give a keyframe in which the feet stand level (--keyframe)")
    lower = [m.jnt_range[j][0] if m.jnt_limited[j] else -np.inf for j in leg]  # type: ignore[attr-defined]
    upper = [m.jnt_range[j][1] if m.jnt_limited[j] else np.inf for j in leg]  # type: ignore[attr-defined]
    reference = [float(reference_qpos[m.jnt_qposadr[j]]) for j in leg]  # type: ignore[attr-defined]
    if five:  # the virtual ankle roll: along the sole's centre line on the floor, unlimited, at 0
        centre_y = float(sole.polygon[:, 1].max() + sole.polygon[:, 1].min()) / 2
        line = ankle + sole.rotation @ np.array([0.0, centre_y, -sole.ankle_height])
        axes, points = np.vstack([axes, sole.rotation[:, 0]]), np.vstack([points, line])
        names, lower, upper, reference = [*names, f"{VIRTUAL_PREFIX}{label}_ankle_roll"], [*lower, -np.inf], \
            [*upper, np.inf], [*reference, 0.0]
    knee = roles.index("knee")
    if abs(reference[knee]) < 0.1:  # the IK branch: a knee bent the way its range allows where the keyframe is straight
        reference[knee] = 0.5 if upper[knee] > 0.5 or upper[knee] >= -lower[knee] else -0.5
    index = 0 if side > 0 else 1
    chain = LegChain(side, tuple(names), axes, points, ankle, reference=np.array(reference), lower=np.array(lower),
                     upper=np.array(upper), role_order=tuple(roles.index(role) for role in ROLES),
                     link_masses=masses.mass[index], link_coms=masses.com[index], sole_rotation=sole.rotation,
                     virtual=5 if five else None, sole_tilt_reference=sole.tilt_reference)
    knee_bend = knee_offset(chain)
    joints = []
    for role in ROLES:
        k = roles.index(role)
        axis = axes[k]
        dominant = int(np.argmax(np.abs(axis)))
        joints.append(LegJoint(
            role=role, name=chain.joint_names[k], axis=(float(axis[0]), float(axis[1]), float(axis[2])),
            sign=1 if axis[dominant] > 0 else -1, zero_offset=knee_bend if role == "knee" else 0.0,
            limits=(float(lower[k]), float(upper[k])),
            actuator=None if k == chain.virtual else joint_actuator(m, leg[k])))
    return chain, joints, sole


def knee_offset(chain: LegChain) -> float:
    """Bend of the zero pose at the knee: angle from the thigh to the shank direction about the knee axis [rad]."""
    axis = chain.axes[3]
    thigh = chain.knee_point - chain.hip
    shank = chain.ankle - chain.knee_point
    thigh -= axis * (axis @ thigh)
    shank -= axis * (axis @ shank)
    return float(math.atan2(float(axis @ np.cross(thigh, shank)), float(thigh @ shank)))
