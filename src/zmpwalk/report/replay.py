"""The interactive replay of a simulated walk: the model's own geoms drawn with three.js in the report page.

The bodies' world poses are replayed from the recorded base position, attitude and leg joint angles through
``mj_kinematics`` (as the GIF does) at :data:`FPS` and embedded as base64 float32 arrays, with the geoms (each with
its body, local pose and colour; meshes decimated to at most :data:`MAX_MESH_FACES` faces), the planned and
measured footprints, the reference ZMP and the measured CoP. The page script (``replay.js``) and three.js
(``vendor/three.min.js``, r159, MIT) are embedded too, so the page opens offline. No simulation is rerun.
"""

from __future__ import annotations

import base64
import json
import math
from importlib import resources
from typing import Any

import mujoco
import numpy as np

from zmpwalk.footsteps import Pose2D, foot_corners
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.contact import LOADED_FRACTION
from zmpwalk.sim.poses import set_base_pose
from zmpwalk.sim.run import SimulationResult

FPS = 40  # [1/s] frames of the replay
MAX_MESH_FACES = 4000  # faces of one mesh after decimation
MIN_SWING = 0.25  # [s] a sole unloaded for less makes no new footprint (flickers while the weight shifts and
# bounces last up to 0.19 s on Booster T1's demo, swings 0.3 s and more)
VISIBLE_GROUPS = 3  # geom groups 0-2 are drawn (MuJoCo's default visual groups)
KINDS = {mujoco.mjtGeom.mjGEOM_BOX: "box", mujoco.mjtGeom.mjGEOM_SPHERE: "sphere",
         mujoco.mjtGeom.mjGEOM_CAPSULE: "capsule", mujoco.mjtGeom.mjGEOM_CYLINDER: "cylinder",
         mujoco.mjtGeom.mjGEOM_ELLIPSOID: "ellipsoid", mujoco.mjtGeom.mjGEOM_MESH: "mesh"}


def _b64(values: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype="<f4").tobytes()).decode("ascii")


def _b64_faces(values: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype="<u4").tobytes()).decode("ascii")


def _quaternions(rpy: np.ndarray) -> np.ndarray:
    roll, pitch, yaw = rpy.T / 2
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    return np.column_stack([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])


def decimate(vertices: np.ndarray, faces: np.ndarray, limit: int = MAX_MESH_FACES) -> tuple[np.ndarray, np.ndarray]:
    """A mesh with at most ``limit`` faces (vertex clustering on a grid made coarser until it fits); unchanged
    when it already fits."""
    if len(faces) <= limit:
        return vertices, faces
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    cells = 64
    while True:
        size = np.maximum((high - low) / cells, 1e-9)
        keys = np.floor((vertices - low) / size).astype(np.int64)
        _, first, cluster = np.unique(keys, axis=0, return_index=True, return_inverse=True)
        cluster = cluster.reshape(-1)
        merged = cluster[faces]
        keep = (merged[:, 0] != merged[:, 1]) & (merged[:, 1] != merged[:, 2]) & (merged[:, 0] != merged[:, 2])
        kept = np.unique(np.sort(merged[keep], axis=1), axis=0, return_index=True)[1]
        if len(kept) <= limit or cells <= 4:
            return vertices[first], merged[keep][np.sort(kept)]
        cells = max(4, int(cells * math.sqrt(limit / len(kept)) * 0.9))


