"""zmpwalk: online ZMP walking patterns for biped humanoid robots."""

import os

# The report renders offscreen with MuJoCo, whose OpenGL backend is fixed when it is first imported;
# EGL needs no display. A value the user set wins.
os.environ.setdefault("MUJOCO_GL", "egl")


from zmpwalk.commands import StepCommand
from zmpwalk.errors import (
    FileFormatError,
    InfeasiblePatternError,
    InvalidParameterError,
    UnknownNameError,
    UnreachableError,
    ZmpwalkError,
)
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots import RobotModel, list_robots, load_robot
from zmpwalk.schedule import Schedule, ShapeParameters

__all__ = [
    "FileFormatError",
    "InfeasiblePatternError",
    "InvalidParameterError",
    "RobotModel",
    "Schedule",
    "ShapeParameters",
    "StepCommand",
    "UnknownNameError",
    "UnreachableError",
    "WalkingPattern",
    "ZmpwalkError",
    "generate",
    "list_robots",
    "load_robot",
]
