"""The options several ``zmpwalk`` commands share, each declared once, and how the commands read them.

A command's module adds the groups it takes, in the order its ``--help`` lists them: the robot (``--robot`` and the
options of a robot's own model), the walk (a steps file or ``--scenario``), the pattern (``--schedule``,
``--pelvis``, ``--generator``), the simulation (``--balance``, ``--latency``, ``--motors``) and the output
(``--out``, ``--json``); then the workers of the batch commands (``--workers``, ``--dask``).
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn, TypeAlias

from zmpwalk.commands import StepCommand
from zmpwalk.errors import ZmpwalkError
from zmpwalk.patterns import GENERATORS
from zmpwalk.robots import list_robots, load_robot
from zmpwalk.robots.model import BOX_MODEL_GENERATOR, OWN_MODEL_GENERATOR, RobotModel
from zmpwalk.scenarios import load_scenario_with_labels, load_steps_file_with_labels
from zmpwalk.schedule import SCHEDULE_FILES, Schedule

if TYPE_CHECKING:
    from zmpwalk.sim.motors import Motor

EXIT_ERROR = 2
EXIT_FAILED = 3  # the walk failed its verdict, or the plan's ZMP left the polygon

DASK_HELP = ("run on a Dask cluster: its scheduler's address (tcp://host:8786), or local "
             '(pip install "zmpwalk[distributed]")')
BALANCE_HELP = ("close the loop with the stabilizer on the simulated sensors (default: on, for every robot; off: the "
                "pattern alone, open loop, as the papers walk it)")


class UsageError(Exception):
    """Bad input on the command line: printed as one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (:class:`UsageError`), without the usage dump."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


Commands: TypeAlias = "argparse._SubParsersAction[Parser]"


def add_robot_options(parser: argparse.ArgumentParser, default: str | None = "hubo") -> None:
    """--robot and the options of a robot imported from its own model."""
    parser.add_argument("--robot", default=default,
                        help=f"built-in robot ({', '.join(list_robots())}), a robot file (.toml) or the robot's own "
                        "model: MJCF (.xml) or URDF (.urdf)" + (f" (default: {default})" if default else ""))
    add_model_options(parser)


def add_model_options(parser: argparse.ArgumentParser) -> None:
    """--feet, --keyframe and --package-path: what a robot's own model (MJCF, URDF) may need to be imported."""
    parser.add_argument("--feet", help="foot body names LEFT,RIGHT of a model whose tree is ambiguous")
    parser.add_argument("--keyframe", help="the model's keyframe of the reference pose (default: its first)")
    parser.add_argument("--package-path", type=Path, action="append", default=[],
                        help="folder holding a URDF's package:// packages (repeatable)")


def load_robot_of(args: argparse.Namespace, ready_stretch: float | None = None) -> RobotModel:
    """The robot of --robot, imported with --feet, --keyframe and --package-path (and a ready posture's
    ``ready_stretch`` [-], :func:`zmpwalk.robots.load_robot`)."""
    feet = None
    if args.feet:
        names = [name.strip() for name in args.feet.split(",")]
        if len(names) != 2 or not all(names):
            raise UsageError(f"--feet = {args.feet!r} must be two body names: LEFT,RIGHT")
        feet = (names[0], names[1])
    return load_robot(args.robot, feet=feet, keyframe=args.keyframe, package_paths=tuple(args.package_path),
                      ready_stretch=ready_stretch)


def require_robot_by_name(args: argparse.Namespace) -> None:
    """Workers load the robot from --robot alone: the model options go into a robot file first."""
    if args.feet or args.keyframe or args.package_path:
        raise UsageError(f"{args.command} loads --robot in every worker: write a robot file with 'zmpwalk robot "
                         "MODEL --feet ... --keyframe ... --package-path ... --write robot.toml' and give "
                         "--robot robot.toml")


def add_walk_options(parser: argparse.ArgumentParser, steps_help: str, scenario_help: str,
                     steps_as_path: bool = False) -> None:
    """The walk: a steps file (positional STEPS, a :class:`Path` with ``steps_as_path``) or --scenario, a built-in
    one."""
    if steps_as_path:
        parser.add_argument("steps", nargs="?", type=Path, help=steps_help)
    else:
        parser.add_argument("steps", nargs="?", help=steps_help)
    parser.add_argument("--scenario", default=None, help=scenario_help)


def walk_of(args: argparse.Namespace) -> tuple[list[StepCommand], list[str]]:
    """The step commands of the steps file or --scenario, and how errors name each."""
    if args.scenario and args.steps:
        raise UsageError("give either a steps file or --scenario, not both")
    if args.scenario:
        return load_scenario_with_labels(args.scenario)
    if args.steps:
        return load_steps_file_with_labels(args.steps)
    raise UsageError("give a steps file or --scenario NAME (see 'zmpwalk scenarios')")


def walk_label(args: argparse.Namespace) -> str:
    """How an error names the walk: the steps file, or ``scenario NAME``."""
    steps = getattr(args, "steps", None)
    return str(steps) if steps else f"scenario {args.scenario}"


@contextmanager
def named_source(label: str) -> Iterator[None]:
    """Name the steps file (or scenario) in front of an error raised while walking its steps."""
    try:
        yield
    except ZmpwalkError as error:
        raise error.in_context(label) from None


def add_schedule_option(parser: argparse.ArgumentParser, example: str = "", help_text: str | None = None) -> None:
    """--schedule: the parameter tables, by name or file (``example`` ends the help text; ``help_text`` replaces it)."""
    names = ", ".join(SCHEDULE_FILES)
    parser.add_argument("--schedule", metavar="NAME|FILE",
                        help=help_text or f"parameter tables: one of {names} (default: HUBO's, Tables 2-3 with V_y "
                        f"per step time; paper: Tables 2-3 as printed) or a schedule file (TOML){example}")


