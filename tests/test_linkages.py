"""Closed linkages: a parallel ankle (two cranks on the shank, each pushing the foot through a rod: LimX Luna's
class) and a parallel waist. The PD layer drives the loop's unactuated hinges (the ankle's pitch and roll, the
waist's pitch), the cranks and rods follow through the equalities, the stand starts with every loop closed, and
the ankle's force-torque sensor reads the ground under the sole, not the joint the rods bypass
(zmpwalk.robots.pd.coupled_joints, zmpwalk.sim.poses.close_loops, zmpwalk.sim.plant)."""

from __future__ import annotations

import json
from pathlib import Path

import mujoco
import numpy as np
import pytest

from test_pd_layer import LEG
from zmpwalk.robots import load_robot
from zmpwalk.robots.description import PD_LOAD_STIFFNESS
from zmpwalk.robots.linkages import LOOP_TOLERANCE
from zmpwalk.sim.loop import simulate_controller
from zmpwalk.sim.plant import build_plant
from zmpwalk.sim.poses import close_loops

CRANK = """
    <body name="{s}_crank_{k}" pos="0 {y} -0.1"><joint name="{s}_crank_{k}" axis="0 1 0"/>
     <geom type="capsule" fromto="0 0 0 -0.04 0 0" size="0.005" mass="0.05" contype="0" conaffinity="0"/>
     <body name="{s}_rod_{k}" pos="-0.04 0 0"><joint name="{s}_rod_{k}" type="ball"/>
      <geom type="capsule" fromto="0 0 0 0 0 -0.18" size="0.004" mass="0.05" contype="0" conaffinity="0"/></body>
    </body>"""
TORSO_MASS = 6.0  # [kg], its centre 0.2 m above the waist pitch axis
ROD = 0.18  # [m] each rod's length: its end meets the foot 20 mm above the ankle, 40 mm behind it


def linkage_biped() -> str:
    """A 19.9 kg biped whose ankles are turned by two crank-and-rod pairs each (motors on the cranks, none on the
    ankle joints) and whose 6 kg torso sits on an unactuated waist pitch that a crank holds through a rod."""
    ankle_end = "     </body>\n    </body>\n   </body>"  # the foot, ankle and shank ends
    legs = "".join(LEG.format(s=s, y=y, knee="").replace(ankle_end, ankle_end[:-11] + CRANK.format(s=s, k="a", y=0.03)
                                                        + CRANK.format(s=s, k="b", y=-0.03) + "\n   </body>")
                   for s, y in (("l", 0.1), ("r", -0.1)))
    motors = "".join(f'<motor name="{s}_{j}_m" joint="{s}_{j}" ctrlrange="-40 40"/>'
                     for s in ("l", "r") for j in ("hy", "hr", "hp", "kn", "crank_a", "crank_b"))
    connects = "".join(f'<connect body1="{s}_rod_{k}" body2="{s}_foot" anchor="0 0 -{ROD}"/>'
                       for s in ("l", "r") for k in ("a", "b"))
    return f"""<mujoco><compiler angle="radian"/><default><joint armature="0.01" damping="0.1"/></default>
<worldbody><geom type="plane" size="5 5 .1"/>
<body name="base" pos="0 0 0.8"><freejoint/><geom type="box" size="0.1 0.15 0.05" mass="4"/>
 <body name="torso"><joint name="waist_pitch" axis="0 1 0" range="-0.5 0.5"/>
  <geom type="box" size="0.08 0.12 0.1" pos="0 0 0.2" mass="{TORSO_MASS}" contype="0" conaffinity="0"/>
  <body name="waist_crank" pos="0.05 0 0.1"><joint name="waist_crank" axis="0 1 0"/>
   <geom type="capsule" fromto="0 0 0 0.04 0 0" size="0.005" mass="0.05" contype="0" conaffinity="0"/>
   <body name="waist_rod" pos="0.04 0 0"><joint name="waist_rod" type="ball"/>
    <geom type="capsule" fromto="0 0 0 0 0 -0.1" size="0.004" mass="0.05" contype="0" conaffinity="0"/></body>
  </body>
 </body>
{legs}</body></worldbody>
<equality><connect body1="waist_rod" body2="base" anchor="0 0 -0.1"/>{connects}</equality>
<actuator>{motors}<motor name="waist_m" joint="waist_crank" ctrlrange="-40 40"/></actuator></mujoco>"""


