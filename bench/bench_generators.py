"""The three generators on the same walks (HUBO, 1 kHz): ZMP margin, multibody ZMP error, and in MuJoCo open loop
and with the stabilizer the CoP tracking, the verdict and the peak joint torque; then their speed: a 100-step
walk with its 12 joint trajectories, and the online walkers' control loop (every iteration timed).

Run: python bench/bench_generators.py [--speed]. Prints Markdown tables (docs/generators.md); asserts nothing. The
simulations run on all cores, the timings on one.
"""

from __future__ import annotations

import dataclasses
import gc
import os
import statistics
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from zmpwalk import OnlineWalker, StepCommand, load_robot
from zmpwalk.dynamics import compare_zmp
from zmpwalk.errors import ZmpwalkError
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns import generator
from zmpwalk.scenarios import load_scenario
from zmpwalk.walk import WalkSpec, planned_walk, run_walk

WALKS = ("fig27", "fig28", "fig29", "fig30", "fig31", "turn45", "demo")
GENERATORS = ("polynomial", "preview", "hyperbolic")


def case(job: tuple[str, str]) -> tuple[str, str, str]:
    """One walk with one generator: the table cell's text (margin, multibody, simulation)."""
    walk, name = job
    robot = load_robot("hubo")
    spec = WalkSpec(robot, load_scenario(walk), generator=name)
    try:
        planned = planned_walk(spec)
    except ZmpwalkError as error:
        return walk, name, f"not planned ({str(error).split(';')[0][:40]})"
    pattern = planned.pattern
    margin = float(np.nanmin(pattern.zmp_margin()))
    comparison = compare_zmp(pattern)
    cells = [f"{margin * 1e3:+.1f} mm; {comparison.rms * 1e3:.1f} ({comparison.max * 1e3:.0f}) mm"]
    for balance in (False, True):
        outcome = run_walk(dataclasses.replace(spec, balance=balance), planned=planned)
        result, verdict = outcome.result, outcome.verdict
        rms, _ = result.cop_error_stats()
        state = "falls" if result.fell else ("pass" if verdict.passed else "fails " + ", ".join(verdict.failed))
        top = max(outcome.rows, key=lambda row: row.peak_torque)
        loop = "stab." if balance else "open"
        cells.append(f"{loop}: CoP {rms * 1e3:.1f} mm, {state}, {top.peak_torque:.0f} N m ({top.joint})")
    return walk, name, "; ".join(cells)


SPEED_WALK = [StepCommand(0.8, 0.15)] * 100  # every generator walks it


def walk_time(name: str) -> float:
    """Median time [s] of the 100-step walk at 1 kHz with its 12 joint trajectories."""
    robot = load_robot("hubo")
    make = generator(name)
    runs = []
    for _ in range(5):
        start = time.perf_counter()
        pattern_joint_trajectory(make(robot, SPEED_WALK, rate=1000.0))
        runs.append(time.perf_counter() - start)
    return statistics.median(runs)


def loop_times(name: str, seconds: float = 30.0) -> np.ndarray:
    """Every iteration [us] of a 1 kHz loop with joints: steps commanded as the one before starts (checked in
    parts over the ticks), walks of five steps from standstill with their automatic stop, 1 s standing between
    walks. Set up as docs/speed.md advises: everything loaded before the loop is frozen out of the garbage
    collector's full passes."""
    walker = OnlineWalker(load_robot("hubo"), rate=1000.0, joints=True, generator=name)
    gc.collect()
    gc.freeze()
    steps = [StepCommand(0.8, 0.15), StepCommand(0.8, 0.1, turn=0.1), StepCommand(0.8, side=0.05),
             StepCommand(0.7, 0.1), StepCommand(0.95, 0.1)]
    iterations, given, standing = [], 0, 0
    for _ in range(round(seconds * 1000)):
        start = time.perf_counter()
        if given < len(steps) and walker.queued is None and walker.checking is None and not standing:
            walker.command(steps[given])
            given += 1
        walker.tick()
        iterations.append(time.perf_counter() - start)
        if given == len(steps) and not walker.walking and walker.checking is None:
            standing += 1
            if standing >= 1000:
                given, standing = 0, 0
    return np.array(iterations) * 1e6


def main() -> None:
    if "--speed" not in sys.argv:  # --speed: the speed table alone
        simulations()
    speed()


def simulations() -> None:
    jobs = [(walk, name) for walk in WALKS for name in GENERATORS]
    with ProcessPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        cells = {(walk, name): text for walk, name, text in pool.map(case, jobs)}
    print("| walk | " + " | ".join(GENERATORS) + " |")
    print("|---" * (len(GENERATORS) + 1) + "|")
    for walk in WALKS:
        print(f"| {walk} | " + " | ".join(cells[(walk, name)] for name in GENERATORS) + " |")
    print("\neach cell: smallest cart-table ZMP margin; multibody - cart-table ZMP, RMS (max); in MuJoCo open loop "
          "and with the stabilizer: CoP - reference ZMP RMS, the verdict, largest joint torque (joint)\n")


def speed() -> None:
    print("| | " + " | ".join(GENERATORS) + " |")
    print("|---" * (len(GENERATORS) + 1) + "|")
    print("| 100 steps of 0.15 m at 0.8 s, 1 kHz, 12 joints | "
          + " | ".join(f"{walk_time(name) * 1e3:.0f} ms" for name in GENERATORS) + " |")
    cells = []
    for name in GENERATORS:
        if name == "preview":
            cells.append("- (offline)")
            continue
        us = loop_times(name)
        cells.append(f"median {np.median(us):.1f} us, p99.9 {np.percentile(us, 99.9):.0f} us, max {us.max():.0f} us")
    print("| online loop at 1 kHz with joints, command(), 30 s | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
