"""zmpwalk: online ZMP walking patterns for biped humanoid robots."""

import os

# The report renders offscreen with MuJoCo, whose OpenGL backend is fixed when it is first imported;
# EGL needs no display. A value the user set wins.
os.environ.setdefault("MUJOCO_GL", "egl")


from zmpwalk.balance import BalanceMeasurement, Stabilizer, StabilizerGains
from zmpwalk.commands import StepCommand
from zmpwalk.control import JointTargets, MockPlant, Plant, WalkingController
from zmpwalk.errors import (
    FileFormatError,
    InfeasibleCommandError,
    InfeasiblePatternError,
    InvalidParameterError,
    SimulationError,
    UnknownNameError,
    UnreachableError,
    ZmpwalkError,
)
from zmpwalk.kinematics import JointLimitError, JointTrajectory, pattern_joint_trajectory
from zmpwalk.leg_chain import LegChain
from zmpwalk.online import OnlineWalker
from zmpwalk.patterns.lipm import generate_hyperbolic
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.preview import generate_preview
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.ready_fit import FittedWalk, fit_ready_posture
from zmpwalk.robots import RobotModel, list_robots, load_robot
from zmpwalk.sample import WalkingSample
from zmpwalk.schedule import Schedule, ShapeParameters
from zmpwalk.walk import WalkOutcome, WalkSpec, run_walk

__all__ = [
    "BalanceMeasurement",
    "FileFormatError",
    "FittedWalk",
    "InfeasibleCommandError",
    "InfeasiblePatternError",
    "InvalidParameterError",
    "JointLimitError",
    "JointTargets",
    "JointTrajectory",
    "LegChain",
    "MockPlant",
    "OnlineWalker",
    "Plant",
    "RobotModel",
    "Schedule",
    "ShapeParameters",
    "SimulationError",
    "Stabilizer",
    "StabilizerGains",
    "StepCommand",
    "UnknownNameError",
    "UnreachableError",
    "WalkOutcome",
    "WalkSpec",
    "WalkingController",
    "WalkingPattern",
    "WalkingSample",
    "ZmpwalkError",
    "fit_ready_posture",
    "generate",
    "generate_hyperbolic",
    "generate_preview",
    "list_robots",
    "load_robot",
    "pattern_joint_trajectory",
    "run_walk",
]
