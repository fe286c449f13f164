"""Time of a full tuning run: the paper's grid (18 rows) and the turn rows (6) for HUBO on every core, as
``zmpwalk tune`` runs it.

Run: python bench/bench_tune.py [--robot hubo] [--trials 40] [--workers N]. Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import os
import time

from zmpwalk.tune import tune


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="hubo")
    parser.add_argument("--trials", type=int, default=40)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    start, cpu = time.perf_counter(), time.process_time()
    result = tune(args.robot, trials=args.trials, workers=args.workers)
    wall = time.perf_counter() - start
    rows = result.results
    inside = sum(1 for r in rows if r.cart_margin > 0 and not r.multibody_margin <= 0)  # nan: no links
    walks = sum(1 for r in rows if r.walks)
    worst = min(rows, key=lambda r: r.cart_margin)
    print(f"{args.robot}: {len(rows)} rows x {args.trials} candidates on {args.workers} worker(s): {wall:.1f} s wall "
          f"clock ({sum(r.seconds for r in rows):.1f} s of rows, {time.process_time() - cpu:.1f} s CPU here)")
    print(f"  rows with both ZMPs inside at every sample: {inside} of {len(rows)}; rows that walk in MuJoCo: {walks} "
          f"of {len(rows)}; smallest cart-table margin {worst.cart_margin * 1e3:+.1f} mm ({worst.condition.name})")
    slowest = max(rows, key=lambda r: r.seconds)
    print(f"  slowest row: {slowest.condition.name}, {slowest.seconds:.1f} s")


if __name__ == "__main__":
    main()
