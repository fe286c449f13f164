"""``zmpwalk tables``: every condition of the parameter tables (Tables 2-3) walked, and its smallest ZMP margin."""

from __future__ import annotations

import argparse
import json

from zmpwalk.cli.options import (
    Commands,
    UsageError,
    add_json_option,
    add_robot_options,
    add_schedule_option,
    load_robot_of,
    schedule_of,
)
from zmpwalk.tables import condition_margins, margins_markdown

NAMES = ("tables",)


def add_parser(commands: Commands) -> None:
    """Add the tables command."""
    parser = commands.add_parser(
        "tables", help="walk every condition of Tables 2-3 and print the ZMP margins",
        description="Walk each tuned condition of the parameter tables (Tables 2 and 3) for a number of "
        "steps at 1 kHz and print the smallest cart-table ZMP margin of each as a Markdown table.",
        epilog="example: zmpwalk tables --steps 10",
    )
    add_robot_options(parser)
    add_schedule_option(parser)
    parser.add_argument("--steps", type=int, default=10, help="steps walked per condition (default: 10)")
    add_json_option(parser, "print JSON instead of Markdown")


def run(args: argparse.Namespace) -> int:
    """Print each condition's smallest cart-table ZMP margin as a Markdown table (or JSON)."""
    if args.steps < 1:
        raise UsageError(f"--steps = {args.steps} must be >= 1")
    results = condition_margins(load_robot_of(args), schedule=schedule_of(args), steps=args.steps)
    if args.json:
        print(json.dumps([vars(r) for r in results], indent=2))
    else:
        print(margins_markdown(results))
    return 0
