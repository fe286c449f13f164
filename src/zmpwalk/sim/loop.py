"""The simulator runs what a robot runs: a :class:`~zmpwalk.control.WalkingController` on the MuJoCo plant.

:func:`simulate_controller` steps :class:`~zmpwalk.sim.mujoco_plant.MujocoPlant` (the model of
:func:`zmpwalk.sim.plant.build_plant`, its sensors read as the robot's) and calls
``controller.update(plant.measure())`` every control period, giving a list of step commands as an operator gives
them: the first at the first tick (the walk starts :data:`~zmpwalk.online.START_DELAY` later, as a robot's does),
each next one during the step before it, once that step has begun, ``command_phase`` of its step time into it. The
result is the :class:`~zmpwalk.sim.result.SimulationResult` of :func:`zmpwalk.sim.run.simulate`, so
:func:`zmpwalk.sim.verdict.walk_verdict` judges it.

The feedforward runs per tick (:class:`~zmpwalk.sim.mujoco_plant.ModelFeedforward`): the inverse dynamics of the
tick's planned pose with the planned ground reaction, as :func:`zmpwalk.sim.plant.static_feedforward` computes it
for a whole pattern; the planned joint rates go to the servos as their rate reference (the servo damping's
feedforward). Where the batch path differences the planned poses centrally (it sees the future), the per-tick path
differences backwards over one tick (0.5-1 ms late); a robot's other servos (arms, torso) hold their pose with the
static torque of the ready posture (the batch path gives them the walk's inverse dynamics). Sensor latency and
noise are the plant's (:class:`~zmpwalk.sim.mujoco_plant.MujocoPlant`); capture steps the controller's
(:mod:`zmpwalk.control.capture`): after one, the operator gives no more commands (the walk ends with the capture's
stop, as the batch walk's does).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.capture import CaptureSettings
from zmpwalk.commands import StepCommand
from zmpwalk.control import JointTargets, WalkingController
from zmpwalk.errors import InvalidParameterError, ZmpwalkError
from zmpwalk.footsteps import sole_corners
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.online import START_DELAY, OnlineWalker, work_budget
from zmpwalk.robots.model import RobotModel
from zmpwalk.sides import SUPPORT_OF_LABEL
from zmpwalk.sim.disturbances import Disturbances, SensorNoise
from zmpwalk.sim.measure import AFTER_FALL
from zmpwalk.sim.mujoco_plant import MujocoPlant
from zmpwalk.sim.ranges import check_range
from zmpwalk.sim.result import SimulationResult
from zmpwalk.sim.soles import SoleMeasurements, foot_slip, rpy_from_quaternion, sole_measurements
from zmpwalk.sim.verdict import HOLD
from zmpwalk.slices import CountingClock
from zmpwalk.stabilizer.layout import LOG_SIZE, L
from zmpwalk.zmp import batch_hull_margin, edge_margin

Array = NDArray[np.float64]


@dataclass
class ControllerRun:
    """A walk simulated through a :class:`~zmpwalk.control.WalkingController`.

    Attributes:
        result: The measurements (:func:`zmpwalk.sim.verdict.walk_verdict` judges them).
        given: When each command was given [s], in order, on the result's clock.
        rejections: The commands refused: their index in the list, the command and the rejection.
        faults: Ticks the stabilizer could not correct (:attr:`WalkingController.faults`).
        controller: The controller, as the run left it.
    """

    result: SimulationResult
    given: list[float]  # [s]
    rejections: list[tuple[int, StepCommand, ZmpwalkError]]
    faults: int
    controller: WalkingController

    def refusal(self, labels: Sequence[str] | None = None, source: str = "") -> ZmpwalkError | None:
        """The first refusal, prefixed with its command's label (``labels[i]``, else ``step i+1``) and ``source``
        (a steps file); None where the controller took every command."""
        if not self.rejections:
            return None
        index, _, error = self.rejections[0]
        label = labels[index] if labels is not None and index < len(labels) else f"step {index + 1}"
        return error.in_context(f"{source}: {label}" if source else label)


class _Operator:
    """Gives a list of commands as an operator does: the first at once, each next one ``phase`` of the step
    time into the step before it, once that step has begun (or at once after a refusal)."""

    def __init__(self, commands: Sequence[StepCommand], phase: float, rate: float, first: int = 0) -> None:
        self.pending = list(commands)
        self.phase, self.rate = phase, rate
        self.index = -1
        self.waiting: StepCommand | None = None  # given, not yet begun or refused
        self.due = first  # tick at which the next one is given
        self.given: list[float] = []
        self.rejections: list[tuple[int, StepCommand, ZmpwalkError]] = []

    @property
    def done(self) -> bool:
        return not self.pending and self.waiting is None

    def __call__(self, controller: WalkingController, tick: int) -> None:
        walker = controller.walker
        if controller.captures:  # a capture step ends the walk, as the batch walk's does
            if self.pending or self.waiting is not None:
                controller.stop()  # drops a step given before the push, which would walk after the capture
                self.pending, self.waiting = [], None
            return
        if self.waiting is not None:
            if walker.checking is not None or walker.queued is not None:
                return
            if walker.rejected is not None:  # refused: the operator gives the next one at once
                self.rejections.append((self.index, self.waiting, controller.rejection or ZmpwalkError()))
                self.due = tick
            else:  # its step has begun
                self.due = tick + round(self.phase * self.waiting.duration * self.rate)
            self.waiting = None
        if self.waiting is None and self.pending and tick >= self.due:
            self.waiting = self.pending.pop(0)
            self.index += 1
            controller.command(self.waiting)
            self.given.append(tick / self.rate)


class _Log:
    """What a run records per tick, preallocated for ``size`` ticks."""

    def __init__(self, size: int, sensors: int, feedforward: bool, balance: bool) -> None:
        self.readings = np.empty((size, sensors))
        self.zmp, self.ankles, self.yaws = np.empty((size, 2)), np.empty((size, 2, 3)), np.empty((size, 2))
        self.support, self.walking = np.empty(size, dtype=np.intp), np.empty(size, dtype=bool)
        self.torques = np.empty((size, 12)) if feedforward else None
        self.stabilizer = np.empty((size, LOG_SIZE)) if balance else None  # the stabilizer's log, a row a tick

    def record(self, k: int, plant: MujocoPlant, controller: WalkingController, targets: JointTargets) -> None:
        sample = targets.sample
        self.readings[k] = plant.sensordata
        self.zmp[k] = sample.zmp_in_world
        self.ankles[k, 0] = sample.position_left_ankle_in_world
        self.ankles[k, 1] = sample.position_right_ankle_in_world
        self.yaws[k, 0], self.yaws[k, 1] = sample.yaw_left_foot_in_world, sample.yaw_right_foot_in_world
        self.support[k] = SUPPORT_OF_LABEL[sample.support]
        self.walking[k] = controller.walking
        if self.torques is not None and targets.torques is not None:
            self.torques[k] = targets.torques
        if self.stabilizer is not None and controller.stabilizer is not None:
            self.stabilizer[k] = controller.stabilizer.log

    def balance(self, n: int) -> dict[str, Array] | None:
        """The stabilizer's state over the first ``n`` ticks, by name (:class:`~zmpwalk.balance.BalanceState`'s)."""
        if self.stabilizer is None:
            return None
        rows = self.stabilizer[:n]
        return {"zmp_desired": rows[:, L.zmp_desired:L.zmp_desired + 2].copy(),
                "com_offset": rows[:, L.com_offset:L.com_offset + 2].copy(),
                "ankle_offsets": rows[:, L.ankle_offsets:L.ankle_offsets + 4].copy(),
                "height_difference": rows[:, L.height_difference].copy(),
                "pelvis_turn": rows[:, L.pelvis_turn:L.pelvis_turn + 2].copy()}


SIMULATED_PART = 0.19  # [-] of the walker's budget that each part of a check costs in a simulation (not a divisor of
# the budget, so that run_for's comparisons of a part's cost against what is left are never exact ties)


def simulated_clock(rate: float) -> CountingClock:
    """The walker's budget clock in a simulated loop at ``rate`` [Hz]: each reading advances
    :data:`SIMULATED_PART` of the budget (:func:`~zmpwalk.online.work_budget`), so a tick runs the parts of a
    command's check that fit the budget at that cost (three to four; this machine's parts take 5-20 us of 50), the
    same on every machine and under any load: a simulated walk, its commands' checks included, does not depend on
    how busy the machine running it is."""
    return CountingClock(SIMULATED_PART * work_budget(rate))


def walk_start(settle: float, rate: float) -> float:
    """When a walk given ``settle`` [s] begins [s] after the robot is stood (:func:`simulate_controller`): its
    first command ``settle - START_DELAY`` after (at once where that is negative), the walk START_DELAY later."""
    return max(0, round((settle - START_DELAY) * rate)) / rate + START_DELAY


def _check_run(commands: Sequence[StepCommand], command_phase: float, duration: float | None, hold: float,
               settle: float | None, operated: bool) -> None:
    """Raise :class:`InvalidParameterError` for a run :func:`simulate_controller` cannot make (its Raises)."""
    if not 0.0 <= command_phase < 1.0:
        raise InvalidParameterError("command_phase", command_phase, "a fraction of the step time in [0, 1)")
    if duration is None and (operated or not commands):
        raise InvalidParameterError("duration", duration, "a run length [s] where an operator gives the commands "
                                    "or none are given")
    if duration is not None and not 0.0 < duration <= 3600.0:
        raise InvalidParameterError("duration", duration, "a run length in (0, 3600] s")
    check_range("hold", hold)
    if settle is not None:
        check_range("settle", settle)


def _longest(commands: Sequence[StepCommand], settle: float | None, start: float, hold: float) -> float:
    """The longest a run of ``commands`` may take [s] from the stand: its start, three times each step, the hold
    and 5 s (a refused command walks a step later; the stop takes up to three step times)."""
    begins = start if settle is not None else START_DELAY  # [s] after the stand
    steps = sum(3.0 * c.duration for c in commands) + 3.0 * max((c.duration for c in commands), default=0.0)
    return begins + steps + hold + 5.0


def simulate_controller(robot: RobotModel, commands: Sequence[StepCommand] = (), *, rate: float = 1000.0,
                        controller: WalkingController | None = None, plant: MujocoPlant | None = None,
                        command_phase: float = 0.5, duration: float | None = None, hold: float = HOLD,
                        operator: Callable[[WalkingController, int], None] | None = None, balance: bool = True,
                        feedforward: bool = True, mass_scale: float = 1.0, disturbances: Disturbances | None = None,
                        latency: float = 0.0, noise: SensorNoise | None = None, settle: float | None = None,
                        capture: CaptureSettings | None = None,
                        progress: Callable[[float], None] | None = None) -> ControllerRun:
    """Walk ``commands`` through a walking controller on the MuJoCo plant, tick by tick (module docstring).

    Args:
        robot: The robot.
        commands: The steps, given one by one during the walk (a steps file's, :func:`zmpwalk.scenarios.load_scenario`).
        rate: Control rate [Hz].
        controller: The controller (default: a :class:`~zmpwalk.control.WalkingController` with the stabilizer
            where ``balance``, capture steps with ``capture``, the plant's
            :class:`~zmpwalk.sim.mujoco_plant.ModelFeedforward` where ``feedforward``, and the walker's budget on
            :func:`simulated_clock`).
        plant: The plant (default: a :class:`~zmpwalk.sim.mujoco_plant.MujocoPlant` with ``mass_scale``,
            ``disturbances``, ``latency`` [s] and ``noise``: the controller measures the sensors ``latency`` late,
            with that noise).
        command_phase: Each command after the first is given this fraction of the step time into the step before
            it, in [0, 1).
        duration: Run this long [s]; None: until every command is given and the walker stands still, then ``hold``.
        hold: Standing still after the walk [s] (the verdict judges how the walk ends over it).
        settle: Standing before the walk begins [s]: the first command is given ``settle -``
            :data:`~zmpwalk.online.START_DELAY` after the robot is stood (at once where that is negative: a walk
            begins START_DELAY after its first command), and the result's time is 0 where the walk begins (the
            walking pattern's time; the standing before it at negative times). None: the first command at once,
            the result's time from the stand. A push's time (``disturbances``) is on the result's clock (the
            plant made here counts from the walk's start, ``time_origin``).
        operator: Called every tick before the update with the controller and the tick's index: anything an
            operator does (commands, velocities, stops); needs a ``duration``.
        progress: Called with the fraction done now and then (of the run's longest length).

    Returns:
        The run: its :class:`~zmpwalk.sim.result.SimulationResult`, when each command was given, the refusals.

    Raises:
        InvalidParameterError: No commands and no duration, an operator without a duration, a phase outside
            [0, 1), a hold outside [0, 60] s, a settle outside [0, 10] s, a latency that is not whole control
            periods, a controller whose rate is not the plant's.
    """
    _check_run(commands, command_phase, duration, hold, settle, operator is not None)
    start = 0.0 if settle is None else walk_start(settle, rate)  # [s] the walk begins
    plant = plant or MujocoPlant(robot, rate, mass_scale=mass_scale, disturbances=disturbances, latency=latency,
                                 noise=noise, time_origin=start)
    controller = controller or WalkingController(robot, plant.rate, balance=balance, capture=capture,
                                                 feedforward=plant.feedforward() if feedforward else None,
                                                 clock=simulated_clock(plant.rate))
    if controller.rate != plant.rate:
        raise InvalidParameterError("controller.rate", controller.rate, f"the plant's rate, {plant.rate:g} Hz")
    plant.stand(OnlineWalker(robot, plant.rate, controller.schedule, joints=True).tick())
    size = round((duration if duration is not None else _longest(commands, settle, start, hold)) * plant.rate)
    log = _Log(size, plant.model.nsensordata, controller.feedforward is not None, controller.stabilizer is not None)
    first = 0 if settle is None else round((start - START_DELAY) * plant.rate)
    giver = _Operator(commands, command_phase, plant.rate, first)
    end, fall = size, None
    for k in range(size):
        if progress is not None and k % 1000 == 0:
            progress(k / size)
        giver(controller, k)
        if operator is not None:
            operator(controller, k)
        targets = controller.update(plant.measure())
        plant.apply(targets)
        plant.step()
        log.record(k, plant, controller, targets)
        if fall is None and plant.fallen():
            fall, end = k, min(end, k + round(AFTER_FALL * plant.rate) + 1)
        if duration is None and end == size and giver.done and not controller.walking:
            end = min(size, k + 1 + round(hold * plant.rate))
        if k + 1 >= end:
            break
    result = _result(robot, plant, log, k + 1, fall, size / plant.rate, hold, start)
    result.captures = [dataclasses.replace(plan, time=plan.time - start) for plan in controller.captures]
    return ControllerRun(result, [t - start for t in giver.given], giver.rejections, controller.faults, controller)


def _plan_margin(robot: RobotModel, log: _Log, n: int) -> float:
    """The least margin [m] of the walker's ZMP to the planned support polygon (the stance sole, or the hull of both
    soles in double support) over the run's samples (> 0 inside)."""
    support, ankles, yaws, zmp = log.support[:n], log.ankles[:n], log.yaws[:n], log.zmp[:n]
    corners = np.stack([sole_corners(ankles[:, f, 0], ankles[:, f, 1], yaws[:, f], np.full(n, side), robot)
                        for f, side in ((0, 1.0), (1, -1.0))], axis=1)  # (n, 2, 4, 2), counter-clockwise
    margin = np.empty(n)
    single = support != 0
    if single.any():
        quad = corners[single, support[single] - 1]
        edge = np.roll(quad, -1, axis=1) - quad
        margin[single] = edge_margin(zmp[single], quad, edge, np.ones(edge.shape[:2], dtype=bool))
    if (~single).any():
        margin[~single] = batch_hull_margin(zmp[~single], corners[~single].reshape(-1, 8, 2))
    return float(margin.min())


def _result(robot: RobotModel, plant: MujocoPlant, log: _Log, n: int, fall: int | None, planned_end: float,
            hold: float, start: float = 0.0) -> SimulationResult:
    """The run's :class:`~zmpwalk.sim.result.SimulationResult` from its first ``n`` ticks (row ``k``: the state at the
    end of tick ``k``, labelled with the tick's time ``k / rate - start``, as :func:`~zmpwalk.sim.run.simulate` labels
    it)."""
    sensors, readings = plant.sensors, log.readings[:n]
    time = np.arange(n) / plant.rate - start
    pelvis, rpy = sensors.take(readings, "pelvis_pos"), rpy_from_quaternion(sensors.take(readings, "pelvis_quat"))
    soles = sole_measurements(robot, plant.sensors, readings, plant.weight)
    angles, velocities, torques = (sensors.columns(readings, [f"{c}_{s}" for c in JOINT_COLUMNS])
                                   for s in ("q", "qd", "tau"))
    end = (math.nan,) * 5 if fall is not None else _end_figures(plant, log, n, soles, hold)
    distance = float(np.linalg.norm(pelvis[-1, :2] - pelvis[0, :2]))
    walked = max(float(log.walking[:n].sum()) / plant.rate, 1.0 / plant.rate)
    return SimulationResult(
        robot=robot, time=time, torso_position=pelvis, torso_rpy=rpy, fell=fall is not None,
        fall_time=None if fall is None else float(time[fall]), distance=distance, average_speed=distance / walked,
        foot_slip=foot_slip(soles.loaded, soles.ankles), cop_left=soles.cop_feet[:, 0], cop_right=soles.cop_feet[:, 1],
        cop=soles.cop, force_left=soles.forces[:, 0], force_right=soles.forces[:, 1],
        reference_zmp=log.zmp[:n].copy(), cop_margin=soles.margin,
        joint_angles=angles, joint_velocities=velocities, joint_torques=torques, joint_power=torques * velocities,
        balance=log.balance(n),
        ankle_positions=np.stack([sensors.take(readings, f"{s}_ankle_pos") for s in ("left", "right")], axis=1),
        planned_torques=None if log.torques is None else log.torques[:n].copy(),
        plan_zmp_margin=_plan_margin(robot, log, n),
        planned_end=planned_end - start if fall is not None else float(time[-1]),
        final_feet_error=end[0], final_feet_yaw_error=end[1], end_min_sole_force=end[2], end_max_speed=end[3],
        end_attitude_range=end[4])


def _end_figures(plant: MujocoPlant, log: _Log, n: int, soles: SoleMeasurements,
                 hold: float) -> tuple[float, float, float, float, float]:
    """How the walk ends: the feet against the walker's final plan (largest distance [m] and yaw error [rad]), and
    over the last ``hold``: the least sole force [N], the base's largest speed [m/s] and the torso's attitude spread
    [rad]."""
    sensors, readings = plant.sensors, log.readings[:n]
    time = np.arange(n) / plant.rate
    feet = soles.ankles[-1]
    feet_error = max(float(np.linalg.norm(feet[f] - log.ankles[n - 1, f, :2])) for f in range(2))
    yaws = [rpy_from_quaternion(sensors.take(readings[-1:], f"{label}_ankle_quat"))[0, 2]
            for label in ("left", "right")]
    yaw_error = max(abs(float((yaws[f] - log.yaws[n - 1, f] + math.pi) % (2 * math.pi) - math.pi)) for f in range(2))
    window = time > time[-1] - max(hold, 1.0 / plant.rate)
    pelvis, rpy = sensors.take(readings, "pelvis_pos"), rpy_from_quaternion(sensors.take(readings, "pelvis_quat"))
    speed = np.linalg.norm(np.gradient(pelvis[:, :2], time, axis=0), axis=1)
    return (feet_error, yaw_error, float(soles.forces[window].min()), float(speed[window].max()),
            float(np.ptp(rpy[window, :2], axis=0).max()))
