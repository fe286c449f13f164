"""Reference motions over a grid of walking commands, each walked in MuJoCo, written in every format, verified.

:func:`export_motions` walks every command of a :class:`Grid` through the walking controller
(:func:`zmpwalk.sim.loop.simulate_controller`, stabilizer and feedforward on; :mod:`zmpwalk.export.clips`), one
command per worker process at a time (:func:`zmpwalk.sweep.in_pool`, Dask too), and writes per command four
clips: the simulated and the planned motion, each whole (start to stop) and cyclic (whole gait cycles of steady
walking, loop points marked), each in mjlab's npz, a LocoMuJoCo-style npz, AMP JSON, CSV and a ROS 2 bag (MCAP;
:mod:`zmpwalk.export.rosbag`). Every file is read
back and replayed kinematically (:func:`zmpwalk.export.verify.replay_check`); a clip whose file fails is marked
in the manifest (``manifest.json``), never dropped silently.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from itertools import product
from pathlib import Path

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError, InvalidParameterError, ZmpwalkError
from zmpwalk.export.amp import amp_json, read_amp
from zmpwalk.export.clips import CONTROL_RATE, Clip, Command, cyclic_window, walk_clips, walk_start_time
from zmpwalk.export.locomujoco import locomujoco_npz, read_locomujoco
from zmpwalk.export.mjlab import mjlab_npz, read_mjlab
from zmpwalk.export.names import joint_names
from zmpwalk.export.rosbag import BagExtras, read_bag, write_bag
from zmpwalk.export.table import clip_csv, read_csv
from zmpwalk.export.verify import replay_check
from zmpwalk.files import read_toml, write_bytes, write_text
from zmpwalk.robots.model import RobotModel
from zmpwalk.sim.result import SimulationResult

Array = NDArray[np.float64]

SWINGS = 10  # [-] swings walked per command (a side or turn step is two)
READ_BACK_TOLERANCE = 1e-4  # [rad or m] a file's qpos read back against the clip's (float32 and 7 digits)
FORMATS: dict[str, tuple[str, Callable[[str], tuple[Array, float]]]] = {
    "mjlab": ("mjlab.npz", read_mjlab), "locomujoco": ("locomujoco.npz", read_locomujoco),
    "amp": ("amp.json", read_amp), "csv": ("csv", read_csv), "ros2bag": ("bag", read_bag)}


@dataclass(frozen=True)
class Grid:
    """Walking commands: every combination of the lists.

    Attributes:
        forward: Forward velocities [m/s].
        side: Leftward velocities [m/s].
        turn: Turn rates [rad/s].
        step_time: Step times [s]; None: the schedule's for each velocity.
    """

    forward: tuple[float, ...] = (0.0, 0.1, 0.2)  # [m/s]
    side: tuple[float, ...] = (0.0,)  # [m/s]
    turn: tuple[float, ...] = (0.0,)  # [rad/s]
    step_time: tuple[float | None, ...] = (None,)  # [s]

    def commands(self) -> list[Command]:
        """Every command of the grid, forward speed varying slowest."""
        return [Command(f, s, t, p) for f, s, t, p in product(self.forward, self.side, self.turn, self.step_time)]

    @classmethod
    def from_toml(cls, path: str | Path) -> Grid:
        """A grid file: ``forward``, ``side``, ``turn`` (lists of numbers), ``step_time`` (a list; optional).

        Raises:
            FileFormatError: Not such a file.
        """
        table = read_toml(path)
        unknown = set(table) - {"forward", "side", "turn", "step_time"}
        if unknown:
            raise FileFormatError(str(path), f"has unknown keys {sorted(unknown)}; allowed: forward, side, turn, "
                                  "step_time")
        try:
            values = {key: tuple(float(v) for v in table[key]) for key in ("forward", "side", "turn", "step_time")
                      if key in table}
        except (TypeError, ValueError) as error:
            raise FileFormatError(str(path), f"needs lists of numbers ({error})") from None
        return cls(**values)


@dataclass
class ClipRecord:
    """One exported clip, as the manifest lists it.

    Attributes:
        name: File stem (``<command>_<kind>_<span>``).
        command: The command (velocities [m/s, m/s, rad/s], step time [s]).
        kind: ``"simulated"`` or ``"planned"``.
        span: ``"whole"`` (start to stop) or ``"cyclic"`` (whole gait cycles; its last frame repeats its first).
        frames: Frames.
        fps: [Hz].
        files: Format to file name, in the output folder.
        verified: Every file read back to the clip's qpos and its replay passed.
        replay: Largest stance slide [m], deepest penetration [m], stance phases (the worst file's).
        loop: First and last frame of the cyclic window in the whole clip, or None.
        loop_error: The window's loop-closure error (joints [rad], base height [m], tilt [rad], rates [rad/s]).
        verdict: The simulated walk's verdict (``PASS``, ``WARN``, ``FAIL``; a planned clip has its walk's).
        failed: The verdict's failed criteria.
        zmp_margin: The plan's least ZMP margin [m].
        cop_margin: The measured CoP's least margin outside touchdowns [m].
        cop_rms: RMS of the measured CoP against the reference ZMP [m].
        foot_slip: Largest slide of a loaded sole in the simulation [m].
        error: Why the command was not walked (no clip then), else empty.
        ready_stretch: The ready posture the walk starts from, its hips' height above the ankles over the straight
            leg [-], where fitted to the command (:func:`zmpwalk.ready_fit.fit_ready_posture`); None: the robot's own.
    """

    name: str
    command: dict[str, float | None]
    kind: str
    span: str
    frames: int = 0
    fps: float = 0.0  # [Hz]
    files: dict[str, str] = field(default_factory=dict)
    verified: bool = False
    replay: dict[str, float] = field(default_factory=dict)
    loop: tuple[int, int] | None = None
    loop_error: dict[str, float] = field(default_factory=dict)
    verdict: str = "FAIL"
    failed: list[str] = field(default_factory=list)
    zmp_margin: float = math.nan  # [m]
    cop_margin: float = math.nan  # [m]
    cop_rms: float = math.nan  # [m]
    foot_slip: float = math.nan  # [m]
    error: str = ""
    ready_stretch: float | None = None  # [-]


@dataclass
class ExportResult:
    """What :func:`export_motions` wrote.

    Attributes:
        out: The output folder.
        manifest: The manifest's path.
        clips: Every clip (and every command that could not be walked), in grid order.
        seconds: Wall-clock time [s].
    """

    out: Path
    manifest: Path
    clips: list[ClipRecord]
    seconds: float  # [s]

    @property
    def verified(self) -> int:
        """Clips that passed their replay."""
        return sum(c.verified for c in self.clips)


def _step(robot_spec: str, command: Command, swings: int) -> tuple[StepCommand, int]:
    """The step command of a velocity and how many of them make ``swings`` swings."""
    from zmpwalk.control import velocity_command
    from zmpwalk.robots import loaded_robot
    from zmpwalk.schedule import Schedule

    step = velocity_command(Schedule.hubo(), loaded_robot(robot_spec), command.forward, command.side, command.turn,
                            command.step_time)
    per_step = 2 if (step.side != 0.0 or step.turn != 0.0) else 1
    return step, max(1, math.ceil(swings / per_step))


def _write_clip(model: mujoco.MjModel, robot: RobotModel, clip: Clip, frames: slice, cyclic: bool, out: Path,
                record: ClipRecord, extras: BagExtras) -> None:
    """Write the clip's ``frames`` in every format, read each back and replay it; fill ``record``."""
    qpos = clip.qpos[frames]
    record.frames, record.fps = len(qpos), clip.fps
    writers = {"mjlab": lambda: mjlab_npz(model, qpos, clip.fps), "csv": lambda: clip_csv(model, qpos, clip.fps),
               "locomujoco": lambda: locomujoco_npz(model, qpos, clip.fps),
               "amp": lambda: amp_json(model, qpos, clip.fps, cyclic)}
    verified, worst = True, {"slide": 0.0, "penetration": 0.0, "phases": math.inf}
    for key, (suffix, reader) in FORMATS.items():
        name = f"{record.name}.{suffix}"
        if key == "ros2bag":
            cop = None if extras.cop is None else extras.cop[frames]
            write_bag(out / name, model, robot, qpos, clip.fps, BagExtras(extras.zmp[frames], cop))
        else:
            write_bytes(out / name, writers[key]())
        record.files[key] = name
        back, fps = reader(str(out / name))
        same = back.shape == qpos.shape and float(np.abs(back - qpos).max(initial=0.0)) <= READ_BACK_TOLERANCE
        check = replay_check(model, back, fps) if same else None
        verified = verified and same and check is not None and check.passed and abs(fps - clip.fps) < 1e-6
        if check is not None:
            worst = {"slide": max(worst["slide"], check.slide),
                     "penetration": max(worst["penetration"], check.penetration),
                     "phases": min(worst["phases"], check.phases)}
    record.verified, record.replay = verified, worst


