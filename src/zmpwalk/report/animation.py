"""An animation of a simulated walk, rendered offscreen with MuJoCo (``MUJOCO_GL=egl`` on a headless machine)."""

from __future__ import annotations

import io
import os
from collections.abc import Callable

import numpy as np

from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.poses import set_base_pose
from zmpwalk.sim.run import SimulationResult

FPS = 12  # [1/s] frames of the GIF
WIDTH, HEIGHT = 400, 300  # [px] of each of the two views


def render_gif(robot: RobotModel, result: SimulationResult, fps: int = FPS,
               progress: Callable[[float], None] | None = None) -> bytes:
    """The walk as an animated GIF: the recorded poses replayed from the side and from the front (lateral sway
    shows there), both cameras following the torso, the simulated time written on every frame.

    Raises:
        RuntimeError: No OpenGL context could be made (set ``MUJOCO_GL=egl`` or ``osmesa``).
    """
    os.environ.setdefault("MUJOCO_GL", "egl")
    import mujoco
    from PIL import Image, ImageDraw, ImageFont

    from zmpwalk.sim.plant import build_plant

    plant = build_plant(robot, result.mass_scale)
    model = plant.model
    data = mujoco.MjData(model)
    data.qpos[:] = plant.qpos_hold
    model.vis.headlight.ambient[:] = (0.45, 0.45, 0.45)  # lit so the robot stands out from the floor
    model.vis.headlight.diffuse[:] = (0.7, 0.7, 0.7)
    renderer = mujoco.Renderer(model, HEIGHT, WIDTH)
    side, front = mujoco.MjvCamera(), mujoco.MjvCamera()
    for camera, azimuth in ((side, 120.0), (front, 180.0)):
        camera.distance = 2.2 * robot.height
        camera.elevation = -12.0
        camera.azimuth = azimuth  # front: looking along +x at the robot's face (lateral sway shows)
    step = max(1, round(1.0 / (fps * (result.time[1] - result.time[0]))))
    frames = []
    rotation = _quaternions(result.torso_rpy)
    font = ImageFont.load_default()
    for i in range(0, len(result.time), step):
        if progress is not None and (i // step) % 20 == 0:
            progress(i / len(result.time))
        set_base_pose(plant, data.qpos, result.torso_position[i], 0.0, rotation[i])
        data.qpos[plant.leg_qpos] = result.joint_angles[i][plant.leg_columns]
        mujoco.mj_kinematics(model, data)
        views = []
        for camera in (side, front):
            camera.lookat[:] = (result.torso_position[i, 0], result.torso_position[i, 1], 0.6 * robot.pelvis_height)
            renderer.update_scene(data, camera)
            views.append(renderer.render())
        image = Image.fromarray(np.concatenate(views, axis=1))
        draw = ImageDraw.Draw(image)
        label = f"t = {result.time[i]:5.2f} s   side | front"
        draw.rectangle((4, 4, 8 + 7 * len(label), 20), fill=(255, 255, 255))
        draw.text((8, 6), label, fill=(0, 0, 0), font=font)
        frames.append(image.quantize(colors=64))
    renderer.close()
    buffer = io.BytesIO()
    frames[0].save(buffer, format="GIF", save_all=True, append_images=frames[1:], duration=int(1000 / fps), loop=0)
    return buffer.getvalue()


def _quaternions(rpy: np.ndarray) -> np.ndarray:
    roll, pitch, yaw = rpy.T / 2
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    return np.column_stack([cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy])
