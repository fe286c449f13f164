"""A robot from its own model: MJCF (``.xml``) or URDF (``.urdf``), read with MuJoCo's compiler.

:func:`import_robot` finds the two legs and derives from the model everything
zmpwalk needs (the builder's model is the single source of truth):

* **Floating base**: the body with the free joint (a URDF gets one at its root
  link). It is the legs' base unless a joint between it and the body where the
  two feet's paths part is driven by no actuator of its own (a waist tied to its
  motors by a tendon or an equality, maybe with slack): then that body, the
  pelvis (:func:`~zmpwalk.robots.tree.legs_base`). The legs' base's frame is the
  **pelvis frame** of zmpwalk (x forward, y left, z up), and the simulator's
  sensors (attitude, gyro) sit on it.
* **Feet**: with no mapping, the two bodies whose collision geoms reach lowest in
  the reference pose (the model's keyframe, or its zero pose), one each side of
  the base (``y > 0`` left). Two candidates within
  :data:`~zmpwalk.robots.tree.FOOT_TIE` of each other on one side make the tree
  ambiguous: give ``feet = (left, right)`` body names (:mod:`zmpwalk.robots.tree`).
* **Legs** (:mod:`zmpwalk.robots.legs`): the hinge joints on the path from the
  point where the two feet's paths part down to each foot; six per leg, or five
  without the ankle roll (a virtual ankle roll completes its chain). Joints above
  that point (a waist) and every other joint (arms, head) are held at the
  reference pose. Each leg joint gets its role (hip yaw, hip roll, hip pitch,
  knee, ankle pitch, ankle roll) from its axis at the zero pose (the axis's
  largest component: z yaw, x roll, y pitch) and its place in the chain, and its
  sign from the direction of that component. The knee's zero offset is the bend
  of the model's zero pose (thigh and shank directions about the knee axis).
* **Geometry** in the pelvis frame at the zero pose: hip centre (the point
  nearest the three hip axes, with their largest distance from it), knee and
  ankle points, link lengths. The hip spacing is the hip centres' (a five-joint
  leg's: its ankles', the plane in which its sole stays flat under an upright
  pelvis).
* **Sole** (:func:`zmpwalk.robots.collision.foot_sole`), taken in the
  **reference posture**, where the foot stands level: the foot's collision geoms
  within :data:`~zmpwalk.robots.collision.SOLE_BAND` of the lowest, projected on
  the floor (polygon), the ankle height above them, and the sole frame's rotation
  in the pelvis frame at zero angles, which the leg chain's inverse kinematics
  keeps level.
* **Ready posture**: the hips above the ankles at the keyframe's
  hip-to-ankle distance, at most :data:`~zmpwalk.robots.posture.READY_STRETCH` of the straight leg (a
  bent knee for walking), or the robot file's ``[posture] ready_stretch`` of it
  (:func:`zmpwalk.ready_fit.fit_ready_posture` chooses one where a walk's strides
  need another). The pattern moves the centre of mass: the CoM's
  offset from the base origin in that posture, ``com_offset``, is found by
  fixed-point iteration (the posture moves the CoM, the CoM moves the
  posture) and every pattern point is shifted by it. The pendulum length is the
  CoM's height.
* **Limits, actuators, mass**: joint ranges per joint and side; each leg joint's
  actuator (type, ``kp``, ``kv``, force range); total mass.
* **Joint PD layer**: a torque motor (``<motor>``), a leg joint without an actuator, and every joint of a
  model without actuators (a URDF) is driven as a humanoid's firmware drives it, by a joint PD loop
  ``tau = kp (q_ref - q) - kv q'`` clipped at the joint's torque limit (:func:`pd_gains`'s rule, or the
  robot file's ``[pd]``); the simulation runs it as a position servo (:mod:`zmpwalk.sim.plant`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError
from zmpwalk.leg_chain import LegChain
from zmpwalk.robots.collision import Sole, collision_points, rigid_bodies, sole_face_up, sole_roll_bound
from zmpwalk.robots.description import (
    HUBO_FOOT_LIFT,
    LIFT_RANGE_MARGIN,
    Actuator,
    LegJoint,
    ModelPlant,
)
from zmpwalk.robots.legs import VIRTUAL_PREFIX, FootAtReference, Segments, build_leg, leg_joint_ids, segments
from zmpwalk.robots.linkages import joint_id
from zmpwalk.robots.model import RobotModel, schedule_scale
from zmpwalk.robots.pd import (
    check_load_stiffness,
    coupled_joints,
    element_name,
    joint_torque_limit,
    linkage_limits,
    model_physics_step,
    pd_layer,
)
from zmpwalk.robots.posture import hip_to_ankle, posture_set_by, ready_posture, reference_reach
from zmpwalk.robots.tree import (
    base_mount,
    find_feet,
    floating_base,
    keyframe_index,
    legs_base,
)

Array = NDArray[np.float64]



def load_model(path: Path, package_paths: tuple[Path, ...] = ()) -> Any:
    """The compiled :class:`mujoco.MjModel` of an MJCF or URDF file (see :func:`load_model_spec`)."""
    return load_model_spec(path, package_paths).compile()


def load_model_spec(path: Path, package_paths: tuple[Path, ...] = ()) -> Any:
    """A :class:`mujoco.MjSpec` of an MJCF or URDF file; a URDF gets a free joint at its root link.

    Raises:
        FileFormatError: No such file, an unresolved ``package://`` path, or MuJoCo cannot compile it
            (the message is MuJoCo's, e.g. the missing mesh).
    """
    import mujoco

    if not path.is_file():
        raise FileFormatError(str(path), "no such file")
    try:
        if path.suffix.lower() == ".urdf":
            text = _resolve_packages(path, package_paths)
            spec = mujoco.MjSpec.from_string(text)
            spec.meshdir = str(path.parent)
            spec.strippath = False
            root = spec.worldbody.first_body()
            if root is None:
                raise FileFormatError(str(path), "the URDF has no links")
            if not root.joints:
                root.add_freejoint()
        else:
            spec = mujoco.MjSpec.from_file(str(path))
        spec.compile()  # checks it (missing meshes, bad references) once, here
    except FileFormatError:
        raise
    except (ValueError, RuntimeError, UnicodeDecodeError) as error:
        message = " ".join(str(error).split())
        raise FileFormatError(str(path), f"MuJoCo cannot compile the model: {message}") from None
    return spec


def _resolve_packages(path: Path, package_paths: tuple[Path, ...]) -> str:
    """The URDF text with ``package://NAME/REST`` replaced by absolute paths (searched in ``package_paths``
    and the file's own folder and its parents), and relative mesh paths made absolute."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        raise FileFormatError(str(path), f"cannot read the URDF: {error}") from None
    roots = [*package_paths, path.parent, *path.parent.parents]

    def package(match: re.Match[str]) -> str:
        name, rest = match.group(1), match.group(2)
        for root in roots:
            for candidate in (root / name / rest, root / rest if root.name == name else None):
                if candidate is not None and candidate.is_file():
                    return str(candidate.resolve())
        searched = ", ".join(str(r) for r in roots[:4])
        raise FileFormatError(str(path), f"cannot resolve package://{name}/{rest} (searched {searched}; "
                              "give the folder that holds the package with --package-path)")

    text = re.sub(r"package://([^/\"']+)/([^\"']+)", package, text)

    def relative(match: re.Match[str]) -> str:
        filename = match.group(2)
        if Path(filename).is_absolute():
            return match.group(0)
        return f"{match.group(1)}{(path.parent / filename).resolve()}{match.group(3)}"

    return re.sub(r"(filename=[\"'])([^\"']+)([\"'])", relative, text)


def import_robot(path: str | Path, *, feet: tuple[str, str] | None = None, keyframe: str | None = None,
                 package_paths: tuple[Path, ...] = (), name: str | None = None,
                 overrides: dict[str, float] | None = None,
                 pd_gains: dict[str, tuple[float, float | None]] | None = None) -> RobotModel:
    """The :class:`~zmpwalk.robots.model.RobotModel` of an MJCF or URDF model (see the module docstring).

    Args:
        path: The model file (a Menagerie ``scene*.xml`` with its floor, a robot ``.xml``, or a ``.urdf``).
        feet: Foot body names (left, right), where the tree is ambiguous.
        keyframe: The keyframe of the reference pose (default: the model's first, else its zero pose).
        package_paths: Folders holding the packages of a URDF's ``package://`` paths.
        name: Short name (default: the model's).
        overrides: Robot-file values replacing derived ones (``pelvis_height``, ``dsp_time``, ...; and
            ``load_stiffness``, the PD rule's ``kappa``, :func:`~zmpwalk.robots.pd.pd_gains`; ``ready_stretch``,
            the ready posture's hip-to-ankle distance over the straight leg [-], instead of the keyframe's).
        pd_gains: The PD layer's gains of some joints (model joint name -> (kp [N m/rad], kv [N m s/rad] or
            None: critical damping)) replacing :func:`pd_gains`'s (a robot file's ``[pd]``).

    Raises:
        FileFormatError: What the model lacks for walking, named (no floating base, no legs, a leg of
            other than five or six hinge joints, ambiguous feet, a sole that does not stand flat in the
            reference posture, ...).
        InvalidParameterError: ``pd_gains`` names a joint the PD layer does not drive, ``load_stiffness`` is
            not a finite number > 1, or ``ready_stretch`` is not in :data:`~zmpwalk.robots.posture.STRETCH_RANGE`.
    """
    import mujoco

    path = Path(path)
    source = str(path)
    model = load_model(path, package_paths)
    data = mujoco.MjData(model)
    root = floating_base(model, source)
    key_id = keyframe_index(model, keyframe, source)
    qpos_reference = model.key_qpos[key_id].copy() if key_id >= 0 else model.qpos0.copy()
    data.qpos[:] = qpos_reference
    mujoco.mj_kinematics(model, data)
    foot_ids = find_feet(model, data, root, feet, source)
    feet_at_reference = [_foot_at_reference(model, data, foot, label, source)
                         for foot, label in zip(foot_ids, ("left", "right"), strict=True)]
    base = legs_base(model, root, foot_ids)  # the pelvis: below a waist, not the floating root
    mount = base_mount(model, qpos_reference, root, base)
    legs = leg_joint_ids(model, base, foot_ids, source)
    leg_joint_set = {j for leg in legs for j in leg}
    root_joint = int(model.body_jntadr[root])
    adr = int(model.jnt_qposadr[root_joint])
    base_rotation, base_origin = _zero_pose(model, data, qpos_reference, leg_joint_set, base, adr)

    def in_pelvis(point: Array) -> Array:
        return np.asarray(base_rotation.T @ (point - base_origin), dtype=np.float64)

    masses = segments(model, data, base, legs, in_pelvis)
    built = [build_leg(model, data, side, foot, leg, qpos_reference, masses, at_reference, in_pelvis, base_rotation,
                       source) for side, foot, leg, at_reference in zip((1, -1), foot_ids, legs, feet_at_reference,
                                                                        strict=True)]
    chains = [chain for chain, _, _ in built]
    leg_joints = [joint for _, joints, _ in built for joint in joints]
    geometry = _geometry(chains, (built[0][2], built[1][2]), source)
    g, straight = geometry, geometry.thigh + geometry.shank  # [m] the straight leg
    mass = float(np.sum(model.body_mass))
    values = dict(overrides or {})
    posture_set_by(values)  # one of them at most
    distance, height_scale = reference_reach(model, data, qpos_reference, base, chains[0].hip, foot_ids[0],
                                              g.ankle_height, straight, values.get("ready_stretch"))
    plant = _model_plant(model, path, (base, root), foot_ids, key_id, leg_joint_set | {root_joint}, masses,
                         built[0][2].polygon, package_paths)
    ready = ready_posture(model, data, chains, legs, qpos_reference, (adr, mount), distance, g.hip_x, g.hip_spacing,
                          g.hip_drop, g.ankle_height, values.get("pelvis_height"), source)
    pelvis_height, pendulum, com_offset, chains_ready, qpos = ready
    length_scale = schedule_scale(pendulum, straight, g.hip_spacing)[1]
    lift = _foot_lift(chains_ready, leg_joints, HUBO_FOOT_LIFT * length_scale)  # [m]
    weight = mass * float(np.linalg.norm(model.opt.gravity))  # [N]; a leg joint holds m g l [N m]
    plant, leg_joints = _with_pd_layer(model, data, qpos, plant, leg_joints, leg_joint_set, geometry, values,
                                       pd_gains or {}, weight, weight * pendulum, source)
    stretch = (hip_to_ankle(chains_ready[0]) if "pelvis_height" in values else distance) / straight  # [-]
    plant = replace(plant, file_values=tuple(sorted(set(values) - {"load_stiffness"})), ready_stretch=stretch)
    return _robot_model(
        name=_robot_name(model, name, path), description=f"imported from {path.name} ({mass:.1f} kg)", mass=mass,
        height=height_scale, geometry=geometry, pelvis_height=pelvis_height, pendulum=pendulum,
        gravity=float(-model.opt.gravity[2]), foot_lift=lift, overrides=values, leg_joints=leg_joints,
        com_offset=com_offset, legs=(chains_ready[0], chains_ready[1]), plant=plant)


def _robot_name(model: Any, name: str | None, path: Path) -> str:
    """``name``, else the model's (letters, digits, ``_.-``), else the file's stem."""
    model_name = model.names[:model.names.find(b"\0")].decode()
    return name or re.sub(r"[^A-Za-z0-9_.-]+", "-", model_name).strip("-") or path.stem


def _with_pd_layer(model: Any, data: Any, qpos: Array, plant: ModelPlant, leg_joints: list[LegJoint],
                   leg_joint_set: set[int], geometry: _Geometry, values: dict[str, float],
                   pd_gains: dict[str, tuple[float, float | None]], weight: float, moment: float, source: str
                   ) -> tuple[ModelPlant, list[LegJoint]]:
    """``plant`` with the joint PD layer (gains from the ready posture ``qpos``'s inertia, a leg joint holding the
    robot's ``moment`` m g l [N m], ``weight`` m g [N]; ``values``' ``load_stiffness``, else the robot's
    :attr:`~zmpwalk.robots.description.ModelPlant.derived_load_stiffness`; ``pd_gains`` given) and the leg joints
    driven by it (a five-joint leg's virtual roll with its range)."""
    import mujoco

    coupled = coupled_joints(model, leg_joint_set)
    _, y_min, _, y_max = geometry.sole_box
    linkage = linkage_limits(model, qpos, coupled)  # a parallel ankle's roll: its motors' torque through the rods
    plant = replace(plant, ankle_roll_torque=_ankle_roll_torque(model, leg_joints, linkage),
                    sole_edge_moment=weight * min(abs(y_min), abs(y_max)))
    load_stiffness = check_load_stiffness(values.get("load_stiffness", plant.derived_load_stiffness))
    pd_joints, physics_step = pd_layer(model, data, qpos, leg_joint_set, moment, pd_gains, coupled, load_stiffness)
    leg_joints = _driven_joints(leg_joints, dict(pd_joints), geometry, values.get("sole_roll_limit"), source)
    names = {j: element_name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in coupled}
    plant = replace(plant, joints=tuple(leg_joints), pd_joints=pd_joints, physics_step=physics_step,
                    model_step=model_physics_step(model),
                    load_stiffness=load_stiffness,
                    pd_given=tuple(sorted(pd_gains)), coupled_joints=tuple(sorted(names.values())),
                    held_joints=tuple(n for n in plant.held_joints if n not in names.values()))
    return plant, leg_joints


def _foot_lift(chains: list[LegChain], leg_joints: list[LegJoint], scaled: float) -> float:
    """The default foot lift [m]: HUBO's scaled to the leg (``scaled``), or less where the leg, its foot raised
    straight up from the ready posture and level (the apex of a step in place), would bring a pitch joint (hip
    pitch, knee, ankle pitch: the lift bends them) that has at least :data:`LIFT_RANGE_MARGIN` of its range free
    in the ready posture closer than that to its limit (Berkeley Humanoid's ankle pitch: 30 -> 10 mm). The roll and
    yaw joints follow the sideways sway more than the lift, and a joint already closer in the ready posture is left
    to the planner, which names it where a step leaves its range."""
    ankles = [chain.fk(chain.reference[None]) for chain in chains]
    limits = [np.array([joint.limits for joint in leg_joints[6 * i:6 * i + 6]]) for i in range(2)]  # by column

    def margins(lift: float) -> Array:
        angles = [chain.solve(ankle + (0.0, 0.0, lift), rotation)[0][0]
                  for chain, (ankle, rotation) in zip(chains, ankles, strict=True)]
        return np.concatenate([np.minimum(q - bounds[:, 0], bounds[:, 1] - q) for q, bounds in zip(angles, limits,
                                                                                                   strict=True)])

    pitch = np.array([joint.role in ("hip_pitch", "knee", "ankle_pitch") for joint in leg_joints])
    watched = pitch & (margins(0.0) >= LIFT_RANGE_MARGIN)
    if not watched.any() or margins(scaled)[watched].min() >= LIFT_RANGE_MARGIN:
        return scaled
    low, high = 0.0, scaled
    for _ in range(30):  # bisection to 1e-9 of the scaled lift
        middle = (low + high) / 2
        low, high = (middle, high) if margins(middle)[watched].min() >= LIFT_RANGE_MARGIN else (low, middle)
    return low


def _zero_pose(model: Any, data: Any, qpos_reference: Array, leg_joints: set[int], base: int,
               adr: int) -> tuple[Array, Array]:
    """Put ``data`` at the zero pose of the legs, the base at the origin (the rest of the body at the reference):
    joint axes and anchors are then in the pelvis frame. Returns the base's rotation and origin there."""
    import mujoco

    zero = qpos_reference.copy()
    for j in leg_joints:
        zero[model.jnt_qposadr[j]] = 0.0
    zero[adr:adr + 7] = (0, 0, 0, 1, 0, 0, 0)
    data.qpos[:] = zero
    mujoco.mj_kinematics(model, data)
    return data.xmat[base].reshape(3, 3).copy(), data.xpos[base].copy()


def _ankle_roll_torque(model: Any, joints: list[LegJoint], linkage: dict[int, float]) -> float:
    """The weaker ankle roll's torque limit [N m]: its actuator's, or its linkage's motors' through the rods
    (``linkage``: joint id -> limit); 0 for a five-joint leg (its roll is virtual), inf where nothing limits it."""
    limits = []
    for joint in joints:
        if joint.role != "ankle_roll":
            continue
        if joint.name.startswith(VIRTUAL_PREFIX):
            limits.append(0.0)
            continue
        index = joint_id(model, joint.name)
        limits.append(min(joint_torque_limit(model, index), linkage.get(index, math.inf)))
    return min(limits, default=math.inf)


def _driven_joints(joints: list[LegJoint], driven: dict[str, Actuator], geometry: _Geometry,
                   sole_roll_limit: float | None, source: str) -> list[LegJoint]:
    """The leg joints with the PD layer's actuators where it drives them, and a five-joint leg's virtual ankle roll
    with its range, the sole roll it may leave: :func:`zmpwalk.robots.collision.sole_roll_bound`, or the robot
    file's ``[walking] sole_roll_limit`` [rad] (a foot that rolls on its centre line, docs/robot-import.md).

    Raises:
        FileFormatError: ``sole_roll_limit`` for legs that have an ankle roll, or of pi/2 rad or more.
    """
    if sole_roll_limit is not None and not sole_roll_limit < math.pi / 2:
        raise FileFormatError(source, f"[walking] sole_roll_limit = {sole_roll_limit!r} must be below pi/2 rad (a "
                              "sole rolled a right angle stands on its side)")
    if sole_roll_limit is not None and not any(joint.name.startswith(VIRTUAL_PREFIX) for joint in joints):
        raise FileFormatError(source, f"[walking] sole_roll_limit = {sole_roll_limit!r} applies to legs of five "
                              "joints (no ankle roll); this robot's legs have an ankle roll")
    bound = sole_roll_bound(geometry.sole_box[3] - geometry.sole_box[1]) if sole_roll_limit is None \
        else sole_roll_limit
    joints = [replace(joint, actuator=driven.get(joint.name, joint.actuator)) for joint in joints]
    return [replace(joint, limits=(-bound, bound)) if joint.name.startswith(VIRTUAL_PREFIX) else joint
            for joint in joints]


def _model_plant(model: Any, path: Path, bases: tuple[int, int], feet: list[int], key_id: int, leg_joints: set[int],
                 masses: Segments, polygon: Array, package_paths: tuple[Path, ...]) -> ModelPlant:
    """What the simulation needs of the model (its leg joints and PD layer are filled in later): every joint but
    ``leg_joints`` (the legs' and the base's) is held at the reference pose. ``bases``: the legs' base and the
    floating root (named where they differ)."""
    import mujoco

    def name(kind: Any, index: int) -> str:
        return element_name(model, kind, index)

    qpos = model.key_qpos[key_id] if key_id >= 0 else model.qpos0
    ctrl = model.key_ctrl[key_id] if key_id >= 0 and model.nu else np.zeros(model.nu)
    rest_com = masses.rest_com
    base, root = bases
    return ModelPlant(
        path=path.resolve(), base_body=name(mujoco.mjtObj.mjOBJ_BODY, base),
        root_body=name(mujoco.mjtObj.mjOBJ_BODY, root) if root != base else "",
        feet=(name(mujoco.mjtObj.mjOBJ_BODY, feet[0]), name(mujoco.mjtObj.mjOBJ_BODY, feet[1])), joints=(),
        qpos_reference=tuple(float(v) for v in qpos), ctrl_reference=tuple(float(v) for v in ctrl),
        package_paths=package_paths, sole_polygon=tuple((float(x), float(y)) for x, y in polygon),
        held_joints=tuple(name(mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt) if j not in leg_joints),
        keyframe=name(mujoco.mjtObj.mjOBJ_KEY, key_id) if key_id >= 0 else None, rest_mass=masses.rest_mass,
        rest_com=(float(rest_com[0]), float(rest_com[1]), float(rest_com[2])))


@dataclass(frozen=True)
class _Geometry:
    """The leg geometry and the sole that the robot model keeps (lengths [m]): the hips' mean x, spacing and
    drop below the base origin, the left thigh and shank, the ankle height and the left sole's bounding
    rectangle (x_min, y_min, x_max, y_max) in the sole frame."""

    hip_x: float
    hip_spacing: float
    hip_drop: float
    thigh: float
    shank: float
    ankle_height: float
    sole_box: tuple[float, float, float, float]


def _geometry(chains: list[LegChain], soles: tuple[Sole, Sole], source: str) -> _Geometry:
    """:class:`_Geometry` of the two legs.

    Raises:
        FileFormatError: The two soles differ by more than 10 mm in length or width.
    """
    # A five-joint leg keeps its sole flat under an upright pelvis only in its own plane: the feet stand there.
    lateral = [chain.ankle[1] if chain.virtual is not None else chain.hip[1] for chain in chains]
    left_hip, right_hip = chains[0].hip, chains[1].hip
    x_min, y_min = soles[0].polygon.min(axis=0)
    x_max, y_max = soles[0].polygon.max(axis=0)
    right_width = soles[1].polygon.max(axis=0) - soles[1].polygon.min(axis=0)
    if abs(right_width[0] - (x_max - x_min)) > 0.01 or abs(right_width[1] - (y_max - y_min)) > 0.01:
        raise FileFormatError(source, "the two soles differ by more than 10 mm in size; zmpwalk mirrors the "
                              "left sole for the right foot")
    return _Geometry(
        hip_x=float((left_hip[0] + right_hip[0]) / 2), hip_spacing=float(lateral[0] - lateral[1]),
        hip_drop=float(-(left_hip[2] + right_hip[2]) / 2), thigh=float(np.linalg.norm(chains[0].knee_point - left_hip)),
        shank=float(np.linalg.norm(chains[0].ankle - chains[0].knee_point)), ankle_height=soles[0].ankle_height,
        sole_box=(float(x_min), float(y_min), float(x_max), float(y_max)))


def _robot_model(*, name: str, description: str, mass: float, height: float, geometry: _Geometry,
                 foot_lift: float, pelvis_height: float, pendulum: float, gravity: float, overrides: dict[str, float],
                 leg_joints: list[LegJoint], com_offset: Array, legs: tuple[LegChain, LegChain],
                 plant: ModelPlant) -> RobotModel:
    """The robot model: derived values (the robot file's ``overrides`` replacing them), the joint ranges by column,
    and the HUBO tables scaled to this robot (docs/robot-import.md): times with sqrt(l/g), strides with the leg
    length, sway and V_y with the hip spacing; the foot lift ``foot_lift`` [m] (:func:`_foot_lift`)."""
    g = geometry
    x_min, y_min, x_max, y_max = g.sole_box
    time_scale, length_scale, lateral_scale = schedule_scale(pendulum, g.thigh + g.shank, g.hip_spacing)
    limits = {f"{'left' if i < 6 else 'right'}_{joint.role}": joint.limits for i, joint in enumerate(leg_joints)}
    fields_: dict[str, Any] = {
        "name": name, "description": description, "mass": mass, "height": height, "hip_spacing": g.hip_spacing,
        "hip_drop": g.hip_drop, "thigh_length": g.thigh, "shank_length": g.shank, "ankle_height": g.ankle_height,
        "foot_length": x_max - x_min, "foot_width": y_max - y_min, "sole_center_x": (x_max + x_min) / 2,
        "sole_center_y": (y_max + y_min) / 2, "pelvis_height": pelvis_height, "pendulum_length": pendulum,
        "min_knee": 0.05, "dsp_time": 0.1 * time_scale, "foot_lift": foot_lift,
        "lateral_velocity": 0.1 * lateral_scale, "gravity": gravity,
    }
    for key, value in overrides.items():
        if key in fields_:
            fields_[key] = value
    return RobotModel(
        **fields_, joint_limits=limits, hip_x=g.hip_x, com_offset=(float(com_offset[0]), float(com_offset[1])),
        legs=legs, plant=plant, schedule_scale=(time_scale, length_scale, lateral_scale),
        foot_speed_limit=overrides.get("foot_speed_limit"),
        foot_acceleration_limit=overrides.get("foot_acceleration_limit"),
    )


def _foot_at_reference(model: object, data: object, foot: int, label: str, source: str) -> FootAtReference:
    """The foot's collision points and the up of its sole's plane in its body frame, ``data`` in the reference posture:
    a box sole's own bottom face where it is nearly level (:func:`~zmpwalk.robots.collision.sole_face_up`), else the
    world's up.

    Raises:
        FileFormatError: The foot body has no collision geom.
    """
    import mujoco

    points = collision_points(model, data, rigid_bodies(model, foot))
    if len(points) == 0:
        foot_name = element_name(model, mujoco.mjtObj.mjOBJ_BODY, foot)
        raise FileFormatError(source, f"the {label} foot body {foot_name!r} has no collision geom (its sole)")
    rotation = np.array(data.xmat[foot], dtype=np.float64).reshape(3, 3)  # type: ignore[attr-defined]  # copies
    position = np.array(data.xpos[foot], dtype=np.float64)  # type: ignore[attr-defined]
    face = sole_face_up(model, data, rigid_bodies(model, foot), float(points[:, 2].min()))  # a box sole's plane
    up = rotation[2, :].copy() if face is None else rotation.T @ face
    return FootAtReference((points - position) @ rotation, up)
