"""One walk, start to verdict: :class:`WalkSpec` in, :func:`run_walk`, :class:`WalkOutcome` out.

The batch walk of ``zmpwalk simulate``, ``report``, ``demo``, ``sweep`` and ``tune``: the walking pattern
(the robot's own generator unless another is named) at the spec's rate, optionally corrected until its multibody
ZMP (Eq. 3) follows the planned ZMP, the 12 joint angles along it (inverse kinematics), the stabilizer where
``balance`` is on (tracking the pattern's own CoM point, :attr:`WalkingPattern.com_point`, the one the
simulation accepts), the MuJoCo walk
standing ``settle`` before and ``hold`` after, the verdict of :func:`zmpwalk.sim.verdict.walk_verdict`, and the
motor table (with each joint's motor from a motor file where one is given).

Importing this module loads neither MuJoCo nor numba; :func:`run_walk` does.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError, SimulationError, UnreachableError, ZmpwalkError
from zmpwalk.patterns import GENERATORS
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.sim.ranges import RANGES, check_range
from zmpwalk.sim.verdict import HOLD, SETTLE

if TYPE_CHECKING:
    from zmpwalk.capture import CaptureSettings
    from zmpwalk.correction import ZmpCorrection
    from zmpwalk.kinematics import JointTrajectory
    from zmpwalk.patterns.result import WalkingPattern
    from zmpwalk.sim.actuators import ActuatorRow
    from zmpwalk.sim.disturbances import Disturbances, SensorNoise
    from zmpwalk.sim.motors import Motor, MotorFit
    from zmpwalk.sim.result import SimulationResult
    from zmpwalk.sim.verdict import Verdict

Progress = Callable[[str, int, int], None]
STAGES = ("pattern", "joints", "simulation", "measures")
PELVIS_CURVES = ("cubic", "quintic")


@dataclass(frozen=True)
class WalkSpec:
    """Everything that chooses a walk.

    Attributes:
        robot: The robot.
        commands: The step commands, in order.
        labels: How errors name each command (a steps file's lines, a scenario's steps); None: by number.
        generator: The pattern generator's name (:data:`zmpwalk.patterns.GENERATORS`); None: the robot's own
            (:attr:`RobotModel.default_generator`).
        schedule: The parameter tables (the polynomial pattern's, and every generator's footstep timing); None:
            the generator's default.
        pelvis: The polynomial generator's pelvis curves, ``"cubic"`` (the paper's) or ``"quintic"``.
        paper_steps: Walk the example of Lim et al. instead of ``commands``: the start, this many steady steps and
            the stop, hyperbolic (:func:`zmpwalk.patterns.hyperbolic.paper_walk`; ``generator``, ``schedule`` and
            ``pelvis`` do not apply); None: ``commands``.
        rate: Sampling rate of the pattern and of the stabilizer [Hz].
        zmp_correction: Move the pelvis until the multibody ZMP follows the planned ZMP
            (:func:`zmpwalk.correction.correct_pattern`; box models with link masses).
        check_limits: Raise :class:`~zmpwalk.kinematics.JointLimitError` where a planned joint angle leaves its
            range (as ``report`` and ``demo`` do); False: the verdict judges the joints instead.
        balance: Close the loop with the stabilizer; False: the pattern alone (open loop).
        latency: Delay of every measurement the stabilizer gets [s] (0 to 0.1).
        noise: Gaussian noise on those measurements; None: none.
        feedforward: The servo feedforwards (gravity, ground reaction, damping); None: the simulation's default
            (on for a robot's own model and with the stabilizer).
        mass_scale: Every mass and inertia of the model (and the servo gains with them) times this [-] (0.01 to
            100; box models).
        disturbances: A push, a floor tilt or a mass error of the plant; None: none.
        capture: Capture steps after a push (needs the stabilizer, and a pattern not ZMP-corrected); None: none.
        motors: Each joint's motor (a motor file's, :func:`zmpwalk.sim.motors.load_motors`); None: none.
        settle: Standing before the walk [s] (0 to 10).
        hold: Standing after the walk [s] (0 to 60), over which the verdict judges how it ends.
        source: How an error of the pattern names the walk (a steps file, ``scenario NAME``); empty: unnamed.
    """

    robot: RobotModel
    commands: Sequence[StepCommand] = ()
    labels: Sequence[str] | None = None
    generator: str | None = None
    schedule: Schedule | None = None
    pelvis: str = "cubic"
    paper_steps: int | None = None  # steady steps of the paper's example [-]
    rate: float = 1000.0  # [Hz]
    zmp_correction: bool = False
    check_limits: bool = False
    balance: bool = True
    latency: float = 0.0  # [s]
    noise: SensorNoise | None = None
    feedforward: bool | None = None
    mass_scale: float = 1.0  # [-]
    disturbances: Disturbances | None = None
    capture: CaptureSettings | None = None
    motors: Sequence[Motor] | None = None
    settle: float = SETTLE  # [s]
    hold: float = HOLD  # [s]
    source: str = ""

    def __post_init__(self) -> None:
        object.__setattr__(self, "commands", tuple(self.commands))
        if self.labels is not None:
            object.__setattr__(self, "labels", tuple(self.labels))
        if self.motors is not None:
            object.__setattr__(self, "motors", tuple(self.motors))
        self._check()

    def _check(self) -> None:
        """Raise :class:`InvalidParameterError`, naming the field, for a spec no walk can follow."""
        if self.generator is not None and self.generator not in GENERATORS:
            raise InvalidParameterError("generator", self.generator, f"one of {', '.join(GENERATORS)}, or None")
        if self.pelvis not in PELVIS_CURVES:
            raise InvalidParameterError("pelvis", self.pelvis, "cubic or quintic")
        if self.pelvis != "cubic" and self.generator_name != "polynomial":
            raise InvalidParameterError("pelvis", self.pelvis, f"cubic with the {self.generator_name} generator "
                                        "(quintic pelvis curves are the polynomial generator's)")
        if self.paper_steps is not None:
            if self.commands:
                raise InvalidParameterError("paper_steps", self.paper_steps, "None with step commands given")
            if isinstance(self.paper_steps, bool) or not isinstance(self.paper_steps, int) or self.paper_steps < 0:
                raise InvalidParameterError("paper_steps", self.paper_steps, "an integer >= 0, or None")
        elif not self.commands:
            raise InvalidParameterError("commands", (), "at least one step command (or paper_steps)")
        if self.capture is not None and not self.balance:
            raise InvalidParameterError("capture", self.capture, "None without the stabilizer (balance=False): "
                                        "its DCM estimate triggers the capture step")
        if self.capture is not None and self.zmp_correction:
            raise InvalidParameterError("capture", self.capture, "None with zmp_correction: capture steps plan "
                                        "the pattern's CoM point")
        for name in RANGES:  # the ranges of the simulation itself
            check_range(name, getattr(self, name))

    @property
    def generator_name(self) -> str:
        """The generator that walks: ``generator``, or the robot's own."""
        return self.generator if self.generator is not None else self.robot.default_generator


