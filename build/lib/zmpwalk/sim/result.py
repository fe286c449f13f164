"""The measurements of a simulated walk (:class:`SimulationResult`) and their CSV file.

One row per millisecond, in world and SI units: the torso's pose, each sole's force and centre of pressure, the
joints' angles, rates, torques and power, the stabilizer's log, and the figures of how the walk ended.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from zmpwalk.capture import CapturePlan
from zmpwalk.files import atomic_output
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.robots.model import RobotModel

Array = NDArray[np.float64]


@dataclass
class SimulationResult:
    """Measurements of one simulated walk, in world (SI), one row per millisecond.

    Attributes:
        robot: The robot.
        time: [s], (n,).
        torso_position: Pelvis centre [m], (n, 3).
        torso_rpy: Torso roll, pitch, yaw [rad], (n, 3).
        fell: Whether it fell (the criterion of :mod:`zmpwalk.sim.measure`).
        fall_time: When [s], or None.
        distance: Horizontal distance of the pelvis from start to end [m].
        average_speed: ``distance`` over the walk's duration [m/s].
        foot_slip: Largest horizontal slide of a loaded sole [m].
        cop_left, cop_right, cop: Centres of pressure [m], (n, 2); NaN where the sole is unloaded.
        force_left, force_right: Normal force on each sole [N], (n,).
        reference_zmp: The pattern's ZMP [m], (n, 2).
        cop_margin: Signed distance of the CoP to the polygon of the loaded soles [m], (n,).
        joint_names: The 12 joint column names.
        joint_angles, joint_velocities, joint_torques, joint_power: (n, 12) [rad], [rad/s], [N m], [W].
        mass_scale: Multiplier of all masses.
        ankle_positions: Left and right ankle positions in world [m], (n, 2, 3).
        planned_torques: The leg joint torques the plan needs on an ideal robot (inverse dynamics of the
            planned motion with the planned ground reaction, what the feedforward sends) [N m], (n, 12); None
            where the feedforward did not run.
        balance: The stabilizer's log per sample (``zmp_desired``, ``com_offset``, ``ankle_offsets``,
            ``height_difference``, ``pelvis_turn``), or None open loop.
        final_feet_error: Largest horizontal distance of a simulated ankle from its planned final place [m]
            (nan after a fall).
        final_feet_yaw_error: Largest yaw error of a foot at the end [rad].
        end_min_sole_force: Smallest normal force on either sole over the final hold [N] (both loaded: > 0).
        end_max_speed: Largest horizontal speed of the base over the final hold [m/s].
        end_attitude_range: Largest spread of torso roll or pitch over the final hold [rad].
        captures: The capture steps taken (``simulate``'s ``capture``), in order; empty when the pattern was
            played to its end.
        plan_zmp_margin: The simulated pattern's least cart-table ZMP margin to its support polygon [m] (> 0
            inside; :meth:`WalkingPattern.min_zmp_margin`).
        planned_end: When the run was to end, the final hold included [s] (``time[-1]`` unless it fell).
    """

    robot: RobotModel
    time: Array
    torso_position: Array
    torso_rpy: Array
    fell: bool
    fall_time: float | None
    distance: float
    average_speed: float
    foot_slip: float
    cop_left: Array
    cop_right: Array
    cop: Array
    force_left: Array
    force_right: Array
    reference_zmp: Array
    cop_margin: Array
    joint_angles: Array
    joint_velocities: Array
    joint_torques: Array
    joint_power: Array
    mass_scale: float = 1.0
    joint_names: tuple[str, ...] = field(default=JOINT_COLUMNS)
    balance: dict[str, Array] | None = None
    ankle_positions: Array | None = None  # [m] (n, 2, 3)
    planned_torques: Array | None = None  # [N m] (n, 12)
    final_feet_error: float = math.nan  # [m]
    final_feet_yaw_error: float = math.nan  # [rad]
    end_min_sole_force: float = math.nan  # [N]
    end_max_speed: float = math.nan  # [m/s]
    end_attitude_range: float = math.nan  # [rad]
    captures: list[CapturePlan] = field(default_factory=list)
    plan_zmp_margin: float = math.nan  # [m]
    planned_end: float = math.nan  # [s]

    @property
    def cop_error(self) -> Array:
        """CoP minus the reference ZMP [m], (n, 2); NaN where no sole is loaded."""
        return self.cop - self.reference_zmp

    def cop_error_stats(self) -> tuple[float, float]:
        """RMS and largest length of the CoP error [m] over the loaded samples."""
        error = np.linalg.norm(self.cop_error, axis=1)
        error = error[np.isfinite(error)]
        if len(error) == 0:
            return math.nan, math.nan
        return float(np.sqrt(np.mean(error**2))), float(error.max())


def write_result_csv(result: SimulationResult, path: Path) -> None:
    """The simulation's time series as CSV, one row per millisecond, SI units in the column names' meaning
    (m, rad, N, N m, W): torso pose, CoP and reference ZMP, sole forces, CoP margin, each joint's angle,
    torque and power."""
    columns: dict[str, np.ndarray] = {
        "t": result.time,
        "torso_x": result.torso_position[:, 0], "torso_y": result.torso_position[:, 1],
        "torso_z": result.torso_position[:, 2], "torso_roll": result.torso_rpy[:, 0],
        "torso_pitch": result.torso_rpy[:, 1], "torso_yaw": result.torso_rpy[:, 2],
        "cop_x": result.cop[:, 0], "cop_y": result.cop[:, 1],
        "zmp_ref_x": result.reference_zmp[:, 0], "zmp_ref_y": result.reference_zmp[:, 1],
        "force_left": result.force_left, "force_right": result.force_right, "cop_margin": result.cop_margin,
    }
    for i, name in enumerate(result.joint_names):
        columns[f"{name}_q"] = result.joint_angles[:, i]
        columns[f"{name}_tau"] = result.joint_torques[:, i]
        columns[f"{name}_power"] = result.joint_power[:, i]
    with atomic_output(path) as temporary:
        np.savetxt(temporary, np.column_stack(list(columns.values())), delimiter=",", header=",".join(columns),
                   comments="", fmt="%.9g")
