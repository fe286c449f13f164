"""Does a motor fit each joint? The walk's torque-speed operating points against a motor's envelope.

A motor file (TOML, example in ``examples/motors.toml``) lists ``[[motors]]``, each with the joints it
drives (roles such as ``"knee"`` for both legs, or columns such as ``"left_knee"``) and, on the motor's
side: ``rated_torque`` [N m] (continuous), ``peak_torque`` [N m], ``no_load_speed`` [rad/s], and the
``gear_ratio`` [-] and ``efficiency`` [-] of its gear. At the joint:

.. math::
    \\tau_{rated} = n \\eta \\tau_{r,m}, \\quad \\tau_{peak} = n \\eta \\tau_{p,m}, \\quad
    \\omega_0 = \\omega_{0,m} / n, \\qquad
    |\\tau| \\le \\tau_{peak} (1 - |\\omega| / \\omega_0)

(the linear torque-speed line of a DC motor at its supply voltage). A joint **fits** when its RMS torque is
within the rated torque and every operating point held for the impact window (see
:mod:`zmpwalk.sim.actuators`) is inside the envelope; otherwise it **exceeds** by the largest ratio minus 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from zmpwalk.errors import FileFormatError
from zmpwalk.files import read_toml
from zmpwalk.robots.model import JOINT_NAMES
from zmpwalk.sim.actuators import IMPACT_WINDOW

if TYPE_CHECKING:
    from zmpwalk.sim.result import SimulationResult

_FIELDS = ("rated_torque", "peak_torque", "no_load_speed", "gear_ratio", "efficiency")


@dataclass(frozen=True)
class Motor:
    """A motor and its gear (motor-side values; see the module docstring).

    Attributes:
        name: Its name.
        joints: Roles or columns it drives.
        rated_torque: [N m]. peak_torque: [N m]. no_load_speed: [rad/s]. gear_ratio: [-]. efficiency: [-].
    """

    name: str
    joints: tuple[str, ...]
    rated_torque: float  # [N m]
    peak_torque: float  # [N m]
    no_load_speed: float  # [rad/s]
    gear_ratio: float  # [-]
    efficiency: float  # [-]

    @property
    def joint_rated_torque(self) -> float:
        return self.rated_torque * self.gear_ratio * self.efficiency

    @property
    def joint_peak_torque(self) -> float:
        return self.peak_torque * self.gear_ratio * self.efficiency

    @property
    def joint_no_load_speed(self) -> float:
        return self.no_load_speed / self.gear_ratio


@dataclass(frozen=True)
class MotorFit:
    """One joint against its motor.

    Attributes:
        joint: Column name. motor: Motor name.
        rms_use: RMS torque over the rated torque [-]. peak_use: Largest held operating point over the
            envelope at its speed [-].
    """

    joint: str
    motor: str
    rms_use: float  # [-]
    peak_use: float  # [-]

    @property
    def fits(self) -> bool:
        return max(self.rms_use, self.peak_use) <= 1.0

    @property
    def verdict(self) -> str:
        worst = max(self.rms_use, self.peak_use)
        return "fits" if worst <= 1.0 else f"exceeds by {(worst - 1.0) * 100:.0f} %"


def load_motors(path: Path) -> list[Motor]:
    """Read a motor file.

    Raises:
        FileFormatError: Missing or non-positive fields, unknown joints (names the motor and the field).
    """
    source = str(path)
    data = read_toml(path)
    entries = data.get("motors")
    if not isinstance(entries, list) or not entries:
        raise FileFormatError(source, "needs [[motors]] tables")
    columns = {f"{side}_{joint}" for side in ("left", "right") for joint in JOINT_NAMES}
    motors = []
    for number, entry in enumerate(entries, start=1):
        where = f"[[motors]] {number}"
        if not isinstance(entry, dict):
            raise FileFormatError(source, f"{where} must be a table")
        name = str(entry.get("name", f"motor {number}"))
        joints = entry.get("joints")
        if not isinstance(joints, list) or not joints or any(j not in JOINT_NAMES and j not in columns
                                                                 for j in joints):
            raise FileFormatError(source, f"{where} ({name}): joints must list roles ({', '.join(JOINT_NAMES)}) "
                                  "or columns such as left_knee")
        values = {}
        for field in _FIELDS:
            value = entry.get(field)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not (math.isfinite(value)
                                                                                       and value > 0):
                raise FileFormatError(source, f"{where} ({name}): {field} = {value!r} must be a number > 0")
            values[field] = float(value)
        if values["efficiency"] > 1.0:
            raise FileFormatError(source, f"{where} ({name}): efficiency = {values['efficiency']:g} must be <= 1")
        motors.append(Motor(name, tuple(str(j) for j in joints), **values))
    return motors


def motor_for(motors: list[Motor], column: str) -> Motor | None:
    """The motor of a joint column: one naming the column wins over one naming its role."""
    role = column.split("_", 1)[1]
    for wanted in (column, role):
        for motor in motors:
            if wanted in motor.joints:
                return motor
    return None


def motor_fits(result: SimulationResult, motors: list[Motor]) -> list[MotorFit]:
    """Each joint with a motor against that motor's envelope (see the module docstring)."""
    period = float(np.median(np.diff(result.time))) if len(result.time) > 1 else 1e-3
    window = max(1, round(IMPACT_WINDOW / period))
    fits = []
    for index, column in enumerate(result.joint_names):
        motor = motor_for(motors, column)
        if motor is None:
            continue
        torque = np.abs(result.joint_torques[:, index])
        speed = np.abs(result.joint_velocities[:, index])
        available = motor.joint_peak_torque * np.maximum(1.0 - speed / motor.joint_no_load_speed, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            use = np.where(available > 0, torque / available, np.inf)
        held = (sliding_window_view(use, window).min(axis=-1).max() if len(use) >= window else use.max())
        rms = float(np.sqrt(np.mean(torque**2)))
        fits.append(MotorFit(column, motor.name, rms / motor.joint_rated_torque, float(held)))
    return fits
