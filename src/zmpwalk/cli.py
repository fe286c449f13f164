"""The ``zmpwalk`` command.

Exit status: 0 success; 2 bad input or usage (one line, ``zmpwalk: error: ...``); 3 the walk failed
(``simulate``, ``report``, ``demo``: a criterion of the verdict failed, each printed with its figure;
``plan``: the ZMP leaves the support polygon, unless ``--allow-outside``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.errors import InvalidParameterError, ZmpwalkError
from zmpwalk.files import write_text
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns import GENERATORS, generator
from zmpwalk.patterns.hyperbolic import HyperbolicGait
from zmpwalk.patterns.polynomial import generate_chunks
from zmpwalk.patterns.result import WalkingPattern, write_pieces_csv
from zmpwalk.robots import list_robots, load_robot
from zmpwalk.robots.model import BOX_MODEL_GENERATOR, OWN_MODEL_GENERATOR, RobotModel
from zmpwalk.scenarios import list_scenarios, load_scenario_with_labels, load_steps_file_with_labels
from zmpwalk.schedule import SCHEDULE_FILES, Schedule, schedule_path
from zmpwalk.tables import condition_margins, margins_markdown, zmp_advice

if TYPE_CHECKING:
    from zmpwalk.patterns.correction import ZmpCorrection
    from zmpwalk.sim.actuators import ActuatorRow
    from zmpwalk.sim.motors import Motor, MotorFit
    from zmpwalk.sim.run import SimulationResult
    from zmpwalk.sim.verdict import Verdict

EXIT_ERROR = 2
EXIT_FAILED = 3  # the walk failed its verdict, or the plan's ZMP left the polygon


def paper_example() -> dict[str, object]:
    """The walking example of Lim et al. (Section 4): Eq. 11 times, lateral sway, Eq. 15 start ZMPs (SI)."""
    gait = HyperbolicGait()
    step = gait.steady()
    (xd, yd), (xs, ys) = gait.start_zmps()
    return {
        "t1": step.t1, "t2": step.t2, "t3": step.t3, "t4": step.t4, "t5": step.t5,
        "y0": step.y0, "v_y": step.v_y, "v_xS": step.v_single, "x_prime": step.end,
        "steady_period": 2 * step.period,
        "zmp_start_double": [xd, yd], "zmp_start_single": [xs, ys],
    }


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # one line, no usage dump
        raise _UsageError(message)


class _UsageError(Exception):
    pass


def _robot_options(parser: argparse.ArgumentParser, default: str | None = "hubo") -> None:
    """--robot and the options of a robot imported from its own model."""
    parser.add_argument("--robot", default=default,
                        help=f"built-in robot ({', '.join(list_robots())}), a robot file (.toml) or the robot's own "
                        "model: MJCF (.xml) or URDF (.urdf)" + (f" (default: {default})" if default else ""))
    parser.add_argument("--feet", help="foot body names LEFT,RIGHT of a model whose tree is ambiguous")
    parser.add_argument("--keyframe", help="the model's keyframe of the reference pose (default: its first)")
    parser.add_argument("--package-path", type=Path, action="append", default=[],
                        help="folder holding a URDF's package:// packages (repeatable)")


def _load_robot(args: argparse.Namespace) -> RobotModel:
    feet = None
    if args.feet:
        names = [name.strip() for name in args.feet.split(",")]
        if len(names) != 2 or not all(names):
            raise _UsageError(f"--feet = {args.feet!r} must be two body names: LEFT,RIGHT")
        feet = (names[0], names[1])
    return load_robot(args.robot, feet=feet, keyframe=args.keyframe, package_paths=tuple(args.package_path))


def _schedule(args: argparse.Namespace) -> Schedule | None:
    """--schedule: a built-in schedule's name (default, paper) or a schedule file; None without it (the default)."""
    value = getattr(args, "schedule", None)
    if value is None:
        return None
    if value in SCHEDULE_FILES:
        return Schedule.named(value)
    if not Path(value).exists():
        raise _UsageError(f"--schedule {value!r} is neither a built-in schedule ({', '.join(SCHEDULE_FILES)}) nor a "
                          "file")
    return Schedule.from_file(Path(value))  # the polynomial pattern's tables, and every generator's footstep timing


def _schedule_option(parser: argparse.ArgumentParser, example: str = "") -> None:
    names = ", ".join(SCHEDULE_FILES)
    parser.add_argument("--schedule", metavar="NAME|FILE",
                        help=f"parameter tables: one of {names} (default: HUBO's, Tables 2-3 with V_y per step "
                        f"time; paper: Tables 2-3 as printed) or a schedule file (TOML){example}")


DASK_HELP = ("run on a Dask cluster: its scheduler's address (tcp://host:8786), or local "
             '(pip install "zmpwalk[distributed]")')


def _generator_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--generator", choices=GENERATORS, default=None,
                        help="polynomial (HUBO, Park et al. 2008), hyperbolic (LIPM, Lim et al., stage by stage) or "
                        f"preview (preview control, Kajita et al. 2003); default: the robot's, {OWN_MODEL_GENERATOR} "
                        f"for a robot's own model (MJCF, URDF), {BOX_MODEL_GENERATOR} for the box models, or a robot "
                        "file's [walking] generator")


def _resolve_generator(args: argparse.Namespace, robot: RobotModel) -> str:
    """--generator, or the robot's default (:attr:`RobotModel.default_generator`) where it is not given; what follows
    reads ``args.generator``, and ``args.generator_given`` says which it was."""
    args.generator_given = args.generator is not None
    if args.generator is None:
        args.generator = robot.default_generator
    return str(args.generator)


def _generator_words(args: argparse.Namespace, robot: RobotModel) -> str:
    """Which generator runs and why: ``preview (the default for a robot's own model; --generator to choose)``."""
    if getattr(args, "generator_given", True):
        return f"{args.generator} (--generator)"
    why = ("the robot file's [walking] generator" if robot.generator is not None else
           "the default for a robot's own model" if robot.plant is not None else "the default for a box model")
    return f"{args.generator} ({why}; --generator to choose)"


