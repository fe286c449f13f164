"""``zmpwalk tune``: the shape factors of Tables 2-3 tuned for a robot and written as a schedule file."""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from zmpwalk.cli.options import (
    EXIT_FAILED,
    Commands,
    add_json_option,
    add_out_option,
    add_robot_options,
    add_schedule_option,
    add_worker_options,
    check_workers,
    require_robot_by_name,
)
from zmpwalk.cli.printing import json_safe, progress
from zmpwalk.files import write_text
from zmpwalk.schedule import schedule_path

NAMES = ("tune",)


def add_parser(commands: Commands) -> None:
    """Add the tune command."""
    parser = commands.add_parser(
        "tune", help="tune the shape factors of Tables 2-3 for a robot and write them as a schedule file",
        description="Search the shape factors of every condition of the tables (or of --schedule's) for the "
        "largest cart-table and multibody ZMP margin, check the best candidates in MuJoCo, and write the tuned "
        "schedule (the format --schedule reads). Exit status 3 when a condition does not walk.",
        epilog="example: zmpwalk tune --robot hubo --out hubo_tuned.toml --storage tune.db",
    )
    add_robot_options(parser)
    add_schedule_option(parser, help_text="the schedule to start from: default, paper or a schedule file (TOML); "
                        "without it Tables 2-3 as printed (paper)")
    add_out_option(parser, "schedule file to write (TOML)", required=True)
    parser.add_argument("--trials", type=int, default=40, help="candidates per condition (default: 40)")
    parser.add_argument("--steps", type=int, default=10, help="steps walked per candidate (default: 10)")
    parser.add_argument("--seed", type=int, default=0, help="sampler seed: the same seed, the same schedule")
    add_worker_options(parser, "conditions")
    parser.add_argument("--storage", type=Path, help="SQLite file of the studies: a stopped run resumes")
    parser.add_argument("--timing", action="store_true",
                        help="also tune V_y and the double-support time of Table 2's rows (added as columns)")
    add_json_option(parser)


def run(args: argparse.Namespace) -> int:
    """``zmpwalk tune``: tune every condition, write the schedule to --out and print each condition's margins."""
    from zmpwalk.files import read_toml
    from zmpwalk.tune import schedule_toml, tune

    require_robot_by_name(args)
    check_workers(args)
    data = read_toml(schedule_path(args.schedule)) if args.schedule else None
    show = None if args.json else (
        (lambda done, total, best: progress(f"conditions (best {best * 1e3:+.1f} mm)", done, total))
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
        print(json.dumps(json_safe({"seconds": wall, "out": str(args.out), "conditions": rows}), indent=2,
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
