"""Reference clips from a walk simulated through the walking controller: the simulated motion and the planned one.

:func:`walk_clips` walks one velocity command (a forward, side and turn velocity at a step time) with
:func:`zmpwalk.sim.loop.simulate_controller` (stabilizer and feedforward on; MuJoCo's noslip solver on, so a
loaded sole holds where it stands as a real one does instead of creeping 2-3 mm a step under the legs' lateral
push, :class:`~zmpwalk.sim.mujoco_plant.MujocoPlant`) and records, at ``fps`` frames a second, the whole model's
``qpos`` in two ways:

The walker plans with the robot's default generator (:attr:`~zmpwalk.robots.model.RobotModel.default_generator`:
the polynomial pattern for HUBO, the hyperbolic one for a robot's own model) unless one is named.

- **simulated**: the MuJoCo state after the control tick nearest each frame time;
- **planned**: the walker's own pose of that tick (its 12 leg angles, the base upright at the pelvis yaw and placed
  so the legs put the ankles where planned, every other joint at the reference pose), lowered or raised once by a
  constant so that its lowest sole is on the floor at the first frame (as the simulation stands the robot).

A clip's ``qpos`` rows are in the model's own order (the free base first: position [m], quaternion w, x, y, z);
its ``qvel`` is the central difference of the rows (:func:`mujoco.mj_differentiatePos`), in MuJoCo's order
(base linear velocity in world [m/s], base angular velocity in the base frame [rad/s], joint rates).
:func:`cyclic_window` finds whole gait cycles in steady walking whose ends repeat (the loop points).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.control import JointTargets, WalkingController
from zmpwalk.errors import InvalidParameterError
from zmpwalk.online import START_DELAY
from zmpwalk.robots.collision import collision_points, rigid_bodies
from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.loop import ControllerRun, simulate_controller, simulated_clock
from zmpwalk.sim.mujoco_plant import MujocoPlant, _ankle_sites, _base_position
from zmpwalk.sim.poses import close_loops, set_base_pose

Array = NDArray[np.float64]

CONTROL_RATE = 1000.0  # [Hz] the controller's rate in the simulation
SKIP_START = 2  # [swings] walking not yet steady after the start
SKIP_END = 2  # [swings] walking no longer steady before the stop


@dataclass(frozen=True)
class Command:
    """One walking command of a grid.

    Attributes:
        forward: Forward velocity [m/s].
        side: Leftward velocity [m/s].
        turn: Counter-clockwise turn rate [rad/s].
        step_time: Step time of one swing [s]; None: the schedule's (:func:`zmpwalk.control.velocity_step_time`).
    """

    forward: float  # [m/s]
    side: float = 0.0  # [m/s]
    turn: float = 0.0  # [rad/s]
    step_time: float | None = None  # [s]

    def name(self) -> str:
        """A file-name stem: ``vx0.10_vy0.00_wz0.00_T0.70``."""
        step = "auto" if self.step_time is None else f"{self.step_time:.2f}"
        return f"vx{self.forward:+.2f}_vy{self.side:+.2f}_wz{self.turn:+.2f}_T{step}"


@dataclass
class Clip:
    """A motion at a fixed frame rate, in the model's ``qpos`` order.

    Attributes:
        qpos: Generalised positions (n, nq) [m, rad; base quaternion w, x, y, z].
        fps: Frames per second [Hz].
        kind: ``"simulated"`` or ``"planned"``.
        loop: First and last frame of the cyclic window (the last repeats the first), or None.
        loop_error: How far the window's last frame is from its first (:func:`cyclic_window`), or empty.
    """

    qpos: Array
    fps: float  # [Hz]
    kind: str
    loop: tuple[int, int] | None = None
    loop_error: dict[str, float] = field(default_factory=dict)


class _RecordingPlant(MujocoPlant):
    """A :class:`MujocoPlant` that keeps the state after every tick and the planned pose of chosen ticks."""

    def __init__(self, robot: RobotModel, rate: float, every: float) -> None:
        super().__init__(robot, rate, noslip=True)
        self.every = every  # [ticks] between frames
        self.states: list[Array] = []
        self.planned: list[Array] = []
        self._scratch = mujoco.MjData(self.plant.model)
        self._sites = _ankle_sites(self.plant.model)

    def apply(self, targets: JointTargets) -> None:
        super().apply(targets)
        frame = len(self.planned)
        if round(frame * self.every) == self._ticks and targets.sample.joint_angles is not None:
            sample, angles = targets.sample, targets.sample.joint_angles
            qpos = self.plant.qpos_hold.copy()
            set_base_pose(self.plant, qpos, _base_position(self.plant, self._scratch, sample, angles, self._sites),
                          sample.yaw_pelvis_in_world)
            qpos[self.plant.leg_qpos] = angles[self.plant.leg_columns]
            if len(self.plant.coupled_dofs):  # a linkage's cranks and rods where the planned legs put them
                self._scratch.qpos[:] = qpos
                close_loops(self.plant, self._scratch)
                qpos = self._scratch.qpos.copy()
            self.planned.append(qpos)

    def step(self) -> None:
        super().step()
        self.states.append(self.data.qpos.copy())


def lowest_sole_height(model: mujoco.MjModel, data: mujoco.MjData, feet: list[list[int]]) -> Array:
    """The lowest collision point's height [m] of each foot (its rigid bodies' collision geoms) in ``data``'s pose."""
    return np.array([float(collision_points(model, data, bodies)[:, 2].min()) for bodies in feet])


