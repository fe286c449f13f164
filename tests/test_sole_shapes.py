"""Feet from every collision shape, and from explicit contact pairs: the sole a synthetic biped's import finds."""

from __future__ import annotations

from pathlib import Path

import pytest

from zmpwalk.robots import load_robot

# A 6-joint leg whose foot body carries FOOT (its geoms), the ankle 0.6 m below the hip.
LEG = """
<body name="{side}_hip" pos="0 {y} -0.1"><joint name="{side}_hy" axis="0 0 1"/><geom size="0.02" mass="1"/>
 <body name="{side}_hr"><joint name="{side}_hr" axis="1 0 0"/><geom size="0.02" mass="1"/>
  <body name="{side}_hp"><joint name="{side}_hp" axis="0 1 0"/><geom size="0.02" mass="1"/>
   <body name="{side}_shank" pos="0 0 -0.3"><joint name="{side}_kn" axis="0 1 0"/><geom size="0.02" mass="1"/>
    <body name="{side}_ank" pos="0 0 -0.3"><joint name="{side}_ap" axis="0 1 0"/>
     <geom size="0.02" mass="0.2" contype="0" conaffinity="0"/>
     <body name="{side}_foot"><joint name="{side}_ar" axis="1 0 0"/>{foot}</body>
    </body>
   </body>
  </body>
 </body>
</body>"""

# Each foot: a sole 0.2 m long (x from -0.07 to +0.13) and 0.08 m wide, its bottom 0.06 m below the ankle.
FEET = {
    "box": '<geom type="box" size="0.1 0.04 0.01" pos="0.03 0 -0.05" mass="0.5"/>',
    "capsules": ('<geom type="capsule" fromto="-0.05 0.02 -0.04 0.11 0.02 -0.04" size="0.02" mass="0.25"/>'
                 '<geom type="capsule" fromto="-0.05 -0.02 -0.04 0.11 -0.02 -0.04" size="0.02" mass="0.25"/>'),
    "cylinders": ('<geom type="cylinder" fromto="-0.07 0 -0.04 0.13 0 -0.04" size="0.02" mass="0.25"/>'
                  '<geom type="cylinder" fromto="0.03 -0.04 -0.04 0.03 0.04 -0.04" size="0.02" mass="0.25"/>'),
    "spheres": "".join(f'<geom type="sphere" size="0.01" pos="{x} {y} -0.05" mass="0.1"/>'
                       for x in (-0.07, 0.13) for y in (-0.04, 0.04)),
    "ellipsoid": '<geom type="ellipsoid" size="0.1 0.04 0.01" pos="0.03 0 -0.05" mass="0.5"/>',
    "mesh": '<geom type="mesh" mesh="{side}_sole" pos="0.03 0 -0.05" mass="0.5"/>',
}
# The soles that are not the 0.2 x 0.08 m rectangle: the capsules' lowest lines (their caps rise off the floor);
# a flat ellipsoid's outline where it lies within SOLE_BAND (2 mm) of its lowest point: semi-axes times
# sqrt(1 - (1 - 2 / 10)^2) = 0.6, sampled on a grid (within 10 %).
SOLES = {"capsules": (0.16, 0.04), "ellipsoid": (0.12, 0.048)}
MESH = ('<mesh name="{side}_sole" vertex="-0.1 -0.04 -0.01  0.1 -0.04 -0.01  0.1 0.04 -0.01  -0.1 0.04 -0.01 '
        '-0.1 -0.04 0.01  0.1 -0.04 0.01  0.1 0.04 0.01  -0.1 0.04 0.01"/>')


def biped(foot: str, contact: str = "") -> str:
    legs = "".join(LEG.format(side=side, y=y, foot=foot.format(side=side)) for side, y in (("l", 0.1), ("r", -0.1)))
    meshes = "".join(MESH.format(side=side) for side in "lr")
    return f"""<mujoco><asset>{meshes}</asset><worldbody><geom name="floor" type="plane" size="5 5 .1"/>
<body name="base" pos="0 0 0.8"><freejoint/><geom type="box" size="0.1 0.15 0.1" mass="10"/>{legs}</body>
</worldbody>{contact}</mujoco>"""


