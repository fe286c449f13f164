"""Speed of the leg IK: closed form (scalar and vectorised) against a numerical IK; tick() with joints; an
imported robot's legs (the compiled whole-body IK), sample by sample and in a walker's check.

Run: python bench/bench_kinematics.py [--only imported]. Prints figures; asserts nothing. The imported robots
need ../shared/robots (those absent are skipped).

The vectorised figures allocate tens of megabytes per call. Whether glibc serves those from fresh pages (a page
fault per 4 kB) or from its heap depends on what the process allocated and freed before (its dynamic mmap
threshold), which halved or doubled them between two runs of the same code: :func:`steady_allocator` fixes the
threshold first, so that the figures measure the IK, not the allocator's history.
"""

from __future__ import annotations

import argparse
import ctypes
import ctypes.util
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from zmpwalk import StepCommand, generate, load_robot, pattern_joint_trajectory
from zmpwalk.kinematics import leg_chains
from zmpwalk.leg_chain import LegChain
from zmpwalk.online import OnlineWalker


def poses(chain: LegChain, n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    q = np.column_stack([rng.uniform(-0.5, 0.5, n), rng.uniform(-0.3, 0.3, n), rng.uniform(-1.0, 0.4, n),
                         rng.uniform(0.2, 1.6, n), np.zeros(n), np.zeros(n)])
    q[:, 5] = -q[:, 1]
    q[:, 4] = -(q[:, 2] + q[:, 3])  # flat feet, as in walking
    position, rotation = chain.fk(q)
    return position, rotation, np.arctan2(rotation[:, 1, 0], rotation[:, 0, 0])


M_MMAP_THRESHOLD = -3  # glibc's mallopt parameter
MMAP_THRESHOLD = 512 * 1024 * 1024  # [B] blocks below this come from the heap


def steady_allocator() -> None:
    """Fix glibc's mmap threshold (no dynamic adjustment); nothing on another C library."""
    name = ctypes.util.find_library("c")
    if name is not None and hasattr(ctypes.CDLL(name), "mallopt"):
        ctypes.CDLL(name).mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)


ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
IMPORTED = {"TALOS": ROBOTS / "pal_talos" / "scene_position.xml", "Booster T1": ROBOTS / "booster_t1" / "scene.xml",
            "Fourier N1": ROBOTS / "fourier_n1" / "scene.xml"}


def imported_legs() -> None:
    """Per imported robot: its legs over a 10 x 10 cm walk at 0.8 s, 1 kHz (``pattern_joint_trajectory``: the base
    under the CoM, the angles and rates, the ranges), best of 5; and a 1 kHz walker's check of a 1 s step and its
    stop while walking (``command(step, wait=True)``), median of 7. This thread's CPU time."""
    for name, path in IMPORTED.items():
        if not path.exists():
            print(f"{name}: {path} absent, skipped")
            continue
        robot = load_robot(path)
        pattern = generate(robot, [StepCommand(duration=0.8, forward=0.1)] * 10, rate=1000.0)
        runs = []
        for _ in range(6):
            start = time.thread_time()
            pattern_joint_trajectory(pattern)
            runs.append(time.thread_time() - start)
        per_sample = min(runs[1:]) / len(pattern.time)
        walker = OnlineWalker(robot, rate=1000.0, joints=True)
        walker.command(StepCommand(duration=1.0, forward=0.05), wait=True)
        checks = []
        for i in range(7):
            for _ in range(300):
                walker.tick()
            start = time.thread_time()
            walker.command(StepCommand(duration=1.0, forward=0.05 + 0.005 * (i % 2)), wait=True)
            checks.append(time.thread_time() - start)
            while walker.queued is not None:
                walker.tick()
        print(f"{name}: legs {per_sample * 1e6:.2f} us a sample ({len(pattern.time)} samples); a walking check "
              f"(1 s step and its stop, 1 kHz, joints): median {statistics.median(checks) * 1e3:.1f} ms, "
              f"best {min(checks) * 1e3:.1f} ms")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--only", choices=["imported"], help="only the imported robots' legs")
    if parser.parse_args().only == "imported":
        imported_legs()
        return
    steady_allocator()
    robot = load_robot("hubo")
    chain = leg_chains(robot)[0]
    position, rotation, yaw = poses(chain, 200_000)
    best = {}
    for name, solve in (("flat-foot (yaw)", lambda: chain.solve_flat(position, yaw)),
                        ("general rotation", lambda: chain.solve(position, rotation))):
        solve()
        runs = []
        for _ in range(5):
            start = time.perf_counter()
            solve()
            runs.append(time.perf_counter() - start)
        best[name] = min(runs) / len(yaw)
        print(f"closed-form IK, vectorised, {name}: {1 / best[name] / 1e6:.2f} M leg solutions/s")
    count = 20_000
    start = time.perf_counter()
    for i in range(count):
        chain.solve_flat_one((float(position[i, 0]), float(position[i, 1]), float(position[i, 2])), float(yaw[i]))
    scalar = (time.perf_counter() - start) / count
    print(f"closed-form IK, scalar (math): {scalar * 1e6:.2f} us per leg solution")
    numeric = []
    for i in range(200):
        def residual(x: np.ndarray, i: int = i) -> np.ndarray:
            p, r = chain.fk(x[None, :])
            return np.concatenate([p[0] - position[i], (r[0] - rotation[i]).ravel()])

        start = time.perf_counter()
        least_squares(residual, np.array([0.0, 0.0, -0.5, 1.0, -0.5, 0.0]), xtol=1e-12, ftol=1e-12)
        numeric.append(time.perf_counter() - start)
    numeric_time = statistics.median(numeric)
    print(f"numerical IK (scipy least_squares on FK): {numeric_time * 1e3:.2f} ms per leg solution; "
          f"closed form is {numeric_time / scalar:.0f}x faster scalar, "
          f"{numeric_time / best['flat-foot (yaw)']:.0f}x vectorised")
    for rate in (100.0, 1000.0):
        walker = OnlineWalker(robot, rate=rate, joints=True)
        durations = []
        commands = [StepCommand(0.8, 0.2), StepCommand(0.95, turn=0.2), StepCommand(0.8, side=0.05)]
        k = 0
        for _ in range(int(60 * rate)):
            if walker.queued is None:
                walker.command(commands[k % 3], wait=True)
                k += 1
            t0 = time.perf_counter_ns()
            walker.tick()
            durations.append(time.perf_counter_ns() - t0)
        us = np.array(durations) / 1e3
        print(f"OnlineWalker.tick() with joints at {rate:.0f} Hz: median {np.median(us):.2f} us, "
              f"p99 {np.percentile(us, 99):.2f} us")
    imported_legs()


if __name__ == "__main__":
    main()
