"""Capture steps in the walking controller: a pushed walk becomes one capture step and a stop, tick by tick.

:class:`CapturePolicy` is what :class:`~zmpwalk.control.WalkingController` asks after each stabilizer tick: in a
single support, at least :data:`~zmpwalk.capture.CAPTURE_INTERVAL` after the last trigger and the last take-over,
with the stabilizer's DCM error beyond :attr:`CaptureSettings.trigger`, it plans the rest of the walk as one capture
step and a stop (:func:`zmpwalk.capture.capture_step`, Eqs. of the capture point: the swinging foot lands where the
measured DCM can come to rest).

**Bounded work per tick.** The plan does not run inside the triggering tick: it takes over
:attr:`CaptureSettings.lead` later (40 ticks at 1 kHz), from the state the walk plays then, and its parts
(:func:`~zmpwalk.capture.capture_step_parts` and the joints', each at most about 0.2 ms on HUBO; an imported
robot's legs :data:`~zmpwalk.whole_body.IK_CHUNK` samples a part, about 25 us) run over the ticks in between,
the parts left (those of the last plan and of one more landing tried, :data:`PULL_PARTS`) spread evenly over the
ticks left (a count, not a clock: the same walk
plans the same way on any machine). That state is known at the trigger: the walker's step under way holds its samples
(:meth:`~zmpwalk.online.OnlineWalker.peek`), a capture under way its pattern; the DCM there is the plan's plus
the stabilizer's error predicted over the lead from its own rate (:meth:`CapturePolicy.predicted_dcm_error`: the
pendulum with the ZMP offset held that moves it now, a push still acting included). The swinging ankle starts
where the stabilizer's landing correction aims it at the trigger; what that correction moves during the lead
stays the stabilizer's (:meth:`~zmpwalk.balance.Stabilizer.hand_over_landing`), so the foot's target does not
jump at the take-over. A plan whose single support ends first (the
foot lands), or that is not complete when its tick comes (more landings tried than it was paced for), is
dropped and the walk goes on; a later trigger plans again.

The :class:`CaptureMotion` (that pattern and its joint angles) then replaces the walker's samples; a later
trigger in the capture's own single support re-plans from it, landing no later than the capture under way needs.
The walker stands where the capture leaves the feet from then on (:meth:`~zmpwalk.online.OnlineWalker.stand_at`);
the capture's last pose blends into the walker's standing one over :data:`BLEND` (the capture's pattern has not
quite come to rest); a step given before the push or during the capture is given to the walker after it and walks
on from there. Where the walker's standing pose cannot reach those feet, the controller holds the capture's last
pose (:attr:`WalkingController.stranded`).

The batch walk (:class:`zmpwalk.sim.replan.CaptureReplanner`) plans inside the triggering tick, as a lead of 0
does here, and as a slow loop does (125 Hz and below, :attr:`CapturePolicy.lead`), whose period holds the whole
plan.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement, Stabilizer
from zmpwalk.capture import CAPTURE_INTERVAL, CapturePlan, CaptureSettings, capture_step_parts, capture_wanted
from zmpwalk.errors import ZmpwalkError
from zmpwalk.footsteps import Pose2D, Stance
from zmpwalk.kinematics import JointTrajectory, pattern_joint_trajectory_in_parts
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.sample import WalkingSample
from zmpwalk.sides import SUPPORT_LABELS
from zmpwalk.slices import Parts
from zmpwalk.whole_body import leg_parts

Array = NDArray[np.float64]

BLEND = 0.5  # [s] after a capture's pattern, its rest pose blends into the walker's standing pose over this
REST = 2.0  # [s] a capture pattern lasts at least this long (the batch walk's: to the end of its run)


def _mix(a: Array | None, b: Array | None, share: float) -> Array:
    """``(1 - share) a + share b``."""
    return np.asarray((1.0 - share) * np.asarray(a) + share * np.asarray(b), dtype=np.float64)

@dataclass(frozen=True)
class CaptureMotion:
    """A capture step's pattern and joint angles, played one sample per tick from ``first`` on.

    Attributes:
        plan: The capture's figures.
        pattern: The rest of the walk: the capture step and the stop.
        joints: Its joint angles and rates.
        first: The controller tick of its first sample.
        rate: Control rate [Hz].
    """

    plan: CapturePlan
    pattern: WalkingPattern
    joints: JointTrajectory
    first: int
    rate: float  # [Hz]

    def sample(self, tick: int, standing: WalkingSample | None) -> WalkingSample:
        """The sample of controller tick ``tick``: the pattern's; after its end, a linear blend over
        :data:`BLEND` from its last sample to the walker's ``standing`` one (its pose at rest over the same feet:
        the capture's pelvis point, :data:`REST` after the plan, is still 0.2 mm from its rest on HUBO, and the
        legs' angles differ by as much), or its last sample held where there is none (the walker cannot stand
        there)."""
        i = tick - self.first
        if i < len(self.pattern.time) or standing is None:
            return self._row(min(max(i, 0), len(self.pattern.time) - 1))
        share = min((i - len(self.pattern.time) + 1) / (BLEND * self.rate), 1.0)
        last = self._row(len(self.pattern.time) - 1)
        return WalkingSample(
            time=standing.time, support="double",
            position_pelvis_in_world=_mix(last.position_pelvis_in_world, standing.position_pelvis_in_world, share),
            yaw_pelvis_in_world=standing.yaw_pelvis_in_world,
            position_left_ankle_in_world=standing.position_left_ankle_in_world,
            yaw_left_foot_in_world=standing.yaw_left_foot_in_world,
            position_right_ankle_in_world=standing.position_right_ankle_in_world,
            yaw_right_foot_in_world=standing.yaw_right_foot_in_world,
            zmp_in_world=_mix(last.zmp_in_world, standing.zmp_in_world, share),
            joint_angles=_mix(last.joint_angles, standing.joint_angles, share),
            joint_velocities=(standing.joint_angles - last.joint_angles) / BLEND if share < 1.0  # type: ignore[operator]
            else np.zeros(12))

    def planned(self, tick: int) -> WalkingSample | None:
        """The pattern's sample of controller tick ``tick``, where the pattern holds it (None after its end)."""
        i = tick - self.first
        return self._row(i) if 0 <= i < len(self.pattern.time) else None

    def ended(self, tick: int) -> bool:
        """Whether the pattern has ended by controller tick ``tick`` (the robot at rest on both feet)."""
        return tick - self.first >= len(self.pattern.time) - 1

    def done(self, tick: int) -> bool:
        """Whether the pattern and the blend after it have ended by controller tick ``tick``."""
        return tick - self.first >= len(self.pattern.time) - 1 + BLEND * self.rate

    def _row(self, i: int) -> WalkingSample:
        """The pattern's sample ``i``."""
        p = self.pattern
        return WalkingSample(
            time=float(p.time[i]), support=SUPPORT_LABELS[int(p.support[i])],
            position_pelvis_in_world=p.position_pelvis_in_world[i].copy(),
            yaw_pelvis_in_world=float(p.yaw_pelvis_in_world[i]),
            position_left_ankle_in_world=p.position_left_ankle_in_world[i].copy(),
            yaw_left_foot_in_world=float(p.yaw_left_foot_in_world[i]),
            position_right_ankle_in_world=p.position_right_ankle_in_world[i].copy(),
            yaw_right_foot_in_world=float(p.yaw_right_foot_in_world[i]),
            zmp_in_world=p.zmp_in_world[i].copy(),
            joint_angles=self.joints.angles[i].copy(), joint_velocities=self.joints.velocities[i].copy())

    def stance(self) -> Stance:
        """Where the capture leaves the feet."""
        p = self.pattern
        left, right = p.position_left_ankle_in_world[-1], p.position_right_ankle_in_world[-1]
        return Stance(Pose2D(float(left[0]), float(left[1]), float(p.yaw_left_foot_in_world[-1])),
                      Pose2D(float(right[0]), float(right[1]), float(p.yaw_right_foot_in_world[-1])), 0)


