"""The plant's integrator against the PD layer's damping (zmpwalk.sim.integrator), and a
diverged simulation reported as one (zmpwalk.errors.SimulationError)."""

from __future__ import annotations

import pickle
from pathlib import Path

import mujoco
import numpy as np
import pytest

from zmpwalk.errors import SimulationError
from zmpwalk.online import OnlineWalker
from zmpwalk.robots import load_robot
from zmpwalk.sim.integrator import EULER_BOUND, explicit_damping_ratio
from zmpwalk.sim.mujoco_plant import MujocoPlant
from zmpwalk.sim.plant import build_plant

PENDULUM = """<mujoco><option timestep="{h}" integrator="{integrator}" gravity="0 0 0"/><worldbody>
<body><joint name="hinge" axis="0 0 1"/><inertial pos="0 0 0" mass="1" diaginertia="{inertia} {inertia} {inertia}"/>
</body></worldbody><actuator><position joint="hinge" kp="0" kv="{kv}"/></actuator></mujoco>"""


@pytest.mark.parametrize("ratio", [1.5, 2.5])
def test_explicit_damping_grows_past_its_bound_and_implicit_does_not(ratio: float) -> None:
    """One degree of freedom, v' = -(kv / I) v: Euler steps v by (1 - kv h / I), which grows once kv h / I >= 2;
    implicitfast steps it by 1 / (1 + kv h / I)."""
    h, inertia = 0.001, 0.01  # [s], [kg m^2]
    kv = ratio * inertia / h  # [N m s/rad]
    for integrator, factor in (("Euler", 1.0 - ratio), ("implicitfast", 1.0 / (1.0 + ratio))):
        model = mujoco.MjModel.from_xml_string(PENDULUM.format(h=h, integrator=integrator, inertia=inertia, kv=kv))
        data = mujoco.MjData(model)
        data.qvel[0] = 1.0  # [rad/s]
        mujoco.mj_step(model, data, 10)
        assert data.qvel[0] == pytest.approx(factor**10, rel=1e-9)
        assert explicit_damping_ratio(model, data.qpos) == pytest.approx(ratio, rel=1e-12)
    assert (abs(1.0 - ratio) > 1.0) == (ratio >= 2.0)


def _torso_on_a_waist(waist_kv: float) -> str:
    """A biped whose 60 kg torso sits on a waist roll held by a position servo of damping ``waist_kv`` [N m s/rad]
    over a 2 kg pelvis (whose legs' motors the PD layer drives)."""
    legs = ""
    for side, y in (("l", 0.1), ("r", -0.1)):
        inner = '<geom type="box" size="0.11 0.07 0.01" pos="0.02 0 -0.05" mass="0.8"/>'
        for name, axis, pos in reversed((("hy", "0 0 1", f"0 {y} -0.1"), ("hr", "1 0 0", "0 0 0"),
                                         ("hp", "0 1 0", "0 0 0"), ("kn", "0 1 0", "0 0 -0.3"),
                                         ("ap", "0 1 0", "0 0 -0.3"), ("ar", "1 0 0", "0 0 0"))):
            inner = (f'<body name="{side}_{name}" pos="{pos}"><joint name="{side}_{name}" axis="{axis}" '
                     'range="-1 1" armature="0.05"/><inertial pos="0 0 -0.1" mass="1" diaginertia="0.01 0.01 0.002"/>'
                     f"{inner}</body>")
        legs += inner
    motors = "".join(f'<motor joint="{s}_{n}"/>' for s in "lr" for n in ("hy", "hr", "hp", "kn", "ap", "ar"))
    return f"""<mujoco><compiler angle="radian"/><worldbody><geom type="plane" size="5 5 .1"/>
<body name="pelvis" pos="0 0 0.75"><freejoint/><inertial pos="0 0 0" mass="2" diaginertia="0.02 0.02 0.02"/>
 <body name="torso" pos="0 0 0.1"><joint name="waist" axis="1 0 0" range="-0.5 0.5"/>
  <inertial pos="0 0 0.3" mass="60" diaginertia="1.5 1.5 0.5"/></body>{legs}</body></worldbody>
<actuator><position joint="waist" kp="5000" kv="{waist_kv}"/>{motors}</actuator></mujoco>"""


@pytest.mark.parametrize(("waist_kv", "integrator"), [(2000.0, mujoco.mjtIntegrator.mjINT_IMPLICITFAST),
                                                      (200.0, mujoco.mjtIntegrator.mjINT_EULER)])
def test_the_plant_integrates_damping_implicitly_where_euler_would_grow(tmp_path: Path, waist_kv: float,
                                                                        integrator: int) -> None:
    """The model's Euler integrator is kept while every damping mode is within its explicit bound, and replaced by
    implicitfast where one is not (Atlas's torso on its back joints)."""
    path = tmp_path / "waist.xml"
    path.write_text(_torso_on_a_waist(waist_kv), encoding="utf-8")
    plant = build_plant(load_robot(path))
    assert mujoco.MjModel.from_xml_path(str(path)).opt.integrator == mujoco.mjtIntegrator.mjINT_EULER
    assert plant.model.opt.integrator == integrator
    assert (explicit_damping_ratio(plant.model, plant.qpos_hold) >= EULER_BOUND) == (waist_kv > 1000.0)


