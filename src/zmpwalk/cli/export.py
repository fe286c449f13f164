"""``zmpwalk export``: reference motions for learning, a grid of commands walked in MuJoCo and written as clips."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from zmpwalk.cli.options import (
    EXIT_FAILED,
    Commands,
    UsageError,
    add_json_option,
    add_out_option,
    add_robot_options,
    add_worker_options,
    check_workers,
    require_robot_by_name,
)
from zmpwalk.cli.printing import progress

NAMES = ("export",)
_LISTS = (("forward", "m/s"), ("side", "m/s"), ("turn", "rad/s"), ("step-time", "s"))


def add_parser(commands: Commands) -> None:
    """Add the export command."""
    parser = commands.add_parser(
        "export", help="reference motions for learning: walk a grid of commands in MuJoCo and export the clips",
        description="Walk every command of a grid (forward, side, turn velocity; step time) through the walking "
        "controller in MuJoCo with the stabilizer, and write the simulated and the planned motion, whole and cyclic, "
        "in the model's joint names and order, as mjlab npz, LocoMuJoCo-style npz, AMP JSON, CSV and a ROS 2 bag "
        "(MCAP), each replayed "
        "from its file and checked, with manifest.json (docs/export.md). Exit status 3 when a clip fails its check.",
        epilog="example: zmpwalk export --robot ../shared/robots/booster_t1/scene.xml --out t1-motions",
    )
    add_robot_options(parser)
    add_out_option(parser, "output folder (default: zmpwalk-motions)", default=Path("zmpwalk-motions"))
    parser.add_argument("--fps", type=float, default=50.0, help="frames per second of the clips (default: 50)")
    parser.add_argument("--grid", type=Path, help="a grid file (TOML: forward, side, turn, step_time lists)")
    for name, unit in _LISTS:
        parser.add_argument(f"--{name}", help=f"comma-separated values [{unit}] (instead of --grid; a list "
                            f"that starts with a minus sign takes '=': --{name}=-0.1,0,0.1)")
    parser.add_argument("--swings", type=int, default=10, help="swings walked per command (default: 10; a side "
                        "or turn step is two)")
    add_worker_options(parser, "commands walked")
    add_json_option(parser, "print the manifest's summary as JSON")


def run(args: argparse.Namespace) -> int:
    """``zmpwalk export``: walk the grid, write the clips and the manifest, and print each clip's check."""
    from zmpwalk.export import Grid, export_motions

    require_robot_by_name(args)
    check_workers(args)
    lists = {key: getattr(args, key) for key in ("forward", "side", "turn", "step_time")}
    if args.grid is not None and any(v is not None for v in lists.values()):
        raise UsageError("give either --grid or --forward/--side/--turn/--step-time, not both")
    grid = Grid.from_toml(args.grid) if args.grid is not None else Grid()
    values: dict[str, tuple[float, ...]] = {}
    for key, text in lists.items():
        if text is not None:
            try:
                values[key] = tuple(float(v) for v in text.split(","))
            except ValueError:
                raise UsageError(f"--{key.replace('_', '-')} = {text!r} must be comma-separated numbers") from None
    grid = Grid(**{**vars(grid), **values})
    show = None if args.json or not sys.stderr.isatty() else (lambda done, total: progress("commands", done, total))
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
                  f"mm  penetration {1000 * c.replay.get('penetration', math.nan):5.2f} mm"
                  + (f"  ready posture {c.ready_stretch:.2f} of the leg" if c.ready_stretch is not None else "")
                  + (f"  {c.error}" if c.error else ""))
        print(f"{result.verified}/{len(result.clips)} clips verified, {result.seconds:.1f} s; manifest: "
              f"{result.manifest}")
    return 0 if not failed else EXIT_FAILED
