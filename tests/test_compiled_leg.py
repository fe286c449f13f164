"""The stabilizer's compiled leg (zmpwalk.stabilizer.leg) agrees with the general chain (zmpwalk.leg_chain.LegChain):
each frame of the product of exponentials, the ankle point, the sole normal, the Jacobian and the whole-body CoM, at
random seeded joint angles, on HUBO's robot-file leg and on imported robots' legs (Booster T1; Unitree H1's
five-joint leg with its virtual ankle roll)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from zmpwalk import balance_kernel  # noqa: F401  (renews a stale disk cache of the compiled modules first)
from zmpwalk.balance import Stabilizer
from zmpwalk.kinematics import leg_chains, rest_mass
from zmpwalk.robots import load_robot
from zmpwalk.robots.model import RobotModel
from zmpwalk.stabilizer.leg import ankle_in_base, com_in_base, leg_jacobian, leg_kinematics, sole_normal

ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
IMPORTED = {"booster_t1": ROBOTS / "booster_t1" / "scene.xml", "unitree_h1": ROBOTS / "unitree_h1" / "scene.xml"}
TOLERANCE = 1e-9  # [m], [rad], [-] (rotations, normals), [m/rad] (Jacobian)
SAMPLES = 25
SPREAD = 0.4  # [rad] standard deviation of the angles about the ready posture


def robot_of(name: str) -> RobotModel:
    if name in IMPORTED:
        if not IMPORTED[name].is_file():
            pytest.skip(f"{IMPORTED[name]} is absent")
        return load_robot(IMPORTED[name])
    return load_robot(name)


@pytest.mark.parametrize("name", ["hubo", "booster_t1", "unitree_h1"])
def test_the_compiled_leg_is_the_chains_own(name: str) -> None:
    robot = robot_of(name)
    stabilizer = Stabilizer(robot, 1000.0)
    chains = leg_chains(robot)
    params, table = stabilizer._params, stabilizer._chain
    rest, rest_com = rest_mass(robot)
    total = rest + sum(float(c.link_masses.sum()) for c in chains)
    rng = np.random.default_rng(11)
    work = np.zeros((6, 7, 12))
    jacobian = np.zeros((6, 6))
    for _ in range(SAMPLES):
        columns = np.zeros(12)  # role-ordered, as the pattern and the encoders give them
        for leg, chain in enumerate(chains):
            columns[6 * leg:6 * leg + 6] = (np.asarray(chain.reference) + rng.normal(0.0, SPREAD, 6))[
                list(chain.role_order)]
        moment = rest * np.asarray(rest_com)
        for leg, chain in enumerate(chains):
            pose = columns[6 * leg:6 * leg + 6][np.argsort(chain.role_order)][None]  # chain-ordered
            frames = work[2 * leg]
            leg_kinematics(table, leg, columns, frames)
            rotations, translations = chain.transforms(pose)
            assert np.abs(frames[:, :9].reshape(7, 3, 3) - rotations[0]).max() < TOLERANCE
            assert np.abs(frames[:, 9:] - translations[0]).max() < TOLERANCE
            ankle = ankle_in_base(params, leg, frames)
            position, sole_rotation = chain.fk(pose)
            assert np.abs(np.array(ankle) - position[0]).max() < TOLERANCE
            assert np.abs(np.array(sole_normal(params, leg, frames)) - sole_rotation[0][:, 2]).max() < TOLERANCE
            leg_jacobian(table, leg, frames, ankle, jacobian)
            assert np.abs(jacobian - chain.jacobian(pose)[0]).max() < TOLERANCE
            moment = moment + chain.link_masses @ chain.link_com_positions(pose)[0]
        assert np.abs(np.array(com_in_base(params, table, work, 0)) - moment / total).max() < TOLERANCE


def test_a_jacobian_column_is_the_ankles_motion_per_radian() -> None:
    """The compiled Jacobian against a central difference of the compiled forward kinematics (HUBO)."""
    robot = load_robot("hubo")
    stabilizer = Stabilizer(robot, 1000.0)
    params, table = stabilizer._params, stabilizer._chain
    columns = np.concatenate([np.asarray(c.reference)[list(c.role_order)] for c in leg_chains(robot)])
    frames, jacobian, step = np.zeros((7, 12)), np.zeros((6, 6)), 1e-6  # [rad]
    leg_kinematics(table, 0, columns, frames)
    leg_jacobian(table, 0, frames, ankle_in_base(params, 0, frames), jacobian)
    for joint in range(6):
        ends = []
        for sign in (1.0, -1.0):
            moved = columns.copy()
            moved[int(table[0, joint, 10])] += sign * step
            leg_kinematics(table, 0, moved, frames)
            ends.append(np.array(ankle_in_base(params, 0, frames)))
        assert np.abs((ends[0] - ends[1]) / (2 * step) - jacobian[:3, joint]).max() < 1e-8  # [m/rad]
