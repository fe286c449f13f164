"""``zmpwalk robot``: a robot imported from its MJCF or URDF, what zmpwalk derives from it, and its robot file."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from zmpwalk.cli.options import Commands, add_json_option, add_model_options, load_robot_of
from zmpwalk.cli.printing import json_safe
from zmpwalk.errors import InvalidParameterError
from zmpwalk.files import write_text

NAMES = ("robot",)


def add_parser(commands: Commands) -> None:
    """Add the robot command."""
    parser = commands.add_parser(
        "robot", help="import a robot from its MJCF or URDF and show what zmpwalk derived",
        description="Load a robot (its own MJCF or URDF model, a robot file or a built-in name), print what "
        "zmpwalk derives from it (legs and joints with axes, signs, limits and actuators; hip positions, link "
        "lengths, sole polygon, mass, centre of mass, ready posture), and optionally write a robot file.",
        epilog="example: zmpwalk robot ../shared/robots/pal_talos/scene_position.xml --write talos.toml",
    )
    parser.add_argument("model", help="the model file (.xml, .urdf) or robot file (.toml) or built-in name")
    add_model_options(parser)
    parser.add_argument("--write", type=Path, help="write a robot file (TOML) that loads this model")
    add_json_option(parser)


def run(args: argparse.Namespace) -> int:
    """``zmpwalk robot``: print the robot's table (or JSON), with its static torques where it has a plant."""
    from zmpwalk.robots.inspect import robot_summary, robot_table, robot_toml

    args.robot = args.model
    robot = load_robot_of(args)
    statics, no_statics = None, ""
    if robot.own_model:
        from zmpwalk.sim.statics import static_torques

        try:
            statics = static_torques(robot)
        except InvalidParameterError as error:  # e.g. leg joints without position servos
            no_statics = f"\nstatic torques not computed: {error}"
    if args.write:
        write_text(args.write, robot_toml(robot, args.write.parent))
    if args.json:
        print(json.dumps(json_safe(robot_summary(robot, statics)), indent=2, allow_nan=False))
    else:
        print(robot_table(robot, statics) + no_statics + (f"\nwritten: {args.write}" if args.write else ""))
    return 0