def _pelvis(args: argparse.Namespace) -> str:
    pelvis = str(getattr(args, "pelvis", "cubic"))
    name = getattr(args, "generator", "polynomial")
    if pelvis != "cubic" and name != "polynomial":
        given = "" if getattr(args, "generator_given", True) else f"; this robot's default generator is {name}: give " \
            "--generator polynomial"
        raise _UsageError(f"--pelvis {pelvis} applies to the polynomial generator{given}")
    return pelvis


def _pattern_options(args: argparse.Namespace) -> dict[str, object]:
    """The generator's keyword options from --schedule and --pelvis (only those given)."""
    options: dict[str, object] = {}
    schedule = _schedule(args)
    if schedule is not None:
        options["schedule"] = schedule
    if _pelvis(args) != "cubic":
        options["pelvis"] = _pelvis(args)
    return options


def _motors(args: argparse.Namespace) -> list[Motor] | None:
    from zmpwalk.sim.motors import load_motors

    return load_motors(args.motors) if getattr(args, "motors", None) else None


def _balance_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--balance", choices=("on", "off"), default="on",
                        help="close the loop with the stabilizer on the simulated sensors (default: on, for every "
                        "robot; off: the pattern alone, open loop, as the papers walk it)")
    parser.add_argument("--latency", type=float, default=0.0, help="sensor latency of the stabilizer [s]")
    parser.add_argument("--motors", type=Path, help="a motor file (TOML, examples/motors.toml): does each joint's "
                        "motor fit?")


def _balance(args: argparse.Namespace) -> bool:
    return bool(args.balance != "off")


def _plan_parsers(commands: argparse._SubParsersAction[_Parser]) -> None:
    """The scenarios, plan and hyperbolic commands."""
    scenarios = commands.add_parser(
        "scenarios", help="list the built-in scenarios",
        description="List the built-in scenarios (the paper's experiments).", epilog="example: zmpwalk scenarios",
    )
    scenarios.add_argument("--json", action="store_true", help="print a JSON object name -> description")

    plan = commands.add_parser(
        "plan", help="generate a walking pattern and write it as CSV",
        description="Generate the walking pattern of a steps file or a scenario, write one CSV row per "
        "sample (world frame, SI units) and print the smallest ZMP margin.",
        epilog="example: zmpwalk plan --scenario fig30 --out fig30.csv   |   zmpwalk plan my_steps.toml",
    )
    plan.add_argument("steps", nargs="?", help="steps file (TOML, [[steps]] tables)")
    plan.add_argument("--scenario", help="a built-in scenario instead of a steps file (see 'zmpwalk scenarios')")
    _robot_options(plan)
    _schedule_option(plan)
    plan.add_argument("--pelvis", choices=("cubic", "quintic"), default="cubic",
                        help="pelvis curves: the paper's cubics, or quintics with a continuous cart-table ZMP")
    plan.add_argument("--rate", type=float, default=1000.0,
                      help="samples per second [Hz] (default: 1000, as report and simulate)")
    plan.add_argument("--allow-outside", action="store_true",
                      help="exit 0 even when the ZMP leaves the support polygon (default: exit 3)")
    _generator_option(plan)
    plan.add_argument("--out", type=Path, help="CSV file to write (without it nothing is written: the summary "
                      "says so)")
    plan.add_argument("--joints", action="store_true", help="append the 12 leg joint angles [rad] to the CSV")
    plan.add_argument("--json", action="store_true", help="print a JSON summary")

    hyperbolic = commands.add_parser(
        "hyperbolic", help="the hyperbolic (LIPM) pattern of Lim et al.: the paper's example",
        description="Solve the paper's walking example (Eqs. 11 and 15 of Lim et al.): steady-step times, "
        "lateral sway and the ZMPs of the start from standstill. Times in s, lengths in m.",
        epilog="example: zmpwalk hyperbolic --paper-example --json",
    )
    hyperbolic.add_argument("--paper-example", action="store_true", required=True,
                            help="z_b = 395 mm, x_s = 100 mm, x_ZMP1 = x_s/8, x_ZMP2 = x_s/4, y_ZMP = 68 mm, "
                            "v_xD = 100 mm/s, t* = 0.2 s, tau* = 0.3 s, g = 9.8 m/s^2")
    hyperbolic.add_argument("--json", action="store_true", help="print a JSON object")


def _simulate_parser(commands: argparse._SubParsersAction[_Parser]) -> None:
    """The simulate command."""
    simulate_cmd = commands.add_parser(
        "simulate", help="walk a pattern in MuJoCo: falls, CoP, joint torques and powers",
        description="Generate the pattern of a steps file, a scenario or the paper example of Lim et al., "
        "walk it in MuJoCo with the robot's servos and ground contact, and write the measurements "
        "(simulation.csv, actuators.csv, actuators.md) to --out.",
        epilog="example: zmpwalk simulate --paper-example --robot mju-biped --json",
    )
    simulate_cmd.add_argument("steps", nargs="?", help="steps file (TOML)")
    simulate_cmd.add_argument("--scenario", help="a built-in scenario")
    simulate_cmd.add_argument("--paper-example", action="store_true",
                              help="the walk of Lim et al. (start, 2 steady steps, stop; hyperbolic)")
    simulate_cmd.add_argument("--steady-steps", type=int, default=2, help="steady steps of --paper-example")
    _robot_options(simulate_cmd)
    _schedule_option(simulate_cmd)
    simulate_cmd.add_argument("--pelvis", choices=("cubic", "quintic"), default="cubic",
                        help="pelvis curves: the paper's cubics, or quintics with a continuous cart-table ZMP")
    _balance_options(simulate_cmd)
    _generator_option(simulate_cmd)
    simulate_cmd.add_argument("--mass-scale", type=float, default=1.0, help="multiply every mass (default 1)")
    simulate_cmd.add_argument("--zmp-correction", action="store_true",
                              help="move the pelvis until the multibody ZMP (Eq. 3) follows the planned ZMP "
                              "(box models with [bodies]; off by default: docs/balance.md)")
    simulate_cmd.add_argument("--push", type=float, nargs=3, metavar=("TIME", "X", "Y"),
                              help="push the torso at TIME [s] with an impulse X, Y [N s] in world over 0.1 s")
    simulate_cmd.add_argument("--capture", action="store_true",
                              help="with the stabilizer: after a push, re-plan the rest of the walk as a capture "
                              "step and a stop once its DCM error passes 80 mm (zmpwalk.capture)")
    simulate_cmd.add_argument("--out", type=Path, help="folder for the result files")
    simulate_cmd.add_argument("--json", action="store_true", help="print a JSON summary")


