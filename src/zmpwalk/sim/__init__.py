"""Physics simulation in MuJoCo: an MJCF model from a robot file, the walk, and its measurements."""

import os

# Offscreen rendering (the report's animation) needs its OpenGL backend chosen before MuJoCo loads;
# EGL renders without a display. A value set by the user wins.
os.environ.setdefault("MUJOCO_GL", "egl")

from zmpwalk.sim.actuators import ActuatorRow, actuator_markdown, actuator_table, write_actuator_csv
from zmpwalk.sim.mjcf import contact_mapping, robot_mjcf
from zmpwalk.sim.run import SimulationResult, simulate

__all__ = [
    "ActuatorRow",
    "SimulationResult",
    "actuator_markdown",
    "actuator_table",
    "contact_mapping",
    "robot_mjcf",
    "simulate",
    "write_actuator_csv",
]
