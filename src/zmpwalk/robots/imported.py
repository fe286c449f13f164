"""A robot from its own model: MJCF (``.xml``) or URDF (``.urdf``), read with MuJoCo's compiler.

:func:`import_robot` finds the two legs and derives from the model everything
zmpwalk needs (the builder's model is the single source of truth):

* **Floating base**: the body with the free joint (a URDF gets one at its root
  link). Its frame is the **pelvis frame** of zmpwalk (x forward, y left, z up).
* **Feet**: with no mapping, the two bodies whose collision geoms reach lowest in
  the reference pose (the model's keyframe, or its zero pose), one each side of
  the base (``y > 0`` left). Two candidates within :data:`FOOT_TIE` of each other
  on one side make the tree ambiguous: give ``feet = (left, right)`` body names.
* **Legs**: the hinge joints on the path from the point where the two feet's
  paths part down to each foot; exactly six per leg. Joints above that point
  (a waist) and every other joint (arms, head) are held at the reference pose.
  Each leg joint gets its role (hip yaw, hip roll, hip pitch, knee, ankle
  pitch, ankle roll) from its axis at the zero pose (the axis's largest
  component: z yaw, x roll, y pitch) and its place in the chain, and its sign
  from the direction of that component. The knee's zero offset is the bend of
  the model's zero pose (thigh and shank directions about the knee axis).
* **Geometry** in the pelvis frame at the zero pose: hip centre (the point
  nearest the three hip axes, with their largest distance from it), knee and
  ankle points, link lengths, ankle height above the sole, the sole polygon
  (the foot's collision geoms, box or mesh, projected; points within
  :data:`SOLE_BAND` of the lowest).
* **Ready posture**: the hips above the ankles at the keyframe's
  hip-to-ankle distance, at most :data:`READY_STRETCH` of the straight leg (a
  bent knee for walking). The pattern moves the centre of mass: the CoM's
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
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError
from zmpwalk.leg_chain import LegChain
from zmpwalk.robots.collision import collision_points, rigid_bodies
from zmpwalk.robots.description import LegJoint, ModelPlant
from zmpwalk.robots.model import RobotModel, schedule_scale
from zmpwalk.robots.pd import element_name, joint_actuator, pd_layer
from zmpwalk.zmp import convex_hull

Array = NDArray[np.float64]

ROLES = ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
FOOT_TIE = 0.005  # [m] two foot candidates this close in height on one side are ambiguous
SOLE_BAND = 0.002  # [m] collision points this close to the lowest form the sole
READY_STRETCH = 0.92  # [-] hip-to-ankle distance of the ready posture, at most this fraction of the straight leg


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
        overrides: Robot-file values replacing derived ones (``pelvis_height``, ``dsp_time``, ...).
        pd_gains: The PD layer's gains of some joints (model joint name -> (kp [N m/rad], kv [N m s/rad] or
            None: critical damping)) replacing :func:`pd_gains`'s (a robot file's ``[pd]``).

    Raises:
        FileFormatError: What the model lacks for walking, named (no floating base, no legs, a leg of
            other than six hinge joints, ambiguous feet, ...).
        InvalidParameterError: ``pd_gains`` names a joint the PD layer does not drive.
    """
    import mujoco

    path = Path(path)
    source = str(path)
    model = load_model(path, package_paths)
    data = mujoco.MjData(model)
    base = _floating_base(model, source)
    key_id = _keyframe(model, keyframe, source)
    qpos_reference = model.key_qpos[key_id].copy() if key_id >= 0 else model.qpos0.copy()
    ctrl_reference = model.key_ctrl[key_id].copy() if key_id >= 0 and model.nu else np.zeros(model.nu)
    data.qpos[:] = qpos_reference
    mujoco.mj_kinematics(model, data)
    foot_ids = _find_feet(model, data, base, feet, source)
    paths = [_joint_path(model, base, foot) for foot in foot_ids]
    left_bodies, right_bodies = (_body_path(model, base, f) for f in foot_ids)
    shared = [b for b in left_bodies if b in right_bodies]
    chains_joints = []
    for label, foot, joints in zip(("left", "right"), foot_ids, paths, strict=True):
        leg = [j for j in joints if int(model.jnt_bodyid[j]) not in shared]
        names = [element_name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in leg]
        foot_name = element_name(model, mujoco.mjtObj.mjOBJ_BODY, foot)
        if len(leg) != 6:
            raise FileFormatError(source, f"the {label} leg (to foot body {foot_name!r}) has {len(leg)} joints "
                                  f"({', '.join(names) or 'none'}); zmpwalk walks legs of 6 hinge joints")
        for j, joint_name in zip(leg, names, strict=True):
            if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
                raise FileFormatError(source, f"{label} leg joint {joint_name!r} is not a hinge (revolute) joint")
        chains_joints.append(leg)
    leg_joint_ids = {j for leg in chains_joints for j in leg}
    # Zero pose of the legs, base at the origin: joint axes and anchors are then in the pelvis frame.
    zero = qpos_reference.copy()
    for j in leg_joint_ids:
        zero[model.jnt_qposadr[j]] = 0.0
    base_joint = int(model.body_jntadr[base])
    adr = int(model.jnt_qposadr[base_joint])
    zero[adr:adr + 7] = (0, 0, 0, 1, 0, 0, 0)
    data.qpos[:] = zero
    mujoco.mj_kinematics(model, data)
    base_rotation = data.xmat[base].reshape(3, 3).copy()
    base_origin = data.xpos[base].copy()

    def in_pelvis(point: Array) -> Array:
        return np.asarray(base_rotation.T @ (point - base_origin), dtype=np.float64)

    # Mass of each leg segment and of the rest (base, trunk, arms, head: rigid with the base at the reference).
    segment_of = {j: (leg_index, k) for leg_index, leg in enumerate(chains_joints) for k, j in enumerate(leg)}
    segment_mass = np.zeros((2, 6))
    segment_moment = np.zeros((2, 6, 3))
    rest_mass, rest_moment = 0.0, np.zeros(3)
    for body in range(1, model.nbody):
        last = None
        for j in _joint_path(model, base, body):
            last = segment_of.get(j, last)
        mass = float(model.body_mass[body])
        com = in_pelvis(data.xipos[body])
        if last is None:
            rest_mass += mass
            rest_moment += mass * com
        else:
            segment_mass[last] += mass
            segment_moment[last] += mass * com
    segment_com = segment_moment / np.maximum(segment_mass, 1e-12)[..., None]
    rest_com = rest_moment / max(rest_mass, 1e-12)

    chains: list[LegChain] = []
    leg_joints: list[LegJoint] = []
    soles = []
    for side, label, foot, leg in zip((1, -1), ("left", "right"), foot_ids, chains_joints, strict=True):
        axes = np.array([base_rotation.T @ data.xaxis[j] for j in leg])
        points = np.array([in_pelvis(data.xanchor[j]) for j in leg])
        roles = _roles(axes, [element_name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in leg], label, source)
        chain = LegChain(side, tuple(element_name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in leg), axes, points,
                         np.zeros(3))
        ankle = chain.ankle_point
        lower = np.array([model.jnt_range[j][0] if model.jnt_limited[j] else -np.inf for j in leg])
        upper = np.array([model.jnt_range[j][1] if model.jnt_limited[j] else np.inf for j in leg])
        # The IK branch of the keyframe (a knee bent the way its range allows, where the keyframe is straight).
        reference = np.array([qpos_reference[model.jnt_qposadr[j]] for j in leg])
        knee = roles.index("knee")
        if abs(reference[knee]) < 0.1:
            bend = 0.5 if upper[knee] > 0.5 or upper[knee] >= -lower[knee] else -0.5
            reference[knee] = bend
        index = 0 if side > 0 else 1
        chain = LegChain(side, chain.joint_names, axes, points, ankle, reference=reference, lower=lower, upper=upper,
                         role_order=tuple(roles.index(role) for role in ROLES), link_masses=segment_mass[index],
                         link_coms=segment_com[index])
        sole_points = collision_points(model, data, rigid_bodies(model, foot))
        if len(sole_points) == 0:
            foot_name = element_name(model, mujoco.mjtObj.mjOBJ_BODY, foot)
            raise FileFormatError(source, f"the {label} foot body {foot_name!r} has no collision geom (its sole)")
        sole_points = np.array([in_pelvis(point) for point in sole_points])
        soles.append(sole_points - ankle)
        chains.append(chain)
        knee_offset = _knee_offset(chain)
        for role in ROLES:
            index = roles.index(role)
            j = leg[index]
            axis = axes[index]
            dominant = int(np.argmax(np.abs(axis)))
            leg_joints.append(LegJoint(
                role=role, name=chain.joint_names[index], axis=(float(axis[0]), float(axis[1]), float(axis[2])),
                sign=1 if axis[dominant] > 0 else -1, zero_offset=knee_offset if role == "knee" else 0.0,
                limits=(float(lower[index]), float(upper[index])), actuator=joint_actuator(model, j)))
    # Sole: the collision points near the lowest, in the foot frame (ankle origin, pelvis axes at zero).
    left_sole = soles[0]
    bottom = left_sole[:, 2].min()
    ankle_height = float(-bottom)
    polygon = convex_hull(left_sole[left_sole[:, 2] < bottom + SOLE_BAND][:, :2])
    right_sole = soles[1]
    right_polygon = convex_hull(right_sole[right_sole[:, 2] < right_sole[:, 2].min() + SOLE_BAND][:, :2])
    left_hip, right_hip = chains[0].hip, chains[1].hip
    hip_spacing = float(left_hip[1] - right_hip[1])
    hip_x = float((left_hip[0] + right_hip[0]) / 2)
    hip_drop = float(-(left_hip[2] + right_hip[2]) / 2)
    thigh = float(np.linalg.norm(chains[0].knee_point - left_hip))
    shank = float(np.linalg.norm(chains[0].ankle - chains[0].knee_point))
    x_min, y_min = polygon.min(axis=0)
    x_max, y_max = polygon.max(axis=0)
    right_width = right_polygon.max(axis=0) - right_polygon.min(axis=0)
    if abs(right_width[0] - (x_max - x_min)) > 0.01 or abs(right_width[1] - (y_max - y_min)) > 0.01:
        raise FileFormatError(source, "the two soles differ by more than 10 mm in size; zmpwalk mirrors the "
                              "left sole for the right foot")
    mass = float(np.sum(model.body_mass))
    values = dict(overrides or {})
    # Ready posture: hip-to-ankle distance from the keyframe, at most READY_STRETCH of the straight leg.
    data.qpos[:] = qpos_reference
    mujoco.mj_kinematics(model, data)
    key_hip = data.xpos[base] + data.xmat[base].reshape(3, 3) @ left_hip
    key_foot_bottom = min(float(p[2]) for p in collision_points(model, data, rigid_bodies(model, foot_ids[0])))
    key_distance = float(key_hip[2] - key_foot_bottom - ankle_height)
    straight = thigh + shank
    distance = min(key_distance if key_distance > 0 else straight, READY_STRETCH * straight)
    com_offset = np.zeros(2)
    height_scale = float(np.max(data.geom_xpos[:, 2]) - key_foot_bottom)
    model_name = model.names[:model.names.find(b"\0")].decode()
    robot_name = name or re.sub(r"[^A-Za-z0-9_.-]+", "-", model_name).strip("-") or path.stem
    held = tuple(element_name(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in range(model.njnt)
                 if j not in leg_joint_ids and j != base_joint)
    plant = ModelPlant(path=path.resolve(), base_body=element_name(model, mujoco.mjtObj.mjOBJ_BODY, base),
                       feet=(element_name(model, mujoco.mjtObj.mjOBJ_BODY, foot_ids[0]),
                             element_name(model, mujoco.mjtObj.mjOBJ_BODY, foot_ids[1])),
                       joints=tuple(leg_joints), qpos_reference=tuple(float(v) for v in qpos_reference),
                       ctrl_reference=tuple(float(v) for v in ctrl_reference), package_paths=package_paths,
                       sole_polygon=tuple((float(x), float(y)) for x, y in polygon), held_joints=held,
                       keyframe=element_name(model, mujoco.mjtObj.mjOBJ_KEY, key_id) if key_id >= 0 else None,
                       rest_mass=rest_mass, rest_com=(float(rest_com[0]), float(rest_com[1]), float(rest_com[2])))
    pelvis_height = 0.0
    pendulum = 0.0
    chains_ready = chains
    for _ in range(8):  # fixed point: posture -> CoM offset -> posture
        dx = hip_x - com_offset[0]
        vertical = math.sqrt(max(distance * distance - dx * dx, 1e-12))
        pelvis_height = float(values.get("pelvis_height", ankle_height + hip_drop + vertical))
        chains_ready = []
        ready = []
        for chain, side in zip(chains, (1, -1), strict=True):
            # the ankle below the pattern point, which is the CoM offset from the base origin
            target = np.array([[com_offset[0], side * hip_spacing / 2 + com_offset[1], ankle_height - pelvis_height]])
            angles, excess = chain.solve(target, np.eye(3)[None])
            if excess[0] > 0:
                raise FileFormatError(source, f"the {chain.label} leg cannot reach the ready posture "
                                      f"(pelvis height {pelvis_height:.3f} m)")
            ready.append(angles[0])
            chains_ready.append(replace(chain, reference=angles[0]))
        qpos = qpos_reference.copy()
        qpos[adr:adr + 7] = (0, 0, pelvis_height, 1, 0, 0, 0)
        for leg, angles in zip(chains_joints, ready, strict=True):
            for j, angle in zip(leg, angles, strict=True):
                qpos[model.jnt_qposadr[j]] = angle
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        com = data.subtree_com[0]
        new_offset = np.array([com[0], com[1]])
        pendulum = float(com[2])
        if np.max(np.abs(new_offset - com_offset)) < 1e-7:
            com_offset = new_offset
            break
        com_offset = new_offset
    # The joint PD layer: gains from the ready posture's inertia; a leg joint holds the robot, m g l.
    pd_joints = pd_layer(model, data, qpos, leg_joint_ids, mass * float(np.linalg.norm(model.opt.gravity)) * pendulum,
                          pd_gains or {})
    driven = dict(pd_joints)
    leg_joints = [replace(joint, actuator=driven.get(joint.name, joint.actuator)) for joint in leg_joints]
    plant = replace(plant, joints=tuple(leg_joints), pd_joints=pd_joints)
    # The HUBO tables scaled to this robot (docs/robot-import.md): times with sqrt(l/g), strides and foot lift
    # with the leg length, sway and V_y with the hip spacing.
    time_scale, length_scale, lateral_scale = schedule_scale(pendulum, thigh + shank, hip_spacing)
    limits = {f"{'left' if i < 6 else 'right'}_{joint.role}": joint.limits for i, joint in enumerate(leg_joints)}
    fields_: dict[str, Any] = {
        "name": robot_name,
        "description": f"imported from {path.name} ({mass:.1f} kg)",
        "mass": mass, "height": height_scale, "hip_spacing": hip_spacing, "hip_drop": hip_drop,
        "thigh_length": thigh, "shank_length": shank, "ankle_height": ankle_height,
        "foot_length": float(x_max - x_min), "foot_width": float(y_max - y_min),
        "sole_center_x": float((x_max + x_min) / 2), "sole_center_y": float((y_max + y_min) / 2),
        "pelvis_height": pelvis_height, "pendulum_length": pendulum, "min_knee": 0.05,
        "dsp_time": 0.1 * time_scale, "foot_lift": 0.04 * length_scale, "lateral_velocity": 0.1 * lateral_scale,
        "gravity": float(-model.opt.gravity[2]),
    }
    for key, value in values.items():
        if key in fields_:
            fields_[key] = value
    return RobotModel(
        **fields_, joint_limits=limits, hip_x=hip_x, com_offset=(float(com_offset[0]), float(com_offset[1])),
        legs=(chains_ready[0], chains_ready[1]), plant=plant,
        schedule_scale=(time_scale, length_scale, lateral_scale),
        foot_speed_limit=values.get("foot_speed_limit"), foot_acceleration_limit=values.get("foot_acceleration_limit"),
    )


def _floating_base(model: object, source: str) -> int:
    import mujoco

    for body in range(1, model.nbody):  # type: ignore[attr-defined]
        start, count = int(model.body_jntadr[body]), int(model.body_jntnum[body])  # type: ignore[attr-defined]
        if count and model.jnt_type[start] == mujoco.mjtJoint.mjJNT_FREE:  # type: ignore[attr-defined]
            return body
    raise FileFormatError(source, "no floating base: no body has a free joint (a walking robot's base moves "
                          "freely; add <freejoint/> to its root body)")


def _keyframe(model: object, keyframe: str | None, source: str) -> int:
    import mujoco

    if keyframe is None:
        return 0 if model.nkey else -1  # type: ignore[attr-defined]
    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, keyframe)
    unnamed = re.fullmatch(r"#(\d+)", keyframe)  # an unnamed keyframe, by its index (as _name writes it)
    if key < 0 and unnamed and int(unnamed.group(1)) < model.nkey:  # type: ignore[attr-defined]
        key = int(unnamed.group(1))
    if key < 0:
        known = [element_name(model, mujoco.mjtObj.mjOBJ_KEY, k) for k in range(model.nkey)]  # type: ignore[attr-defined]
        raise FileFormatError(source, f"no keyframe {keyframe!r}; the model has: {', '.join(known) or 'none'}")
    return int(key)