def _report_parsers(commands: argparse._SubParsersAction[_Parser]) -> None:
    """The demo and report commands."""
    for name, help_text, example in (
        ("demo", "the first thing to run: walk HUBO, check the ZMP, simulate, and write a report",
         "example: zmpwalk demo   |   zmpwalk demo --robot mju-biped --scenario fig30 --out my-report   |   "
         "zmpwalk demo my_steps.toml"),
        ("report", "generate, check, simulate and report any walk as a self-contained HTML page",
         "example: zmpwalk report --scenario fig28 --out fig28-report   |   zmpwalk report my_steps.toml"),
    ):
        report_cmd = commands.add_parser(
            name, help=help_text,
            description="Generate the pattern (1 kHz), check its ZMP, compute the joint angles, simulate the "
            "walk in MuJoCo and write a report folder: index.html (plots, actuator table, ZMP margin per step, "
            "an interactive 3D replay of the simulated walk; self-contained, opens offline), figures, CSV and JSON "
            "files.",
            epilog=example,
        )
        report_cmd.add_argument("steps", nargs="?", type=Path, help="steps file (TOML), as plan and simulate take it")
        report_cmd.add_argument("--scenario", default=None,
                                help="built-in scenario" + (" (default: demo, without a steps file)" if name == "demo"
                                                            else ""))
        report_cmd.add_argument("--steps", type=Path, dest="steps_option", metavar="STEPS",
                                help="the steps file given as an option (the same as the positional STEPS)")
        _robot_options(report_cmd)
        _schedule_option(report_cmd)
        report_cmd.add_argument("--pelvis", choices=("cubic", "quintic"), default="cubic",
                            help="pelvis curves: the paper's cubics, or quintics with a continuous cart-table ZMP")
        _balance_options(report_cmd)
        _generator_option(report_cmd)
        default_out = Path("zmpwalk-demo" if name == "demo" else "zmpwalk-report")
        report_cmd.add_argument("--out", type=Path, default=default_out,
                                help="report folder (default: ./zmpwalk-demo or ./zmpwalk-report)")
        report_cmd.add_argument("--no-animation", action="store_true",
                                help="skip the interactive replay (and the GIF)")
        report_cmd.add_argument("--gif", action="store_true",
                                help="also render a GIF of the walk offscreen with MuJoCo (walk.gif, shown where the "
                                "browser has no WebGL; slower)")
        report_cmd.add_argument("--json", action="store_true", help="print a JSON summary")


def _batch_parsers(commands: argparse._SubParsersAction[_Parser]) -> None:
    """The tables, sweep and tune commands."""
    tables = commands.add_parser(
        "tables", help="walk every condition of Tables 2-3 and print the ZMP margins",
        description="Walk each tuned condition of the parameter tables (Tables 2 and 3) for a number of "
        "steps at 1 kHz and print the smallest cart-table ZMP margin of each as a Markdown table.",
        epilog="example: zmpwalk tables --steps 10",
    )
    _robot_options(tables)
    _schedule_option(tables)
    tables.add_argument("--steps", type=int, default=10, help="steps walked per condition (default: 10)")
    tables.add_argument("--json", action="store_true", help="print JSON instead of Markdown")
    sweep_cmd = commands.add_parser(
        "sweep", help="simulate many scenarios on all cores and judge each walk",
        description="Simulate built-in scenarios on one robot, one walk per core at a time, and print each "
        "walk's verdict. Exit status 3 when any walk fails its verdict.",
        epilog="example: zmpwalk sweep --robot hubo --balance on   |   zmpwalk sweep --scenario fig27 fig28",
    )
    _robot_options(sweep_cmd)
    sweep_cmd.add_argument("--scenario", nargs="+", help="scenarios to walk (default: every built-in one)")
    sweep_cmd.add_argument("--workers", type=int, help="walks at a time (default: one per core)")
    sweep_cmd.add_argument("--dask", metavar="SCHEDULER", help=DASK_HELP)
    sweep_cmd.add_argument("--balance", choices=("on", "off"), default="on",
                           help="the stabilizer (default: on, for every robot; off: open loop, as the papers walk)")
    _generator_option(sweep_cmd)
    _schedule_option(sweep_cmd, " (e.g. from zmpwalk tune)")
    sweep_cmd.add_argument("--pelvis", choices=("cubic", "quintic"), default="cubic",
                           help="pelvis curves: the paper's cubics, or quintics with a continuous cart-table ZMP")
    sweep_cmd.add_argument("--json", action="store_true", help="print JSON")
    tune_cmd = commands.add_parser(
        "tune", help="tune the shape factors of Tables 2-3 for a robot and write them as a schedule file",
        description="Search the shape factors of every condition of the tables (or of --schedule's) for the "
        "largest cart-table and multibody ZMP margin, check the best candidates in MuJoCo, and write the tuned "
        "schedule (the format --schedule reads). Exit status 3 when a condition does not walk.",
        epilog="example: zmpwalk tune --robot hubo --out hubo_tuned.toml --storage tune.db",
    )
    _robot_options(tune_cmd)
    tune_cmd.add_argument("--schedule", metavar="NAME|FILE",
                          help="the schedule to start from: default, paper or a schedule file (TOML); without it "
                          "Tables 2-3 as printed (paper)")
    tune_cmd.add_argument("--out", type=Path, required=True, help="schedule file to write (TOML)")
    tune_cmd.add_argument("--trials", type=int, default=40, help="candidates per condition (default: 40)")
    tune_cmd.add_argument("--steps", type=int, default=10, help="steps walked per candidate (default: 10)")
    tune_cmd.add_argument("--seed", type=int, default=0, help="sampler seed: the same seed, the same schedule")
    tune_cmd.add_argument("--workers", type=int, help="conditions at a time (default: one per core)")
    tune_cmd.add_argument("--dask", metavar="SCHEDULER", help=DASK_HELP)
    tune_cmd.add_argument("--storage", type=Path, help="SQLite file of the studies: a stopped run resumes")
    tune_cmd.add_argument("--timing", action="store_true",
                          help="also tune V_y and the double-support time of Table 2's rows (added as columns)")
    tune_cmd.add_argument("--json", action="store_true", help="print JSON")


