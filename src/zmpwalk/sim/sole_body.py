"""A foot that an equality acts on (a parallel ankle's rods) gets a massless sole body: welded to it in its frame,
carrying its collision geoms, so that the ankle's force-torque sensors, placed on it, read the ground's wrench under
the sole rather than the ankle joint's, which the rods bypass (:func:`sole_bodies`, used by
:func:`zmpwalk.sim.plant.build_plant`)."""

from __future__ import annotations

import mujoco
import numpy as np

from zmpwalk.robots.description import ModelPlant
from zmpwalk.robots.linkages import equality_bodies

SOLE_BODY = "zmpwalk_{}_sole"  # the body that carries a foot's collision geoms where an equality acts on the foot
_GEOM_FIELDS = ("name", "friction", "solref", "solimp", "solmix", "condim", "contype", "conaffinity", "margin", "gap",
                "priority", "group", "rgba", "meshname", "hfieldname", "material")  # kept as the model gives them


def sole_bodies(spec: mujoco.MjSpec, model: mujoco.MjModel, plant: ModelPlant) -> dict[str, str]:
    """For each foot that an active connect or weld equality acts on (the rods of a parallel ankle), a massless
    body welded to it in the foot's frame that carries the foot's collision geoms (and those an explicit contact
    pair names): the ankle's force-torque sensors on it then read the ground's wrench alone, where on the foot they
    would read the joint's, which the rods bypass (a real parallel-ankle foot measures its sole, not the ankle
    joint). Each geom keeps its compiled pose in the foot (whatever frame, ``euler`` or ``fromto`` placed it); the
    foot keeps its mass (made explicit where its geoms gave it; with ``inertiafromgeom="true"`` the moved geoms
    keep theirs); contacts the model excludes for the foot are excluded for the sole too, and so is the foot's
    parent. Returns foot body name -> sole body name; empty for every other robot."""
    pushed = {int(model.body_weldid[body]) for body in equality_bodies(model)}
    paired = {name for pair in spec.pairs for name in (pair.geomname1, pair.geomname2) if name}
    soles = {}
    for label, foot in zip(("left", "right"), plant.feet, strict=True):
        body_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, foot)
        if int(model.body_weldid[body_id]) not in pushed:
            continue
        body = spec.body(foot)
        keep_mass = spec.compiler.inertiafromgeom != mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_TRUE
        if keep_mass and not body.explicitinertial:  # keep the mass the geoms gave it on the foot itself
            body.explicitinertial = True
            body.mass, body.ipos = float(model.body_mass[body_id]), model.body_ipos[body_id].copy()
            body.iquat, body.inertia = model.body_iquat[body_id].copy(), model.body_inertia[body_id].copy()
        sole = body.add_body(name=SOLE_BODY.format(label))
        first = int(model.body_geomadr[body_id])  # the compiled geoms of the body, in the spec's order
        for index, geom in enumerate(list(body.geoms), start=first):
            if geom.contype == 0 and geom.conaffinity == 0 and geom.name not in paired:
                continue  # visual
            _move_geom(spec, model, geom, index, sole, keep_mass)
        parent = int(model.body_parentid[body_id])
        for other in [model.body(parent).name] + [_excluded_partner(spec, pair, foot) for pair in spec.excludes]:
            if other:
                spec.add_exclude(bodyname1=sole.name, bodyname2=other)
        soles[foot] = sole.name
    return soles


def _move_geom(spec: mujoco.MjSpec, model: mujoco.MjModel, geom: mujoco.MjsGeom, index: int, sole: mujoco.MjsBody,
               massless: bool) -> None:
    """Move ``geom`` (compiled as ``model``'s geom ``index``) from the foot to its ``sole`` body (the foot's frame) at
    its compiled pose and size (a mesh's at the pose before the compiler's offset to the mesh's own frame)."""
    kind, mass, density = int(model.geom_type[index]), geom.mass, geom.density
    position, quaternion = model.geom_pos[index].copy(), model.geom_quat[index].copy()
    if kind == mujoco.mjtGeom.mjGEOM_MESH:  # compiled pose = given pose composed with the mesh's offset
        mesh = int(model.geom_dataid[index])
        inverse = np.empty(4)
        mujoco.mju_negQuat(inverse, model.mesh_quat[mesh])
        mujoco.mju_mulQuat(quaternion, quaternion.copy(), inverse)
        shift = np.empty(3)
        mujoco.mju_rotVecQuat(shift, model.mesh_pos[mesh], quaternion)
        position = position - shift
    values = {name: getattr(geom, name) for name in _GEOM_FIELDS}
    spec.delete(geom)
    moved = sole.add_geom(type=mujoco.mjtGeom(kind), pos=position, quat=quaternion, size=model.geom_size[index])
    for name, value in values.items():
        setattr(moved, name, value)
    moved.mass, moved.density = (0.0, 0.0) if massless else (mass, density)


def _excluded_partner(spec: mujoco.MjSpec, pair: object, body: str) -> str:
    """The other body of an ``<exclude>`` pair that names ``body``, else empty."""
    names = (getattr(pair, "bodyname1", ""), getattr(pair, "bodyname2", ""))
    return names[1] if names[0] == body else names[0] if names[1] == body else ""
