"""Speed of the HUBO pattern: OnlineWalker.tick() at 100 Hz and 1 kHz, the batch walks at 1 kHz, and the
control loop at 1 kHz with joints, every iteration timed; PlaCo's walking loop side by side when PlaCo is
installed (bench/placo_walk.py; optional, not a dependency).

Run: python bench/bench_pattern.py. Prints figures; asserts nothing.
"""

from __future__ import annotations

import gc
import importlib.util
import statistics
import time
from importlib.metadata import version

import numpy as np

from zmpwalk import StepCommand, generate, load_robot
from zmpwalk.kinematics import pattern_joint_trajectory
from zmpwalk.online import OnlineWalker
from zmpwalk.patterns.polynomial import plan_walk


def tick_times(rate: float, seconds: float) -> np.ndarray:
    robot = load_robot("hubo")
    walker = OnlineWalker(robot, rate=rate)
    commands = [StepCommand(0.95, 0.0), StepCommand(0.8, 0.2), StepCommand(0.7, 0.2), StepCommand(0.8, side=0.05),
                StepCommand(0.95, turn=0.2), StepCommand(0.8, 0.1, turn=0.1)]
    durations = []
    index = 0
    for _ in range(int(seconds * rate)):
        if walker.queued is None:
            walker.command(commands[index % len(commands)], wait=True)  # queued off the tick, as a controller would
            index += 1
        start = time.perf_counter_ns()
        walker.tick()
        durations.append(time.perf_counter_ns() - start)
    return np.array(durations) / 1e3  # [us]


def control_loop(rate: float, seconds: float, joints: bool, wait: bool) -> tuple[np.ndarray, np.ndarray]:
    """What a robot's loop sees: every iteration timed (tick plus any command given in it). Walks of five
    steps, each step commanded in the loop as the one before it starts (the first from standstill), then
    the automatic stop and 1 s of standing. ``wait``: each command checked whole in its call (command(step,
    wait=True)) instead of in parts over the ticks. Returns the iterations' and the commands' times [us]."""
    walker = OnlineWalker(load_robot("hubo"), rate=rate, joints=joints)
    gc.collect()
    gc.freeze()  # as docs/speed.md advises: what was loaded before the loop is out of the GC's full passes
    steps = [StepCommand(0.8, 0.2), StepCommand(0.8, 0.1, turn=0.1), StepCommand(0.8, side=0.05),
             StepCommand(0.7, 0.15), StepCommand(0.95, 0.1)]
    iterations, commands = [], []
    given, standing = 0, 0
    for _ in range(round(seconds * rate)):
        start = time.perf_counter()
        if given < len(steps) and walker.queued is None and walker.checking is None and not standing:
            walker.command(steps[given], wait=wait)
            commands.append(time.perf_counter() - start)
            given += 1
        walker.tick()
        iterations.append(time.perf_counter() - start)
        if given == len(steps) and not walker.walking and walker.checking is None:
            standing += 1
            if standing >= rate:  # 1 s standing, then the next walk
                given, standing = 0, 0
    return np.array(iterations) * 1e6, np.array(commands) * 1e6


def _figures(us: np.ndarray) -> str:
    return (f"median {np.median(us):6.2f} us, p99 {np.percentile(us, 99):7.1f} us, p99.9 "
            f"{np.percentile(us, 99.9):7.1f} us, max {us.max():8.1f} us, over 100 us: {(us > 100).sum()}, "
            f"over 1 ms: {(us > 1000).sum()} of {len(us)}")


def main() -> None:
    print("OnlineWalker.tick() (HUBO, commands queued as each step starts)")
    for rate in (100.0, 1000.0):
        us = tick_times(rate, 120.0 if rate == 100.0 else 60.0)
        print(f"  {rate:6.0f} Hz: median {np.median(us):6.2f} us, p99 {np.percentile(us, 99):7.2f} us, "
              f"max {us.max():8.1f} us over {len(us)} ticks")
    robot = load_robot("hubo")
    commands = [StepCommand(0.8, 0.2)] * 100
    generate(robot, commands, rate=1000.0)  # warm-up
    runs = []
    plans = []
    for _ in range(7):
        start = time.perf_counter()
        pattern = generate(robot, commands, rate=1000.0)
        runs.append(time.perf_counter() - start)
        start = time.perf_counter()
        plan_walk(robot, commands)
        plans.append(time.perf_counter() - start)
    print(f"100-step walk at 1 kHz ({len(pattern.time)} samples): median {statistics.median(runs) * 1e3:.1f} ms "
          f"(planning alone {statistics.median(plans) * 1e3:.1f} ms)")
    for steps in (20, 100):  # the batch path with the 12 joints and their rates
        walk = [StepCommand(0.8, 0.2)] * steps
        pattern_joint_trajectory(generate(robot, walk, rate=1000.0))  # warm-up
        times = []
        for _ in range(7):
            start = time.perf_counter()
            pattern = generate(robot, walk, rate=1000.0)
            pattern_joint_trajectory(pattern)
            times.append(time.perf_counter() - start)
        print(f"{steps}-step walk at 1 kHz with 12 joints and their rates ({len(pattern.time)} samples): "
              f"median {statistics.median(times) * 1e3:.1f} ms, best {min(times) * 1e3:.1f} ms")
    command_times = []
    walker = OnlineWalker(robot, rate=1000.0)
    walker.command(StepCommand(0.8, 0.2), wait=True)
    walker.tick()
    for _ in range(200):
        start = time.perf_counter()
        walker.command(StepCommand(0.8, 0.2), wait=True)
        command_times.append(time.perf_counter() - start)
    print(f"OnlineWalker.command(step, wait=True) at 1 kHz (the whole check in the call): median "
          f"{statistics.median(command_times) * 1e3:.2f} ms")
    print("Control loop at 1 kHz with joints, 60 s, every iteration timed (commands given inside the loop, "
          "first commands from standstill and automatic stops included)")
    for wait in (False, True):
        loop, given = control_loop(1000.0, 60.0, True, wait)
        name = "command(step, wait=True)" if wait else "command(step)"
        print(f"  with {name:24}: iterations {_figures(loop)}")
        print(f"  {'':30}{name} alone: median {np.median(given):.1f} us, max {given.max():.1f} us "
              f"({len(given)} commands)")
    if importlib.util.find_spec("placo") is None:
        print("PlaCo side by side: skipped (pip install placo to run it)")
        return
    from placo_walk import placo_loop

    loop, distance = placo_loop(60.0)
    print(f"  PlaCo {version('placo')} (its walking example's loop on HUBO's box model: trajectory, whole-body IK "
          f"QP, a replan with the next command every 10 planning steps; walked {distance:.2f} m):")
    print(f"  {'':30}iterations {_figures(loop)}")


if __name__ == "__main__":
    main()
