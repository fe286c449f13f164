"""What the simulated sensors say of the soles: the named slices of MuJoCo's sensor data, each sole's normal force
and centre of pressure from its ankle force-torque sensor, the CoP's margin to the loaded soles, the ankles'
slide while loaded. One implementation for the batch simulation (:mod:`zmpwalk.sim.run`) and the controller's loop
(:mod:`zmpwalk.sim.loop`)."""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.contact import LOADED_FRACTION
from zmpwalk.zmp import batch_hull_margin, edge_margin

Array = NDArray[np.float64]


def rpy_from_quaternion(quaternion: Array) -> Array:
    """Roll, pitch, yaw [rad] (n, 3) from unit quaternions (n, 4) ``w, x, y, z``."""
    w, x, y, z = quaternion.T
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1, 1))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.column_stack([roll, pitch, yaw])


def rotation_from_quaternion(quaternion: Array) -> Array:
    """Rotation matrices (n, 3, 3) from unit quaternions (n, 4) ``w, x, y, z``."""
    w, x, y, z = quaternion.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


class SensorSlices:
    """Slices of ``sensordata`` by sensor name."""

    def __init__(self, model: mujoco.MjModel) -> None:
        self.slices: dict[str, slice] = {}
        for i in range(model.nsensor):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SENSOR, i)
            start = int(model.sensor_adr[i])
            self.slices[name] = slice(start, start + int(model.sensor_dim[i]))

    def take(self, data: Array, name: str) -> Array:
        return data[:, self.slices[name]]

    def columns(self, data: Array, names: list[str]) -> Array:
        return np.column_stack([data[:, self.slices[n]] for n in names])


def ground_reaction(sensors: SensorSlices, data: Array, label: str, ankle_height: float) -> tuple[Array, Array]:
    """Normal force [N] (n,) and centre of pressure in world [m] (n, 2) of one sole, from its ankle sensor.

    The sensor gives the wrench between the foot and the leg in the foot frame; the ground's is its
    opposite (the foot's own weight and inertia are not removed, as on the robot). With the reaction
    ``R`` and torque ``T`` about the ankle and the sole ``ankle_height`` below it:
    ``p_x = -(T_y + h R_x) / R_z``, ``p_y = (T_x - h R_y) / R_z``.
    """
    force = -sensors.take(data, f"{label}_force")
    torque = -sensors.take(data, f"{label}_torque")
    h = ankle_height
    with np.errstate(invalid="ignore", divide="ignore"):
        local = np.column_stack([-(torque[:, 1] + h * force[:, 0]) / force[:, 2],
                                 (torque[:, 0] - h * force[:, 1]) / force[:, 2], np.full(len(force), -h)])
    rotation = rotation_from_quaternion(sensors.take(data, f"{label}_ankle_quat"))
    world = sensors.take(data, f"{label}_ankle_pos") + np.einsum("nij,nj->ni", rotation, local)
    return force[:, 2], world[:, :2]


def cop_margins(cop: Array, corners: Array, loaded: NDArray[np.bool_]) -> Array:
    """Signed distance of the CoP to the polygon of the loaded soles per sample [m] (NaN when none).

    Single support is vectorised (the sole is a rectangle, already counter-clockwise); double
    support takes the hull of the eight corners.
    """
    n = len(cop)
    margin = np.full(n, np.nan)
    single = loaded[:, 0] ^ loaded[:, 1]
    if single.any():
        foot = np.where(loaded[single, 0], 0, 1)
        quad = corners[single][np.arange(int(single.sum())), foot]  # (m, 4, 2), counter-clockwise
        edge = np.roll(quad, -1, axis=1) - quad
        margin[single] = edge_margin(cop[single], quad, edge, np.ones(edge.shape[:2], dtype=bool))
    both = loaded[:, 0] & loaded[:, 1]
    if both.any():
        margin[both] = batch_hull_margin(cop[both], corners[both].reshape(-1, 8, 2))
    return margin


@dataclass
class SoleMeasurements:
    """Per sample: each sole's normal force (n, 2) [N], whether it is loaded (n, 2), its CoP in world (n, 2, 2) [m]
    (nan unloaded), the total CoP (n, 2) [m] (nan with no sole loaded) and its margin to the loaded soles (n,) [m]
    (positive inside), the sole corners (n, 2, 4, 2) [m] and the ankles (n, 2, 2) [m] in world."""

    forces: Array
    loaded: NDArray[np.bool_]
    cop_feet: Array
    cop: Array
    margin: Array
    corners: Array
    ankles: Array


def sole_measurements(robot: RobotModel, sensors: SensorSlices, readings: Array, weight: float) -> SoleMeasurements:
    """The soles from the ankle sensors' rows ``readings`` (n, nsensordata) of a robot of ``weight`` [N]: a sole
    carrying more than :data:`~zmpwalk.sim.contact.LOADED_FRACTION` of it is loaded; the total CoP is the loaded
    soles' CoPs weighted by their forces."""
    reactions = [ground_reaction(sensors, readings, label, robot.ankle_height) for label in ("left", "right")]
    forces = np.column_stack([r[0] for r in reactions])
    loaded = forces > LOADED_FRACTION * weight
    cop_feet = np.stack([r[1] for r in reactions], axis=1)
    cop_feet[~loaded] = np.nan
    weights = np.where(loaded, forces, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        cop = np.nansum(cop_feet * weights[..., None], axis=1) / weights.sum(axis=1)[:, None]
    cop[~loaded.any(axis=1)] = np.nan
    corners, ankles = np.empty((len(readings), 2, 4, 2)), np.empty((len(readings), 2, 2))
    half_length, half_width = robot.foot_length / 2, robot.foot_width / 2
    for foot, (label, side) in enumerate((("left", 1), ("right", -1))):
        rotation = rotation_from_quaternion(sensors.take(readings, f"{label}_ankle_quat"))
        origin = sensors.take(readings, f"{label}_ankle_pos")
        cx, cy, z = robot.sole_center_x, side * robot.sole_center_y, -robot.ankle_height
        local = np.array([[cx - half_length, cy - half_width, z], [cx + half_length, cy - half_width, z],
                          [cx + half_length, cy + half_width, z], [cx - half_length, cy + half_width, z]])
        corners[:, foot] = (origin[:, None, :] + np.einsum("nij,cj->nci", rotation, local))[..., :2]
        ankles[:, foot] = origin[:, :2]
    return SoleMeasurements(forces, loaded, cop_feet, cop, cop_margins(cop, corners, loaded), corners, ankles)


def foot_slip(loaded: NDArray[np.bool_], ankles: Array) -> float:
    """The largest horizontal slide [m] of an ankle (n, 2, 2) while its sole stays loaded (n, 2)."""
    slip = 0.0
    for foot in range(2):
        starts = np.flatnonzero(loaded[:, foot] & ~np.concatenate([[False], loaded[:-1, foot]]))
        stops = np.flatnonzero(loaded[:, foot] & ~np.concatenate([loaded[1:, foot], [False]]))
        for a, b in zip(starts, stops, strict=True):
            slip = max(slip, float(np.linalg.norm(ankles[a:b + 1, foot] - ankles[a, foot], axis=1).max()))
    return slip