def _robot_parser(commands: argparse._SubParsersAction[_Parser]) -> None:
    """The robot command."""
    robot_cmd = commands.add_parser(
        "robot", help="import a robot from its MJCF or URDF and show what zmpwalk derived",
        description="Load a robot (its own MJCF or URDF model, a robot file or a built-in name), print what "
        "zmpwalk derives from it (legs and joints with axes, signs, limits and actuators; hip positions, link "
        "lengths, sole polygon, mass, centre of mass, ready posture), and optionally write a robot file.",
        epilog="example: zmpwalk robot ../shared/robots/pal_talos/scene_position.xml --write talos.toml",
    )
    robot_cmd.add_argument("model", help="the model file (.xml, .urdf) or robot file (.toml) or built-in name")
    robot_cmd.add_argument("--feet", help="foot body names LEFT,RIGHT of a model whose tree is ambiguous")
    robot_cmd.add_argument("--keyframe", help="the model's keyframe of the reference pose (default: its first)")
    robot_cmd.add_argument("--package-path", type=Path, action="append", default=[],
                           help="folder holding a URDF's package:// packages (repeatable)")
    robot_cmd.add_argument("--write", type=Path, help="write a robot file (TOML) that loads this model")
    robot_cmd.add_argument("--json", action="store_true", help="print JSON")


def _export_parser(commands: argparse._SubParsersAction[_Parser]) -> None:
    """The export command."""
    export_cmd = commands.add_parser(
        "export", help="reference motions for learning: walk a grid of commands in MuJoCo and export the clips",
        description="Walk every command of a grid (forward, side, turn velocity; step time) through the walking "
        "controller in MuJoCo with the stabilizer, and write the simulated and the planned motion, whole and cyclic, "
        "in the model's joint names and order, as mjlab npz, LocoMuJoCo-style npz, AMP JSON and CSV, each replayed "
        "from its file and checked, with manifest.json (docs/export.md). Exit status 3 when a clip fails its check.",
        epilog="example: zmpwalk export --robot ../shared/robots/booster_t1/scene.xml --out t1-motions",
    )
    _robot_options(export_cmd)
    export_cmd.add_argument("--out", type=Path, default=Path("zmpwalk-motions"),
                            help="output folder (default: zmpwalk-motions)")
    export_cmd.add_argument("--fps", type=float, default=50.0, help="frames per second of the clips (default: 50)")
    export_cmd.add_argument("--grid", type=Path, help="a grid file (TOML: forward, side, turn, step_time lists)")
    for name, unit in (("forward", "m/s"), ("side", "m/s"), ("turn", "rad/s"), ("step-time", "s")):
        export_cmd.add_argument(f"--{name}", help=f"comma-separated values [{unit}] (instead of --grid; a list "
                                f"that starts with a minus sign takes '=': --{name}=-0.1,0,0.1)")
    export_cmd.add_argument("--swings", type=int, default=10, help="swings walked per command (default: 10; a side "
                            "or turn step is two)")
    export_cmd.add_argument("--workers", type=int, help="commands walked at a time (default: one per core)")
    export_cmd.add_argument("--dask", metavar="SCHEDULER", help=DASK_HELP)
    export_cmd.add_argument("--json", action="store_true", help="print the manifest's summary as JSON")


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="zmpwalk",
        description="Online ZMP walking patterns for biped humanoids (HUBO polynomial pattern).",
        epilog="example: zmpwalk plan --scenario fig28 --rate 1000 --out fig28.csv",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser)

    _plan_parsers(commands)
    _simulate_parser(commands)
    _report_parsers(commands)
    _batch_parsers(commands)
    _robot_parser(commands)
    _export_parser(commands)
    return parser


@contextmanager
def _source(label: str) -> Iterator[None]:
    """Name the steps file (or scenario) in front of an error raised while walking its steps."""
    try:
        yield
    except ZmpwalkError as error:
        raise error.in_context(label) from None


def _label(args: argparse.Namespace) -> str:
    steps = getattr(args, "steps", None)
    return str(steps) if steps else f"scenario {args.scenario}"


def _commands(args: argparse.Namespace) -> tuple[list[StepCommand], list[str]]:
    """The step commands of the arguments and how errors name each."""
    if args.scenario and args.steps:
        raise _UsageError("give either a steps file or --scenario, not both")
    if args.scenario:
        return load_scenario_with_labels(args.scenario)
    if args.steps:
        return load_steps_file_with_labels(args.steps)
    raise _UsageError("give a steps file or --scenario NAME (see 'zmpwalk scenarios')")


def _progress(stage: str, done: int, total: int) -> None:
    width = 24
    filled = width * done // total
    print(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} {stage:<10}", end="" if done < total else "\n",
          file=sys.stderr, flush=True)


