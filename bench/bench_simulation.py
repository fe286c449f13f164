"""Real-time factor of the MuJoCo simulation: in the process, as a whole ``zmpwalk simulate`` process, and a
sweep of the built-in scenarios on one and on every core.

Run: python bench/bench_simulation.py. Prints figures; asserts nothing.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

from zmpwalk import load_robot
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.hyperbolic import paper_walk
from zmpwalk.patterns.polynomial import generate
from zmpwalk.scenarios import load_scenario
from zmpwalk.sim import simulate


def main() -> None:
    cases = {
        "hubo (fig28, 13.7 s)": (load_robot("hubo"), lambda r: generate(r, load_scenario("fig28"), rate=1000.0)),
        "mju-biped (paper walk, 6 steady steps)": (
            load_robot("mju-biped"), lambda r: paper_walk(r, steps=6).sample(1000.0)),
    }
    for name, (robot, make) in cases.items():
        pattern = make(robot)
        joints = pattern_joint_trajectory(pattern)
        simulate(robot, joints, pattern)  # warm-up
        runs = []
        for _ in range(3):
            start = time.perf_counter()
            simulate(robot, joints, pattern)
            runs.append(time.perf_counter() - start)
        best = min(runs)
        print(f"{name}: {pattern.time[-1]:.2f} s simulated in {best:.2f} s -> "
              f"real-time factor {pattern.time[-1] / best:.1f}x "
              f"(one core, 0.5 ms steps, all measurements)")
    # the whole process, as a user runs it (interpreter start, imports, pattern, joints, MuJoCo, verdict)
    command = [sys.executable, "-m", "zmpwalk.cli", "simulate", "--scenario", "fig28", "--json"]
    runs = []
    for _ in range(3):
        start = time.perf_counter()
        out = subprocess.run(command, capture_output=True, text=True, check=False)
        runs.append(time.perf_counter() - start)
    simulated = json.loads(out.stdout)["duration"]
    print(f"zmpwalk simulate --scenario fig28 as a process: {simulated:.1f} s simulated (walk, 0.5 s standing "
          f"before, 2 s after) in {min(runs):.2f} s (best of 3, median {sorted(runs)[1]:.2f} s) -> "
          f"{simulated / min(runs):.1f}x real time")
    for workers in (1, os.cpu_count() or 1):
        command = [sys.executable, "-m", "zmpwalk.cli", "sweep", "--workers", str(workers), "--json"]
        start = time.perf_counter()
        out = subprocess.run(command, capture_output=True, text=True, check=False)
        wall = time.perf_counter() - start
        summary = json.loads(out.stdout)
        simulated = sum(r["simulated"] for r in summary["results"])
        print(f"zmpwalk sweep (8 scenarios, HUBO) on {workers} worker(s): {simulated:.1f} s simulated in "
              f"{wall:.2f} s as a process ({simulated / wall:.1f}x real time; "
              f"{summary['walk_seconds'] / summary['wall_seconds']:.2f} walks at a time)")


if __name__ == "__main__":
    main()
