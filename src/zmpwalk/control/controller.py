"""One object for a robot's control loop: the walker, the stabilizer and the feedforward behind ``update()``.

.. code-block:: python

    controller = WalkingController(load_robot("hubo"), rate=1000)
    controller.command(StepCommand(duration=0.8, forward=0.2))   # or controller.set_velocity(0.2, 0.0, 0.0)
    while running:
        targets = controller.update(plant.measure())             # one walker tick, one stabilizer tick
        plant.apply(targets)                                     # angles [rad], rates [rad/s], tau_ff [N m]
        plant.step()

Per tick :meth:`WalkingController.update` runs one :meth:`~zmpwalk.online.OnlineWalker.tick`, one
:meth:`~zmpwalk.balance.Stabilizer.update` on the measurement and, where one is given, the :class:`Feedforward`'s
torques of the tick's sample, then the walker's bounded share of a command's check in what is left of the walker's
budget (:func:`~zmpwalk.online.work_budget`) after the tick's own work: no planning beyond that, whatever the
timing of commands.

**Velocity commands** (:meth:`WalkingController.set_velocity`), as joysticks and learned policies give them, become
one :class:`~zmpwalk.commands.StepCommand` by :func:`velocity_command`'s rule, given to the walker for every step
while the velocity holds; nothing is clipped: a step the robot cannot take is the walker's rejection
(:attr:`WalkingController.rejection`), and the walk then stops after the step under way.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement, Stabilizer
from zmpwalk.capture import CapturePlan, CaptureSettings
from zmpwalk.commands import StepCommand
from zmpwalk.control.capture import CaptureMotion, CapturePolicy
from zmpwalk.control.plant import JointTargets
from zmpwalk.errors import InvalidParameterError, ZmpwalkError
from zmpwalk.online import OnlineWalker
from zmpwalk.robots.model import RobotModel
from zmpwalk.sample import WalkingSample
from zmpwalk.schedule import Schedule
from zmpwalk.sides import SUPPORT_OF_LABEL
from zmpwalk.stabilizer_gains import StabilizerGains

Array = NDArray[np.float64]

VELOCITY_FIELDS = {"forward": "vx", "side": "vy", "turn": "wz"}  # a step's stride field -> its velocity
SUPPORT_CODES = {label: int(code) for label, code in SUPPORT_OF_LABEL.items()}  # plain ints: the compiled
# stabilizer types an IntEnum member in Python (10 us a tick), a plain int in C


class Feedforward(Protocol):
    """The joint torques [N m] (12,) the planned motion of one sample needs (inverse dynamics of a model).

    :class:`zmpwalk.sim.loop.ModelFeedforward` computes them from a MuJoCo model, tick by tick.
    """

    def torques(self, sample: WalkingSample) -> Array:
        """Torques [N m], (12,), in the walker's joint-column order, for ``sample`` (given once per tick, in order)."""
        ...


def velocity_step_time(schedule: Schedule, robot: RobotModel, vx: float, vy: float, wz: float) -> float:
    """The step time [s] a walking velocity is walked at: the longest of the schedule's tabulated step times (scaled
    to ``robot``) whose tables hold the velocity's steps, else the shortest.

    A step of time ``T`` takes the stride ``|vx| T``, a side step ``2 |vy| T`` and a turn ``2 |wz| T`` (side and
    turn steps take two swings, :mod:`zmpwalk.commands`); each must be at most the table's longest entry at that
    step time (the side table's, the turn table's where the schedule has one; strides scaled by the robot's stride
    and lateral factors, step times by its time factor). The longest such step time is the slowest cadence whose
    steps the tables were tuned for; a velocity beyond every table takes the shortest step time, and its steps
    are checked by the walker like any other.

    Args:
        schedule: The walker's schedule.
        robot: The robot (its :attr:`~zmpwalk.robots.model.RobotModel.schedule_scale`).
        vx, vy, wz: Forward [m/s], leftward [m/s] and counter-clockwise [rad/s] velocity.
    """
    time_scale, stride_scale, lateral_scale = robot.schedule_scale
    scales = {"forward": stride_scale, "side": lateral_scale, "turn": 1.0}
    longest: dict[tuple[str, float], float] = {}
    for mode, duration, value in schedule.conditions():
        key = (mode, duration)
        longest[key] = max(longest.get(key, 0.0), abs(value) * scales[mode])
    has_turn_table = any(mode == "turn" for mode, _ in longest)
    times = sorted({duration for mode, duration in longest if mode == "forward"}, reverse=True)
    for duration in times:
        step_time = duration * time_scale
        needs = {"forward": abs(vx) * step_time, "side": 2.0 * abs(vy) * step_time, "turn": 2.0 * abs(wz) * step_time}
        if all(need == 0.0 or (mode == "turn" and not has_turn_table)
               or need <= longest.get((mode, duration), 0.0) + 1e-12 for mode, need in needs.items()):
            return step_time
    return times[-1] * time_scale


