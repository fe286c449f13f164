"""Any 6-DoF leg: the Paden-Kahan closed form against the canonical leg, FK round trips, the Jacobian against
finite differences, and the numeric IK against the closed form."""

import numpy as np
import pytest

from zmpwalk.kinematics import rot_x, rot_y, rot_z
from zmpwalk.leg_chain import LegChain
from zmpwalk.robots import load_robot

EX, EY, EZ = np.eye(3)


def hubo_chain() -> tuple[tuple[np.ndarray, float, float], LegChain]:
    """HUBO's left leg as a chain of axes and points (no link lengths: the Paden-Kahan closed form)."""
    robot = load_robot("hubo")
    hip = np.array(robot.hip_in_pelvis(1))
    knee = hip + [0.0, 0.0, -robot.thigh_length]
    ankle = knee + [0.0, 0.0, -robot.shank_length]
    chain = LegChain(1, tuple("abcdef"), np.array([EZ, EX, EY, EY, EY, EX]),
                     np.array([hip, hip, hip, knee, ankle, ankle]), ankle, reference=np.array([0, 0, -0.5, 1, -0.5, 0]))
    return (hip, robot.thigh_length, robot.shank_length), chain


def canonical_fk(hip: np.ndarray, thigh: float, shank: float, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The yaw-roll-pitch-pitch-pitch-roll leg of Lim et al. in closed form: ankle and foot rotation."""
    hip_rotation = rot_z(q[:, 0]) @ rot_x(q[:, 1])
    leg_vector = np.stack([-thigh * np.sin(q[:, 2]) - shank * np.sin(q[:, 2] + q[:, 3]), np.zeros(len(q)),
                           -thigh * np.cos(q[:, 2]) - shank * np.cos(q[:, 2] + q[:, 3])], axis=-1)
    ankle = hip + np.einsum("nij,nj->ni", hip_rotation, leg_vector)
    return ankle, hip_rotation @ rot_y(q[:, 2] + q[:, 3] + q[:, 4]) @ rot_x(q[:, 5])


def pitch_roll_yaw_chain() -> LegChain:
    """Hip pitch, roll, yaw (meeting), knee 10 mm forward of the hip line, pitch-roll ankle."""
    hip = np.array([0.0, 0.08, -0.05])
    knee = hip + [0.01, 0.0, -0.3]
    ankle = hip + [0.01, 0.0, -0.6]
    return LegChain(1, tuple("abcdef"), np.array([EY, EX, EZ, EY, EY, EX]),
                    np.array([hip, hip, hip, knee, ankle, ankle]), ankle,
                    reference=np.array([-0.5, 0, 0, 1.0, -0.5, 0]))


def random_angles(rng: np.random.Generator, n: int) -> np.ndarray:
    q = rng.uniform(-0.4, 0.4, (n, 6))
    q[:, 3] = rng.uniform(0.2, 1.5, n)
    return q


def test_chain_fk_equals_the_canonical_leg() -> None:
    lengths, chain = hubo_chain()
    q = random_angles(np.random.default_rng(1), 2000)
    p1, r1 = canonical_fk(*lengths, q)
    p2, r2 = chain.fk(q)
    assert np.abs(p1 - p2).max() < 1e-12  # [m]
    assert np.abs(r1 - r2).max() < 1e-12


@pytest.mark.parametrize("make", [lambda: hubo_chain()[1], pitch_roll_yaw_chain])
def test_closed_form_round_trip_any_hip_order(make) -> None:  # type: ignore[no-untyped-def]
    chain = make()
    assert chain.closed_form
    q = random_angles(np.random.default_rng(2), 2000)
    if chain.axes[0] @ EY > 0.5:
        q[:, 0] -= 0.3
    position, rotation = chain.fk(q)
    solved, excess = chain.solve(position, rotation)
    assert np.abs(solved - q).max() < 1e-9  # [rad]
    assert np.all(excess <= 0)


@pytest.mark.parametrize("make", [lambda: hubo_chain()[1], pitch_roll_yaw_chain])
def test_numeric_agrees_with_closed_form(make) -> None:  # type: ignore[no-untyped-def]
    chain = make()
    q = random_angles(np.random.default_rng(3), 500)
    position, rotation = chain.fk(q)
    closed, _ = chain.solve(position, rotation, numeric=False)
    numeric, excess = chain.solve(position, rotation, numeric=True)
    assert np.abs(closed - numeric).max() < 1e-6  # [rad]
    assert np.all(excess <= 0)


def test_jacobian_matches_finite_differences() -> None:
    chain = pitch_roll_yaw_chain()
    q = random_angles(np.random.default_rng(4), 5)
    jacobian = chain.jacobian(q)
    eps = 1e-7
    for i in range(6):
        dq = np.zeros(6)
        dq[i] = eps
        plus, _ = chain.fk(q + dq)
        minus, _ = chain.fk(q - dq)
        assert np.abs((plus - minus) / (2 * eps) - jacobian[:, :3, i]).max() < 1e-6  # [m/rad]


def test_offset_hip_axes_use_the_numeric_ik() -> None:
    hip = np.array([0.0, 0.1, -0.1])
    roll = hip + [0.0, 0.0, -0.02]
    yaw = roll + [0.0, 0.0, -0.08]
    knee = yaw + [-0.014, 0.0, -0.13]
    ankle = knee + [0.0, 0.0, -0.28]
    chain = LegChain(1, tuple("abcdef"), np.array([EY, EX, EZ, EY, EY, EX]),
                     np.array([hip, roll, yaw, knee, ankle, ankle + [0, 0, -0.012]]), ankle,
                     reference=np.array([-0.4, 0, 0, 0.8, -0.4, 0]))
    assert not chain.closed_form
    q = random_angles(np.random.default_rng(5), 300)
    position, rotation = chain.fk(q)
    solved, excess = chain.solve(position, rotation)
    back, back_rotation = chain.fk(solved)
    assert np.all(excess <= 0)
    assert np.abs(back - position).max() < 1e-7  # [m]
    assert np.abs(back_rotation - rotation).max() < 1e-7


def test_unreachable_target_reports_excess() -> None:
    _, chain = hubo_chain()
    position, rotation = chain.fk(np.array([[0, 0, -0.5, 1.0, -0.5, 0]]))
    position[0, 2] -= 0.5  # 0.5 m further down than a straight leg reaches from there
    _, excess = chain.solve(position, rotation)
    assert excess[0] > 0.1


def test_any_chain_solves_flat_soles_with_joint_rates_in_each_path() -> None:
    """A chain without the straight leg's own closed form: the flat-sole paths are its IK and J^-1 twist."""
    from zmpwalk.slices import run_to_end

    chain = pitch_roll_yaw_chain()
    rng = np.random.default_rng(6)
    q = random_angles(rng, 200)
    q[:, 0] -= 0.3
    position, _ = chain.fk(q)
    yaw = rng.uniform(-0.3, 0.3, 200)
    velocity, yaw_rate = rng.normal(size=(200, 3)), rng.normal(size=200)
    angles, excess, rates = chain.solve_flat(position, yaw, velocity, yaw_rate)
    assert np.all(excess <= 0) and rates is not None
    np.testing.assert_array_equal(angles, chain.solve(position, rot_z(yaw))[0])
    back, rotation = chain.fk(angles)
    assert np.abs(back - position).max() < 1e-9 and np.abs(rotation - rot_z(yaw)).max() < 1e-9
    twist = np.column_stack([velocity, np.zeros((200, 2)), yaw_rate])
    assert np.abs(np.einsum("nij,nj->ni", chain.jacobian(angles), rates) - twist).max() < 1e-9
    rows, row_rates = np.empty((6, 200)), np.empty((6, 200))
    parts_excess = run_to_end(chain.solve_flat_in_parts((position[:, 0], position[:, 1], position[:, 2]), yaw,
                                                        (*velocity.T, yaw_rate), True, rows, row_rates))
    np.testing.assert_array_equal(rows.T, angles)
    np.testing.assert_array_equal(row_rates.T, rates)
    np.testing.assert_array_equal(parts_excess, excess)
    np.testing.assert_array_equal(chain.solve_flat_one(tuple(position[7]), float(yaw[7])), angles[7])