@pytest.fixture(scope="module")
def model_path(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("linkage") / "linkage.xml"
    path.write_text(linkage_biped(), encoding="utf-8")
    return path


def _residual(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """The largest residual of the model's equalities [m]."""
    mujoco.mj_forward(model, data)
    rows = data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY
    return float(np.abs(data.efc_pos[:data.nefc][rows]).max())


def test_the_pd_layer_drives_the_loops_unactuated_hinges_and_releases_the_cranks(model_path: Path) -> None:
    robot = load_robot(model_path)
    assert robot.plant is not None
    joints = {joint.role: joint.actuator for joint in robot.plant.joints[:6]}
    for role in ("ankle_pitch", "ankle_roll"):  # no motor of their own: the PD layer's, on the rule's gains
        actuator = joints[role]
        assert actuator is not None and actuator.kind == "none" and actuator.pd_layer
        assert actuator.kp == pytest.approx(PD_LOAD_STIFFNESS * robot.mass * robot.gravity * robot.pendulum_length,
                                            rel=1e-12)
    cranks = {f"{s}_{part}_{k}" for s in ("l", "r") for part in ("crank", "rod") for k in ("a", "b")}
    assert set(robot.plant.coupled_joints) == cranks | {"waist_crank", "waist_rod"}
    held = dict(robot.plant.pd_joints)
    assert "waist_pitch" in held and not cranks & set(held) and "waist_crank" not in held
    # the waist pitch holds the torso: at least 4 times the weight moment it carries (6 kg, 0.2 m up)
    assert held["waist_pitch"].kp >= PD_LOAD_STIFFNESS * TORSO_MASS * 9.81 * 0.2 - 1e-9
    assert "waist_pitch" in robot.plant.held_joints


def test_the_stand_closes_every_loop_and_the_ankle_sensor_reads_the_ground(model_path: Path) -> None:
    robot = load_robot(model_path)
    plant = build_plant(robot)
    model = plant.model
    assert len(plant.coupled_dofs) == 2 * (2 * (1 + 3)) + (1 + 3)  # cranks (hinges) and rods (balls)
    data = mujoco.MjData(model)
    data.qpos[:] = plant.qpos_hold
    assert robot.legs is not None
    for chain in robot.legs:  # the ready posture's knees and ankles: the rods torn from the feet
        for name, angle in zip(chain.joint_names, chain.reference, strict=True):
            data.qpos[model.joint(name).qposadr[0]] = angle
    assert _residual(model, data) > 0.005  # [m]
    close_loops(plant, data)
    assert _residual(model, data) < LOOP_TOLERANCE * 10
    for label in ("left", "right"):  # the sensors sit on a massless sole body that carries the foot's geoms
        sole = int(model.site_bodyid[model.site(f"{label}_ankle").id])
        assert model.body(sole).name == f"zmpwalk_{label}_sole" and model.body_mass[sole] == 0.0
        assert int(model.body_parentid[sole]) == model.body(f"{label[0]}_foot").id
        assert (model.geom_bodyid == sole).sum() == 1 and model.body_mass[model.body(f"{label[0]}_foot").id] == 0.5
    run = simulate_controller(robot, (), duration=1.5)  # standing: the soles carry the whole weight
    total = run.result.force_left[-200:] + run.result.force_right[-200:]
    weight = float(np.sum(model.body_mass)) * robot.gravity
    assert not run.result.fell
    assert np.abs(total - weight).max() < 0.01 * weight  # [N]


@pytest.mark.slow
def test_a_parallel_ankled_biped_walks(model_path: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from zmpwalk.cli import main

    steps = tmp_path / "steps.toml"
    steps.write_text("[[steps]]\nduration = 0.8\nforward = 0.08\nrepeat = 6\n", encoding="utf-8")
    code = main(["simulate", "--robot", str(model_path), str(steps), "--json"])
    summary = json.loads(capsys.readouterr().out)
    assert code == 0 and summary["verdict"]["state"] == "PASS" and not summary["fell"]
    assert summary["final_feet_error"] < 0.01  # [m]
    assert summary["cop_error_rms"] < 0.03  # [m]
    assert summary["distance"] == pytest.approx(0.48, abs=0.04)  # [m]


def test_an_export_refuses_the_rods_ball_joints_naming_one(model_path: Path) -> None:
    """Every clip format has one column per joint after the free base: a rod's ball joint is named in the error."""
    from zmpwalk.errors import InvalidParameterError
    from zmpwalk.export.names import joint_names

    with pytest.raises(InvalidParameterError, match=r"'waist_rod \(ball joint\)'.*ball-jointed rods"):
        joint_names(build_plant(load_robot(model_path)).model)


def test_the_ankles_torque_limits_come_from_the_cranks_through_the_linkage(model_path: Path) -> None:
    """The ankle's pitch and roll get the torque their two 40 N m cranks can give them (virtual work,
    ``tau_ankle = G^T tau_cranks``, ``G = d q_cranks / d q_ankle`` in the ready posture with its loops closed):
    ``G`` from the equalities' Jacobian against finite differences of the closed linkage."""
    from zmpwalk.robots.linkages import close_equalities, joint_dofs

    robot = load_robot(model_path)
    assert robot.plant is not None and robot.legs is not None
    model = mujoco.MjModel.from_xml_path(str(model_path))
    data = mujoco.MjData(model)
    for chain in robot.legs:  # the ready posture
        for name, angle in zip(chain.joint_names, chain.reference, strict=True):
            data.qpos[model.joint(name).qposadr[0]] = angle
    coupled = joint_dofs(model, [model.joint(name).id for name in robot.plant.coupled_joints])
    close_equalities(model, data, coupled)
    base = data.qpos.copy()
    cranks = [model.joint(f"l_crank_{k}").qposadr[0] for k in ("a", "b")]
    gear = np.zeros((2, 2))  # d q_cranks / d q_ankle, by central differences
    for column, name in enumerate(("l_ap", "l_ar")):
        moved = []
        for sign in (1.0, -1.0):
            data.qpos[:] = base
            data.qpos[model.joint(name).qposadr[0]] += sign * 1e-6
            close_equalities(model, data, coupled)
            moved.append(data.qpos[cranks].copy())
        gear[:, column] = (moved[0] - moved[1]) / 2e-6
    to_cranks = np.linalg.inv(gear.T)
    expected = [float(np.min(40.0 / np.abs(to_cranks[:, j]))) for j in range(2)]  # [N m]
    limits = {joint.name: joint.actuator.force_limit for joint in robot.plant.joints if joint.actuator is not None}
    assert [limits["l_ap"], limits["l_ar"]] == pytest.approx(expected, rel=1e-4)
    assert 60.0 < limits["l_ap"] < 120.0 and 40.0 < limits["l_ar"] < 80.0  # [N m]: two 40 N m cranks, 40 mm levers


def test_the_soles_geoms_keep_their_pose_and_unnamed_rods_are_found(tmp_path: Path) -> None:
    """A foot geom turned by ``euler`` and one placed in a ``<frame>`` sit where the model puts them once moved to
    the sole body; rods whose ball joints have no name are the coupled joints all the same (each its own three
    degrees of freedom)."""
    text = linkage_biped().replace(
        '<geom type="box" size="0.1 0.05 0.01" pos="0 0 -0.05" mass="0.5"/>',
        '<geom type="box" size="0.1 0.05 0.01" pos="0 0 -0.05" mass="0.5"/>'
        '<geom type="box" size="0.02 0.01 0.005" pos="0.05 0 -0.04" euler="0 0 0.5" mass="0"/>'
        '<frame pos="-0.05 0.01 -0.03"><geom type="sphere" size="0.01" pos="0 0 -0.005" mass="0"/></frame>')
    for side in ("l", "r"):
        for k in ("a", "b"):
            text = text.replace(f'<joint name="{side}_rod_{k}" type="ball"/>', '<joint type="ball"/>')
    path = tmp_path / "unnamed.xml"
    path.write_text(text, encoding="utf-8")
    robot = load_robot(path)
    plant = build_plant(robot)
    original = mujoco.MjModel.from_xml_path(str(path))
    assert robot.plant is not None and len(plant.coupled_dofs) == len(set(plant.coupled_dofs.tolist())) == 20
    assert {int(plant.model.dof_jntid[d]) for d in plant.coupled_dofs} == {
        j for j in range(original.njnt) if int(original.jnt_type[j]) == mujoco.mjtJoint.mjJNT_BALL
        or original.joint(j).name.endswith(("crank_a", "crank_b", "waist_crank"))}
    placed, moved = mujoco.MjData(original), mujoco.MjData(plant.model)
    placed.qpos[:] = moved.qpos[:] = original.qpos0
    mujoco.mj_kinematics(original, placed)
    mujoco.mj_kinematics(plant.model, moved)
    sole = plant.model.body("zmpwalk_left_sole").id
    foot = original.body("l_foot").id
    before = sorted((placed.geom_xpos[g].round(9).tolist(), placed.geom_xmat[g].round(9).tolist())
                    for g in range(original.ngeom) if original.geom_bodyid[g] == foot)
    after = sorted((moved.geom_xpos[g].round(9).tolist(), moved.geom_xmat[g].round(9).tolist())
                   for g in range(plant.model.ngeom) if plant.model.geom_bodyid[g] == sole)
    assert len(before) == len(after) == 3 and np.allclose(np.array([p for p, _ in before]),
                                                           np.array([p for p, _ in after]), atol=1e-9)
    assert np.allclose(np.array([m for _, m in before]), np.array([m for _, m in after]), atol=1e-9)


def test_a_joint_name_the_model_lacks_and_a_loop_that_cannot_close_are_errors(model_path: Path) -> None:
    """``joint_id`` names the joint it cannot find; a loop that the joints given cannot close (a crank turned alone,
    its rod held) is refused naming its residual, the posture's other joints untouched."""
    from zmpwalk.errors import InvalidParameterError
    from zmpwalk.robots.linkages import close_or_refuse, joint_dofs, joint_id

    model = mujoco.MjModel.from_xml_path(str(model_path))
    assert joint_id(model, "l_crank_a") == model.joint("l_crank_a").id
    assert joint_id(model, f"#{model.joint('l_rod_a').id}") == model.joint("l_rod_a").id  # an unnamed joint's name
    for bad in ("no_such_joint", "#999"):
        with pytest.raises(InvalidParameterError, match=r"joint = .*a joint of the model"):
            joint_id(model, bad)
    data = mujoco.MjData(model)
    data.qpos[model.joint("l_ap").qposadr[0]] = 0.5  # the foot turned: its anchor leaves the crank's circle
    kept = data.qpos.copy()
    cranks = [model.joint("l_crank_a").id]  # the crank alone, its rod held: one angle for a 3-D anchor
    with pytest.raises(InvalidParameterError, match=r"linkage residual = .* m.*must close"):
        close_or_refuse(model, data, joint_dofs(model, cranks))
    legs = [model.joint(n).qposadr[0] for n in ("l_kn", "l_ap", "l_ar", "l_hp")]
    assert np.array_equal(data.qpos[legs], kept[legs])  # only the loop's own joints were moved
