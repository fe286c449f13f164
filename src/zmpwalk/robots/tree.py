"""The kinematic tree of a robot's own model: its floating base, its keyframe, the paths from the base to a body,
its two feet (the lowest bodies with collision geoms, one each side of the base) and the legs' base (the body where
the feet's paths part) with its place on the floating base."""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError
from zmpwalk.robots.collision import collision_points
from zmpwalk.robots.pd import element_name

Array = NDArray[np.float64]
Mount = tuple[Array, Array]  # the legs' base in the root body's frame: origin [m] (3,), rotation (3, 3)

FOOT_TIE = 0.005  # [m] two foot candidates this close in height on one side are ambiguous


def floating_base(model: object, source: str) -> int:
    """The body with the free joint.

    Raises:
        FileFormatError: No body has one.
    """
    import mujoco

    for body in range(1, model.nbody):  # type: ignore[attr-defined]
        start, count = int(model.body_jntadr[body]), int(model.body_jntnum[body])  # type: ignore[attr-defined]
        if count and model.jnt_type[start] == mujoco.mjtJoint.mjJNT_FREE:  # type: ignore[attr-defined]
            return body
    raise FileFormatError(source, "no floating base: no body has a free joint (a walking robot's base moves "
                          "freely; add <freejoint/> to its root body)")


def keyframe_index(model: object, keyframe: str | None, source: str) -> int:
    """The index of the keyframe named ``keyframe`` (or ``#N``), the first where None, -1 where the model has none.

    Raises:
        FileFormatError: No keyframe of that name.
    """
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


def body_path(model: object, base: int, body: int) -> list[int]:
    """Bodies from ``base`` (excluded) down to ``body`` (included)."""
    path = []
    while body != base and body > 0:
        path.append(body)
        body = int(model.body_parentid[body])  # type: ignore[attr-defined]
    return path[::-1]


def joint_path(model: object, base: int, body: int) -> list[int]:
    """Joints on the bodies from ``base`` (excluded) down to ``body``, in order."""
    joints = []
    for b in body_path(model, base, body):
        start, count = int(model.body_jntadr[b]), int(model.body_jntnum[b])  # type: ignore[attr-defined]
        joints += list(range(start, start + count)) if count > 0 else []
    return joints


def find_feet(model: object, data: object, base: int, feet: tuple[str, str] | None, source: str) -> list[int]:
    """The (left, right) foot bodies: those named in ``feet``, or the lowest bodies with collision geoms at the
    posture of ``data`` that hang from ``base`` through at least five hinge joints, one each side of the base.

    Raises:
        FileFormatError: A named body is missing, a side has no foot, or two bodies tie (:data:`FOOT_TIE`).
    """
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
        if base not in ancestors(m, body):
            continue
        hinges = [j for j in joint_path(m, base, body)
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
                              "through 5 or 6 hinge joints (a foot)")
    lowest = min(c[0] for c in candidates)
    result = []
    for label, sign in (("left", 1.0), ("right", -1.0)):
        side = sorted((c for c in candidates if sign * c[2] > 0), key=lambda c: c[0])
        if not side or side[0][0] > lowest + 0.05:
            raise FileFormatError(source, f"no {label} foot found (no low body with collision geoms on the "
                                  f"{label} of the base); give the feet: feet = [left body, right body]")
        ties = [c for c in side[1:] if c[0] < side[0][0] + FOOT_TIE and c[1] not in ancestors(m, side[0][1])]
        if ties:
            names = ", ".join(element_name(m, mujoco.mjtObj.mjOBJ_BODY, c[1]) for c in [side[0], *ties])
            raise FileFormatError(source, f"ambiguous {label} foot: {names} reach equally low; give the feet: "
                                  "feet = [left body, right body] (--feet LEFT,RIGHT)")
        result.append(side[0][1])
    return result


def ancestors(model: object, body: int) -> list[int]:
    """The bodies above ``body``, up to the world (0)."""
    result = []
    while body > 0:
        body = int(model.body_parentid[body])  # type: ignore[attr-defined]
        result.append(body)
    return result


def legs_base(model: object, root: int, feet: list[int]) -> int:
    """The legs' base: the floating ``root``, unless a joint between it and the last body on both feet's paths (the
    pelvis, below a waist) is driven by no actuator of its own (a waist tied to its motors by a tendon or an
    equality, which may leave it slack): then that pelvis, whose waist the simulation holds. A joint held by its
    own servo at the reference pose is taken as rigid, as the arms are (Booster T1's waist yaw)."""
    import mujoco

    m = model
    split = root
    for left, right in zip(body_path(m, root, feet[0]), body_path(m, root, feet[1]), strict=False):
        if left != right:
            break
        split = left
    if m.nu == 0:  # type: ignore[attr-defined]
        return root  # no actuators (a URDF): the PD layer drives every joint, the waist's as a servo holds it
    on_joints = {int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT)}  # a numpy integer is
    # never `in` a tuple of enum members
    driven = {int(m.actuator_trnid[a][0]) for a in range(m.nu)  # type: ignore[attr-defined]
              if int(m.actuator_trntype[a]) in on_joints}  # type: ignore[attr-defined]
    return split if any(j not in driven for j in joint_path(m, root, split)) else root


def base_mount(model: object, qpos: Array, root: int, base: int) -> Mount | None:
    """Where the legs' ``base`` sits on the floating ``root`` with the model at ``qpos`` (the held joints between
    them at the reference pose): its origin [m] and rotation in the root's frame; None where it is the root."""
    import mujoco

    if base == root:
        return None
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    rotation_root = data.xmat[root].reshape(3, 3)
    return (rotation_root.T @ (data.xpos[base] - data.xpos[root]),
            rotation_root.T @ data.xmat[base].reshape(3, 3))


def root_from_base(mount: Mount | None, position_base: Array, rotation_base: Array) -> tuple[Array, Array]:
    """The floating root's position [m] and rotation in world that put the legs' base at ``position_base`` [m]
    with ``rotation_base`` (:func:`base_mount`'s ``mount``)."""
    if mount is None:
        return np.asarray(position_base, dtype=np.float64), np.asarray(rotation_base, dtype=np.float64)
    offset, rotation = mount
    rotation_root = rotation_base @ rotation.T
    return position_base - rotation_root @ offset, rotation_root