def foot_bodies(model: mujoco.MjModel) -> list[list[int]]:
    """The rigid bodies of each foot (left, right): those welded to the bodies of the ``left_ankle`` and
    ``right_ankle`` sites."""
    return [rigid_bodies(model, int(model.site_bodyid[site])) for site in _ankle_sites(model)]


def walk_clips(robot: RobotModel, command: StepCommand, count: int, fps: float,
               generator: str | None = None) -> tuple[ControllerRun, Clip, Clip]:
    """Walk ``count`` copies of ``command`` through the controller (``generator``: the pattern generator, default
    the robot's :attr:`~zmpwalk.robots.model.RobotModel.default_generator`); the simulated and the planned clips.

    Raises:
        InvalidParameterError: ``fps`` outside (0, 1000] Hz.
    """
    if not (math.isfinite(fps) and 0.0 < fps <= CONTROL_RATE):
        raise InvalidParameterError("fps", fps, f"a frame rate in (0, {CONTROL_RATE:g}] Hz")
    every = CONTROL_RATE / fps
    plant = _RecordingPlant(robot, CONTROL_RATE, every)
    controller = WalkingController(robot, CONTROL_RATE, generator=generator or robot.default_generator,
                                   feedforward=plant.feedforward(), clock=simulated_clock(CONTROL_RATE))
    run = simulate_controller(robot, [command] * count, rate=CONTROL_RATE, plant=plant, controller=controller)
    states = np.asarray(plant.states)
    frames = np.arange(math.floor((len(states) - 1) / every) + 1)
    simulated = states[np.rint(frames * every).astype(int)]
    planned = np.asarray(plant.planned)[: len(simulated)]
    model, data = plant.plant.model, mujoco.MjData(plant.plant.model)
    data.qpos[:] = planned[0]
    mujoco.mj_kinematics(model, data)
    planned[:, 2] -= float(lowest_sole_height(model, data, foot_bodies(model)).min())
    return run, Clip(simulated, fps, "simulated"), Clip(planned, fps, "planned")


def velocities(model: mujoco.MjModel, qpos: Array, fps: float) -> Array:
    """``qvel`` rows (n, nv) of ``qpos`` rows: central differences (one-sided at the ends)."""
    n, dt = len(qpos), 1.0 / fps
    qvel = np.zeros((n, model.nv))
    if n < 2:
        return qvel
    for i in range(n):
        a, b = max(i - 1, 0), min(i + 1, n - 1)
        mujoco.mj_differentiatePos(model, qvel[i], (b - a) * dt, qpos[a], qpos[b])
    return qvel


def _heading_free(model: mujoco.MjModel, qpos: Array) -> Array:
    """``qpos`` rows with the base's horizontal position and yaw taken out (the state a gait cycle repeats)."""
    rows = qpos.copy()
    w, x, y, z = rows[:, 3], rows[:, 4], rows[:, 5], rows[:, 6]
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    half = -yaw / 2
    c, s = np.cos(half), np.sin(half)  # (c, 0, 0, s) * q: the yaw taken out
    rows[:, 3:7] = np.column_stack([c * w - s * z, c * x - s * y, c * y + s * x, c * z + s * w])
    rows[:, 0:2] = 0.0
    return rows


def cyclic_window(model: mujoco.MjModel, qpos: Array, fps: float, walk_start: float, swings: int,
                  step_time: float) -> tuple[tuple[int, int], dict[str, float]] | None:
    """The window of whole gait cycles (two swings each) in steady walking whose last frame best repeats its first.

    Steady walking: from :data:`SKIP_START` swings after the walk starts (``walk_start`` [s]) to :data:`SKIP_END`
    swings before its ``swings`` end. The window holds as many whole cycles as fit; its start is searched over one
    cycle for the least joint error. Returns the first and last frame and the loop-closure error: ``joints``
    [rad] (largest joint angle difference), ``base_height`` [m], ``base_tilt`` [rad] (roll and pitch, as the
    quaternion's angle with the yaw taken out), ``joint_rates`` [rad/s] (largest); None where no whole cycle fits.
    """
    cycle = 2.0 * step_time
    first = walk_start + SKIP_START * step_time
    last = walk_start + (swings - SKIP_END) * step_time
    cycles = math.floor((last - first) / cycle + 1e-9)
    if cycles < 1:
        return None
    span = round(cycles * cycle * fps)
    rows, qvel = _heading_free(model, qpos), velocities(model, qpos, fps)
    best: tuple[float, int] | None = None
    for start in range(round(first * fps), round((first + cycle) * fps) + 1):
        end = start + span
        if end >= len(rows):
            break
        error = float(np.abs(rows[end, 7:] - rows[start, 7:]).max(initial=0.0))
        if best is None or error < best[0]:
            best = (error, start)
    if best is None:
        return None
    start, end = best[1], best[1] + span
    dot = abs(float(np.dot(rows[start, 3:7], rows[end, 3:7])))
    errors = {"joints": best[0], "base_height": abs(float(rows[end, 2] - rows[start, 2])),
              "base_tilt": 2.0 * math.acos(min(dot, 1.0)),
              "joint_rates": float(np.abs(qvel[end, 6:] - qvel[start, 6:]).max(initial=0.0))}
    return (start, end), errors


def walk_start_time() -> float:
    """When a walk given at the first tick starts [s] (the walker's start delay)."""
    return START_DELAY
