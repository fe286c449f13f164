"""The walking controller a robot's loop runs, and what it drives: one object per control tick.

:class:`WalkingController` puts the :class:`~zmpwalk.online.OnlineWalker` (with joints), the
:class:`~zmpwalk.balance.Stabilizer` and an optional :class:`Feedforward` behind ``update(measurement) ->
JointTargets``; a :class:`Plant` measures and carries out the targets (a robot's driver,
:class:`zmpwalk.sim.mujoco_plant.MujocoPlant`, or :class:`MockPlant`). docs/controller.md shows a robot's loop.
"""

from zmpwalk.control.controller import Feedforward, WalkingController, velocity_command, velocity_step_time
from zmpwalk.control.mock import MockPlant, sole_wrenches
from zmpwalk.control.plant import JointTargets, Plant

__all__ = [
    "Feedforward",
    "JointTargets",
    "MockPlant",
    "Plant",
    "WalkingController",
    "sole_wrenches",
    "velocity_command",
    "velocity_step_time",
]