@dataclass(frozen=True)
class PlannedWalk:
    """The walk as planned, before any simulation.

    Attributes:
        pattern: The pattern walked (the corrected one with ``zmp_correction``).
        correction: The ZMP correction and its errors before and after; None without it.
        joints: The joint angles along ``pattern``.
    """

    pattern: WalkingPattern
    correction: ZmpCorrection | None
    joints: JointTrajectory


@dataclass(frozen=True)
class WalkOutcome:
    """What :func:`run_walk` made.

    Attributes:
        spec: The walk asked for.
        pattern: The pattern walked (the corrected one with ``zmp_correction``).
        correction: The ZMP correction; None without it.
        joints: The joint angles along ``pattern``.
        result: The MuJoCo walk's measurements.
        verdict: Its verdict (every criterion with its figure).
        rows: The motor table, one row per joint (:func:`zmpwalk.sim.actuators.actuator_table`).
        fits: Each joint against its motor; empty without ``spec.motors``.
        controller: What ran in the loop, in words (:func:`zmpwalk.sim.verdict.controller_words`).
        seconds: Wall time of each stage of :data:`STAGES` [s].
    """

    spec: WalkSpec
    pattern: WalkingPattern
    correction: ZmpCorrection | None
    joints: JointTrajectory
    result: SimulationResult
    verdict: Verdict
    rows: list[ActuatorRow]
    fits: list[MotorFit]
    controller: str
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def warnings(self) -> tuple[str, ...]:
        """What the verdict warns of (a motor that does not fit, a joint near its limit, ...)."""
        return tuple(self.verdict.warnings)

    @property
    def wall_time(self) -> float:
        """Wall time of the whole walk [s]."""
        return sum(self.seconds.values())


