"""Physics simulation in MuJoCo: an MJCF model from a robot file, the walk, and its measurements."""

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
