"""``zmpwalk plan``: the walking pattern of a steps file or a scenario, as CSV, and its smallest ZMP margin."""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Iterator

from zmpwalk.cli.options import (
    EXIT_FAILED,
    Commands,
    add_generator_option,
    add_json_option,
    add_out_option,
    add_pelvis_option,
    add_robot_options,
    add_schedule_option,
    add_walk_options,
    generator_words,
    load_robot_of,
    named_source,
    pattern_options,
    pelvis_of,
    resolve_generator,
    schedule_of,
    walk_label,
    walk_of,
)
from zmpwalk.cli.printing import margin_words
from zmpwalk.commands import StepCommand
from zmpwalk.errors import ZmpwalkError
from zmpwalk.joint_limits import check_joint_limits
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns import generator
from zmpwalk.patterns.polynomial import generate_chunks
from zmpwalk.patterns.result import WalkingPattern, write_pieces_csv
from zmpwalk.ready_fit import FittedWalk, fit_ready_posture
from zmpwalk.robots.model import RobotModel
from zmpwalk.tables import zmp_advice
from zmpwalk.walk import WalkSpec

NAMES = ("plan",)


def add_parser(commands: Commands) -> None:
    """Add the plan command."""
    parser = commands.add_parser(
        "plan", help="generate a walking pattern and write it as CSV",
        description="Generate the walking pattern of a steps file or a scenario, write one CSV row per "
        "sample (world frame, SI units) and print the smallest ZMP margin.",
        epilog="example: zmpwalk plan --scenario fig30 --out fig30.csv   |   zmpwalk plan my_steps.toml",
    )
    add_walk_options(parser, "steps file (TOML, [[steps]] tables)",
                     "a built-in scenario instead of a steps file (see 'zmpwalk scenarios')")
    add_robot_options(parser)
    add_schedule_option(parser)
    add_pelvis_option(parser)
    parser.add_argument("--rate", type=float, default=1000.0,
                        help="samples per second [Hz] (default: 1000, as report and simulate)")
    parser.add_argument("--allow-outside", action="store_true",
                        help="exit 0 even when the ZMP leaves the support polygon (default: exit 3)")
    add_generator_option(parser)
    add_out_option(parser, "CSV file to write (without it nothing is written: the summary says so)")
    parser.add_argument("--joints", action="store_true", help="append the 12 leg joint angles [rad] to the CSV")
    add_json_option(parser, "print a JSON summary")


class PlanSummary:
    """What ``zmpwalk plan`` prints of a walk, gathered from its pieces as they pass."""

    def __init__(self) -> None:
        self.last: WalkingPattern | None = None
        self.samples = 0
        self.swings = 0
        self.margin = (math.inf, 0.0)

    def follow(self, pieces: Iterator[WalkingPattern]) -> Iterator[WalkingPattern]:
        """Pass the pieces on, counting their samples and swings and keeping the smallest ZMP margin [m]."""
        for piece in pieces:
            self.last = piece
            self.samples += len(piece.time)
            self.swings += len([s for s in piece.steps if s.kind not in ("start", "settle")])
            self.margin = min(self.margin, piece.min_zmp_margin())
            yield piece

    def result(self) -> dict[str, object]:
        """The summary of the walk (SI): generator, robot, rate, duration, margin, the ankles' final places."""
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


def run(args: argparse.Namespace) -> int:
    """``zmpwalk plan``: the pattern to --out (nothing written without it, and it says so) and its ZMP margin.
    Where an imported robot's own ready posture refuses the walk for its legs (reach, or a joint's range, checked
    whether or not --joints writes the angles), the walk is planned from the posture that fits it
    (:mod:`zmpwalk.ready_fit`), as ``zmpwalk simulate`` walks it."""
    commands, labels = walk_of(args)
    robot = load_robot_of(args)
    resolve_generator(args, robot)
    fitted = None
    if robot.plant is not None and not robot.plant.posture_set_by:
        options: dict[str, object] = {} if schedule_of(args) is None else {"schedule": schedule_of(args)}
        spec = WalkSpec(robot, commands, labels, generator=args.generator, pelvis=pelvis_of(args), rate=args.rate,
                        source=walk_label(args), **options)  # type: ignore[arg-type]
        fitted = fit_ready_posture(spec, lambda stretch: load_robot_of(args, stretch))
        robot = fitted.spec.robot
    return _plan(args, robot, commands, labels, fitted)


def _plan(args: argparse.Namespace, robot: RobotModel, commands: list[StepCommand], labels: list[str],
          fitted: FittedWalk | None) -> int:
    """Plan (or take the walk ``fitted`` planned), write and print the walk of ``robot`` (standing as ``fitted``
    chose, where it did)."""
    make = generator(args.generator)
    schedule = schedule_of(args)
    options = pattern_options(args)
    summary = PlanSummary()
    with named_source(walk_label(args)):
        if fitted is not None and fitted.planned is not None:  # planned whole already, its joints with it
            planned = fitted.planned
            if args.joints:
                check_joint_limits(planned.joints.time, planned.joints.angles, robot)
            columns = planned.joints.columns() if args.joints else None
            stream = ((piece, columns) for piece in summary.follow(iter([planned.pattern])))
        else:
            if args.generator == "polynomial":  # long walks: planned whole, sampled and written piece by piece
                pieces = generate_chunks(robot, commands, rate=args.rate, schedule=schedule, labels=labels,
                                         pelvis=pelvis_of(args))
            else:
                pieces = iter([make(robot, commands, rate=args.rate, labels=labels, **options)])
            stream = ((piece, pattern_joint_trajectory(piece).columns() if args.joints else None)
                      for piece in summary.follow(pieces))
        if args.out:
            write_pieces_csv(args.out, stream)
        else:
            for _ in stream:
                pass
    result = {**summary.result(), "out": str(args.out) if args.out else None,
              "ready_stretch": None if fitted is None else fitted.stretch,
              "ready_posture_refusal": None if fitted is None else fitted.refusal or None}
    outside = float(result["min_zmp_margin"]) < 0  # type: ignore[arg-type]
    if outside and args.generator == "polynomial" and pelvis_of(args) == "cubic":  # what to change, from its terms
        result["advice"] = zmp_advice(robot, commands, float(result["min_zmp_margin_time"]),  # type: ignore[arg-type]
                                      float(result["min_zmp_margin"]), schedule, labels).text  # type: ignore[arg-type]
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        margin = float(result["min_zmp_margin"])  # type: ignore[arg-type]
        print(f"generator: {generator_words(args, robot)}")
        if fitted is not None and fitted.stretch is not None:
            print(fitted.words())
        print(f"{result['swings']} swings, {result['duration']:.3f} s, {result['samples']} samples at "
              f"{args.rate:g} Hz" + (f" -> {args.out}" if args.out else
                                     "; no CSV written (give --out FILE to write it)"))
        print(f"min ZMP margin: {margin_words(margin, float(result['min_zmp_margin_time']))}")  # type: ignore[arg-type]
        if "advice" in result:
            print(f"to bring it inside: {result['advice']}")
    return EXIT_FAILED if outside and not args.allow_outside else 0