def _body_path(model: object, base: int, body: int) -> list[int]:
    """Bodies from ``base`` (excluded) down to ``body`` (included)."""
    path = []
    while body != base and body > 0:
        path.append(body)
        body = int(model.body_parentid[body])  # type: ignore[attr-defined]
    return path[::-1]


def _joint_path(model: object, base: int, body: int) -> list[int]:
    """Joints on the bodies from ``base`` (excluded) down to ``body``, in order."""
    joints = []
    for b in _body_path(model, base, body):
        start, count = int(model.body_jntadr[b]), int(model.body_jntnum[b])  # type: ignore[attr-defined]
        joints += list(range(start, start + count)) if count > 0 else []
    return joints


def _find_feet(model: object, data: object, base: int, feet: tuple[str, str] | None, source: str) -> list[int]:
    import mujoco

    m = model
    if feet is not None:
        ids = []
        for label, body_name in zip(("left", "right"), feet, strict=True):
            body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body_name)
            if body < 0:
                raise FileFormatError(source, f"no body {body_name!r} (the {label} foot of the mapping)")
            ids.append(int(body))
        return ids
    base_position = data.xpos[base]  # type: ignore[attr-defined]
    base_rotation = data.xmat[base].reshape(3, 3)  # type: ignore[attr-defined]
    candidates: list[tuple[float, int, float]] = []
    for body in range(1, m.nbody):  # type: ignore[attr-defined]
        if base not in _ancestors(m, body):
            continue
        hinges = [j for j in _joint_path(m, base, body)
                  if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]  # type: ignore[attr-defined]
        if len(hinges) < 5:
            continue
        points = collision_points(m, data, [body])
        if len(points) == 0:
            continue
        lateral = float((base_rotation.T @ (data.xpos[body] - base_position))[1])  # type: ignore[attr-defined]
        candidates.append((float(points[:, 2].min()), body, lateral))
    if not candidates:
        raise FileFormatError(source, "no legs: no body with collision geoms hangs from the floating base "
                              "through 6 hinge joints (a foot)")
    lowest = min(c[0] for c in candidates)
    result = []
    for label, sign in (("left", 1.0), ("right", -1.0)):
        side = sorted((c for c in candidates if sign * c[2] > 0), key=lambda c: c[0])
        if not side or side[0][0] > lowest + 0.05:
            raise FileFormatError(source, f"no {label} foot found (no low body with collision geoms on the "
                                  f"{label} of the base); give the feet: feet = [left body, right body]")
        ties = [c for c in side[1:] if c[0] < side[0][0] + FOOT_TIE and c[1] not in _ancestors(m, side[0][1])]
        if ties:
            names = ", ".join(element_name(m, mujoco.mjtObj.mjOBJ_BODY, c[1]) for c in [side[0], *ties])
            raise FileFormatError(source, f"ambiguous {label} foot: {names} reach equally low; give the feet: "
                                  "feet = [left body, right body] (--feet LEFT,RIGHT)")
        result.append(side[0][1])
    return result


