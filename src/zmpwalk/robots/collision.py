r"""The collision geometry of a robot's own model that touches the floor: the points spanning a body's colliding
geoms (a foot's sole), for every geom shape, the geoms that collide (contact type and affinity, or an explicit
``<contact><pair>``), and the sole they make (:func:`foot_sole`).

**The sole is taken in the reference posture** (the keyframe, where the robot stands with its feet on a level
floor), not at zero joint angles: a foot whose sole is pitched 10 degrees at zero angles and level in the
keyframe has a 0 mm long sole at zero angles (only its toe edge is lowest) and its real one in the keyframe.
The sole's normal is the world's up in the reference posture, carried into the foot body; the **sole frame**
is the frame the inverse kinematics keeps level (x forward along the sole, y left, z along that normal),
written in the pelvis frame at zero angles as

.. math:: R_s = R_y(\theta) R_x(\phi), \qquad n = R_s e_z = (\cos\phi \sin\theta,\ -\sin\phi,\
    \cos\phi \cos\theta)

so the sole's roll ``phi = atan2(-n_y, sqrt(n_x^2 + n_z^2))`` and pitch ``theta = atan2(n_x, n_z)`` at zero
angles are read from its normal ``n`` there, and ``R_s`` turns the sole no more than the tilt needs (its x axis
stays in the pelvis's x-z plane: no yaw). ``R_s`` is the identity where the foot is level at zero angles too
(TALOS, Booster T1, Fourier N1, Unitree H1: tilts below 1e-15 rad).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.zmp import convex_hull

Array = NDArray[np.float64]

SOLE_BAND = 0.002  # [m] collision points this close to the lowest (along the sole's normal) form the sole
LEVEL = 1e-12  # [rad] a tilt below this is level (the rounding of the model's own rotations)
FACE_TILT = 0.1  # [rad] a foot box's bottom face this close to level in the reference posture is the sole's plane


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
    """The geoms that can touch the floor: by their contact type and affinity, or paired with a geom of the world
    body (the floor) in an explicit contact pair (``<contact><pair>``, whose geoms often have ``contype =
    conaffinity = 0``); a geom paired only with the robot's own geoms (a foot box kept for foot-to-shin
    collisions) is not."""
    m = model
    geoms = {g for g in range(m.ngeom)  # type: ignore[attr-defined]
             if m.geom_contype[g] != 0 or m.geom_conaffinity[g] != 0}  # type: ignore[attr-defined]
    for pair in range(m.npair):  # type: ignore[attr-defined]
        first, second = int(m.pair_geom1[pair]), int(m.pair_geom2[pair])  # type: ignore[attr-defined]
        for geom, other in ((first, second), (second, first)):
            if int(m.body_weldid[m.geom_bodyid[other]]) == 0:  # type: ignore[attr-defined]  # on the world
                geoms.add(geom)
    return geoms


def sole_face_up(model: object, data: object, bodies: list[int], lowest: float) -> Array | None:
    """The world up of the sole's own plane where the foot's sole is a box: the outward normal of the bottom face of
    the collision box that reaches lowest (reversed, pointing up), in world, when it is within :data:`FACE_TILT` of
    the vertical in the posture of ``data`` and reaches within :data:`SOLE_BAND` of ``lowest``, the height [m] of
    the foot's lowest collision point there; None where the foot has no such box (its sole is then taken level
    in that posture). A keyframe whose feet stand 2° off level (a model's standing pose on soft contacts) then
    still gives the whole box face as the sole, not its lowest edge."""
    import mujoco

    m, d = model, data
    colliding = colliding_geoms(m)
    best: tuple[float, Array] | None = None
    for g in range(m.ngeom):  # type: ignore[attr-defined]
        if (int(m.geom_bodyid[g]) not in bodies or g not in colliding  # type: ignore[attr-defined]
                or int(m.geom_type[g]) != mujoco.mjtGeom.mjGEOM_BOX):  # type: ignore[attr-defined]
            continue
        rotation = d.geom_xmat[g].reshape(3, 3)  # type: ignore[attr-defined]
        axis = int(np.argmax(np.abs(rotation[2, :])))  # the box axis nearest the vertical
        up = rotation[:, axis] * (1.0 if rotation[2, axis] > 0 else -1.0)
        lowest = float(d.geom_xpos[g][2] - np.abs(rotation[2, :]) @ m.geom_size[g])  # type: ignore[attr-defined]
        if best is None or lowest < best[0]:
            best = (lowest, np.array(up, dtype=np.float64))
    if best is None:
        best = _lowest_bar_up(m, d, bodies, colliding)
    if best is None or math.acos(min(float(best[1][2]), 1.0)) > FACE_TILT:
        return None
    if best[0] > lowest + SOLE_BAND:  # the box is not what the foot stands on (spheres, a mesh below it)
        return None
    return best[1]


def _lowest_bar_up(model: object, data: object, bodies: list[int],
                   colliding: set[int]) -> tuple[float, Array] | None:
    """Of a foot without a collision box, the cylinder or capsule lying lowest (PNDbotics Adam Lite's two
    cylinders along the foot): its lowest height [m] and the up of the plane its bottom line lies in, the world's
    up made square to its axis (level across the bar, along the bar as it lies); None without such a geom."""
    import mujoco

    m, d = model, data
    bars = (int(mujoco.mjtGeom.mjGEOM_CYLINDER), int(mujoco.mjtGeom.mjGEOM_CAPSULE))
    best: tuple[float, Array] | None = None
    for g in range(m.ngeom):  # type: ignore[attr-defined]
        kind = int(m.geom_type[g])  # type: ignore[attr-defined]
        if int(m.geom_bodyid[g]) not in bodies or g not in colliding or kind not in bars:  # type: ignore[attr-defined]
            continue
        axis = d.geom_xmat[g].reshape(3, 3)[:, 2]  # type: ignore[attr-defined]
        radius, half = float(m.geom_size[g][0]), float(m.geom_size[g][1])  # type: ignore[attr-defined]
        across = math.sqrt(max(1.0 - float(axis[2]) ** 2, 0.0))  # a cylinder's end circle reaches down this much
        drop = radius if kind == int(mujoco.mjtGeom.mjGEOM_CAPSULE) else radius * across
        lowest = float(d.geom_xpos[g][2]) - abs(float(axis[2])) * half - drop  # type: ignore[attr-defined]
        up = np.array([0.0, 0.0, 1.0]) - float(axis[2]) * np.asarray(axis, dtype=np.float64)
        if np.linalg.norm(up) < 1e-9:  # a bar standing upright: no plane
            continue
        if best is None or lowest < best[0]:
            best = (lowest, up / np.linalg.norm(up))
    return best


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


@dataclass(frozen=True)
class Sole:
    """One foot's sole (see the module docstring), in the sole frame: origin the ankle point, axes ``rotation``.

    Attributes:
        points: The foot's collision points within :data:`SOLE_BAND` of the lowest [m], (m, 3).
        polygon: Their convex hull in the sole plane, counter-clockwise [m], (k, 2).
        ankle_height: The ankle point's height above the sole [m].
        rotation: The sole frame in the pelvis frame at zero joint angles, (3, 3).
        tilt_zero: The sole's (roll, pitch) at zero angles, relative to the pelvis [rad].
        tilt_reference: The (roll, pitch) of the plane through :attr:`points` in the reference posture, relative
            to level [rad]: 0 where the reference posture stands the sole flat (nan where the points are on a line).
    """

    points: Array
    polygon: Array
    ankle_height: float  # [m]
    rotation: Array
    tilt_zero: tuple[float, float]  # [rad]
    tilt_reference: tuple[float, float]  # [rad]

    @property
    def extent(self) -> tuple[float, float]:
        """Length and width of the polygon's bounding rectangle [m]."""
        if len(self.polygon) == 0:
            return 0.0, 0.0
        size = self.polygon.max(axis=0) - self.polygon.min(axis=0)
        return float(size[0]), float(size[1])


def tilt_of(normal: Array) -> tuple[float, float]:
    """(roll, pitch) [rad] of the frame ``R_y(pitch) R_x(roll)`` whose z axis is the unit ``normal`` (module
    docstring)."""
    nx, ny, nz = (float(v) for v in normal)
    return math.atan2(-ny, math.hypot(nx, nz)), math.atan2(nx, nz)


def tilt_rotation(roll: float, pitch: float) -> Array:
    """``R_y(pitch) R_x(roll)``, (3, 3)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    return np.array([[cp, sp * sr, sp * cr], [0.0, cr, -sr], [-sp, cp * sr, cp * cr]])


def sole_roll_bound(sole_width: float) -> float:
    r"""The largest roll of a sole that it may be left with by a leg without an ankle roll (a five-joint leg's
    virtual ankle roll's range) [rad]: the roll about its centre line that keeps the sole a sole, its points within
    :data:`SOLE_BAND` of one another across its width ``W``,

    .. math:: W \sin\phi \le \mathrm{SOLE\_BAND}, \qquad |\phi| \le \arcsin\frac{\mathrm{SOLE\_BAND}}{W}

    (a sole rolled further stands on an edge: Unitree H1's 60 mm soles, 0.0333 rad). Why a walk needs more than
    that of a five-joint leg: :mod:`zmpwalk.robots.legs`.
    """
    return math.asin(min(1.0, SOLE_BAND / sole_width))


def foot_sole(points: Array, up: Array, rotation: Array, position: Array, ankle: Array) -> Sole:
    """The sole of one foot.

    Args:
        points: The foot's collision points (:func:`collision_points`) in the reference posture, in the foot
            body's frame [m], (m, 3).
        up: The up of the sole's plane in the foot body's frame in the reference posture, (3,): the world's, or
            a box sole's own bottom face (:func:`sole_face_up`).
        rotation, position: The foot body's pose in the pelvis frame at zero joint angles ((3, 3), [m] (3,)).
        ankle: The ankle point in the pelvis frame at zero angles [m], (3,).
    """
    roll, pitch = tilt_of(rotation @ (up / np.linalg.norm(up)))
    if abs(roll) < LEVEL and abs(pitch) < LEVEL:
        roll = pitch = 0.0
    frame = tilt_rotation(roll, pitch)
    local = (points @ rotation.T + position - ankle) @ frame  # R_s^T (x - ankle), row by row
    bottom = float(local[:, 2].min()) if len(local) else 0.0
    band = local[local[:, 2] < bottom + SOLE_BAND]
    polygon = convex_hull(band[:, :2]) if len(band) else np.zeros((0, 2))
    tilt_reference = (math.nan, math.nan)
    if len(band) >= 3:
        centred = band - band.mean(axis=0)
        _, singular, vectors = np.linalg.svd(centred)
        if singular[1] > 1e-9:
            normal = vectors[2] if vectors[2][2] > 0 else -vectors[2]
            tilt_reference = tilt_of(normal)
    return Sole(band, np.asarray(polygon, dtype=np.float64), -bottom, frame, (roll, pitch), tilt_reference)
