"""The collision geometry of a robot's own model that touches the floor: the points spanning a body's colliding
geoms (a foot's sole), for every geom shape, and the geoms that collide (contact type and affinity, or an explicit
``<contact><pair>``)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]


def rigid_bodies(model: object, body: int) -> list[int]:
    """``body`` and its descendants that are welded to it (no joint in between)."""
    bodies = [body]
    for child in range(body + 1, model.nbody):  # type: ignore[attr-defined]
        parent = int(model.body_parentid[child])  # type: ignore[attr-defined]
        if parent in bodies and model.body_jntnum[child] == 0:  # type: ignore[attr-defined]
            bodies.append(child)
    return bodies


def _unit_sphere_grid(polar: int = 49, around: int = 48) -> Array:
    """Points on the unit sphere: ``polar`` latitudes from pole to pole, ``around`` longitudes each."""
    theta = np.linspace(0.0, np.pi, polar)[:, None]
    phi = np.linspace(0.0, 2 * np.pi, around, endpoint=False)[None, :]
    grid = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta) + 0 * phi], axis=-1)
    return np.asarray(grid.reshape(-1, 3), dtype=np.float64)


_ELLIPSOID_SURFACE = _unit_sphere_grid()  # an ellipsoid's surface, scaled by its semi-axes


def _round_bar_bottom(centre: Array, rotation: Array, size: Array, capsule: bool) -> Array:
    """World points of a capsule's or cylinder's lowest line (its contact with a level floor): the lowest point
    of each end's hemisphere (a capsule) or rim (a cylinder); a standing cylinder's lower disc rim."""
    radius, half = float(size[0]), float(size[1])
    axis = rotation[:, 2]
    ends = centre + np.outer((-half, half), axis)
    if capsule:
        return np.asarray(ends - np.array([0.0, 0.0, radius]), dtype=np.float64)
    down = np.array([0.0, 0.0, -1.0]) - axis * -axis[2]  # -z off the axis: towards the rim's lowest point
    if float(np.linalg.norm(down)) < 1e-9:  # standing upright: the whole lower disc is on the floor
        angles = np.linspace(0, 2 * np.pi, 16, endpoint=False)
        ring = np.column_stack([np.cos(angles), np.sin(angles), np.zeros(16)]) * radius @ rotation.T
        return np.asarray(np.vstack([end + ring for end in ends]), dtype=np.float64)
    return np.asarray(ends + radius * down / np.linalg.norm(down), dtype=np.float64)


def colliding_geoms(model: object) -> set[int]:
    """The geoms that can touch anything: by their contact type and affinity, or named in an explicit contact
    pair (``<contact><pair>``, whose geoms often have ``contype = conaffinity = 0``)."""
    m = model
    geoms = {g for g in range(m.ngeom)  # type: ignore[attr-defined]
             if m.geom_contype[g] != 0 or m.geom_conaffinity[g] != 0}  # type: ignore[attr-defined]
    for pair in range(m.npair):  # type: ignore[attr-defined]
        geoms.update((int(m.pair_geom1[pair]), int(m.pair_geom2[pair])))  # type: ignore[attr-defined]
    return geoms


def collision_points(model: object, data: object, bodies: list[int]) -> Array:
    """World points spanning the collision geoms of ``bodies``, (m, 3): box corners, mesh vertices, an
    ellipsoid's surface, a sphere's lowest point, a capsule's or cylinder's lowest line (see
    :func:`_round_bar_bottom`). The geoms are those that can touch the floor (:func:`colliding_geoms`)."""
    import mujoco

    m, d = model, data
    points: list[Array] = []
    geom_type = mujoco.mjtGeom
    colliding = colliding_geoms(m)
    for g in range(m.ngeom):  # type: ignore[attr-defined]
        if int(m.geom_bodyid[g]) not in bodies or g not in colliding:  # type: ignore[attr-defined]
            continue
        kind = int(m.geom_type[g])  # type: ignore[attr-defined]  # a numpy integer is never `in` a tuple of enums
        size = m.geom_size[g]  # type: ignore[attr-defined]
        rotation = d.geom_xmat[g].reshape(3, 3)  # type: ignore[attr-defined]
        centre = d.geom_xpos[g]  # type: ignore[attr-defined]
        if kind == geom_type.mjGEOM_BOX:
            local = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * size
        elif kind == geom_type.mjGEOM_MESH:
            mesh = int(m.geom_dataid[g])  # type: ignore[attr-defined]
            start, count = int(m.mesh_vertadr[mesh]), int(m.mesh_vertnum[mesh])  # type: ignore[attr-defined]
            local = np.asarray(m.mesh_vert[start:start + count], dtype=float)  # type: ignore[attr-defined]
        elif kind == geom_type.mjGEOM_SPHERE:
            points.append(centre - np.array([[0.0, 0.0, size[0]]]))  # its lowest point
            continue
        elif kind in (geom_type.mjGEOM_CAPSULE, geom_type.mjGEOM_CYLINDER):
            points.append(_round_bar_bottom(centre, rotation, size, kind == geom_type.mjGEOM_CAPSULE))
            continue
        elif kind == geom_type.mjGEOM_ELLIPSOID:
            local = _ELLIPSOID_SURFACE * size[:3]
        else:
            continue
        points.append(centre + local @ rotation.T)
    return np.vstack(points) if points else np.zeros((0, 3))
