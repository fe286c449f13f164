"""Long walks: plan and check 1k, 10k and 100k steps at 100 Hz, time and peak memory of each.

Each size runs in its own process (so its peak resident memory is its own): the walk is
planned whole (every command checked, the legs' reach included), then sampled piece by
piece with :func:`zmpwalk.patterns.polynomial.generate_chunks` and every sample's ZMP
margin computed, as ``zmpwalk plan`` does. Writing the CSV is not timed.

Run: python bench/bench_long_walk.py [--sizes 1000 10000 100000]. Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time


def one(steps: int) -> dict[str, float]:
    from zmpwalk import StepCommand, load_robot
    from zmpwalk.patterns.polynomial import generate_chunks

    robot = load_robot("hubo")
    pattern = [StepCommand(0.8, 0.2), StepCommand(0.8, 0.1, turn=0.1), StepCommand(0.9, side=0.05),
               StepCommand(0.8, 0.1, turn=-0.1)]
    commands = [pattern[i % len(pattern)] for i in range(steps)]
    start = time.perf_counter()
    samples, low = 0, float("inf")
    for piece in generate_chunks(robot, commands, rate=100.0):
        samples += len(piece.time)
        low = min(low, float(piece.zmp_margin().min()))
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # [MiB] (Linux reports KiB)
    return {"steps": steps, "samples": samples, "seconds": seconds, "peak_mib": peak, "min_margin_m": low}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000, 100000])
    parser.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        print(json.dumps(one(args.one)))
        return
    print(f"{'steps':>8} {'samples':>10} {'time [s]':>9} {'us/step':>8} {'peak [MiB]':>11} {'min margin [mm]':>16}")
    for steps in args.sizes:
        out = subprocess.run([sys.executable, __file__, "--one", str(steps)], capture_output=True, text=True,
                             check=True)
        r = json.loads(out.stdout)
        print(f"{r['steps']:>8} {r['samples']:>10} {r['seconds']:>9.2f} {r['seconds'] / steps * 1e6:>8.0f} "
              f"{r['peak_mib']:>11.0f} {r['min_margin_m'] * 1e3:>16.1f}")


if __name__ == "__main__":
    main()