def _report(args: argparse.Namespace) -> int:
    from zmpwalk.report import build_report

    if args.steps and args.steps_option:
        raise _UsageError("give the steps file once: STEPS or --steps STEPS")
    args.steps = args.steps or args.steps_option
    if args.steps and args.scenario:
        raise _UsageError("give either a steps file or --scenario, not both")
    if args.command == "demo" and not args.steps and not args.scenario:
        args.scenario = "demo"
    if args.steps:
        (commands, labels), name = load_steps_file_with_labels(args.steps), args.steps.name
    elif args.scenario:
        (commands, labels), name = load_scenario_with_labels(args.scenario), args.scenario
    else:
        raise _UsageError("give --scenario NAME or a steps file (see 'zmpwalk scenarios')")
    robot = _load_robot(args)
    _resolve_generator(args, robot)
    quiet = args.json or not sys.stderr.isatty()
    with _source(str(args.steps) if args.steps else f"scenario {args.scenario}"):
        report = build_report(robot, commands, args.out, title=f"zmpwalk: {robot.name}, {name}",
                              generator=args.generator, animate=not args.no_animation,
                              gif=args.gif and not args.no_animation,
                              progress=None if quiet else _progress, labels=labels,
                              balance=_balance(args), latency=args.latency, schedule=_schedule(args),
                              motors=_motors(args), pelvis=_pelvis(args))
    verdict = report.verdict
    if args.json:
        summary = {**report.summary, "index": str(report.index), "seconds": report.seconds}
        print(json.dumps(_json_safe(summary), indent=2, allow_nan=False))
    else:
        s = report.summary
        state = f"FELL at t = {s['fall_time']:.2f} s" if s["fell"] else "no fall"
        print(f"generator: {_generator_words(args, robot)}")
        print(f"{robot.name}, {name}: {verdict.state} ({state}); plan's min ZMP margin "
              f"{_margin_words(float(s['min_zmp_margin']))} -> {report.index}")
        _print_verdict(verdict)
    return 0 if verdict.passed else EXIT_FAILED


def _simulated_pattern(args: argparse.Namespace, robot: RobotModel) -> tuple[WalkingPattern, ZmpCorrection | None]:
    """The pattern ``simulate`` walks (the paper example, a steps file or a scenario) and its ZMP correction."""
    from zmpwalk.patterns.hyperbolic import paper_walk

    _resolve_generator(args, robot)
    if args.paper_example:
        if args.steps or args.scenario:
            raise _UsageError("--paper-example takes no steps file or scenario")
        if args.steady_steps < 0:
            raise _UsageError(f"--steady-steps = {args.steady_steps} must be >= 0")
        pattern = paper_walk(robot, steps=args.steady_steps).sample(1000.0)
    else:
        commands, labels = _commands(args)
        make = generator(args.generator)
        options = _pattern_options(args)
        with _source(_label(args)):
            pattern = make(robot, commands, rate=1000.0, labels=labels, **options)
    if not args.zmp_correction:
        return pattern, None
    from zmpwalk.patterns.correction import correct_pattern

    correction = correct_pattern(pattern)
    return correction.pattern, correction


def _simulate(args: argparse.Namespace) -> int:
    from zmpwalk.balance import Stabilizer
    from zmpwalk.capture import CaptureSettings
    from zmpwalk.sim import actuator_markdown, actuator_table, simulate, write_actuator_csv
    from zmpwalk.sim.motors import motor_fits
    from zmpwalk.sim.run import Disturbances, write_result_csv
    from zmpwalk.sim.verdict import HOLD, SETTLE, walk_verdict

    robot = _load_robot(args)
    show = None if args.json or not sys.stderr.isatty() else _progress
    stages = ("pattern", "joints", "simulation", "measures")
    if show:
        show(stages[0], 0, len(stages))
    pattern, correction = _simulated_pattern(args, robot)
    if show:
        show(stages[1], 1, len(stages))
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    if show:
        show(stages[2], 2, len(stages))
    stabilizer = Stabilizer(robot, 1000.0, com_reference=pattern.com_point) if _balance(args) else None
    if args.capture and stabilizer is None:
        raise _UsageError("--capture needs the stabilizer (--balance on): its DCM estimate triggers the capture step")
    if args.capture and correction is not None:
        raise _UsageError("--capture plans the pattern's CoM point; it does not combine with --zmp-correction")
    disturbances = None
    if args.push is not None:
        disturbances = Disturbances(push_time=args.push[0], push_impulse=(args.push[1], args.push[2], 0.0))
    result = simulate(robot, joints, pattern, mass_scale=args.mass_scale, stabilizer=stabilizer,
                      latency=args.latency, settle=SETTLE, hold=HOLD, disturbances=disturbances,
                      capture=CaptureSettings() if args.capture else None,
                      progress=None if show is None else lambda done: show("simulation", round(100 * done), 100))
    motors = _motors(args)
    verdict = walk_verdict(result, HOLD, motors)
    if show:
        show(stages[3], 4, len(stages))
    rows = actuator_table(result)
    fits = motor_fits(result, motors) if motors else []
    summary = {**_simulation_summary(result, verdict, rows, fits, correction), "balance": stabilizer is not None,
               "generator": pattern.generator}
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        write_actuator_csv(rows, args.out / "actuators.csv")
        write_text(args.out / "actuators.md", actuator_markdown(rows) + "\n")
        write_result_csv(result, args.out / "simulation.csv")
    if args.json:
        print(json.dumps(_json_safe(summary), indent=2, allow_nan=False))
    else:
        print("generator: " + ("hyperbolic (the paper example of Lim et al.)" if args.paper_example else
                               _generator_words(args, robot)))
        _print_simulation(result, verdict, rows, fits, correction)
    return 0 if verdict.passed else EXIT_FAILED


