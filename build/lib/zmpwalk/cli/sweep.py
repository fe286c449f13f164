"""``zmpwalk sweep``: many scenarios simulated on one robot, one walk per core at a time, each walk judged."""

from __future__ import annotations

import argparse
import json
import sys
import time

from zmpwalk.cli.options import (
    EXIT_FAILED,
    Commands,
    add_balance_option,
    add_generator_option,
    add_json_option,
    add_pelvis_option,
    add_robot_options,
    add_schedule_option,
    add_worker_options,
    balance_of,
    check_workers,
    load_robot_of,
    pelvis_of,
    require_robot_by_name,
    resolve_generator,
    schedule_of,
)
from zmpwalk.cli.printing import json_safe, progress
from zmpwalk.errors import ZmpwalkError
from zmpwalk.scenarios import list_scenarios
from zmpwalk.schedule import schedule_path

NAMES = ("sweep",)


def add_parser(commands: Commands) -> None:
    """Add the sweep command."""
    parser = commands.add_parser(
        "sweep", help="simulate many scenarios on all cores and judge each walk",
        description="Simulate built-in scenarios on one robot, one walk per core at a time, and print each "
        "walk's verdict. Exit status 3 when any walk fails its verdict.",
        epilog="example: zmpwalk sweep --robot hubo --balance on   |   zmpwalk sweep --scenario fig27 fig28",
    )
    add_robot_options(parser)
    parser.add_argument("--scenario", nargs="+", help="scenarios to walk (default: every built-in one)")
    add_worker_options(parser, "walks")
    add_balance_option(parser, "the stabilizer (default: on, for every robot; off: open loop, as the papers walk)")
    add_generator_option(parser)
    add_schedule_option(parser, " (e.g. from zmpwalk tune)")
    add_pelvis_option(parser)
    add_json_option(parser)


def run(args: argparse.Namespace) -> int:
    """``zmpwalk sweep``: walk the scenarios and print each walk's verdict and the time it took."""
    import os

    require_robot_by_name(args)
    from zmpwalk.sweep import sweep

    names = args.scenario or list(list_scenarios())
    for name in names:
        if name not in list_scenarios():
            raise ZmpwalkError(f"unknown scenario {name!r}; known: {', '.join(list_scenarios())}")
    check_workers(args)
    workers = args.workers or os.cpu_count() or 1
    show = None if args.json or not sys.stderr.isatty() else (lambda done, total: progress("walks", done, total))
    balance = balance_of(args)
    if args.generator is None:
        resolve_generator(args, load_robot_of(args))
    started, cpu = time.perf_counter(), time.process_time()
    schedule = schedule_of(args)  # read here: a bad file is one error, not one per worker
    results = sweep(args.robot, names, balance=balance, workers=workers, progress=show, generator=args.generator,
                    schedule=str(schedule_path(args.schedule).resolve()) if schedule is not None else None,
                    pelvis=pelvis_of(args),
                    scheduler=args.dask)
    wall = time.perf_counter() - started
    walked = sum(r.seconds for r in results)
    if args.json:
        print(json.dumps(json_safe({"generator": args.generator, "workers": workers, "wall_seconds": wall,
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