def velocity_command(schedule: Schedule, robot: RobotModel, vx: float, vy: float, wz: float,
                     step_time: float | None = None) -> StepCommand:
    """The step that walks a velocity: ``forward = vx T``, ``side = 2 vy T``, ``turn = 2 wz T`` at the step time
    ``T`` of :func:`velocity_step_time` (or ``step_time``), nothing clipped.

    Raises:
        InvalidParameterError: A velocity that is not a finite number, or whose step no robot could take (a stride
            over :data:`~zmpwalk.commands.MAX_STRIDE`, a turn over :data:`~zmpwalk.commands.MAX_TURN` per swing),
            naming the velocity, its value and the step time; or a step time outside
            [:data:`~zmpwalk.commands.MIN_DURATION`, :data:`~zmpwalk.commands.MAX_DURATION`].
    """
    velocity = {"vx": vx, "vy": vy, "wz": wz}
    for name, value in velocity.items():
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
            raise InvalidParameterError(name, value, "a finite number (m/s for vx and vy, rad/s for wz)")
    vx, vy, wz = float(vx), float(vy), float(wz)
    if step_time is None:
        step_time = velocity_step_time(schedule, robot, vx, vy, wz)
    try:
        return StepCommand(duration=step_time, forward=vx * step_time, side=2.0 * vy * step_time,
                           turn=2.0 * wz * step_time)
    except InvalidParameterError as error:
        if error.parameter not in VELOCITY_FIELDS:
            raise InvalidParameterError("step_time", step_time, error.allowed) from None
        name = VELOCITY_FIELDS[error.parameter]
        factor = "" if name == "vx" else "2 "
        raise InvalidParameterError(
            name, velocity[name], f"a velocity whose step at the step time {step_time:g} s ({error.parameter} = "
            f"{factor}{name} T = {error.value:g}) is {error.allowed}") from None


