"""What the servos and the stabilizer are given at the control rate: a pattern's references, tick by tick.

The pattern and its joint trajectory are linearly interpolated to the 1 kHz servo rate (:data:`CONTROL_RATE`), as
HUBO's servo controllers do between the main computer's references: the leg joint references, the controls with
the model-based feedforward of the planned motion (:mod:`zmpwalk.sim.plant`, docs/balance.md), and what the
stabilizer tracks (the CoM point, the yaws, the ankles, the support phase).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from zmpwalk.kinematics import JointTrajectory
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.sim.plant import Plant, damping_feedforward, servo_offsets, servo_torques
from zmpwalk.sim.poses import plant_qpos
from zmpwalk.sim.ranges import CONTROL_RATE as CONTROL_RATE  # [Hz] servo reference and measurement rate

Array = NDArray[np.float64]



def rows_at(times: Array, pattern_times: Array, values: Array) -> Array:
    """Each column of ``values`` (m, k) linearly interpolated at ``times`` (n,): (n, k)."""
    return np.column_stack([np.interp(times, pattern_times, values[:, i]) for i in range(values.shape[1])])


def tracked_references(pattern: WalkingPattern, times: Array) -> dict[str, NDArray[np.generic]]:
    """What the stabilizer tracks of ``pattern`` at ``times`` (n,): its CoM point ``com`` (n, 3), pelvis ``yaw``,
    ankles ``left`` and ``right`` (n, 3), foot yaws ``left_yaw`` and ``right_yaw``, and the ``support`` code (a
    time at a phase change has the phase that begins)."""
    return {"com": rows_at(times, pattern.time, pattern.position_com_point_in_world),
            "yaw": np.interp(times, pattern.time, pattern.yaw_pelvis_in_world),
            "left": rows_at(times, pattern.time, pattern.position_left_ankle_in_world),
            "right": rows_at(times, pattern.time, pattern.position_right_ankle_in_world),
            "left_yaw": np.interp(times, pattern.time, pattern.yaw_left_foot_in_world),
            "right_yaw": np.interp(times, pattern.time, pattern.yaw_right_foot_in_world),
            "support": pattern.support[np.clip(np.searchsorted(pattern.time, times - 1e-9), 0,
                                               len(pattern.time) - 1)]}


def servo_controls(plant: Plant, pattern: WalkingPattern, joints: JointTrajectory, pattern_time: Array,
                   zmp_ref: Array, feedforward: bool) -> tuple[Array, Array, Array | None]:
    """The leg joint references (n, 12) at ``pattern_time`` (n,), the controls (n, nu) with the feedforwards of
    the planned motion where ``feedforward`` (gravity, ground reaction and servo damping, docs/balance.md), and
    the planned leg torques (n, 12) [N m] or None."""
    reference = rows_at(pattern_time, joints.time, joints.angles)
    control = np.repeat(plant.ctrl_hold[None, :], len(pattern_time), axis=0)
    control[:, plant.leg_actuators] = reference
    if not feedforward:
        return reference, control, None
    base_planned = (pattern.position_pelvis_in_world if joints.position_base_in_world is None
                    else joints.position_base_in_world)
    base_path = rows_at(pattern_time, pattern.time, base_planned)
    yaw_path = np.interp(pattern_time, pattern.time, pattern.yaw_pelvis_in_world)
    planned_ankles = [rows_at(pattern_time, pattern.time, a)
                      for a in (pattern.position_left_ankle_in_world, pattern.position_right_ankle_in_world)]
    qpos_path = plant_qpos(plant, base_path, yaw_path, reference)
    rates = rows_at(pattern_time, joints.time, joints.velocities)
    control[:, plant.leg_actuators] += damping_feedforward(plant, rates)
    index = np.clip(np.searchsorted(pattern.time, pattern_time), 0, len(pattern.time) - 1)
    needed = servo_torques(plant, qpos_path, zmp_ref, pattern.support[index], (planned_ankles[0], planned_ankles[1]))
    control += servo_offsets(plant, needed)
    return reference, control, needed[:, plant.leg_actuators]