def _extras(result: SimulationResult, frames: int, fps: float, measured: bool) -> BagExtras:
    """The reference ZMP and (``measured``) the CoP of the walk's control tick nearest each frame [m]."""
    rows = np.clip(np.rint(np.arange(frames) * CONTROL_RATE / fps).astype(int), 0, len(result.time) - 1)
    return BagExtras(result.reference_zmp[rows], result.cop[rows] if measured else None)


def export_command(robot_spec: str, command: Command, out: str, fps: float, swings: int = SWINGS) -> list[ClipRecord]:
    """Walk one command (``swings`` swings of it) and write its four clips (simulated and planned, whole and
    cyclic) to ``out``."""
    from zmpwalk.ready_fit import fit_ready_posture_of
    from zmpwalk.robots import loaded_robot
    from zmpwalk.sim.plant import build_plant
    from zmpwalk.sim.verdict import HOLD, cop_margin_outside_touchdowns, walk_verdict
    from zmpwalk.walk import WalkSpec

    stem, described = command.name(), asdict(command)
    try:
        step, count = _step(robot_spec, command, swings)
        fitted = fit_ready_posture_of(robot_spec, WalkSpec(loaded_robot(robot_spec), [step] * count))
    except ZmpwalkError as error:
        return [ClipRecord(stem, described, "simulated", "whole", error=str(error))]
    robot = fitted.spec.robot
    try:
        with fitted.walking(say=False):
            run, simulated, planned = walk_clips(robot, step, count, fps)
            refusal = run.refusal([f"step {i + 1} of {count}, refused by the walking controller"
                                   for i in range(count)])
            if refusal is not None:  # the robot stood where it was refused: no clip of this command
                raise refusal
    except ZmpwalkError as error:
        return [ClipRecord(stem, described, "simulated", "whole", ready_stretch=fitted.stretch, error=str(error))]
    result = run.result
    described["step_time"] = step.duration
    stem = replace(command, step_time=step.duration).name()
    verdict = walk_verdict(result, HOLD)
    walk = ClipRecord(stem, described, "simulated", "whole", verdict=verdict.state, failed=verdict.failed,
                      zmp_margin=result.plan_zmp_margin, cop_margin=cop_margin_outside_touchdowns(result),
                      cop_rms=result.cop_error_stats()[0], foot_slip=result.foot_slip, ready_stretch=fitted.stretch)
    model = build_plant(robot).model
    records = []
    for clip in (simulated, planned):
        extras = _extras(result, len(clip.qpos), fps, clip.kind == "simulated")
        window = cyclic_window(model, clip.qpos, fps, walk_start_time(), count * (2 if step.side or step.turn else 1),
                               step.duration)
        whole = replace(walk, name=f"{stem}_{clip.kind}_whole", kind=clip.kind, files={}, replay={})
        _write_clip(model, robot, clip, slice(None), False, Path(out), whole, extras)
        records.append(whole)
        if window is None:
            continue
        (first, last), errors = window
        whole.loop, whole.loop_error = (first, last), errors
        cyclic = replace(walk, name=f"{stem}_{clip.kind}_cyclic", kind=clip.kind, span="cyclic", files={},
                         replay={}, loop=(0, last - first), loop_error=errors)
        _write_clip(model, robot, clip, slice(first, last + 1), True, Path(out), cyclic, extras)
        records.append(cyclic)
    return records