def _simulation_summary(result: SimulationResult, verdict: Verdict, rows: list[ActuatorRow], fits: list[MotorFit],
                        correction: ZmpCorrection | None) -> dict[str, object]:
    """What ``simulate --json`` prints (SI)."""
    from zmpwalk.sim.actuators import planned_over_limit
    from zmpwalk.sim.verdict import cop_margin_outside_touchdowns

    rms, largest = result.cop_error_stats()
    return {
        "robot": result.robot.name, "fell": result.fell, "fall_time": result.fall_time,
        "duration": float(result.time[-1]), "distance": result.distance, "average_speed": result.average_speed,
        "foot_slip": result.foot_slip, "cop_error_rms": rms, "cop_error_max": largest,
        "min_cop_margin": float(np.nanmin(result.cop_margin)),
        "min_cop_margin_judged": cop_margin_outside_touchdowns(result),
        "plan_min_zmp_margin": result.plan_zmp_margin,
        "mass_scale": result.mass_scale,
        "final_feet_error": result.final_feet_error, "final_feet_yaw_error": result.final_feet_yaw_error,
        "end_min_sole_force": result.end_min_sole_force, "end_max_speed": result.end_max_speed,
        "end_attitude_range": result.end_attitude_range, "verdict": verdict.as_dict(),
        "captures": [{"time": c.time, "swing": c.swing, "swing_time": c.swing_time, "landing": list(c.landing),
                      "reached": c.reached} for c in result.captures],
        "zmp_correction": None if correction is None else {
            "passes": correction.passes, "multibody_error_rms_before": correction.before.rms,
            "multibody_error_rms_after": correction.after.rms},
        "motors": [{"joint": f.joint, "motor": f.motor, "rms_use": f.rms_use, "peak_use": f.peak_use,
                    "fits": f.fits} for f in fits],
        "actuators": [vars(row) for row in rows],
        "planned_over_limit": [row.joint for row in planned_over_limit(rows)],
        "warnings": list(verdict.warnings),
    }


def _print_simulation(result: SimulationResult, verdict: Verdict, rows: list[ActuatorRow], fits: list[MotorFit],
                      correction: ZmpCorrection | None) -> None:
    """What ``simulate`` prints: the walk, the plan's ZMP margin, the CoP, the motors, the warnings, the verdict."""
    from zmpwalk.sim.verdict import controller_words, cop_margin_outside_touchdowns

    state = f"FELL at t = {result.fall_time:.3f} s" if result.fell else "walked to the end without falling"
    print(f"controller: {controller_words(result.balance is not None)}")
    print(f"{result.robot.name}: {state}; distance {result.distance:.3f} m, average speed "
          f"{result.average_speed * 1e3:.1f} mm/s, foot slip {result.foot_slip * 1e3:.1f} mm")
    if correction is not None:
        print(f"multibody ZMP - planned ZMP: RMS {correction.before.rms * 1e3:.1f} mm as generated, "
              f"{correction.after.rms * 1e3:.1f} mm corrected (passes kept: {correction.passes})")
    if result.captures:
        last = result.captures[-1]
        print(f"capture steps planned: {len(result.captures)}, the first at t = {result.captures[0].time:.3f} s; "
              f"the walk ended on the last: {last.swing} foot to ({last.landing[0]:.3f}, {last.landing[1]:.3f}) "
              f"m at t = {last.time + last.swing_time:.3f} s, then standing (the commanded steps after it dropped)")
    print(f"plan: min ZMP margin {_margin_words(result.plan_zmp_margin)}")
    rms, largest = result.cop_error_stats()
    print(f"CoP - reference ZMP: RMS {rms * 1e3:.1f} mm, max {largest * 1e3:.1f} mm; "
          + _cop_margin_words(cop_margin_outside_touchdowns(result), float(np.nanmin(result.cop_margin))))
    top = max(rows, key=lambda r: r.peak_torque)
    power = max(rows, key=lambda r: r.peak_power)
    print(f"largest torque {top.peak_torque:.3g} N m at {top.joint}; largest power {power.peak_power:.3g} W "
          f"at {power.joint}")
    for fit in fits:
        if fit.fits:  # a motor that does not fit is a warning, printed with the verdict
            print(f"motor {fit.motor!r} at {fit.joint}: RMS {fit.rms_use * 100:.0f} % of rated, held peak "
                  f"{fit.peak_use * 100:.0f} % of the envelope: {fit.verdict}")
    _print_verdict(verdict)


def _margin_words(margin: float, at: float | None = None) -> str:
    """A ZMP margin as ``plan`` prints it: signed (positive inside), and whether it leaves the polygon."""
    if not math.isfinite(margin):
        return "not measured"
    where = "inside the support polygon" if margin >= 0 else "OUTSIDE the support polygon"
    return f"{margin * 1e3:+.1f} mm" + ("" if at is None else f" at t = {at:.3f} s") + f" ({where})"


def _cop_margin_words(judged: float, every: float) -> str:
    """The CoP margin two ways, each saying which samples it covers (the verdict judges the first)."""
    from zmpwalk.sim.verdict import TOUCHDOWN_WINDOW

    return (f"least CoP margin (positive inside) {judged * 1e3:+.1f} mm outside the {TOUCHDOWN_WINDOW * 1e3:g} ms "
            f"after each touchdown (the verdict's), {every * 1e3:+.1f} mm over every sample")


def _print_verdict(verdict: Verdict) -> None:
    """The warnings, the outcome and every criterion: what the page shows too."""
    for warning in verdict.warnings:
        print(f"warning: {warning}")
    print(f"verdict: {verdict.state}: the walk {verdict.outcome()}")
    for line in verdict.lines():
        print(f"  {line}")


def _robot_by_name(args: argparse.Namespace) -> None:
    """Workers load the robot from --robot alone: the model options go into a robot file first."""
    if args.feet or args.keyframe or args.package_path:
        raise _UsageError(f"{args.command} loads --robot in every worker: write a robot file with 'zmpwalk robot "
                          "MODEL --feet ... --keyframe ... --package-path ... --write robot.toml' and give "
                          "--robot robot.toml")