def _geoms(model: mujoco.MjModel) -> tuple[list[dict[str, Any]], list[int]]:
    """The drawn geoms (JSON-able, ``body`` indexing the returned body list) and the model's body ids drawn
    (the world body's geoms, obstacles of a scene, stay where they are)."""
    geoms: list[dict[str, Any]] = []
    bodies: list[int] = []
    for g in range(model.ngeom):
        kind = KINDS.get(int(model.geom_type[g]))
        rgba = model.mat_rgba[model.geom_matid[g]] if model.geom_matid[g] >= 0 else model.geom_rgba[g]
        if kind is None or model.geom_group[g] >= VISIBLE_GROUPS or rgba[3] <= 0:
            continue  # planes (the page draws its own floor), collision-only and invisible geoms
        body = int(model.geom_bodyid[g])
        if body not in bodies:
            bodies.append(body)
        geom: dict[str, Any] = {
            "kind": kind, "body": bodies.index(body), "size": model.geom_size[g].round(5).tolist(),
            "pos": model.geom_pos[g].round(5).tolist(), "quat": model.geom_quat[g].round(6).tolist(),
            "rgba": [round(float(c), 3) for c in rgba]}
        if kind == "mesh":
            mesh = int(model.geom_dataid[g])
            start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
            fstart, fcount = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
            vertices, faces = decimate(model.mesh_vert[start:start + count], model.mesh_face[fstart:fstart + fcount])
            geom["vertices"], geom["faces"] = _b64(vertices), _b64_faces(faces)
        geoms.append(geom)
    return geoms, bodies


def _frames(plant: Any, result: SimulationResult, bodies: list[int]) -> dict[str, Any]:
    """The bodies' world poses at :data:`FPS`, with the base position, reference ZMP and CoP at those frames."""
    data = mujoco.MjData(plant.model)
    step = max(1, round(1.0 / (FPS * (result.time[1] - result.time[0]))))
    rows = np.arange(0, len(result.time), step)
    rotation = _quaternions(result.torso_rpy)
    positions = np.zeros((len(rows), len(bodies), 3))
    quaternions = np.zeros((len(rows), len(bodies), 4))
    for k, i in enumerate(rows):
        _pose(plant, data, result, rotation, int(i))
        positions[k] = data.xpos[bodies]
        quaternions[k] = data.xquat[bodies]
    return {"count": len(rows), "bodies": len(bodies), "time": _b64(result.time[rows]),
            "position": _b64(positions), "quaternion": _b64(quaternions),
            "base": _b64(result.torso_position[rows]), "zmp": _b64(result.reference_zmp[rows]),
            "cop": _b64(result.cop[rows])}


def _pose(plant: Any, data: mujoco.MjData, result: SimulationResult, rotation: np.ndarray, i: int) -> None:
    """Set ``data`` to the recorded pose at row ``i`` (world poses computed)."""
    data.qpos[:] = plant.qpos_hold
    set_base_pose(plant, data.qpos, result.torso_position[i], 0.0, rotation[i])
    data.qpos[plant.leg_qpos] = result.joint_angles[i][plant.leg_columns]
    mujoco.mj_kinematics(plant.model, data)


def _landing_rows(time: np.ndarray, loaded: np.ndarray) -> list[int]:
    """Rows 50 ms after a sole became loaded: first (at the start if loaded there) and after each unloaded spell
    of at least :data:`MIN_SWING`."""
    onsets = np.flatnonzero(loaded[1:] & ~loaded[:-1]) + 1
    offsets = np.flatnonzero(~loaded[1:] & loaded[:-1]) + 1
    rows = [0] if loaded[0] else []
    for onset in onsets.tolist():
        before = offsets[offsets < onset]
        if not len(before) or time[onset] - time[before[-1]] >= MIN_SWING:  # first loaded, or after a swing
            rows.append(onset)
    return [min(row + 50, len(time) - 1) for row in rows]


