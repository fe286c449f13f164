"""The batch walk stepped tick by tick: the stabilizer in the loop, pushes applied, capture steps taken.

:func:`closed_loop` steps the MuJoCo model one control period at a time. With a
:class:`~zmpwalk.balance.Stabilizer` it gets the sensor values only, as on the robot: each tick's measurement is
read from the sensor row of ``latency`` earlier (:class:`~zmpwalk.sim.disturbances.SensorNoise` added where
given), and its joint angles plus the feedforward's share of the leg controls go to the servos. Without one the
controls are played as planned, with a push applied where :class:`~zmpwalk.sim.disturbances.Disturbances` has one.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement, BalanceState, Stabilizer
from zmpwalk.capture import CAPTURE_INTERVAL, capture_wanted
from zmpwalk.errors import InfeasiblePatternError, UnreachableError
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.sides import Support
from zmpwalk.sim.disturbances import Disturbances, SensorNoise, _MeasurementReader
from zmpwalk.sim.integrator import diverged, divergence_counters
from zmpwalk.sim.plant import Plant
from zmpwalk.sim.references import CONTROL_RATE, tracked_references
from zmpwalk.sim.soles import SensorSlices

Array = NDArray[np.float64]
Tail = Callable[[int, Stabilizer, int], dict[str, NDArray[np.generic]]]

@dataclass
class _Tracks:
    """The references the loop plays, one row per tick; a capture step replaces them from a tick on.

    Attributes:
        tracked: What the stabilizer tracks (:func:`~zmpwalk.sim.references.tracked_references`).
        zmp: The reference ZMP [m], (n, 2).
        reference: The leg joint references [rad], (n, 12).
        control: The controls, (n, nu).
        offsets: The feedforward's share of the leg controls, (n, 12).
    """

    tracked: dict[str, NDArray[np.generic]]
    zmp: Array
    reference: Array
    control: Array
    offsets: Array

    def replace_after(self, k: int, tail: dict[str, NDArray[np.generic]], leg_actuators: NDArray[np.intp]) -> None:
        """Every reference from tick ``k + 1`` on by ``tail``'s (the same keys, and ``zmp``, ``reference``,
        ``control``)."""
        for key, values in self.tracked.items():
            values[k + 1:] = tail[key]
        self.zmp[k + 1:], self.reference[k + 1:], self.control[k + 1:] = tail["zmp"], tail["reference"], tail["control"]
        self.offsets[k + 1:] = self.control[k + 1:, leg_actuators] - self.reference[k + 1:]

    def update(self, stabilizer: Stabilizer, k: int, measurement: BalanceMeasurement) -> Array:
        """The stabilizer's joint angles at tick ``k`` for ``measurement``."""
        tracked = self.tracked
        return stabilizer.update(
            support=int(tracked["support"][k]), position_com_in_world=tracked["com"][k],
            yaw_pelvis_in_world=float(tracked["yaw"][k]), zmp_in_world=self.zmp[k],
            ankles_in_world=(tracked["left"][k], tracked["right"][k]),
            foot_yaws=(float(tracked["left_yaw"][k]), float(tracked["right_yaw"][k])),
            joint_angles=self.reference[k], measurement=measurement)