def _export(args: argparse.Namespace) -> int:
    from zmpwalk.export import Grid, export_motions

    _robot_by_name(args)
    if args.workers is not None and args.workers < 1:
        raise _UsageError(f"--workers = {args.workers} must be >= 1")
    lists = {key: getattr(args, key) for key in ("forward", "side", "turn", "step_time")}
    if args.grid is not None and any(v is not None for v in lists.values()):
        raise _UsageError("give either --grid or --forward/--side/--turn/--step-time, not both")
    grid = Grid.from_toml(args.grid) if args.grid is not None else Grid()
    values: dict[str, tuple[float, ...]] = {}
    for key, text in lists.items():
        if text is not None:
            try:
                values[key] = tuple(float(v) for v in text.split(","))
            except ValueError:
                raise _UsageError(f"--{key.replace('_', '-')} = {text!r} must be comma-separated numbers") from None
    grid = Grid(**{**vars(grid), **values})
    show = None if args.json or not sys.stderr.isatty() else (lambda done, total: _progress("commands", done, total))
    result = export_motions(args.robot, grid, args.out, fps=args.fps, workers=args.workers, scheduler=args.dask,
                            progress=show, swings=args.swings)
    failed = [c for c in result.clips if not c.verified]
    if args.json:
        print(json.dumps({"manifest": str(result.manifest), "clips": len(result.clips), "verified": result.verified,
                          "seconds": result.seconds, "failed": [c.name for c in failed]}, indent=2))
    else:
        for c in result.clips:
            check = "ok" if c.verified else "FAILED"
            print(f"{c.name:<48} {c.verdict:<4} replay {check:<6} slide {1000 * c.replay.get('slide', math.nan):5.2f} "
                  f"mm  penetration {1000 * c.replay.get('penetration', math.nan):5.2f} mm {c.error}")
        print(f"{result.verified}/{len(result.clips)} clips verified, {result.seconds:.1f} s; manifest: "
              f"{result.manifest}")
    return 0 if not failed else EXIT_FAILED


def _sweep(args: argparse.Namespace) -> int:
    import os

    _robot_by_name(args)
    from zmpwalk.sim.sweep import sweep

    names = args.scenario or list(list_scenarios())
    for name in names:
        if name not in list_scenarios():
            raise ZmpwalkError(f"unknown scenario {name!r}; known: {', '.join(list_scenarios())}")
    if args.workers is not None and args.workers < 1:
        raise _UsageError(f"--workers = {args.workers} must be >= 1")
    workers = args.workers or os.cpu_count() or 1
    show = None if args.json or not sys.stderr.isatty() else (lambda done, total: _progress("walks", done, total))
    balance = _balance(args)
    if args.generator is None:
        _resolve_generator(args, _load_robot(args))
    started, cpu = time.perf_counter(), time.process_time()
    schedule = _schedule(args)  # read here: a bad file is one error, not one per worker
    results = sweep(args.robot, names, balance=balance, workers=workers, progress=show, generator=args.generator,
                    schedule=str(schedule_path(args.schedule).resolve()) if schedule is not None else None,
                    pelvis=_pelvis(args),
                    scheduler=args.dask)
    wall = time.perf_counter() - started
    walked = sum(r.seconds for r in results)
    if args.json:
        print(json.dumps(_json_safe({"generator": args.generator, "workers": workers, "wall_seconds": wall,
                                     "walk_seconds": walked,
                                     "results": [vars(r) for r in results]}), indent=2, allow_nan=False))
    else:
        width = max(len(name) for name in names)
        for r in results:
            if r.error:
                print(f"{r.scenario:<{width}}  not planned: {r.error}")
                continue
            state = "PASS" if r.passed else "FAIL " + ", ".join(r.failed)
            print(f"{r.scenario:<{width}}  {r.simulated:5.1f} s simulated in {r.seconds:5.2f} s  "
                  f"distance {r.distance:6.3f} m  CoP RMS {r.cop_error_rms * 1e3:6.1f} mm  {state}")
        print(f"{len(results)} walks with the {args.generator} generator, {sum(r.simulated for r in results):.1f} s "
              f"simulated: {wall:.1f} s wall clock on "
              f"{workers} worker(s), {walked:.1f} s of walks ({walked / wall:.2f} walks at a time; "
              f"{time.process_time() - cpu:.1f} s CPU in this process)")
    return 0 if all(r.passed for r in results) else EXIT_FAILED


def _tune(args: argparse.Namespace) -> int:
    from zmpwalk.files import read_toml
    from zmpwalk.tune import schedule_toml, tune

    _robot_by_name(args)
    if args.workers is not None and args.workers < 1:
        raise _UsageError(f"--workers = {args.workers} must be >= 1")
    data = read_toml(schedule_path(args.schedule)) if args.schedule else None
    show = None if args.json else (
        (lambda done, total, best: _progress(f"conditions (best {best * 1e3:+.1f} mm)", done, total))
        if sys.stderr.isatty() else  # a log file: one line per condition (a tune runs for minutes)
        (lambda done, total, best: print(f"{done}/{total} conditions tuned, best {best * 1e3:+.1f} mm",
                                         file=sys.stderr, flush=True)))
    started = time.perf_counter()
    result = tune(args.robot, trials=args.trials, seed=args.seed, workers=args.workers, storage=args.storage,
                  steps=args.steps, data=data, progress=show, scheduler=args.dask, timing=args.timing)
    wall = time.perf_counter() - started
    write_text(args.out, schedule_toml(result, args.robot) + "\n")
    if args.json:
        from dataclasses import asdict

        rows = [asdict(r) for r in result.results]
        print(json.dumps(_json_safe({"seconds": wall, "out": str(args.out), "conditions": rows}), indent=2,
                         allow_nan=False))
    else:
        for r in result.results:
            values = ", ".join(f"{k} {v:.3g}" for k, v in r.values.items())
            multibody = "" if math.isnan(r.multibody_margin) else f" / {r.multibody_margin * 1e3:+.1f}"
            before = "" if math.isnan(r.table_multibody_margin) else f" / {r.table_multibody_margin * 1e3:+.1f}"
            print(f"{r.condition.name}: {values}; margin {r.cart_margin * 1e3:+.1f}{multibody} mm (table "
                  f"{r.table_cart_margin * 1e3:+.1f}{before}); {'walks' if r.walks else 'FAILS in simulation'}")
        print(f"{len(result.results)} conditions in {wall:.1f} s -> {args.out}")
    return 0 if all(r.walks for r in result.results) else EXIT_FAILED