def _footprints(plant: Any, pattern: WalkingPattern, result: SimulationResult) -> dict[str, Any]:
    """Planned soles (the first stance and every landing) and measured ones (each ankle where its sole became
    loaded after a swing, 50 ms later, with the foot's yaw), as lists of four (x, y) corners, with the time each
    is placed."""
    robot = result.robot
    planned = [(0.0, foot_corners(pose, side, robot)) for pose, side in pattern.support_phases[0].feet]
    for step in pattern.steps:
        x, y, yaw = step.landing
        side = 1 if step.swing == "left" else -1
        planned.append((step.start + step.duration, foot_corners(Pose2D(x, y, yaw), side, robot)))
    measured = []
    data = mujoco.MjData(plant.model)
    rotation = _quaternions(result.torso_rpy)
    weight = robot.mass * robot.gravity
    for foot, force in enumerate((result.force_left, result.force_right)):
        site = mujoco.mj_name2id(plant.model, mujoco.mjtObj.mjOBJ_SITE, ("left", "right")[foot] + "_ankle")
        for i in _landing_rows(result.time, force > LOADED_FRACTION * weight):
            _pose(plant, data, result, rotation, i)
            x, y = data.site_xpos[site][:2]
            matrix = data.site_xmat[site].reshape(3, 3)
            yaw = math.atan2(float(matrix[1, 0]), float(matrix[0, 0]))
            measured.append((float(result.time[i]),
                             foot_corners(Pose2D(float(x), float(y), yaw), 1 if foot == 0 else -1, robot)))
    return {side: [{"t": round(t, 3), "corners": np.round(c, 4).tolist()} for t, c in prints]
            for side, prints in (("planned", planned), ("measured", measured))}


def replay_payload(robot: RobotModel, pattern: WalkingPattern, result: SimulationResult) -> dict[str, Any]:
    """Everything the page's replay draws, JSON-able (arrays as base64 little-endian float32)."""
    from zmpwalk.sim.plant import build_plant

    plant = build_plant(robot, result.mass_scale)
    geoms, bodies = _geoms(plant.model)
    return {"robot": robot.name, "height": float(robot.height), "pelvis_height": float(robot.pelvis_height),
            "fps": FPS, "geoms": geoms, "frames": _frames(plant, result, bodies),
            "footprints": _footprints(plant, pattern, result), "start": float(result.time[0]),
            "end": float(result.time[-1])}


def _resource(name: str) -> bytes:
    return resources.files("zmpwalk.report").joinpath(name).read_bytes()


def replay_html(payload: dict[str, Any], fallback: str) -> str:
    """The replay's section of the page: canvas, controls, a time plot, the data and the scripts (three.js as a
    data URI, so nothing is fetched). ``fallback`` is HTML shown where WebGL is missing."""
    three = base64.b64encode(_resource("vendor/three.min.js")).decode("ascii")
    script = _resource("replay.js").decode("utf-8")
    data = json.dumps(payload, separators=(",", ":")).replace("</", "<\\/")
    return f"""<section id="replay" data-ready="no" data-frames="{payload['frames']['count']}">
<div id="replay-view" style="position:relative;width:100%;height:420px;background:#e8ecf0"></div>
<div id="replay-controls">
<button id="replay-play" type="button">pause</button>
<input id="replay-slider" type="range" min="{payload['start']:.3f}" max="{payload['end']:.3f}" step="0.001" value="0"
 style="width:50%" aria-label="time [s]">
<span id="replay-time">t = 0.00 s</span>
<label>speed <select id="replay-speed"><option>0.25</option><option>0.5</option><option selected>1</option>
<option>2</option></select></label>
<label><input id="replay-follow" type="checkbox" checked> follow</label>
</div>
<canvas id="replay-plot" width="940" height="160" style="width:100%;height:160px;cursor:crosshair"></canvas>
<p class="legend">The walk replayed from the simulation: drag to orbit, wheel to zoom; grey soles planned,
red measured at each landing (shown once landed); blue disc: reference ZMP, red disc: measured CoP.
Below: ZMP (blue) and CoP (red) x and y against time; click or drag there to set the time.</p>
<div id="replay-fallback" hidden>{fallback}</div>
</section>
<script type="application/json" id="replay-data">{data}</script>
<script src="data:text/javascript;base64,{three}"></script>
<script>
{script}
</script>"""