def test_the_bound_is_the_damping_modes_not_one_joint_at_a_time() -> None:
    """Two hinges in series, each damper within its own bound taken alone with the other free (``kv h (M^-1)_jj``
    = 1.9 at most), can still have a mode past 2: the ratio is the largest eigenvalue of ``h D^1/2 M^-1 D^1/2``, checked
    against numpy on the model's own mass matrix and against the growth Euler gives that mode."""
    h = 0.001  # [s]
    text = """<mujoco><option timestep="{h}" gravity="0 0 0"/><worldbody>
<body><joint name="a" axis="0 0 1"/><inertial pos="0.1 0 0" mass="1" diaginertia="0.001 0.001 0.001"/>
 <body pos="0.2 0 0"><joint name="b" axis="0 0 1"/><inertial pos="0.1 0 0" mass="1" diaginertia="0.001 0.001 0.001"/>
 </body></body></worldbody><actuator><position joint="a" kp="0" kv="{kv}"/><position joint="b" kp="0" kv="{kv}"/>
</actuator></mujoco>"""
    probe = mujoco.MjModel.from_xml_string(text.format(h=h, kv=1.0))
    data = mujoco.MjData(probe)
    mujoco.mj_forward(probe, data)
    mass = np.zeros((2, 2))
    mujoco.mj_fullM(probe, data, mass)
    inverse = np.linalg.inv(mass)
    kv = 1.9 / (h * inverse.diagonal().max())  # [N m s/rad] each joint alone at 1.9
    model = mujoco.MjModel.from_xml_string(text.format(h=h, kv=kv))
    largest = float(np.linalg.eigvals(h * inverse * kv).real.max())
    assert largest > 2.0  # the coupled mode is past the bound
    assert explicit_damping_ratio(model, np.zeros(2)) == pytest.approx(largest, rel=1e-9)
    data = mujoco.MjData(model)
    values, vectors = np.linalg.eig(h * inverse * kv)
    data.qvel[:] = 1e-6 * vectors[:, int(np.argmax(values.real))].real  # [rad/s] small: M stays as it is
    before = np.linalg.norm(data.qvel)
    mujoco.mj_step(model, data, 5)
    assert np.linalg.norm(data.qvel) == pytest.approx(before * abs(1.0 - largest) ** 5, rel=1e-6)  # Euler grows it


def test_a_diverged_simulation_raises_at_its_tick(tmp_path: Path) -> None:
    """Forced back to Euler, the waist's damping diverges within a few ticks: the plant raises at the end of that
    tick, on its own clock (MuJoCo's restarts at its reset), instead of walking on from the state MuJoCo resets to;
    the error pickles with its fields."""
    path = tmp_path / "waist.xml"
    path.write_text(_torso_on_a_waist(2000.0), encoding="utf-8")
    robot = load_robot(path)
    plant = MujocoPlant(robot, 1000.0)
    plant.model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    plant.stand(OnlineWalker(robot, rate=1000.0, joints=True).tick())
    plant.data.qvel[6] = 1.0  # [rad/s] the waist
    ticks = [0]
    with pytest.raises(SimulationError, match=r"diverged by t = .*: MuJoCo found a non-finite or huge") as raised:
        while ticks[0] < 1000:
            ticks[0] += 1
            plant.step()
    assert 1 < ticks[0] < 100  # the tick that raised
    assert raised.value.time == pytest.approx(plant.time, abs=1e-12) == pytest.approx(ticks[0] / 1000.0)  # [s]
    error = pickle.loads(pickle.dumps(raised.value))
    assert (error.joint, error.time, error.quantity) == (raised.value.joint, raised.value.time, raised.value.quantity)


def test_a_non_finite_position_names_its_joint(tmp_path: Path) -> None:
    """MuJoCo names a bad position by its qpos address: the error maps it to the joint that holds it (after a free
    joint's seven positions the addresses and the degrees of freedom part)."""
    path = tmp_path / "waist.xml"
    path.write_text(_torso_on_a_waist(200.0), encoding="utf-8")
    robot = load_robot(path)
    plant = MujocoPlant(robot, 1000.0)
    plant.stand(OnlineWalker(robot, rate=1000.0, joints=True).tick())
    knee = plant.model.joint("r_kn")
    plant.data.qpos[knee.qposadr[0]] = np.nan
    with pytest.raises(SimulationError) as raised:
        plant.step()
    assert (raised.value.joint, raised.value.quantity, raised.value.time) == ("r_kn", "position", 0.001)
