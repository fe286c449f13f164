"""``zmpwalk scenarios``: the built-in scenarios, the paper's experiments."""

from __future__ import annotations

import argparse
import json

from zmpwalk.cli.options import Commands, add_json_option
from zmpwalk.scenarios import list_scenarios

NAMES = ("scenarios",)


def add_parser(commands: Commands) -> None:
    """Add the scenarios command."""
    parser = commands.add_parser(
        "scenarios", help="list the built-in scenarios",
        description="List the built-in scenarios (the paper's experiments).", epilog="example: zmpwalk scenarios",
    )
    add_json_option(parser, "print a JSON object name -> description")


def run(args: argparse.Namespace) -> int:
    """Print each scenario with its description (or a JSON object name -> description)."""
    scenarios = list_scenarios()
    if args.json:
        print(json.dumps(scenarios, indent=2))
    else:
        width = max(len(name) for name in scenarios)
        for name, description in scenarios.items():
            print(f"{name:<{width}}  {description}")
    return 0
