"""Walks with and without the stabilizer, per robot and scenario: the tables of docs/balance.md.

Run: python bench/bench_balance.py [--quick]. Prints Markdown tables and the stabilizer's cost per tick;
asserts nothing. TALOS and Booster T1 need ../shared/robots (skipped when absent). Runs on all cores.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from zmpwalk import StepCommand, load_robot
from zmpwalk.balance import BalanceMeasurement, Stabilizer
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.patterns.polynomial import generate
from zmpwalk.robots.model import RobotModel
from zmpwalk.scenarios import load_scenario
from zmpwalk.walk import WalkSpec, run_walk

TALOS = Path(__file__).resolve().parents[2] / "shared" / "robots" / "pal_talos" / "scene_position.xml"
T1 = Path(__file__).resolve().parents[2] / "shared" / "robots" / "booster_t1" / "scene.xml"
HUBO_SCENARIOS = ("fig10", "fig27", "fig28", "fig29", "fig30", "fig31", "turn45", "demo")


def walks_of(*forward: tuple[float, float]) -> dict[str, list[StepCommand]]:
    """Ten steps of each forward walk (stride [m], step time [s]), then the side walk and the turn every robot
    walks."""
    named = {f"10 x {stride * 100:.0f} cm, {duration} s": [StepCommand(duration=duration, forward=stride)] * 10
             for stride, duration in forward}
    named["side 6 x 5 cm, 0.9 s"] = [StepCommand(duration=0.9, side=0.05)] * 6
    named["turn 3 x 15 deg, 1.0 s"] = [StepCommand(duration=1.0, turn=math.radians(15))] * 3
    return named


TALOS_WALKS = walks_of((0.1, 0.8), (0.15, 0.9), (0.2, 1.0))
T1_WALKS = walks_of((0.1, 0.9), (0.1, 0.8), (0.15, 0.8))
PATHS = {"talos": TALOS, "t1": T1}
WALKS = {"talos": TALOS_WALKS, "t1": T1_WALKS}


def robot(name: str, kp: float | None) -> RobotModel:
    model = load_robot(PATHS.get(name, name))
    if kp is not None and model.servos is not None:
        model = dataclasses.replace(model, servos=dataclasses.replace(model.servos, kp=kp, kv=kp / 50))
    return model


def case(job: tuple[str, float | None, str, bool]) -> str:
    name, kp, walk, balance = job
    model = robot(name, kp)
    commands = WALKS[name][walk] if name in WALKS else load_scenario(walk)
    outcome = run_walk(WalkSpec(model, commands, generator="polynomial", balance=balance))
    result, seconds = outcome.result, outcome.seconds["simulation"]
    rms, _ = result.cop_error_stats()
    state = f"fell at {result.fall_time:.2f} s" if result.fell else "walks"
    label = f"{name} (kp {kp:g})" if kp else name
    return (f"| {label} | {walk} | {'on' if balance else 'off'} | {state} | {rms * 1e3:.0f} | "
            f"{result.final_feet_error * 1e3:.1f} | {result.end_min_sole_force:.0f} | "
            f"{result.end_attitude_range:.3f} | {seconds:.1f} |")


def stabilizer_cost() -> str:
    model = load_robot("hubo")
    pattern = generate(model, [StepCommand(duration=0.8, forward=0.2)] * 4, rate=1000.0)
    joints = pattern_joint_trajectory(pattern)
    stabilizer = Stabilizer(model, 1000.0)
    weight = model.mass * model.gravity / 2
    measurement = BalanceMeasurement(np.array([0, 0, weight, 0, 0, 0.0]), np.array([0, 0, weight, 0, 0, 0.0]),
                                     np.zeros(2), np.zeros(3), joints.angles[0])
    ticks = []
    for k in range(len(pattern.time)):
        measurement.joint_angles = joints.angles[k]
        start = time.perf_counter()
        stabilizer.update(support=int(pattern.support[k]), position_com_in_world=pattern.position_pelvis_in_world[k],
                          yaw_pelvis_in_world=float(pattern.yaw_pelvis_in_world[k]),
                          zmp_in_world=pattern.zmp_in_world[k],
                          ankles_in_world=(pattern.position_left_ankle_in_world[k],
                                           pattern.position_right_ankle_in_world[k]),
                          foot_yaws=(float(pattern.yaw_left_foot_in_world[k]),
                                     float(pattern.yaw_right_foot_in_world[k])),
                          joint_angles=joints.angles[k], measurement=measurement)
        ticks.append(time.perf_counter() - start)
    cost = np.array(ticks) * 1e6
    return (f"stabilizer update, HUBO, {len(cost)} ticks: median {np.median(cost):.1f} us, p99 "
            f"{np.percentile(cost, 99):.1f} us, p99.9 {np.percentile(cost, 99.9):.0f} us, max {cost.max():.0f} us")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="fig27 and one walk of each imported robot only")
    args = parser.parse_args()
    jobs: list[tuple[str, float | None, str, bool]] = []
    scenarios = ("fig27",) if args.quick else HUBO_SCENARIOS
    for walk in scenarios:
        for kp in (None, 3000.0):
            jobs += [("hubo", kp, walk, False), ("hubo", kp, walk, True)]
    for name, path in PATHS.items():
        if path.is_file():
            walks = list(WALKS[name])[:1] if args.quick else list(WALKS[name])
            jobs += [(name, None, walk, balance) for walk in walks for balance in (False, True)]
        else:
            print(f"{name} skipped: {path} is absent", file=sys.stderr)
    print(stabilizer_cost())
    print("| robot | walk | stabilizer | result | CoP - ZMP RMS [mm] | final feet error [mm] | "
          "least sole force, last 2 s [N] | torso attitude spread, last 2 s [rad] | wall time [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    with ProcessPoolExecutor(max_workers=os.cpu_count()) as pool:
        for line in pool.map(case, jobs):
            print(line, flush=True)


if __name__ == "__main__":
    main()
