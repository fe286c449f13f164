"""PlaCo's walk on HUBO's box model, timed as bench_pattern times zmpwalk's loop (used when PlaCo is installed).

PlaCo (Rhoban, ``pip install placo``; optional, not a dependency of zmpwalk) plans the CoM by a LIPM
model-predictive controller over its footsteps and solves the whole-body inverse kinematics (a QP) at every
tick. The loop below is the one of PlaCo's own walking example (``placo-examples/walk/walk.py``): per tick,
the tasks from the trajectory, the kinematics, the QP, the support foot on the floor, and a replan every
``replan_timesteps``, each with the next command of the same list zmpwalk walks (stride, side step,
turn), as a new command before every step.

The robot is HUBO's box model of ``zmpwalk.load_robot("hubo")`` written as a URDF (the same links, masses,
joint axes and ranges as ``zmpwalk.sim.mjcf``; frames named as PlaCo's ``HumanoidRobot`` expects:
``trunk``, ``left_foot``/``right_foot`` at the soles, ``left_hip_yaw``), at HUBO's pendulum height, hip
spacing and sole size, 0.7 s of single support and 0.1 s of double support.
"""

from __future__ import annotations

import gc
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

from zmpwalk import load_robot
from zmpwalk.kinematics import LEG_JOINTS
from zmpwalk.robots.model import Link, RobotModel
from zmpwalk.sim.mjcf import SMALL_FRACTION

AXES = {"hip_yaw": "0 0 1", "hip_roll": "1 0 0", "hip_pitch": "0 1 0", "knee": "0 1 0", "ankle_pitch": "0 1 0",
        "ankle_roll": "1 0 0"}
COMMANDS = [(0.2, 0.0, 0.0), (0.1, 0.0, 0.1), (0.0, 0.05, 0.0), (0.15, 0.0, 0.0), (0.1, 0.0, 0.0)]  # dx, dy, dtheta