def _ancestors(model: object, body: int) -> list[int]:
    result = []
    while body > 0:
        body = int(model.body_parentid[body])  # type: ignore[attr-defined]
        result.append(body)
    return result


def _roles(axes: Array, names: list[str], label: str, source: str) -> list[str]:
    """Role of each chain joint from its axis and place (see the module docstring)."""
    kinds = ["yaw" if k == 2 else "roll" if k == 0 else "pitch" for k in np.argmax(np.abs(axes), axis=1)]
    counts = {k: kinds.count(k) for k in ("yaw", "roll", "pitch")}
    described = ", ".join(f"{n} ({k})" for n, k in zip(names, kinds, strict=True))
    if counts != {"yaw": 1, "roll": 2, "pitch": 3} or kinds[3] != "pitch" or kinds[4:] not in (
            ["pitch", "roll"], ["roll", "pitch"]) or "yaw" not in kinds[:3]:
        raise FileFormatError(source, f"the {label} leg's joints are {described}; zmpwalk walks legs with a "
                              "3-axis hip (yaw, roll, pitch in any order), a pitch knee and a pitch-roll ankle")
    roles = []
    for index, kind in enumerate(kinds):
        if index < 3:
            roles.append(f"hip_{kind}")
        elif index == 3:
            roles.append("knee")
        else:
            roles.append(f"ankle_{kind}")
    return roles


def _knee_offset(chain: LegChain) -> float:
    """Bend of the zero pose at the knee: angle from the thigh to the shank direction about the knee axis."""
    axis = chain.axes[3]
    thigh = chain.knee_point - chain.hip
    shank = chain.ankle - chain.knee_point
    thigh -= axis * (axis @ thigh)
    shank -= axis * (axis @ shank)
    return float(math.atan2(float(axis @ np.cross(thigh, shank)), float(thigh @ shank)))


