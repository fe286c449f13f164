"""Static joint torques of the ready posture (``zmpwalk.sim.statics``) against the moment of the bodies a joint
holds up, summed body by body from MuJoCo's own masses and positions."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk.errors import InvalidParameterError
from zmpwalk.kinematics import JOINT_COLUMNS
from zmpwalk.robots import load_robot
from zmpwalk.sim.plant import build_plant
from zmpwalk.sim.statics import StaticTorques, static_torques

ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
TALOS = ROBOTS / "pal_talos" / "scene_position.xml"
T1 = ROBOTS / "booster_t1" / "scene.xml"
needs_robots = pytest.mark.skipif(not TALOS.is_file() or not T1.is_file(), reason="../shared/robots is absent")
TORQUE_TOL = 1e-6  # [N m]


def held_moments(model: mujoco.MjModel, qpos: np.ndarray, joints: list[str], stance: bool) -> np.ndarray:
    """Torque about each joint's axis [N m]: on the stance leg, the gravity moment of every body *not* below
    the joint (the foot carries the robot); on the unloaded leg, minus that of the bodies below it."""
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    gravity = model.opt.gravity
    result = []
    for name in joints:
        joint = model.joint(name).id
        below = {b for b in range(1, model.nbody) if _descends(model, b, int(model.jnt_bodyid[joint]))}
        bodies = [b for b in range(1, model.nbody) if (b not in below) == stance]
        moment = sum((np.cross(data.xipos[b] - data.xanchor[joint], model.body_mass[b] * gravity)
                      for b in bodies), np.zeros(3))
        result.append(float((1.0 if stance else -1.0) * data.xaxis[joint] @ moment))
    return np.array(result)


def _descends(model: mujoco.MjModel, body: int, ancestor: int) -> bool:
    while body > 0:
        if body == ancestor:
            return True
        body = int(model.body_parentid[body])
    return False


@needs_robots
@pytest.mark.parametrize("path", [TALOS, T1], ids=["talos", "t1"])
def test_one_foot_torques_are_the_moment_of_what_each_joint_holds(path: Path) -> None:
    robot = load_robot(path)
    assert robot.plant is not None
    statics = static_torques(robot)
    model = build_plant(robot).model
    names = [joint.name for joint in robot.plant.joints]
    for row, torques, stance_leg in ((1, statics.on_left, 0), (2, statics.on_right, 1)):
        for leg in (0, 1):
            columns = slice(6 * leg, 6 * leg + 6)
            expected = held_moments(model, statics.poses[row], names[columns], stance=leg == stance_leg)
            assert torques[columns] == pytest.approx(expected, abs=TORQUE_TOL)
    # standing on both feet the two legs mirror each other (the models are symmetric to 1 mm)
    mirror = np.array([-1, -1, 1, 1, 1, -1] * 2)
    assert statics.both_feet[6:] == pytest.approx(statics.both_feet[:6] * mirror[:6], abs=0.5)


@needs_robots
@pytest.mark.parametrize("path", [TALOS, T1], ids=["talos", "t1"])
def test_both_feet_is_the_ready_posture(path: Path) -> None:
    """Standing, the base is at the ready posture's height and the knees bent as in it (the CoM over the soles'
    centres rather than the ankles moves the others by a few hundredths of a radian)."""
    robot = load_robot(path)
    assert robot.plant is not None and robot.legs is not None
    statics = static_torques(robot)
    plant = build_plant(robot)
    data = mujoco.MjData(plant.model)
    data.qpos[:] = statics.poses[0]
    mujoco.mj_kinematics(plant.model, data)
    pelvis = mujoco.mj_name2id(plant.model, mujoco.mjtObj.mjOBJ_SITE, "pelvis")
    assert data.site_xpos[pelvis][2] == pytest.approx(robot.pelvis_height, abs=1e-9)  # [m]
    columns = list(plant.leg_columns)
    knees = [statics.poses[0][plant.leg_qpos[columns.index(c)]] for c in (3, 9)]  # [rad] the knee columns
    ready = [chain.reference[3] for chain in robot.legs]  # [rad] a chain's fourth joint is its knee
    assert knees == pytest.approx(ready, abs=0.01)  # [rad]


@needs_robots
def test_t1_one_foot_torques_and_limits() -> None:
    statics = static_torques(load_robot(T1))
    column = {name: i for i, name in enumerate(JOINT_COLUMNS)}
    # Booster T1's pitch-roll-yaw hip in its ready posture: the sideways moment of ~26 kg over one sole needs
    # 33 N m of its 30 N m hip roll (a walk's sway keeps the CoM inside of the sole's centre).
    assert abs(statics.on_right[column["right_hip_roll"]]) == pytest.approx(32.90, abs=0.05)
    assert abs(statics.on_right[column["right_hip_yaw"]]) == pytest.approx(14.18, abs=0.05)
    assert statics.limits[column["right_hip_roll"]] == pytest.approx(30.0)
    assert statics.over_limit == ["left_hip_roll", "right_hip_roll"]
    assert statics.one_foot == pytest.approx(np.maximum(np.abs(statics.on_left), np.abs(statics.on_right)))


def test_box_models_are_refused() -> None:
    with pytest.raises(InvalidParameterError, match="imported from its MJCF or URDF"):
        static_torques(load_robot("hubo"))


@needs_robots
def test_zmpwalk_robot_prints_the_static_torques_and_flags_what_exceeds(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from zmpwalk.cli import main

    assert main(["robot", str(T1)]) == 0
    out = capsys.readouterr().out
    assert "2 feet" in out and "1 foot" in out
    assert "over the actuator's limit standing still: left_hip_roll, right_hip_roll" in out
    assert main(["robot", str(T1), "--json"]) == 0
    joints = {j["column"]: j for j in json.loads(capsys.readouterr().out)["joints"]}
    assert abs(joints["right_hip_roll"]["static_torque"]["on_right"]) == pytest.approx(32.90, abs=0.05)


def test_a_limit_below_the_static_torque_is_named() -> None:
    statics = StaticTorques(both_feet=np.zeros(12), on_left=np.full(12, 5.0), on_right=np.full(12, -7.0),
                            limits=np.full(12, 10.0), poses=np.zeros((3, 7)))
    assert statics.over_limit == []
    limits = statics.limits.copy()
    limits[3] = 6.0  # left knee: 7 N m on one foot (the other stance's), 6 N m motor
    assert dataclasses.replace(statics, limits=limits).over_limit == ["left_knee"]