def closed_loop(model: mujoco.MjModel, data: mujoco.MjData, plant: Plant, stabilizer: Stabilizer | None,
                pattern: WalkingPattern, pattern_time: Array, reference: Array, control: Array, zmp_ref: Array,
                steps_per_tick: int, sensors: SensorSlices, latency: float, noise: SensorNoise | None,
                progress: Callable[[float], None] | None = None, disturbances: Disturbances | None = None,
                time: Array | None = None, capture: tuple[float, Tail] | None = None,
                ) -> tuple[Array, dict[str, Array]]:
    """Step the model tick by tick (the stabilizer in the loop where given, pushes applied); sensor rows
    (n, nsensordata) and the stabilizer's log. With ``capture = (trigger, tail)``: whenever the stabilizer's DCM
    error passes ``trigger`` [m] in a single support while the swinging sole is unloaded
    (:func:`~zmpwalk.capture.capture_wanted`; at most every :data:`CAPTURE_INTERVAL`), ``tail`` re-makes
    the references from the next tick on (what the stabilizer tracks, the ZMP, the joint references and the
    controls; ``reference``, ``control`` and ``zmp_ref`` are changed in place)."""
    n = len(pattern_time)
    time = pattern_time if time is None else time
    tracks = _Tracks(tracked_references(pattern, pattern_time), zmp_ref, reference, control,
                     control[:, plant.leg_actuators] - reference)
    readings = np.empty((n, model.nsensordata))
    delay = round(latency * CONTROL_RATE)
    rng = np.random.default_rng(noise.seed) if noise else None
    log = {"zmp_desired": np.empty((n, 2)), "com_offset": np.empty((n, 2)), "ankle_offsets": np.empty((n, 4)),
           "height_difference": np.empty(n), "pelvis_turn": np.empty((n, 2))}
    mujoco.mj_forward(model, data)
    current = data.sensordata.copy()
    reader = _MeasurementReader(sensors, None if disturbances is None else disturbances.floor_rotation)
    push_body = int(model.site_bodyid[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "pelvis")])
    if stabilizer is None:
        _played(model, data, control, steps_per_tick, readings, time, progress, disturbances, push_body)
        return readings, log
    stabilizer.reset()
    last_capture = -n
    counters = divergence_counters(data)
    for k in range(n):
        if progress is not None and k % 500 == 0:
            progress(k / n)
        if disturbances is not None:
            data.xfrc_applied[push_body, :3] = disturbances.force_at(float(time[k]))
        measurement = reader.read(current if k - 1 - delay < 0 else readings[k - 1 - delay])
        if rng is not None and noise is not None:
            noise.add_to(measurement, rng)
        angles = tracks.update(stabilizer, k, measurement)
        data.ctrl[:] = tracks.control[k]
        data.ctrl[plant.leg_actuators] = angles + tracks.offsets[k]
        for _ in range(steps_per_tick):
            mujoco.mj_step(model, data)
        readings[k] = data.sensordata
        _raise_diverged(model, counters, float(time[k]))
        state = stabilizer.state
        _record(log, k, state)
        if capture is not None and _capture_due(tracks.tracked["support"], k, last_capture, state, capture[0],
                                                measurement, stabilizer.load_threshold):
            last_capture = k
            try:
                tail = capture[1](k, stabilizer, int(tracks.tracked["support"][k]))
            except (UnreachableError, InfeasiblePatternError):
                pass  # no capture step fits: the plan goes on as it was
            else:
                tracks.replace_after(k, tail, plant.leg_actuators)
        if not np.all(np.isfinite(data.qpos)):
            readings[k + 1:] = readings[k]
            break
    return readings, log


def _played(model: mujoco.MjModel, data: mujoco.MjData, control: Array, steps_per_tick: int, readings: Array,
            time: Array, progress: Callable[[float], None] | None, disturbances: Disturbances | None,
            push_body: int) -> None:
    """Play ``control`` tick by tick with no stabilizer (the push of ``disturbances`` applied), filling
    ``readings``; after the state turns non-finite every later row repeats the last one."""
    n = len(readings)
    counters = divergence_counters(data)
    for k in range(n):
        if progress is not None and k % 500 == 0:
            progress(k / n)
        if disturbances is not None:
            data.xfrc_applied[push_body, :3] = disturbances.force_at(float(time[k]))
        data.ctrl[:] = control[k]
        for _ in range(steps_per_tick):
            mujoco.mj_step(model, data)
        readings[k] = data.sensordata
        _raise_diverged(model, counters, float(time[k]))
        if not np.all(np.isfinite(data.qpos)):
            readings[k + 1:] = readings[k]
            break


def _raise_diverged(model: mujoco.MjModel, counters: tuple[object, ...], time: float) -> None:
    """Raise :class:`~zmpwalk.errors.SimulationError` where MuJoCo found the state diverged (and reset it)."""
    error = diverged(model, counters, time)
    if error is not None:
        raise error


def _record(log: dict[str, Array], k: int, state: BalanceState) -> None:
    """The stabilizer's ``state`` into row ``k`` of ``log``."""
    log["zmp_desired"][k] = state.zmp_desired
    log["com_offset"][k] = state.com_offset
    log["ankle_offsets"][k] = state.ankle_offsets.ravel()
    log["height_difference"][k] = state.height_difference
    log["pelvis_turn"][k] = state.pelvis_turn


def _capture_due(support: NDArray[np.generic], k: int, last_capture: int, state: BalanceState, trigger: float,
                 measurement: BalanceMeasurement, load_threshold: float) -> bool:
    """Whether a capture step is planned at tick ``k``: in a single support that goes on at the next tick, at least
    :data:`CAPTURE_INTERVAL` after the last one, as :func:`~zmpwalk.capture.capture_wanted` (the DCM error beyond
    ``trigger`` [m], the swinging sole unloaded)."""
    if not (k + 1 < len(support) and support[k] != 0 and support[k + 1] == support[k]
            and k - last_capture >= CAPTURE_INTERVAL * CONTROL_RATE):
        return False
    swing = measurement.wrench_right if support[k] == Support.LEFT else measurement.wrench_left
    return capture_wanted(state.dcm_error, trigger, float(swing[2]), load_threshold)