def _inertial(link: Link) -> str:
    """A link's mass properties (a uniform box) as a URDF ``<inertial>``."""
    ixx, iyy, izz = link.inertia
    return (f'<inertial><origin xyz="{link.com[0]} {link.com[1]} {link.com[2]}"/><mass value="{link.mass}"/>'
            f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="0" ixz="0" iyz="0"/></inertial>')


def box_urdf(robot: RobotModel) -> str:
    """HUBO's box model (a robot file with ``[bodies]``) as URDF text."""
    links = robot.links
    small = links["thigh"].mass * SMALL_FRACTION  # the joint-only links, as in zmpwalk.sim.mjcf
    joint_only = Link(small, (0.01, 0.01, 0.01), (0.0, 0.0, 0.0))
    parts = [f'<robot name="{robot.name}">', f'<link name="trunk">{_inertial(links["torso"])}</link>']
    for side, label in ((1, "left"), (-1, "right")):
        offsets = {"hip_yaw": (0.0, side * robot.hip_spacing / 2, -robot.hip_drop),
                   "knee": (0.0, 0.0, -robot.thigh_length), "ankle_pitch": (0.0, 0.0, -robot.shank_length)}
        thigh, foot = links["thigh"], links["foot"]
        bodies = {"hip_pitch": Link(thigh.mass - 2 * small, thigh.size, thigh.com), "knee": links["shank"],
                  "ankle_roll": Link(foot.mass - small, foot.size, (foot.com[0], side * foot.com[1], foot.com[2]))}
        parent = "trunk"
        for role in LEG_JOINTS:
            child = f"{label}_{role}_link"
            body = bodies.get(role, joint_only)
            lower, upper = robot.limits_of(f"{label}_{role}")
            x, y, z = offsets.get(role, (0.0, 0.0, 0.0))
            parts += [f'<link name="{child}">{_inertial(body)}</link>',
                      f'<joint name="{label}_{role}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
                      f'<origin xyz="{x} {y} {z}"/><axis xyz="{AXES[role]}"/>'
                      f'<limit lower="{max(lower, -3.1)}" upper="{min(upper, 3.1)}" effort="1000" velocity="100"/>'
                      '</joint>']
            parent = child
        parts += [f'<link name="{label}_foot"/>',
                  f'<joint name="{label}_sole" type="fixed"><parent link="{parent}"/><child link="{label}_foot"/>'
                  f'<origin xyz="0 0 {-robot.ankle_height}"/></joint>']
    parts.append("</robot>")
    return "\n".join(parts)


def placo_loop(seconds: float, rate: float = 1000.0) -> tuple[np.ndarray, float]:
    """Every iteration [us] of PlaCo's walking loop on HUBO's box model, and the distance walked [m]."""
    import placo  # optional: only when installed

    warnings.filterwarnings("ignore")
    robot = load_robot("hubo")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "robot.urdf"
        path.write_text(box_urdf(robot))
        model = placo.HumanoidRobot(str(path))
    parameters = placo.HumanoidParameters()
    parameters.single_support_duration = 0.7  # [s]
    parameters.single_support_timesteps = 10
    parameters.double_support_ratio = 0.1 / 0.7  # 0.1 s [-]
    parameters.startend_double_support_ratio = 1.5
    parameters.planned_timesteps = 48
    parameters.replan_timesteps = 10
    parameters.walk_com_height = robot.pendulum_length  # [m]
    parameters.walk_foot_height = 0.05  # [m]
    parameters.walk_trunk_pitch = 0.0
    parameters.walk_foot_rise_ratio = 0.2
    parameters.foot_length, parameters.foot_width = robot.foot_length, robot.foot_width  # [m]
    parameters.feet_spacing = robot.hip_spacing  # [m]
    parameters.zmp_margin = 0.0
    parameters.walk_max_dtheta, parameters.walk_max_dy = 1.0, 0.1  # [rad], [m]
    parameters.walk_max_dx_forward, parameters.walk_max_dx_backward = 0.3, 0.2  # [m]
    solver = placo.KinematicsSolver(model)
    solver.enable_velocity_limits(True)
    solver.dt = 1.0 / rate
    tasks = placo.WalkTasks()
    tasks.initialize_tasks(solver, model)
    for knee in ("left_knee", "right_knee"):
        model.set_joint(knee, 0.5)  # [rad] a bent knee to start the IK from (HUBO's knees bend one way)
    tasks.reach_initial_pose(np.eye(4), parameters.feet_spacing, parameters.walk_com_height,
                             parameters.walk_trunk_pitch)
    planner = placo.FootstepsPlannerRepetitive(parameters)
    planner.configure(*COMMANDS[0], 6)
    footsteps = planner.plan(placo.HumanoidRobot_Side.left, placo.flatten_on_floor(model.get_T_world_left()),
                             placo.flatten_on_floor(model.get_T_world_right()))
    supports = placo.FootstepsPlanner.make_supports(footsteps, 0.0, True, parameters.has_double_support(), True)
    walk = placo.WalkPatternGenerator(model, parameters)
    trajectory = walk.plan(supports, model.com_world(), 0.0)
    start_position = np.array(model.com_world())
    gc.collect()
    gc.freeze()
    iterations = []
    t, last_replan, given = 0.0, 0.0, 1
    for _ in range(round(seconds * rate)):
        start = time.perf_counter()
        tasks.update_tasks_from_trajectory(trajectory, t)
        model.update_kinematics()
        solver.solve(True)
        if not trajectory.support_is_both(t):
            model.update_support_side(str(trajectory.support_side(t)))
            model.ensure_on_floor()
        if t - last_replan > parameters.replan_timesteps * parameters.dt() and walk.can_replan_supports(trajectory, t):
            planner.configure(*COMMANDS[given % len(COMMANDS)], 6)  # the next command
            given += 1
            supports = walk.replan_supports(planner, trajectory, t, last_replan)
            trajectory = walk.replan(supports, trajectory, t)
            last_replan = t
        iterations.append(time.perf_counter() - start)
        t += 1.0 / rate
    distance = float(np.linalg.norm(np.array(model.com_world())[:2] - start_position[:2]))
    return np.array(iterations) * 1e6, distance
