"""``zmpwalk hyperbolic``: the walking example of Lim et al., solved with the hyperbolic (LIPM) pattern."""

from __future__ import annotations

import argparse
import json

from zmpwalk.cli.options import Commands, add_json_option
from zmpwalk.patterns.hyperbolic import HyperbolicGait

NAMES = ("hyperbolic",)


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


def add_parser(commands: Commands) -> None:
    """Add the hyperbolic command."""
    parser = commands.add_parser(
        "hyperbolic", help="the hyperbolic (LIPM) pattern of Lim et al.: the paper's example",
        description="Solve the paper's walking example (Eqs. 11 and 15 of Lim et al.): steady-step times, "
        "lateral sway and the ZMPs of the start from standstill. Times in s, lengths in m.",
        epilog="example: zmpwalk hyperbolic --paper-example --json",
    )
    parser.add_argument("--paper-example", action="store_true", required=True,
                        help="z_b = 395 mm, x_s = 100 mm, x_ZMP1 = x_s/8, x_ZMP2 = x_s/4, y_ZMP = 68 mm, "
                        "v_xD = 100 mm/s, t* = 0.2 s, tau* = 0.3 s, g = 9.8 m/s^2")
    add_json_option(parser, "print a JSON object")


def run(args: argparse.Namespace) -> int:
    """Print the paper example's figures (or a JSON object)."""
    result = paper_example()
    if args.json:
        print(json.dumps(result, indent=2))
    else:
        for key, value in result.items():
            print(f"{key:>17}: {value}")
    return 0
