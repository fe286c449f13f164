"""The three generators on the same walks (HUBO, 1 kHz): ZMP margin, multibody ZMP error, and in MuJoCo with the
stabilizer the CoP tracking, the verdict and the peak joint torque.

Run: python bench/bench_generators.py. Prints a Markdown table (docs/generators.md); asserts nothing. Runs on
all cores.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from zmpwalk import load_robot
from zmpwalk.balance import Stabilizer
from zmpwalk.dynamics import compare_zmp
from zmpwalk.errors import ZmpwalkError
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns import generator
from zmpwalk.scenarios import load_scenario
from zmpwalk.sim import actuator_table, simulate
from zmpwalk.sim.verdict import HOLD, SETTLE, walk_verdict

WALKS = ("fig27", "fig28", "fig29", "fig30", "fig31", "turn45", "demo")
GENERATORS = ("polynomial", "preview", "hyperbolic")


def case(job: tuple[str, str]) -> tuple[str, str, str]:
    """One walk with one generator: the table cell's text (margin, multibody, simulation)."""
    walk, name = job
    robot = load_robot("hubo")
    try:
        pattern = generator(name)(robot, load_scenario(walk), rate=1000.0)
    except ZmpwalkError as error:
        return walk, name, f"not planned ({str(error).split(';')[0][:40]})"
    margin = float(np.nanmin(pattern.zmp_margin()))
    comparison = compare_zmp(pattern)
    joints = pattern_joint_trajectory(pattern, check_limits=False)
    result = simulate(robot, joints, pattern, stabilizer=Stabilizer(robot, 1000.0), settle=SETTLE, hold=HOLD)
    verdict = walk_verdict(result, HOLD)
    rms, _ = result.cop_error_stats()
    state = "falls" if result.fell else ("pass" if verdict.passed else "fails " + ", ".join(verdict.failed))
    top = max(actuator_table(result), key=lambda row: row.peak_torque)
    return walk, name, (f"{margin * 1e3:+.1f} mm; {comparison.rms * 1e3:.1f} ({comparison.max * 1e3:.0f}) mm; "
                        f"CoP {rms * 1e3:.1f} mm, {state}; {top.peak_torque:.0f} N m ({top.joint})")


def main() -> None:
    jobs = [(walk, name) for walk in WALKS for name in GENERATORS]
    with ProcessPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        cells = {(walk, name): text for walk, name, text in pool.map(case, jobs)}
    print("| walk | " + " | ".join(GENERATORS) + " |")
    print("|---" * (len(GENERATORS) + 1) + "|")
    for walk in WALKS:
        print(f"| {walk} | " + " | ".join(cells[(walk, name)] for name in GENERATORS) + " |")
    print("\neach cell: smallest cart-table ZMP margin; multibody - cart-table ZMP, RMS (max); in MuJoCo with the "
          "stabilizer: CoP - reference ZMP RMS and the verdict; largest joint torque (joint)")


if __name__ == "__main__":
    main()