def _json_safe(value: object) -> object:
    """NaN and infinity (e.g. no loaded sole) become null, so the output is strict JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {key: _json_safe(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_json_safe(item) for item in value]
    return value


class _PlanSummary:
    """What ``zmpwalk plan`` prints of a walk, gathered from its pieces as they pass."""

    def __init__(self) -> None:
        self.last: WalkingPattern | None = None
        self.samples = 0
        self.swings = 0
        self.margin = (math.inf, 0.0)

    def follow(self, pieces: Iterator[WalkingPattern]) -> Iterator[WalkingPattern]:
        for piece in pieces:
            self.last = piece
            self.samples += len(piece.time)
            self.swings += len([s for s in piece.steps if s.kind not in ("start", "settle")])
            self.margin = min(self.margin, piece.min_zmp_margin())
            yield piece

    def result(self) -> dict[str, object]:
        pattern = self.last
        if pattern is None:  # pragma: no cover - every walk has at least one piece
            raise ZmpwalkError("the walk has no samples")
        left, right = pattern.position_left_ankle_in_world[-1], pattern.position_right_ankle_in_world[-1]
        return {
            "generator": pattern.generator,
            "robot": pattern.robot.name,
            "rate": pattern.rate,
            "duration": pattern.duration,
            "samples": self.samples,
            "swings": self.swings,
            "min_zmp_margin": self.margin[0],
            "min_zmp_margin_time": self.margin[1],
            "final_left_ankle": [float(v) for v in left],
            "final_right_ankle": [float(v) for v in right],
        }


def _plan(args: argparse.Namespace) -> int:
    """``zmpwalk plan``: the pattern to --out (nothing written without it, and it says so) and its ZMP margin."""
    commands, labels = _commands(args)
    robot = _load_robot(args)
    _resolve_generator(args, robot)
    make = generator(args.generator)
    schedule = _schedule(args)
    options = _pattern_options(args)
    with _source(_label(args)):
        if args.generator == "polynomial":  # long walks: planned whole, sampled and written piece by piece
            pieces = generate_chunks(robot, commands, rate=args.rate, schedule=schedule, labels=labels,
                                     pelvis=_pelvis(args))
        else:
            pieces = iter([make(robot, commands, rate=args.rate, labels=labels, **options)])
        summary = _PlanSummary()
        stream = ((piece, pattern_joint_trajectory(piece).columns() if args.joints else None)
                  for piece in summary.follow(pieces))
        if args.out:
            write_pieces_csv(args.out, stream)
        else:
            for _ in stream:
                pass
    result = {**summary.result(), "out": str(args.out) if args.out else None}
    outside = float(result["min_zmp_margin"]) < 0  # type: ignore[arg-type]
    if outside and args.generator == "polynomial" and _pelvis(args) == "cubic":  # what to change, from its terms
        result["advice"] = zmp_advice(robot, commands, float(result["min_zmp_margin_time"]),  # type: ignore[arg-type]
                                      float(result["min_zmp_margin"]), schedule, labels).text  # type: ignore[arg-type]
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        margin = float(result["min_zmp_margin"])  # type: ignore[arg-type]
        print(f"generator: {_generator_words(args, robot)}")
        print(f"{result['swings']} swings, {result['duration']:.3f} s, {result['samples']} samples at "
              f"{args.rate:g} Hz" + (f" -> {args.out}" if args.out else
                                     "; no CSV written (give --out FILE to write it)"))
        print(f"min ZMP margin: {_margin_words(margin, float(result['min_zmp_margin_time']))}")  # type: ignore[arg-type]
        if "advice" in result:
            print(f"to bring it inside: {result['advice']}")
    return EXIT_FAILED if outside and not args.allow_outside else 0


def _run(args: argparse.Namespace) -> int:
    if args.command == "scenarios":
        scenarios = list_scenarios()
        if args.json:
            print(json.dumps(scenarios, indent=2))
        else:
            width = max(len(name) for name in scenarios)
            for name, description in scenarios.items():
                print(f"{name:<{width}}  {description}")
        return 0
    if args.command == "plan":
        return _plan(args)
    if args.command in ("demo", "report"):
        return _report(args)
    if args.command == "simulate":
        return _simulate(args)
    if args.command == "sweep":
        return _sweep(args)
    if args.command == "export":
        return _export(args)
    if args.command == "tune":
        return _tune(args)
    if args.command == "robot":
        from zmpwalk.robots.inspect import robot_summary, robot_table, robot_toml

        args.robot = args.model
        robot = _load_robot(args)
        statics, no_statics = None, ""
        if robot.plant is not None:
            from zmpwalk.sim.statics import static_torques

            try:
                statics = static_torques(robot)
            except InvalidParameterError as error:  # e.g. leg joints without position servos
                no_statics = f"\nstatic torques not computed: {error}"
        if args.write:
            write_text(args.write, robot_toml(robot, args.write.parent))
        if args.json:
            print(json.dumps(_json_safe(robot_summary(robot, statics)), indent=2, allow_nan=False))
        else:
            print(robot_table(robot, statics) + no_statics + (f"\nwritten: {args.write}" if args.write else ""))
        return 0
    if args.command == "hyperbolic":
        result = paper_example()
        if args.json:
            print(json.dumps(result, indent=2))
        else:
            for key, value in result.items():
                print(f"{key:>17}: {value}")
        return 0
    if args.command == "tables":
        if args.steps < 1:
            raise _UsageError(f"--steps = {args.steps} must be >= 1")
        results = condition_margins(_load_robot(args), schedule=_schedule(args), steps=args.steps)
        if args.json:
            print(json.dumps([vars(r) for r in results], indent=2))
        else:
            print(margins_markdown(results))
        return 0
    raise _UsageError(f"unknown command {args.command!r}")  # pragma: no cover


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("zmpwalk")
    except PackageNotFoundError:  # run from a source tree that was not installed
        return "unknown"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``zmpwalk`` command; returns the exit status."""
    try:
        parser = _parser()
        args = parser.parse_args(argv)
        if args.command is None:  # zmpwalk alone: the commands and what they do
            parser.print_help()
            return 0
        return _run(args)
    except (ZmpwalkError, _UsageError) as error:
        print(f"zmpwalk: error: {error}", file=sys.stderr)
        return EXIT_ERROR
    except OSError as error:  # an output folder or file the system refuses (full disk, permissions)
        where = f"{error.filename}: " if error.filename else ""
        print(f"zmpwalk: error: {where}cannot be written: {error.strerror or error}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())