@pytest.mark.parametrize("shape", sorted(FEET))
def test_the_sole_of_every_collision_shape(tmp_path: Path, shape: str) -> None:
    path = tmp_path / f"{shape}.xml"
    path.write_text(biped(FEET[shape]), encoding="utf-8")
    robot = load_robot(path)
    length, width = SOLES.get(shape, (0.2, 0.08))
    assert robot.ankle_height == pytest.approx(0.06, abs=1.5e-3)
    tolerance = 0.1 if shape == "ellipsoid" else 1e-3  # [-] of the size: the ellipsoid's grid
    assert robot.foot_length == pytest.approx(length, rel=tolerance)
    assert robot.foot_width == pytest.approx(width, rel=tolerance)


def test_feet_whose_contacts_are_explicit_pairs(tmp_path: Path) -> None:
    """Sole geoms with contype = conaffinity = 0 that touch the floor only through <contact><pair>."""
    foot = ('<geom name="{side}_sole" type="box" size="0.1 0.04 0.01" pos="0.03 0 -0.05" mass="0.5" '
            'contype="0" conaffinity="0"/>')
    pairs = '<contact><pair geom1="l_sole" geom2="floor"/><pair geom1="r_sole" geom2="floor"/></contact>'
    path = tmp_path / "pairs.xml"
    path.write_text(biped(foot, pairs), encoding="utf-8")
    robot = load_robot(path)
    assert robot.foot_length == pytest.approx(0.2, abs=1e-6) and robot.foot_width == pytest.approx(0.08, abs=1e-6)
    assert robot.ankle_height == pytest.approx(0.06, abs=1e-6)


def test_a_foot_geom_paired_only_with_the_robot_is_not_its_sole(tmp_path: Path) -> None:
    """A larger, lower foot box kept for foot-to-foot collisions (paired with the other foot, never with the
    floor, contype = conaffinity = 0) beside the sole paired with the floor: the sole is the floor's pair."""
    foot = ('<geom name="{side}_sole" type="box" size="0.1 0.04 0.01" pos="0.03 0 -0.05" mass="0.5" '
            'contype="0" conaffinity="0"/>'
            '<geom name="{side}_guard" type="box" size="0.12 0.05 0.005" pos="0.03 0 -0.057" mass="0.01" '
            'contype="0" conaffinity="0"/>')
    pairs = ('<contact><pair geom1="l_sole" geom2="floor"/><pair geom1="r_sole" geom2="floor"/>'
             '<pair geom1="l_guard" geom2="r_guard"/></contact>')
    path = tmp_path / "guard.xml"
    path.write_text(biped(foot, pairs), encoding="utf-8")
    robot = load_robot(path)
    assert robot.foot_length == pytest.approx(0.2, abs=1e-6) and robot.foot_width == pytest.approx(0.08, abs=1e-6)
    assert robot.ankle_height == pytest.approx(0.06, abs=1e-6)


def test_a_pair_of_slightly_tilted_cylinders_is_the_sole_along_them(tmp_path: Path) -> None:
    """Two cylinders along the foot whose far ends sit 2.1 mm lower over 0.2 m (0.6 degrees, PNDbotics Adam Lite's
    0.53): measured from the world's up only their toe ends were within 2 mm of the lowest (a 0 mm long sole,
    refused); the plane their bottom lines lie in is the sole's, its pitch the tilt the inverse kinematics levels."""
    import math

    from zmpwalk.robots.collision import tilt_of

    drop = 0.0021  # [m] over the 0.2 m bars
    foot = "".join(f'<geom type="cylinder" fromto="-0.07 {y} -0.04 0.13 {y} {-0.04 - drop}" size="0.02" '
                   'mass="0.25"/>' for y in (0.02, -0.02))
    path = tmp_path / "tilted.xml"
    path.write_text(biped(foot), encoding="utf-8")
    robot = load_robot(path)
    assert robot.foot_length == pytest.approx(0.2, rel=1e-3)  # [m]
    assert robot.foot_width == pytest.approx(0.04, rel=1e-3)  # [m] between the bars' bottom lines
    assert robot.legs is not None
    roll, pitch = tilt_of(robot.legs[0].sole_rotation[:, 2])
    assert roll == pytest.approx(0.0, abs=1e-12)
    assert abs(pitch) == pytest.approx(math.atan2(drop, 0.2), abs=1e-9)  # [rad]
