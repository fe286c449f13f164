"""The actuator table of a simulated walk (Table 2 and Figs. 12-14 of Lim et al.)."""

from __future__ import annotations

import csv
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from zmpwalk.sim.run import SimulationResult


@dataclass(frozen=True)
class ActuatorRow:
    """What one joint's motor must deliver over a walk.

    Attributes:
        joint: Column name, e.g. ``left_hip_roll``.
        peak_torque: Largest |torque| [N m].
        rms_torque: RMS torque [N m].
        peak_velocity: Largest |velocity| [rad/s].
        peak_power: Largest |torque x velocity| [W].
        mean_power: Mean |torque x velocity| [W].
    """

    joint: str
    peak_torque: float  # [N m]
    rms_torque: float  # [N m]
    peak_velocity: float  # [rad/s]
    peak_power: float  # [W]
    mean_power: float  # [W]


def actuator_table(result: SimulationResult, skip: float = 0.0) -> list[ActuatorRow]:
    """Per joint requirements over the walk, from ``skip`` seconds on (the paper ignores its touchdown)."""
    keep = result.time >= skip
    torque = result.joint_torques[keep]
    velocity = result.joint_velocities[keep]
    power = np.abs(result.joint_power[keep])
    return [
        ActuatorRow(name, float(np.abs(torque[:, i]).max()), float(np.sqrt(np.mean(torque[:, i] ** 2))),
                    float(np.abs(velocity[:, i]).max()), float(power[:, i].max()), float(power[:, i].mean()))
        for i, name in enumerate(result.joint_names)
    ]


def write_actuator_csv(rows: list[ActuatorRow], path: Path) -> None:
    """The table as CSV, SI units in the header."""
    with Path(path).open("w", newline="", encoding="utf-8") as handle:
        writer = csv.writer(handle)
        writer.writerow(["joint", "peak_torque_Nm", "rms_torque_Nm", "peak_velocity_rad_s", "peak_power_W",
                         "mean_power_W"])
        for row in rows:
            values = asdict(row)
            writer.writerow([values.pop("joint"), *(f"{v:.6g}" for v in values.values())])


def actuator_markdown(rows: list[ActuatorRow]) -> str:
    """The table as Markdown."""
    lines = ["| joint | peak torque [N m] | RMS torque [N m] | peak velocity [rad/s] | peak power [W] "
             "| mean power [W] |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r.joint} | {r.peak_torque:.3g} | {r.rms_torque:.3g} | {r.peak_velocity:.3g} | "
                     f"{r.peak_power:.3g} | {r.mean_power:.3g} |")
    return "\n".join(lines)
