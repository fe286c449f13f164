"""What the plan does not know: a push, a tilted floor, a mass error, and the noise of the sensors.

:class:`Disturbances` changes the plant's world after the pattern, the feedforward and the stabilizer were made
for the nominal robot; :class:`SensorNoise` adds seeded Gaussian noise to what the stabilizer measures; the
measurement reader turns one row of MuJoCo sensor data into the stabilizer's
:class:`~zmpwalk.balance.BalanceMeasurement`, as the robot's force-torque sensors, IMU and encoders give it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.balance import BalanceMeasurement
from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.sim.soles import SensorSlices, rotation_from_quaternion

Array = NDArray[np.float64]

NOSLIP_ITERATIONS = 5  # MuJoCo noslip iterations on a tilted floor (Disturbances.apply: no creep of loaded soles)


@dataclass(frozen=True)
class Disturbances:
    """What the world does to the robot that the plan does not know.

    Attributes:
        push_time: When a push on the torso (base) starts [s], or None.
        push_impulse: Its impulse in world [N s], (x, y, z); applied as a constant force over ``push_duration``.
        push_duration: [s].
        floor_tilt: Roll and pitch of the floor [rad] (the floor's rotation ``Rx(roll) Ry(pitch)`` from level:
            pitch > 0 runs downhill ahead, roll > 0 raises the left side);
            simulated by turning gravity in the floor's frame; the IMU reads attitude against gravity.
        mass_error: The plant's masses and inertias are ``1 + mass_error`` times the model's [-].
    """

    push_time: float | None = None  # [s]
    push_impulse: tuple[float, float, float] = (0.0, 0.0, 0.0)  # [N s]
    push_duration: float = 0.1  # [s]
    floor_tilt: tuple[float, float] = (0.0, 0.0)  # [rad]
    mass_error: float = 0.0  # [-]

    def __post_init__(self) -> None:
        if not -0.5 < self.mass_error < 1.0:
            raise InvalidParameterError("mass_error", self.mass_error, "a fraction in (-0.5, 1)")
        if len(self.floor_tilt) != 2 or max(abs(a) for a in self.floor_tilt) > 0.3:
            raise InvalidParameterError("floor_tilt", self.floor_tilt, "(roll, pitch) within 0.3 rad")
        if not 0.001 <= self.push_duration <= 1.0:
            raise InvalidParameterError("push_duration", self.push_duration, "a time in [0.001, 1] s")
        if len(self.push_impulse) != 3 or not all(math.isfinite(v) and abs(v) <= 1000.0 for v in self.push_impulse):
            raise InvalidParameterError("push_impulse", self.push_impulse, "three components within 1000 N s")

    @property
    def floor_rotation(self) -> Array:
        """The floor's rotation from level, ``Rx(roll) Ry(pitch)``."""
        roll, pitch = self.floor_tilt
        cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
        rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
        ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
        return np.asarray(rx @ ry, dtype=np.float64)

    def apply(self, model: mujoco.MjModel) -> None:
        """Tilt gravity and scale the masses of ``model`` (in place; MuJoCo's derived constants recomputed).

        On a tilted floor gravity pulls along the floor at every loaded sole, all the time. MuJoCo's soft
        contacts let a sole creep under such a lasting tangential force although it is far inside the
        friction cone (TALOS on 2 degrees of pitch: its stance ankle moved 2.3-3.9 mm while loaded, against
        0.1-1.2 mm on a level floor, and the leg odometry, which cannot see it, was 22 mm off after ten
        steps); a real sole does not. The noslip solver (:data:`NOSLIP_ITERATIONS`) removes that creep, so it
        runs on a tilted floor (on TALOS it costs two thirds more time per step; on a level floor, where no
        lasting tangential force acts, the odometry lost 0.3 mm over a whole walk's single supports).
        """
        gravity = float(np.linalg.norm(model.opt.gravity))
        model.opt.gravity[:] = self.floor_rotation.T @ np.array([0.0, 0.0, -gravity])
        if any(self.floor_tilt):
            model.opt.noslip_iterations = NOSLIP_ITERATIONS
        model.body_mass[:] *= 1.0 + self.mass_error
        model.body_inertia[:] *= 1.0 + self.mass_error
        mujoco.mj_setConst(model, mujoco.MjData(model))  # scratch data: mj_setConst works at qpos0

    def force_at(self, time: float) -> Array:
        """The push's force at ``time`` [N], (3,)."""
        if self.push_time is None or not self.push_time <= time < self.push_time + self.push_duration:
            return np.zeros(3)
        return np.asarray(self.push_impulse, dtype=float) / self.push_duration