def export_motions(robot: str, grid: Grid | None = None, out: str | Path = "zmpwalk-motions", *, fps: float = 50.0,
                   workers: int | None = None, scheduler: str | None = None, swings: int = SWINGS,
                   progress: Callable[[int, int], None] | None = None) -> ExportResult:
    """Walk every command of ``grid`` on ``robot`` (a name, robot file or model path) and export its clips.

    Args:
        robot: What ``--robot`` takes (workers load it themselves).
        grid: The commands (default: :class:`Grid`'s, three forward speeds).
        out: The output folder (made if missing).
        fps: Frame rate of the clips [Hz], in (0, 1000].
        workers: Commands walked at a time (default: one per core).
        swings: Swings walked per command (a side or turn step is two), at least 6 for a cyclic clip (two swings
            of start, one gait cycle, two of stop).
        scheduler: A Dask scheduler's address or ``"local"`` (:func:`zmpwalk.sweep.in_pool`).
        progress: Called with commands done and their number.

    Returns:
        Every clip's record; the manifest at ``out/manifest.json``.

    Raises:
        InvalidParameterError: ``workers`` < 1, ``swings`` outside [1, 200], ``fps`` outside (0, 1000] Hz, an empty
            grid.
        FileFormatError: ``out`` cannot be made.
    """
    from zmpwalk.robots import loaded_robot
    from zmpwalk.sweep import in_pool

    grid = grid or Grid()
    workers = workers if workers is not None else (os.cpu_count() or 1)
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InvalidParameterError("workers", workers, "an integer >= 1")
    if isinstance(swings, bool) or not isinstance(swings, int) or not 1 <= swings <= 200:
        raise InvalidParameterError("swings", swings, "an integer in [1, 200]")
    if not (math.isfinite(fps) and 0.0 < fps <= 1000.0):
        raise InvalidParameterError("fps", fps, "a frame rate in (0, 1000] Hz")
    commands = grid.commands()
    if not commands:
        raise InvalidParameterError("grid", grid, "at least one value of each of forward, side, turn, step_time")
    loaded_robot(robot)  # a bad robot is one error here, not one per worker
    folder = Path(out)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise FileFormatError(str(folder), f"cannot be made: {error.strerror or error}") from None
    started, results = time.perf_counter(), {}

    def record(index: int, clips: list[ClipRecord]) -> None:
        results[index] = clips
        if progress is not None:
            progress(len(results), len(commands))

    in_pool(export_command, {i: (robot, c, str(folder), float(fps), swings) for i, c in enumerate(commands)}, workers,
            record, scheduler)
    clips = [c for i in range(len(commands)) for c in results[i]]
    seconds = time.perf_counter() - started
    manifest = folder / "manifest.json"
    write_manifest(manifest, robot, clips, fps, seconds)
    return ExportResult(folder, manifest, clips, seconds)


def write_manifest(path: Path, robot: str, clips: Sequence[ClipRecord], fps: float, seconds: float) -> None:
    """The manifest: the robot, its pattern generator, the frame rate, the joint names, every clip's record (JSON;
    nan as null)."""
    from zmpwalk.robots import loaded_robot
    from zmpwalk.sim.disturbances import NOSLIP_ITERATIONS
    from zmpwalk.sim.plant import build_plant

    def finite(value: object) -> object:
        if isinstance(value, float):
            return value if math.isfinite(value) else None
        if isinstance(value, dict):
            return {k: finite(v) for k, v in value.items()}
        if isinstance(value, (list, tuple)):
            return [finite(v) for v in value]
        return value

    model = loaded_robot(robot)
    document = {"robot": robot, "generator": model.default_generator, "fps": fps,
                "joint_names": joint_names(build_plant(model).model), "quaternion_order": "wxyz", "seconds": seconds,
                "noslip_iterations": NOSLIP_ITERATIONS,
                "clips": [finite(asdict(c)) for c in clips],
                "verified": sum(c.verified for c in clips), "count": len(clips)}
    write_text(path, json.dumps(document, indent=1, allow_nan=False) + "\n")