def schedule_of(args: argparse.Namespace) -> Schedule | None:
    """--schedule: a built-in schedule's name (default, paper) or a schedule file; None without it (the default)."""
    value = getattr(args, "schedule", None)
    if value is None:
        return None
    if value in SCHEDULE_FILES:
        return Schedule.named(value)
    if not Path(value).exists():
        raise UsageError(f"--schedule {value!r} is neither a built-in schedule ({', '.join(SCHEDULE_FILES)}) nor a "
                         "file")
    return Schedule.from_file(Path(value))  # the polynomial pattern's tables, and every generator's footstep timing


def add_pelvis_option(parser: argparse.ArgumentParser) -> None:
    """--pelvis: the polynomial generator's pelvis curves."""
    parser.add_argument("--pelvis", choices=("cubic", "quintic"), default="cubic",
                        help="pelvis curves: the paper's cubics, or quintics with a continuous cart-table ZMP")


def pelvis_of(args: argparse.Namespace) -> str:
    """--pelvis, checked against the generator that runs (only the polynomial one takes quintics)."""
    pelvis = str(getattr(args, "pelvis", "cubic"))
    name = getattr(args, "generator", "polynomial")
    if pelvis != "cubic" and name != "polynomial":
        given = "" if getattr(args, "generator_given", True) else f"; this robot's default generator is {name}: give " \
            "--generator polynomial"
        raise UsageError(f"--pelvis {pelvis} applies to the polynomial generator{given}")
    return pelvis


def pattern_options(args: argparse.Namespace) -> dict[str, object]:
    """The generator's keyword options from --schedule and --pelvis (only those given)."""
    options: dict[str, object] = {}
    schedule = schedule_of(args)
    if schedule is not None:
        options["schedule"] = schedule
    if pelvis_of(args) != "cubic":
        options["pelvis"] = pelvis_of(args)
    return options


def add_generator_option(parser: argparse.ArgumentParser) -> None:
    """--generator: which pattern generator walks (default: the robot's)."""
    parser.add_argument("--generator", choices=GENERATORS, default=None,
                        help="polynomial (HUBO, Park et al. 2008), hyperbolic (LIPM, Lim et al., stage by stage) or "
                        f"preview (preview control, Kajita et al. 2003); default: the robot's, {OWN_MODEL_GENERATOR} "
                        f"for a robot's own model (MJCF, URDF), {BOX_MODEL_GENERATOR} for the box models, or a robot "
                        "file's [walking] generator")


def resolve_generator(args: argparse.Namespace, robot: RobotModel) -> str:
    """--generator, or the robot's default (:attr:`RobotModel.default_generator`) where it is not given; what follows
    reads ``args.generator``, and ``args.generator_given`` says which it was."""
    args.generator_given = args.generator is not None
    if args.generator is None:
        args.generator = robot.default_generator
    return str(args.generator)


def generator_words(args: argparse.Namespace, robot: RobotModel) -> str:
    """Which generator runs and why: ``preview (the default for a robot's own model; --generator to choose)``."""
    if getattr(args, "generator_given", True):
        return f"{args.generator} (--generator)"
    why = ("the robot file's [walking] generator" if robot.generator is not None else
           "the default for a robot's own model" if robot.own_model else "the default for a box model")
    return f"{args.generator} ({why}; --generator to choose)"


def add_balance_option(parser: argparse.ArgumentParser, help_text: str = BALANCE_HELP) -> None:
    """--balance: the stabilizer on or off (on by default)."""
    parser.add_argument("--balance", choices=("on", "off"), default="on", help=help_text)


def add_simulation_options(parser: argparse.ArgumentParser) -> None:
    """--balance, --latency and --motors: how a walk is simulated and what its motors are checked against."""
    add_balance_option(parser)
    parser.add_argument("--latency", type=float, default=0.0, help="sensor latency of the stabilizer [s]")
    parser.add_argument("--motors", type=Path, help="a motor file (TOML, examples/motors.toml): does each joint's "
                        "motor fit?")


def balance_of(args: argparse.Namespace) -> bool:
    """--balance: whether the stabilizer closes the loop."""
    return bool(args.balance != "off")


def motors_of(args: argparse.Namespace) -> list[Motor] | None:
    """The motors of --motors; None without it."""
    from zmpwalk.sim.motors import load_motors

    return load_motors(args.motors) if getattr(args, "motors", None) else None


def add_out_option(parser: argparse.ArgumentParser, help_text: str, default: Path | None = None,
                   required: bool = False) -> None:
    """--out: the file or folder a command writes."""
    parser.add_argument("--out", type=Path, default=default, required=required, help=help_text)


def add_json_option(parser: argparse.ArgumentParser, help_text: str = "print JSON") -> None:
    """--json: print JSON instead of text."""
    parser.add_argument("--json", action="store_true", help=help_text)


def add_worker_options(parser: argparse.ArgumentParser, what: str) -> None:
    """--workers (``what`` runs at a time) and --dask."""
    parser.add_argument("--workers", type=int, help=f"{what} at a time (default: one per core)")
    parser.add_argument("--dask", metavar="SCHEDULER", help=DASK_HELP)


def check_workers(args: argparse.Namespace) -> None:
    """--workers, when given, is at least one."""
    if args.workers is not None and args.workers < 1:
        raise UsageError(f"--workers = {args.workers} must be >= 1")