@dataclass(frozen=True)
class SensorNoise:
    """Standard deviations of Gaussian noise added to the stabilizer's measurements (seeded).

    Attributes:
        force: On each force component [N].
        torque: On each torque component [N m].
        attitude: On roll and pitch [rad].
        rate: On each gyro axis [rad/s].
        encoder: On each joint angle [rad].
        seed: Of ``numpy.random.default_rng``.
    """

    force: float = 5.0  # [N]
    torque: float = 0.5  # [N m]
    attitude: float = 0.002  # [rad]
    rate: float = 0.01  # [rad/s]
    encoder: float = 0.0005  # [rad]
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("force", "torque", "attitude", "rate", "encoder"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                raise InvalidParameterError(f"noise.{name}", value, "a standard deviation >= 0")

    def add_to(self, measurement: BalanceMeasurement, rng: np.random.Generator) -> None:
        """Add the noise to ``measurement`` (in place), drawn from ``rng``: the left and right wrenches, the
        attitude, the gyro rates and the joint angles, in that order."""
        measurement.wrench_left += rng.normal(0, [self.force] * 3 + [self.torque] * 3)
        measurement.wrench_right += rng.normal(0, [self.force] * 3 + [self.torque] * 3)
        measurement.attitude = measurement.attitude + rng.normal(0, self.attitude, 2)
        measurement.rate = measurement.rate + rng.normal(0, self.rate, 3)
        measurement.joint_angles = measurement.joint_angles + rng.normal(0, self.encoder, 12)


def _as_slice(index: NDArray[np.intp]) -> NDArray[np.intp] | slice:
    """``index`` as a slice where it is one run of consecutive columns (a slice reads a row's columns without the
    copy and the bounds checks of an index array)."""
    if len(index) and (np.diff(index) == 1).all():
        return slice(int(index[0]), int(index[-1]) + 1)
    return index


class _MeasurementReader:
    """The stabilizer's inputs from one row of sensor data (:meth:`read`), with the sensors' columns found once.

    The ground's wrench on each foot is the opposite of what the ankle sensor between foot and leg reads
    (both in the foot frame); the IMU's attitude is relative to gravity (on a tilted floor, ``floor`` is the
    floor's rotation from level).
    """

    def __init__(self, sensors: SensorSlices, floor: Array | None = None) -> None:
        def columns(*names: str) -> NDArray[np.intp]:
            return np.concatenate([np.arange(sensors.slices[n].start, sensors.slices[n].stop) for n in names])

        self._left = _as_slice(columns("left_force", "left_torque"))
        self._right = _as_slice(columns("right_force", "right_torque"))
        self._quaternion = sensors.slices["pelvis_quat"]
        self._gyro = sensors.slices["pelvis_gyro"]
        self._joints = _as_slice(columns(*(f"{c}_q" for c in JOINT_COLUMNS)))
        self._floor = None if floor is None or np.allclose(floor, np.eye(3)) else floor

    def read(self, row: Array) -> BalanceMeasurement:
        """The measurement of one row of ``sensordata``."""
        w, x, y, z = row[self._quaternion].tolist()
        if self._floor is None:
            roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
            pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
            yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        else:
            level = self._floor @ rotation_from_quaternion(row[None, self._quaternion])[0]
            roll, pitch = math.atan2(level[2, 1], level[2, 2]), math.asin(max(-1.0, min(1.0, -level[2, 0])))
            yaw = math.atan2(level[1, 0], level[0, 0])
        joints = row[self._joints]
        return BalanceMeasurement(wrench_left=-row[self._left], wrench_right=-row[self._right],
                                  attitude=np.array([roll, pitch]), rate=row[self._gyro].copy(), yaw=yaw,
                                  joint_angles=joints.copy() if isinstance(self._joints, slice) else joints)
