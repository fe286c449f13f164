"""``zmpwalk demo`` and ``zmpwalk report``: a walk generated, checked, simulated and reported as an HTML page.

``demo`` is the first thing to run: without a steps file or --scenario it walks HUBO through the demo scenario.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from zmpwalk.cli.options import (
    EXIT_FAILED,
    Commands,
    UsageError,
    add_generator_option,
    add_json_option,
    add_out_option,
    add_pelvis_option,
    add_robot_options,
    add_schedule_option,
    add_simulation_options,
    add_walk_options,
    balance_of,
    generator_words,
    load_robot_of,
    motors_of,
    named_source,
    pelvis_of,
    resolve_generator,
    schedule_of,
)
from zmpwalk.cli.printing import json_safe, margin_words, print_verdict, progress
from zmpwalk.scenarios import load_scenario_with_labels, load_steps_file_with_labels

NAMES = ("demo", "report")
_HELP = {
    "demo": "the first thing to run: walk HUBO, check the ZMP, simulate, and write a report",
    "report": "generate, check, simulate and report any walk as a self-contained HTML page",
}
_EXAMPLES = {
    "demo": "example: zmpwalk demo   |   zmpwalk demo --robot mju-biped --scenario fig30 --out my-report   |   "
            "zmpwalk demo my_steps.toml",
    "report": "example: zmpwalk report --scenario fig28 --out fig28-report   |   zmpwalk report my_steps.toml",
}


def add_parser(commands: Commands) -> None:
    """Add the demo and report commands."""
    for name in NAMES:
        parser = commands.add_parser(
            name, help=_HELP[name],
            description="Generate the pattern (1 kHz), check its ZMP, compute the joint angles, simulate the "
            "walk in MuJoCo and write a report folder: index.html (plots, actuator table, ZMP margin per step, "
            "an interactive 3D replay of the simulated walk; self-contained, opens offline), figures, CSV and JSON "
            "files.",
            epilog=_EXAMPLES[name],
        )
        add_walk_options(parser, "steps file (TOML), as plan and simulate take it",
                         "built-in scenario" + (" (default: demo, without a steps file)" if name == "demo" else ""),
                         steps_as_path=True)
        parser.add_argument("--steps", type=Path, dest="steps_option", metavar="STEPS",
                            help="the steps file given as an option (the same as the positional STEPS)")
        add_robot_options(parser)
        add_schedule_option(parser)
        add_pelvis_option(parser)
        add_simulation_options(parser)
        add_generator_option(parser)
        add_out_option(parser, "report folder (default: ./zmpwalk-demo or ./zmpwalk-report)",
                       default=Path("zmpwalk-demo" if name == "demo" else "zmpwalk-report"))
        parser.add_argument("--no-animation", action="store_true",
                            help="skip the interactive replay (and the GIF)")
        parser.add_argument("--gif", action="store_true",
                            help="also render a GIF of the walk offscreen with MuJoCo (walk.gif, shown where the "
                            "browser has no WebGL; slower)")
        add_json_option(parser, "print a JSON summary")


def run(args: argparse.Namespace) -> int:
    """``zmpwalk demo`` and ``zmpwalk report``: write the report folder and print the walk's verdict."""
    from zmpwalk.ready_fit import fit_ready_posture
    from zmpwalk.report import build_report
    from zmpwalk.walk import WalkSpec

    if args.steps and args.steps_option:
        raise UsageError("give the steps file once: STEPS or --steps STEPS")
    args.steps = args.steps or args.steps_option
    if args.steps and args.scenario:
        raise UsageError("give either a steps file or --scenario, not both")
    if args.command == "demo" and not args.steps and not args.scenario:
        args.scenario = "demo"
    if args.steps:
        (commands, labels), name = load_steps_file_with_labels(args.steps), args.steps.name
    elif args.scenario:
        (commands, labels), name = load_scenario_with_labels(args.scenario), args.scenario
    else:
        raise UsageError("give --scenario NAME or a steps file (see 'zmpwalk scenarios')")
    robot = load_robot_of(args)
    resolve_generator(args, robot)
    quiet = args.json or not sys.stderr.isatty()
    with named_source(str(args.steps) if args.steps else f"scenario {args.scenario}"):
        fitted = fit_ready_posture(WalkSpec(robot, commands, labels, generator=args.generator,
                                            schedule=schedule_of(args), pelvis=pelvis_of(args), check_limits=True,
                                            balance=balance_of(args), latency=args.latency, motors=motors_of(args)),
                                   lambda stretch: load_robot_of(args, stretch))
        robot = fitted.spec.robot
        with fitted.walking(say=not args.json):
            report = build_report(robot, commands, args.out, title=f"zmpwalk: {robot.name}, {name}",
                                  generator=args.generator, animate=not args.no_animation,
                                  gif=args.gif and not args.no_animation,
                                  progress=None if quiet else progress, labels=labels,
                                  balance=balance_of(args), latency=args.latency, schedule=schedule_of(args),
                                  motors=motors_of(args), pelvis=pelvis_of(args), planned=fitted.planned)
    verdict = report.verdict
    if args.json:
        summary = {**report.summary, "index": str(report.index), "seconds": report.seconds,
                   "ready_stretch": fitted.stretch, "ready_posture_refusal": fitted.refusal or None}
        print(json.dumps(json_safe(summary), indent=2, allow_nan=False))
    else:
        s = report.summary
        state = f"FELL at t = {s['fall_time']:.2f} s" if s["fell"] else "no fall"
        print(f"generator: {generator_words(args, robot)}")
        print(f"controller: {s['controller']}")
        print(f"{robot.name}, {name}: {verdict.state} ({state}); plan's min ZMP margin "
              f"{margin_words(float(s['min_zmp_margin']))} -> {report.index}")
        print_verdict(verdict)
    return 0 if verdict.passed else EXIT_FAILED