class WalkingController:
    """The walker (with joints), the stabilizer and an optional feedforward behind one :meth:`update` per tick.

    Args:
        robot: The robot.
        rate: Control rate [Hz] (the walker's and the stabilizer's).
        schedule: The walker's parameter tables (default: HUBO's, :meth:`Schedule.hubo`).
        generator: ``"polynomial"`` or ``"hyperbolic"``; None: the robot's own (:class:`~zmpwalk.online.OnlineWalker`).
        pelvis: ``"cubic"`` or ``"quintic"`` (polynomial generator).
        balance: Run the stabilizer (False: the pattern's angles, open loop).
        gains: The stabilizer's gains (default: the robot file's, :class:`~zmpwalk.balance.Stabilizer`).
        feedforward: Torques of the planned motion per tick (:class:`Feedforward`), sent as
            :attr:`JointTargets.torques`; None: no torques (the targets' ``torques`` is None).
        capture: Take capture steps (:mod:`zmpwalk.control.capture`: when the stabilizer's DCM error passes the
            trigger in a single support, the rest of the walk becomes one capture step and a stop; the walker
            then stands where it left the feet); None: none.
        clock: The walker's budget clock (:class:`~zmpwalk.online.OnlineWalker`): None, the machine's; the
            simulator gives one that counts parts (:func:`zmpwalk.sim.loop.simulated_clock`).
        budget: The time [s] a tick may spend on a command's check, the tick's own work (stabilizer, feedforward)
            included (:class:`~zmpwalk.online.OnlineWalker`'s ``budget``; None: :func:`~zmpwalk.online.work_budget`,
            50 us at 1 kHz). An imported robot's checks at 1 kHz fall a step behind commands given half a step
            ahead at 50 us on a 2-core machine; 100 us catches up most of that delay (docs/speed.md).

    Raises:
        InvalidParameterError: As :class:`~zmpwalk.online.OnlineWalker` and :class:`~zmpwalk.balance.Stabilizer`
            (a rate outside [10, 10000] Hz, an unknown generator or pelvis, a budget not within the control
            period), or ``capture`` without the
            stabilizer (its DCM estimate triggers a capture).

    Attributes:
        walker: The :class:`~zmpwalk.online.OnlineWalker` (read its state; command through the controller).
        stabilizer: The :class:`~zmpwalk.balance.Stabilizer`, or None with ``balance=False``.
        fault: The last error that kept the stabilizer from correcting a tick (a measurement it could not use), or
            None; that tick's targets are the pattern's (``corrected`` False) and the stabilizer starts again.
        faults: How many ticks it kept it from correcting.
    """

    def __init__(self, robot: RobotModel, rate: float = 1000.0, *, schedule: Schedule | None = None,
                 generator: str | None = None, pelvis: str = "cubic", balance: bool = True,
                 gains: StabilizerGains | None = None, feedforward: Feedforward | None = None,
                 capture: CaptureSettings | None = None, clock: Callable[[], float] | None = None,
                 budget: float | None = None) -> None:
        if capture is not None and not isinstance(capture, CaptureSettings):
            raise InvalidParameterError("capture", capture, "a CaptureSettings, or None")
        if capture is not None and not balance:
            raise InvalidParameterError("capture", capture, "None without the stabilizer (balance=False): its DCM "
                                        "estimate triggers the capture step")
        self.robot = robot
        self.schedule = schedule or Schedule.hubo()
        self.walker = OnlineWalker(robot, rate, self.schedule, joints=True, pelvis=pelvis, generator=generator,
                                   clock=clock, budget=budget)
        self.rate = self.walker.rate
        self.stabilizer = Stabilizer(robot, rate, gains) if balance else None
        self.feedforward = feedforward
        self.fault: ZmpwalkError | None = None
        self.faults = 0
        self._velocity: tuple[float, float, float] | None = None
        self._velocity_step: StepCommand | None = None
        self._velocity_refused = False
        self._sample: WalkingSample | None = None
        self._capture = None if capture is None else CapturePolicy(robot, self.rate, capture)
        self._motion: CaptureMotion | None = None
        self._deferred: StepCommand | None = None  # a command given during a capture
        self._stranded = False  # the last capture left the feet where the walker cannot stand
        self._ticks = 0

    @property
    def walking(self) -> bool:
        """True while a walk or a capture step is under way or a walk is queued (or waits for a capture's end)."""
        if self._motion is not None and not self._motion.ended(self._ticks):
            return True
        return self.walker.walking or self._deferred is not None

    @property
    def stranded(self) -> bool:
        """True when the last capture step left the feet where the walker's standing pose cannot reach (a wide
        sideways capture): the controller holds the capture's rest pose and gives no command to the walker."""
        return self._stranded

    @property
    def capture(self) -> CapturePolicy | None:
        """The capture policy (its lead and pacing: :class:`~zmpwalk.control.capture.CapturePolicy`), or None
        without ``capture``."""
        return self._capture

    @property
    def captures(self) -> list[CapturePlan]:
        """The capture steps taken, in order (empty without ``capture``)."""
        return [] if self._capture is None else self._capture.captures

    @property
    def time(self) -> float:
        """Time of the next tick [s]."""
        return self.walker.time

    @property
    def sample(self) -> WalkingSample | None:
        """The last tick's sample of the pattern (None before the first :meth:`update`)."""
        return self._sample

    @property
    def velocity(self) -> tuple[float, float, float] | None:
        """The walking velocity being walked (vx [m/s], vy [m/s], wz [rad/s]), or None (step commands)."""
        return self._velocity

    @property
    def velocity_step(self) -> StepCommand | None:
        """The step the velocity is walked with (:func:`velocity_command`), or None."""
        return self._velocity_step

    @property
    def rejection(self) -> ZmpwalkError | None:
        """Why the last command (or the velocity's step) was refused, naming the parameter, its value and what
        fits (:attr:`OnlineWalker.rejection`: the first read searches the largest stride that fits, tens of
        milliseconds; read it outside the hard part of the loop, e.g. once :attr:`rejected` is not None)."""
        return self.walker.rejection

    @property
    def rejected(self) -> StepCommand | None:
        """The last command, where it was refused (free to read every tick)."""
        return self.walker.rejected

    def command(self, step: StepCommand) -> None:
        """Give the step that follows the one under way (:meth:`OnlineWalker.command`: stored in microseconds,
        checked a little per :meth:`update`; a refusal is :attr:`rejection`; during a capture step, given to the
        walker when the capture is over). Leaves velocity mode.

        Raises:
            InvalidParameterError: ``step`` is not a :class:`~zmpwalk.commands.StepCommand`, or the last capture
                step left the feet where the walker cannot stand (:attr:`stranded`).
        """
        if self._motion is not None:
            if not isinstance(step, StepCommand):
                raise InvalidParameterError("command", type(step).__name__, "a StepCommand")
            if self._stranded:
                raise InvalidParameterError("command", step, "none: the last capture step left the feet where the "
                                            "walker's standing pose cannot reach (controller.stranded)")
            self._deferred = step  # given to the walker once the capture is over
        else:
            self.walker.command(step)
        self._leave_velocity()

    def stop(self) -> None:
        """Stop after the step under way (:meth:`OnlineWalker.stop`; a capture step ends standing anyway, and a
        command given during it is dropped); leaves velocity mode."""
        self._deferred = None
        self.walker.stop()
        self._leave_velocity()

    def set_velocity(self, vx: float, vy: float, wz: float, *, step_time: float | None = None) -> None:
        """Walk at a velocity: forward ``vx`` [m/s], leftward ``vy`` [m/s], counter-clockwise ``wz`` [rad/s].

        Every step takes :func:`velocity_command`'s step (its step time from the schedule unless ``step_time``
        [s] is given). Only stored here (tens of microseconds); :meth:`update` gives it to the walker (module
        docstring): as soon as the walker holds no step, and in place of a step it holds for after the one under
        way once that step's check is done (a step held for a walk from standstill is kept: replacing it would
        start the walk :data:`~zmpwalk.online.START_DELAY` later again). So a new velocity takes effect at the next
        step whose check completes before it begins. The same velocity again changes nothing (a joystick may send
        it every tick; a velocity that changes every tick re-checks the next step continually: quantise it). All
        three 0 stops after the step under way (:meth:`stop`). A step the walker refuses is :attr:`rejection`; it
        is not given again (the walk stops after the step under way) until another velocity is set.

        Raises:
            InvalidParameterError: As :func:`velocity_command` (the walk goes on as it was).
        """
        if all(isinstance(v, numbers.Real) and not isinstance(v, bool) and v == 0 for v in (vx, vy, wz)):
            self.stop()
            return
        step = velocity_command(self.schedule, self.robot, vx, vy, wz, step_time)
        if step == self._velocity_step:
            return
        self._velocity = (float(vx), float(vy), float(wz))
        self._velocity_step = step
        self._velocity_refused = False

    def _leave_velocity(self) -> None:
        self._velocity = None
        self._velocity_step = None
        self._velocity_refused = False

    def _give_velocity_step(self) -> None:
        """Give the velocity's step to the walker where it is due (:meth:`set_velocity`); bounded: it only
        compares commands and stores one."""
        step = self._velocity_step
        walker = self.walker
        if step is None or self._velocity_refused or walker.checking is not None or self._motion is not None:
            return
        if walker.rejected == step:
            self._velocity_refused = True
            return
        queued = walker.queued
        if queued is None or (queued != step and walker.current is not None):
            walker.command(step)

    def update(self, measurement: BalanceMeasurement) -> JointTargets:
        """One control tick: the walker's sample, corrected by the stabilizer on ``measurement``, and the
        feedforward's torques.

        Never raises once the measurement is one: a measurement the stabilizer cannot use (wrong sizes, values that
        make its targets non-finite) gives the pattern's own angles for this tick (``corrected`` False), keeps the
        error in :attr:`fault` and restarts the stabilizer.

        Raises:
            InvalidParameterError: ``measurement`` is not a :class:`~zmpwalk.balance.BalanceMeasurement`.
        """
        if not isinstance(measurement, BalanceMeasurement):
            raise InvalidParameterError("measurement", type(measurement).__name__, "a BalanceMeasurement")
        begin = self.walker.now()
        walker, tick, previous = self.walker, self._ticks, self._sample
        sample = walker.tick(work=False)  # ticked during a capture too: its clock runs on, standing
        if self._capture is not None and self._capture.planning and self.stabilizer is not None:
            self._take_over(tick)
        if self._motion is not None:
            sample = self._motion.sample(tick, None if self._stranded else sample)
        self._sample = sample
        self._ticks = tick + 1
        angles = sample.joint_angles
        velocities = sample.joint_velocities
        if angles is None or velocities is None:  # pragma: no cover - the walker is made with joints
            raise InvalidParameterError("walker.joints", False, "True")
        corrected = self._corrected(sample, angles, measurement)
        if self._capture is not None and corrected is not None and previous is not None:
            self._capture_step(tick, sample, previous, measurement)  # no call per tick without a capture policy
        if self._motion is not None and not self._stranded and self._motion.done(tick):
            self._motion = None
            if self._deferred is not None:
                walker.command(self._deferred)
                self._deferred = None
        torques = None if self.feedforward is None else self.feedforward.torques(sample)
        if walker.checking is not None:  # the check's parts, in the budget the tick has left
            walker.work(walker.now() - begin)
        self._give_velocity_step()
        return JointTargets(sample.time, angles if corrected is None else corrected, velocities, torques, sample,
                            corrected is not None)

    def _capture_step(self, tick: int, sample: WalkingSample, previous: WalkingSample,
                      measurement: BalanceMeasurement) -> None:
        """Begin planning a capture step where one is due, and run this tick's parts of the plan under way
        (:mod:`zmpwalk.control.capture`)."""
        policy, stabilizer = self._capture, self.stabilizer
        if policy is None or stabilizer is None:
            return
        policy.observe(stabilizer.state.dcm_error)
        if policy.due(tick, sample, stabilizer, measurement):
            policy.start(tick, sample, previous, stabilizer, self._motion, self._ahead)
        if policy.planning:
            policy.work(tick, sample, measurement, stabilizer)

    def _ahead(self, ahead: int) -> WalkingSample | None:
        """The sample played ``ahead + 1`` ticks after the last one, where known now (the capture's pattern under
        way, else the walker's step under way)."""
        if self._motion is not None:
            return self._motion.planned(self._ticks + ahead)
        return self.walker.peek(ahead)

    def _take_over(self, tick: int) -> None:
        """Let the capture step planned for ``tick`` take over (its plan complete), the walker standing where it
        leaves the feet; a step given before the push or during the capture is walked after it."""
        policy, stabilizer = self._capture, self.stabilizer
        if policy is None or stabilizer is None:
            return
        motion = policy.take_over(tick, stabilizer)
        if motion is None:
            return
        walker = self.walker
        waiting = walker.checking or walker.queued  # a step given before the push: walked after the capture
        if self._deferred is None and waiting is not None and not waiting.stop:
            self._deferred = waiting
        self._motion = motion
        try:
            walker.stand_at(motion.stance())
            self._stranded = False
        except ZmpwalkError:  # the walker's standing pose cannot reach these feet: the capture's last pose is held
            self._stranded = True
            self._deferred = None

    def _corrected(self, sample: WalkingSample, angles: Array, measurement: BalanceMeasurement) -> Array | None:
        """The stabilizer's targets (a copy), or None without a stabilizer or on a fault."""
        stabilizer = self.stabilizer
        if stabilizer is None:
            return None
        try:
            targets = stabilizer.update(
                support=SUPPORT_CODES[sample.support], position_com_in_world=sample.position_pelvis_in_world,
                yaw_pelvis_in_world=sample.yaw_pelvis_in_world, zmp_in_world=sample.zmp_in_world,
                ankles_in_world=(sample.position_left_ankle_in_world, sample.position_right_ankle_in_world),
                foot_yaws=(sample.yaw_left_foot_in_world, sample.yaw_right_foot_in_world), joint_angles=angles,
                measurement=measurement)
        except ZmpwalkError as error:
            self._fault(error)
            return None
        if not math.isfinite(sum(targets.tolist())):  # a sum of Python floats: no numpy reduction per tick
            self._fault(InvalidParameterError("measurement", "values that make the stabilizer's targets non-finite",
                                              "finite wrenches, attitude, rates and encoders"))
            return None
        return targets.copy()

    def _fault(self, error: ZmpwalkError) -> None:
        self.fault = error
        self.faults += 1
        if self.stabilizer is not None:
            self.stabilizer.reset()
        if self._capture is not None:
            self._capture.forget()
