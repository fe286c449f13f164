"""The model's own names and orders: joints (the free base first), ``qpos`` columns, bodies."""

from __future__ import annotations

import mujoco

from zmpwalk.errors import InvalidParameterError

BASE_COLUMNS = ("x", "y", "z", "qw", "qx", "qy", "qz")  # the free base's qpos columns: [m], quaternion w, x, y, z


def joint_names(model: mujoco.MjModel) -> list[str]:
    """Every joint's name in the model's order (an unnamed free base: ``"root"``).

    Raises:
        InvalidParameterError: The model's first joint is not a free base, or another joint is not a hinge or a
            slide (a clip's columns are the base's seven and one per joint).
    """
    if model.njnt == 0 or int(model.jnt_type[0]) != mujoco.mjtJoint.mjJNT_FREE:
        raise InvalidParameterError("model", "first joint", "a free base as the model's first joint")
    names = []
    for j in range(model.njnt):
        if j > 0 and int(model.jnt_type[j]) not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint {j}"
            kind = "ball" if int(model.jnt_type[j]) == mujoco.mjtJoint.mjJNT_BALL else "free"
            raise InvalidParameterError("model", f"{name} ({kind} joint)", "hinge or slide joints after the free "
                                        "base: a clip has one column per joint (a linkage's ball-jointed rods, "
                                        "as in a parallel ankle, are not exported)")
        names.append(mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or ("root" if j == 0 else f"joint{j}"))
    return names


def qpos_names(model: mujoco.MjModel) -> list[str]:
    """The name of every ``qpos`` column: ``<base>_x`` ... ``<base>_qz``, then one per joint."""
    names = joint_names(model)
    return [f"{names[0]}_{c}" for c in BASE_COLUMNS] + names[1:]


def body_names(model: mujoco.MjModel) -> list[str]:
    """Every body's name but the world's, in the model's order (an unnamed body: ``body<i>``)."""
    return [mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}" for b in range(1, model.nbody)]