def walk_pattern(spec: WalkSpec) -> tuple[WalkingPattern, ZmpCorrection | None]:
    """The pattern of ``spec`` and its ZMP correction (None without ``spec.zmp_correction``).

    Raises:
        ZmpwalkError: The walk cannot be planned (prefixed with ``spec.source`` where it names one).
    """
    if spec.paper_steps is not None:
        from zmpwalk.patterns.hyperbolic import paper_walk

        pattern = paper_walk(spec.robot, steps=spec.paper_steps).sample(spec.rate)
    else:
        from zmpwalk.patterns import generator

        options: dict[str, object] = {} if spec.schedule is None else {"schedule": spec.schedule}
        if spec.pelvis != "cubic":
            options["pelvis"] = spec.pelvis
        try:
            pattern = generator(spec.generator_name)(spec.robot, list(spec.commands), rate=spec.rate,
                                                     labels=None if spec.labels is None else list(spec.labels),
                                                     **options)
        except ZmpwalkError as error:
            raise (error.in_context(spec.source) if spec.source else error) from None
    if not spec.zmp_correction:
        return pattern, None
    from zmpwalk.correction import correct_pattern

    correction = correct_pattern(pattern)
    return correction.pattern, correction


def planned_walk(spec: WalkSpec) -> PlannedWalk:
    """The pattern of ``spec``, corrected where asked, and the joint angles along it.

    Raises:
        ZmpwalkError: The walk cannot be planned, a leg cannot reach, or (``check_limits``) a joint leaves its range.
    """
    pattern, correction = walk_pattern(spec)
    return PlannedWalk(pattern, correction, _joints(spec, pattern))


def checked_walk(spec: WalkSpec) -> PlannedWalk:
    """:func:`planned_walk` as :func:`run_walk` plans: where the legs cannot reach along the pattern of a walk the
    controller runs, the error is the walker's refusal of the command (:func:`_named_joints`).

    Raises:
        ZmpwalkError: As :func:`planned_walk`.
    """
    pattern, correction = walk_pattern(spec)
    return PlannedWalk(pattern, correction, _named_joints(spec, pattern))


def _joints(spec: WalkSpec, pattern: WalkingPattern) -> JointTrajectory:
    """The joint angles along ``pattern`` (their ranges checked with ``spec.check_limits``)."""
    from zmpwalk.kinematics import pattern_joint_trajectory

    return pattern_joint_trajectory(pattern, check_limits=spec.check_limits)


def _named_joints(spec: WalkSpec, pattern: WalkingPattern) -> JointTrajectory:
    """:func:`_joints`; where the legs cannot reach along the pattern of a walk the controller runs, the error is
    the walker's own check of the commands, which names the command and the stride that fits (the pattern's leg
    check knows a sample's time only): the controller walks the commands until its first refusal, an error path of
    seconds.

    Raises:
        ZmpwalkError: The walker's refusal of the first command it cannot walk; else the pattern's own error.
    """
    try:
        return _joints(spec, pattern)
    except UnreachableError as error:
        if not through_controller(spec):
            raise
        try:
            _controller_walk(spec, None)  # raises the first refusal, in spec.source's words
        except SimulationError:
            raise error from None
        raise