@dataclass
class _Planning:
    """A capture step being planned: its parts, the tick it takes over at, the single support it was planned in."""

    parts: Parts[tuple[WalkingPattern, CapturePlan, JointTrajectory]]
    first: int  # [ticks]
    support: str
    expected: int  # parts it is paced for
    aim: Array  # [m] (2,) the swinging foot's landing correction the plan starts from
    done: int = 0  # parts run
    result: tuple[WalkingPattern, CapturePlan, JointTrajectory] | None = None


class CapturePolicy:
    """When and how the controller takes a capture step (module docstring).

    Args:
        robot: The robot.
        rate: Control rate [Hz].
        settings: The trigger, the lead and the capture step's limits.

    Attributes:
        captures: The capture steps taken, in order.
        lead: Ticks from the trigger to the take-over: ``settings.lead`` in whole ticks, at least one; one (the plan
            within the triggering tick) where the control period holds the whole plan twice over at
            :data:`NOMINAL_PART` a part (125 Hz and below: at 100 Hz a 40 ms lead, 4 ticks of 14 parts, took
            1.0-2.4 ms a tick against 1.3 ms in one, and lost two pushes of three that the plan in one tick
            survived).
        parts_per_tick: The most parts of a plan one tick has run so far.
    """

    def __init__(self, robot: RobotModel, rate: float, settings: CaptureSettings) -> None:
        self.robot, self.rate, self.settings = robot, float(rate), settings
        self.captures: list[CapturePlan] = []
        in_one_tick = IN_TICK_SHARE / self.rate >= EXPECTED_PARTS * NOMINAL_PART  # a slow loop's period holds it
        self.lead = 1 if in_one_tick else max(1, round(settings.lead * self.rate))
        self.parts_per_tick = 0
        self._last = -math.inf  # [ticks] of the last trigger or take-over
        self._planning: _Planning | None = None
        self._expected = EXPECTED_PARTS + leg_parts(robot, math.ceil(REST * self.rate) + 1)  # an imported robot's legs
        self._errors = np.zeros((max(1, round(ERROR_RATE_WINDOW * self.rate)) + 1, 2))  # [m] the last DCM errors
        self._observed = 0
        self._omega = math.sqrt(robot.gravity / robot.pendulum_length)  # [1/s] the pendulum's

    @property
    def planning(self) -> bool:
        """True while a capture step is being planned."""
        return self._planning is not None

    def due(self, tick: int, sample: WalkingSample, stabilizer: Stabilizer, measurement: BalanceMeasurement) -> bool:
        """Whether a capture step is planned from ``tick`` (``sample``'s, after the stabilizer's update on
        ``measurement``): none being planned, :func:`~zmpwalk.capture.capture_wanted` in a single support."""
        if self._planning is not None or sample.support == "double" or tick - self._last < CAPTURE_INTERVAL * self.rate:
            return False
        return capture_wanted(stabilizer.state.dcm_error, self.settings.trigger, _swing_force(sample, measurement),
                              stabilizer.load_threshold)

    def start(self, tick: int, sample: WalkingSample, previous: WalkingSample, stabilizer: Stabilizer,
              under_way: CaptureMotion | None, ahead: Callable[[int], WalkingSample | None]) -> bool:
        """Begin planning the capture step that takes over at tick ``tick + lead``, from the state the walk plays
        then: its planned samples at the two ticks before (``ahead(i)``: the sample played ``i + 1`` ticks after
        ``tick``, None where not known yet; ``sample`` and ``previous``, ticks ``tick`` and ``tick - 1``, where the
        lead is shorter), and the stabilizer's DCM error grown over the lead (:meth:`predicted_dcm_error`);
        ``under_way``: the capture being played, if any. False where the single support ends within the lead (no
        plan: the step lands first)."""
        self._last = tick  # tried again only after the interval, as a plan that fails
        lead = self.lead
        last = sample if lead == 1 else ahead(lead - 2)  # tick first - 1
        second = previous if lead == 1 else sample if lead == 2 else ahead(lead - 3)  # tick first - 2
        if last is None or second is None or last.support != sample.support:
            return False
        dt = 1.0 / self.rate
        stance, swing = sample.support, "right" if sample.support == "left" else "left"
        position = last.position_pelvis_in_world
        velocity = (position - second.position_pelvis_in_world) / dt
        ankles = [last.position_left_ankle_in_world, last.position_right_ankle_in_world]
        rates = [(a - b) / dt for a, b in zip(ankles, (second.position_left_ankle_in_world,
                                                        second.position_right_ankle_in_world), strict=True)]
        ankles = [a + r * dt for a, r in zip(ankles, rates, strict=True)]  # at the capture's first tick
        aim = stabilizer.landing_correction(swing)
        ankles[0 if swing == "left" else 1][:2] += aim
        position_next = position + velocity * dt
        error = self.predicted_dcm_error(lead)
        dcm = position_next[:2] + velocity[:2] / stabilizer.omega + error
        touchdown = None if under_way is None else under_way.plan.time + under_way.plan.swing_time
        begin = last.time + dt
        parts = capture_step_parts(
            self.robot, time=begin, rate=self.rate, end=begin + REST, stance=stance,
            position_com_in_world=position_next, dcm_in_world=dcm, yaw_pelvis_in_world=last.yaw_pelvis_in_world,
            ankles_in_world=(ankles[0], ankles[1]), ankle_velocities_in_world=(rates[0], rates[1]),
            foot_yaws=(last.yaw_left_foot_in_world, last.yaw_right_foot_in_world), settings=self.settings,
            touchdown=touchdown)
        self._planning = _Planning(_with_joints(parts), tick + lead, stance, self._expected + PULL_PARTS, aim)
        return True

    def observe(self, dcm_error: Array) -> None:
        """Keep this tick's DCM error of the stabilizer [m], (2,) (called every tick: its rate over the last
        :data:`ERROR_RATE_WINDOW` predicts it over the lead)."""
        self._errors[self._observed % len(self._errors)] = dcm_error
        self._observed += 1

    def forget(self) -> None:
        """Forget the DCM errors kept (the stabilizer restarted: its error starts again from zero)."""
        self._observed = 0

    def predicted_dcm_error(self, ticks: int) -> Array:
        r"""The stabilizer's DCM error ``ticks`` control periods after the last observed one [m], (2,).

        The pendulum's DCM obeys :math:`\dot\xi = \omega(\xi - p)` for the plan and for the robot, so the error
        obeys :math:`\dot e = \omega (e - \Delta p)`, ``Delta p`` the ZMP's offset from the plan's that acts on
        the body: the stabilizer's clamped correction as far as the sole achieves it, and a push still acting. It is
        taken from the error's own rate over the last :data:`ERROR_RATE_WINDOW` (:math:`\Delta p = e - \dot e /
        \omega`) and held, which gives :math:`e(t) = e + (\dot e / \omega)(e^{\omega t} - 1)`. (A push 36 N s
        backward on HUBO: the error grew from 80.4 to 111.8 mm over 20 ms, this predicts 110.7 mm; the stabilizer's
        desired ZMP alone, ``Delta p = p_d - p_ref``, predicted 78.9 mm.)"""
        size = len(self._errors)
        span = min(self._observed - 1, size - 1)
        error = self._errors[(self._observed - 1) % size]
        if span <= 0 or ticks <= 0:
            return np.array(error, dtype=np.float64)
        rate = (error - self._errors[(self._observed - 1 - span) % size]) * self.rate / span  # [m/s]
        omega = self._omega
        return np.asarray(error + rate / omega * math.expm1(omega * ticks / self.rate), dtype=np.float64)

    def work(self, tick: int, sample: WalkingSample, measurement: BalanceMeasurement,
             stabilizer: Stabilizer) -> None:
        """Run this tick's share of the plan's parts: the parts left over the ticks left before its take-over, at
        least one (a count, not a time: the same walk plans the same way on any machine). The plan is dropped where
        the single support it was planned in has ended or its swinging sole is loaded (the step has landed), or where
        it fails (no capture step fits: the walk goes on as planned). With a lead of one tick, the whole plan in this
        tick."""
        job = self._planning
        if job is None or job.result is not None:
            return
        if sample.support != job.support or _swing_force(sample, measurement) > stabilizer.load_threshold:
            self._planning = None
            return
        ticks_left = max(job.first - tick, 1)
        quota = max(-(-(max(job.expected - job.done, 1)) // ticks_left), 1) if self.lead > 1 else 1 << 30
        ran = 0
        try:
            while ran < quota:
                ran += 1
                next(job.parts)
        except StopIteration as finished:
            job.result = finished.value
            self._expected = job.done + ran
        except ZmpwalkError:
            self._planning = None
        job.done += ran
        self.parts_per_tick = max(self.parts_per_tick, ran)

    def take_over(self, tick: int, stabilizer: Stabilizer) -> CaptureMotion | None:
        """The capture step that takes over at ``tick``, where its plan is complete (one not complete by then is
        dropped: a later trigger plans again from the state then); its swing starts where the stabilizer's landing
        correction aimed it, which it hands over."""
        job = self._planning
        if job is None or tick < job.first:
            return None
        self._planning = None
        if job.result is None:  # more landings tried than paced for: the next plan gets the parts this one ran
            self._expected = max(self._expected, job.done)
            return None
        self._last = tick  # the next capture at least CAPTURE_INTERVAL after this one takes over
        pattern, plan, joints = job.result
        stabilizer.hand_over_landing(plan.swing, job.aim)  # the correction's moves since the trigger stay its own
        self.captures.append(plan)
        return CaptureMotion(plan, pattern, joints, tick, self.rate)


ERROR_RATE_WINDOW = 0.005  # [s] the DCM error's rate is taken over this (whole ticks, at least one)
PULL_PARTS = 16  # a plan is paced for this many parts more than the last one took: one more landing tried
NOMINAL_PART = 1e-4  # [s] a part's cost, nominal (HUBO: 10-130 us alone, up to about 0.35 ms inside the loop)
IN_TICK_SHARE = 0.5  # [-] a whole plan taking this share of the control period or less, nominally, is made in one tick
EXPECTED_PARTS = 40  # the parts a capture plan is paced for before the first one has been counted


def _swing_force(sample: WalkingSample, measurement: BalanceMeasurement) -> float:
    """The measured normal force [N] on the swinging sole of ``sample``'s single support."""
    swing = measurement.wrench_right if sample.support == "left" else measurement.wrench_left
    return float(swing[2])


def _with_joints(parts: Parts[tuple[WalkingPattern, CapturePlan]]) -> Parts[tuple[WalkingPattern, CapturePlan,
                                                                                   JointTrajectory]]:
    """A capture step's parts, then its joint angles' (:func:`~zmpwalk.kinematics.pattern_joint_trajectory_in_parts`,
    no range check: a capture is taken within reach whatever the joints' soft ranges). Every sample's legs are
    solved before the capture takes over: a sample they cannot reach drops the plan (an imported robot's base is not
    the pattern's point, so the plan's own reach check, hip to ankle from that point, does not settle it: TALOS
    pushed 68 N s sideways re-planned a capture whose left ankle its IK left 32 mm short for 0.5 s)."""
    pattern, plan = yield from parts
    yield
    joints = yield from pattern_joint_trajectory_in_parts(pattern, check_limits=False)
    return pattern, plan, joints
