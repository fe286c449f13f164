"""Physics simulation in MuJoCo: an MJCF model from a robot file, the walk, and its measurements."""

import os

# Offscreen rendering (the report's animation) needs its OpenGL backend chosen before MuJoCo loads;
# EGL renders without a display. A value set by the user wins.
os.environ.setdefault("MUJOCO_GL", "egl")

from importlib import import_module
from typing import Any

_WHERE = {"ActuatorRow": "actuators", "actuator_markdown": "actuators", "actuator_table": "actuators",
          "write_actuator_csv": "actuators", "contact_mapping": "mjcf", "robot_mjcf": "mjcf",
          "SimulationResult": "result", "simulate": "run"}


def __getattr__(name: str) -> Any:
    """The package's names, imported when first used: importing a submodule (the verdict's constants, a motor
    file's reader) does not load MuJoCo."""
    if name in _WHERE:
        return getattr(import_module(f"zmpwalk.sim.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'zmpwalk.sim' has no attribute {name!r}")


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