def run_walk(spec: WalkSpec, progress: Progress | None = None, planned: PlannedWalk | None = None) -> WalkOutcome:
    """Plan ``spec``'s walk, walk it in MuJoCo and judge it.

    Args:
        spec: The walk.
        progress: Called as each stage of :data:`STAGES` starts, ``progress(stage, index, len(STAGES))``, and
            while the simulation runs, ``progress("simulation", percent, 100)``.
        planned: The walk already planned from this very spec (:func:`planned_walk`, its rate and generator); None:
            planned here.

    Returns:
        The pattern, the joints, the measurements, the verdict, the motor table and the wall time of each stage.

    Raises:
        ZmpwalkError: As :func:`planned_walk`, or a simulation setting out of range.
    """
    from zmpwalk.balance import Stabilizer
    from zmpwalk.sim.actuators import actuator_table
    from zmpwalk.sim.motors import motor_fits
    from zmpwalk.sim.run import simulate
    from zmpwalk.sim.verdict import controller_words, walk_verdict

    seconds: dict[str, float] = {}
    clock = time.perf_counter()

    def stage(name: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        if name != STAGES[0]:
            seconds[STAGES[STAGES.index(name) - 1]] = now - clock
        clock = now
        if progress is not None:
            progress(name, STAGES.index(name) + (name == "measures"), len(STAGES))

    stage("pattern")
    if planned is None:
        pattern, correction = walk_pattern(spec)
        stage("joints")
        planned = PlannedWalk(pattern, correction, _named_joints(spec, pattern))
    else:
        stage("joints")
    stage("simulation")
    pattern = planned.pattern
    report = None if progress is None else (lambda done: progress("simulation", round(100 * done), 100))
    if through_controller(spec):
        result = _controller_walk(spec, report)
        if result.fell and result.fall_time is not None:  # the run was sized for the longest walk the commands
            # might take; the plan says its length (capture steps may have walked on past it)
            result = replace(result, planned_end=max(float(pattern.time[-1]) + spec.hold, result.fall_time))
        balanced = True
    else:
        stabilizer = Stabilizer(spec.robot, spec.rate, com_reference=pattern.com_point) if spec.balance else None
        result = simulate(spec.robot, planned.joints, pattern, mass_scale=spec.mass_scale, stabilizer=stabilizer,
                          latency=spec.latency, noise=spec.noise, feedforward=spec.feedforward, settle=spec.settle,
                          hold=spec.hold, disturbances=spec.disturbances, capture=spec.capture, progress=report)
        balanced = stabilizer is not None
    motors = None if spec.motors is None else list(spec.motors)
    verdict = walk_verdict(result, spec.hold, motors)
    stage("measures")
    rows = actuator_table(result)
    fits = motor_fits(result, motors) if motors else []
    seconds["measures"] = time.perf_counter() - clock
    return WalkOutcome(spec, pattern, planned.correction, planned.joints, result, verdict, rows, fits,
                       controller_words(balanced, through_controller(spec)), seconds)


def through_controller(spec: WalkSpec) -> bool:
    """Whether :func:`run_walk` simulates ``spec`` through the :class:`~zmpwalk.control.WalkingController` (the
    code a robot's loop runs, commands given mid-walk): every walk with the stabilizer on a generator the walker
    runs online (capture steps included, :mod:`zmpwalk.control.capture`), but those the batch closed loop
    (:mod:`zmpwalk.sim.closed_loop`) keeps: the paper's example (``paper_steps``), a ZMP-corrected pattern, the
    preview generator and no feedforward."""
    from zmpwalk.online_check import ONLINE_GENERATORS

    return (spec.balance and spec.paper_steps is None and not spec.zmp_correction
            and spec.feedforward is not False and spec.generator_name in ONLINE_GENERATORS)


def _controller_walk(spec: WalkSpec, progress: Callable[[float], None] | None) -> SimulationResult:
    """``spec``'s walk through the walking controller in MuJoCo at 1 kHz (:func:`zmpwalk.sim.loop.simulate_controller`),
    its time 0 where the walk begins, as the pattern's.

    Raises:
        ZmpwalkError: The walker refused a command (the first refusal, in ``spec.source``'s words).
    """
    from zmpwalk.control import WalkingController
    from zmpwalk.sim.loop import simulate_controller, simulated_clock, walk_start
    from zmpwalk.sim.mujoco_plant import MujocoPlant
    from zmpwalk.sim.references import CONTROL_RATE

    plant = MujocoPlant(spec.robot, CONTROL_RATE, mass_scale=spec.mass_scale, disturbances=spec.disturbances,
                        latency=spec.latency, noise=spec.noise,
                        time_origin=walk_start(spec.settle, CONTROL_RATE))  # a push at the walk's time
    controller = WalkingController(spec.robot, CONTROL_RATE, schedule=spec.schedule,
                                   generator=spec.generator_name, pelvis=spec.pelvis, feedforward=plant.feedforward(),
                                   capture=spec.capture, clock=simulated_clock(CONTROL_RATE))
    run = simulate_controller(spec.robot, spec.commands, controller=controller, plant=plant, hold=spec.hold,
                              settle=spec.settle, progress=progress)
    refusal = run.refusal(spec.labels, spec.source)
    if refusal is not None:
        raise refusal
    return run.result
