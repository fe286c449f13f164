"""The actuator table of a simulated walk (Table 2 and Figs. 12-14 of Lim et al.)."""

from __future__ import annotations

import csv
import math
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from zmpwalk.files import atomic_output

if TYPE_CHECKING:
    from zmpwalk.sim.result import SimulationResult

IMPACT_WINDOW = 0.02  # [s] a torque or power held for less than this is an impact, shown apart


@dataclass(frozen=True)
class ActuatorRow:
    """What one joint's motor must deliver over a walk.

    Attributes:
        joint: Column name, e.g. ``left_hip_roll``.
        peak_torque: Largest |torque| held for at least :data:`IMPACT_WINDOW` [N m] (the sizing peak).
        impact_torque: Largest |torque| of any sample, impacts at touchdown included [N m].
        rms_torque: RMS torque over the walk [N m] (the continuous demand).
        peak_velocity: Largest |velocity| [rad/s].
        peak_power: Largest |torque x velocity| held for at least :data:`IMPACT_WINDOW` [W].
        mean_power: Mean |torque x velocity| [W].
        torque_limit: The model's actuator limit [N m] (inf where it has none): a position servo's force range,
            a torque motor's control range times its gear (where the joint PD layer clips its torque), the joint's
            ``actuatorfrcrange`` (a URDF's effort limit), the smallest (:class:`zmpwalk.robots.description.Actuator`).
        planned_torque: Largest |torque| the plan needs on an ideal robot, held for at least
            :data:`IMPACT_WINDOW` [N m] (the feedforward's inverse dynamics; nan where it did not run).
    """

    joint: str
    peak_torque: float  # [N m]
    impact_torque: float  # [N m]
    rms_torque: float  # [N m]
    peak_velocity: float  # [rad/s]
    peak_power: float  # [W]
    mean_power: float  # [W]
    torque_limit: float = math.inf  # [N m]
    planned_torque: float = math.nan  # [N m]


def sustained(values: np.ndarray, window: int) -> np.ndarray:
    """Per column, the largest value held for ``window`` samples in a row: ``max_t min_{[t, t + window)} x``
    (a morphological opening; shorter spikes are removed), (columns,)."""
    if window <= 1 or len(values) < window:
        return np.asarray(values.max(axis=0))
    return np.asarray(sliding_window_view(values, window, axis=0).min(axis=-1).max(axis=0))


def actuator_table(result: SimulationResult, skip: float = 0.0) -> list[ActuatorRow]:
    """Per joint requirements over the walk, from ``skip`` seconds on (the paper ignores its touchdown).

    Peaks of torque and power are those held for :data:`IMPACT_WINDOW` (a motor's rating is thermal and
    by current over milliseconds, not by one sample); the largest single-sample torque is reported apart.
    """
    keep = result.time >= skip
    if not keep.any():  # a walk that ended before ``skip``: its figures over every sample it has
        keep = np.ones(len(result.time), dtype=bool)
    torque = np.abs(result.joint_torques[keep])
    velocity = result.joint_velocities[keep]
    power = np.abs(result.joint_power[keep])
    period = float(np.median(np.diff(result.time))) if len(result.time) > 1 else 1e-3
    window = max(1, round(IMPACT_WINDOW / period))
    held_torque = sustained(torque, window)
    held_power = sustained(power, window)
    limits = _torque_limits(result)
    planned = (np.full(len(result.joint_names), math.nan) if result.planned_torques is None
               else sustained(np.abs(result.planned_torques[keep]), window))
    return [
        ActuatorRow(name, float(held_torque[i]), float(torque[:, i].max()),
                    float(np.sqrt(np.mean(torque[:, i] ** 2))), float(np.abs(velocity[:, i]).max()),
                    float(held_power[i]), float(power[:, i].mean()), limits[i], float(planned[i]))
        for i, name in enumerate(result.joint_names)
    ]


def planned_over_limit(rows: list[ActuatorRow]) -> list[ActuatorRow]:
    """The joints whose planned torque (an ideal robot's) exceeds the actuator's limit: the plan itself asks
    more than the motor gives, whatever the control."""
    return [r for r in rows if math.isfinite(r.planned_torque) and r.planned_torque > r.torque_limit]


def _torque_limits(result: SimulationResult) -> list[float]:
    plant = result.robot.plant
    if plant is None:
        return [math.inf] * len(result.joint_names)
    return [joint.actuator.force_limit if joint.actuator is not None else math.inf for joint in plant.joints]


def write_actuator_csv(rows: list[ActuatorRow], path: Path) -> None:
    """The table as CSV, SI units in the header."""
    with atomic_output(path) as temporary, temporary.open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["joint", "peak_torque_Nm", "impact_torque_Nm", "rms_torque_Nm", "peak_velocity_rad_s",
                         "peak_power_W", "mean_power_W", "torque_limit_Nm", "planned_torque_Nm"])
        for row in rows:
            values = asdict(row)
            writer.writerow([values.pop("joint"), *(f"{v:.6g}" for v in values.values())])


def actuator_markdown(rows: list[ActuatorRow]) -> str:
    """The table as Markdown."""
    window = f"{IMPACT_WINDOW * 1e3:g} ms"
    lines = [f"| joint | peak torque (held {window}) [N m] | impact peak [N m] | RMS torque [N m] | "
             f"peak velocity [rad/s] | peak power (held {window}) [W] | mean power [W] | "
             "model's limit [N m] (held peak's share) | planned, ideal robot [N m] |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        limit = "none"
        if math.isfinite(r.torque_limit):
            share = r.peak_torque / r.torque_limit
            limit = f"{r.torque_limit:.3g} ({share * 100:.0f} %{', EXCEEDED' if share > 1 else ''})"
        lines.append(f"| {r.joint} | {r.peak_torque:.3g} | {r.impact_torque:.3g} | {r.rms_torque:.3g} | "
                     f"{r.peak_velocity:.3g} | {r.peak_power:.3g} | {r.mean_power:.3g} | {limit} | "
                     f"{'-' if math.isnan(r.planned_torque) else format(r.planned_torque, '.3g')} |")
    return "\n".join(lines)
