"""Time per stage of the demo (zmpwalk demo): pattern, joints, simulation, plots, animation, page.

Run: python bench/bench_demo.py. Prints figures; asserts nothing.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from zmpwalk import load_robot
from zmpwalk.report import build_report
from zmpwalk.scenarios import load_scenario


def main() -> None:
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        report = build_report(load_robot("hubo"), load_scenario("demo"), Path(folder) / "demo", title="bench")
    total = time.perf_counter() - start
    for stage, seconds in report.seconds.items():
        print(f"{stage:>10}: {seconds:6.2f} s")
    print(f"{'total':>10}: {total:6.2f} s (target: 120 s on 2 cores)")


if __name__ == "__main__":
    main()
