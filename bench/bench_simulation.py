"""Real-time factor of the MuJoCo simulation with all measurements on, for each robot.

Run: python bench/bench_simulation.py. Prints figures; asserts nothing.
"""

from __future__ import annotations

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


if __name__ == "__main__":
    main()
