"""Robustness of walking with and without the stabilizer: sensor latency, a mass error, a tilted floor, pushes.

Run: python bench/bench_robustness.py [--quick]. Prints Markdown tables; asserts nothing. Runs on all cores.

Push recovery: the largest impulse [N s] on the torso, applied over 0.1 s in the middle of a single support
(the fourth step's), below which the walk survives (no fall to its end) every push on a 2 N s grid, forward,
backward and sideways (towards the swinging foot's side), open loop (the feedforward only) and with the
stabilizer, and with the stabilizer and capture steps (:func:`zmpwalk.capture.capture_step`: the rest of the walk
re-planned from the stabilizer's DCM estimate once its error passes the trigger). TALOS needs ../shared/robots
(skipped when absent).

Survival is not monotonic in the impulse (a walk that survives 20 N s may fall at 12): ``--grid STEP`` also walks
every push on a STEP grid up to the search's ceiling and prints how many of them each loop survives, the falls
marked (``.`` survived, ``x`` fell). ``--batch`` walks them in the batch closed loop instead of the walking
controller (:func:`zmpwalk.walk.through_controller` forced off: the reference the controller is compared with).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from zmpwalk import StepCommand, load_robot
from zmpwalk.capture import CaptureSettings
from zmpwalk.robots.model import RobotModel
from zmpwalk.scenarios import load_scenario
from zmpwalk.sim.disturbances import Disturbances
from zmpwalk.walk import WalkSpec, planned_walk, run_walk

TALOS = Path(__file__).resolve().parents[2] / "shared" / "robots" / "pal_talos" / "scene_position.xml"


def robot(name: str) -> RobotModel:
    if name == "talos":
        return load_robot(TALOS)
    model = load_robot("hubo")
    if name == "hubo-soft" and model.servos is not None:
        model = dataclasses.replace(model, servos=dataclasses.replace(model.servos, kp=3000.0, kv=60.0))
    return model


def walk(name: str) -> list[StepCommand]:
    if name == "talos":
        return [StepCommand(duration=1.0, forward=0.1)] * 8
    return load_scenario("fig10")[:1] + [StepCommand(duration=0.95, forward=0.2)] * 8


MODES = ("off", "stabilizer", "capture")  # open loop (feedforward only); the stabilizer; and capture steps


def run(job: tuple[str, str, str, float]) -> tuple[str, str, str, float, bool, bool]:
    """(robot, condition, mode of :data:`MODES`, value) -> (..., fell, verdict passed)."""
    name, condition, mode, value = job
    balance = mode != "off"
    model = robot(name)
    spec = WalkSpec(model, walk(name), generator="polynomial", balance=balance, feedforward=True,
                    latency=value / 1000.0 if condition == "latency" else 0.0,
                    capture=CaptureSettings() if mode == "capture" else None)
    planned = planned_walk(spec)
    disturbances = None
    if condition == "mass":
        disturbances = Disturbances(mass_error=value)
    elif condition in ("tilt-pitch", "tilt-roll"):
        angle = math.radians(value)
        disturbances = Disturbances(floor_tilt=(angle, 0.0) if condition == "tilt-roll" else (0.0, angle))
    elif condition.startswith("push"):
        step = planned.pattern.steps[4]
        middle = step.start + step.duration / 2
        direction = {"push-forward": (1.0, 0.0), "push-backward": (-1.0, 0.0),
                     "push-sideways": (0.0, 1.0 if step.swing == "left" else -1.0)}[condition]
        disturbances = Disturbances(push_time=middle, push_impulse=(direction[0] * value, direction[1] * value, 0.0))
    outcome = run_walk(dataclasses.replace(spec, disturbances=disturbances), planned=planned)
    result = outcome.result
    return name, condition, mode, value, result.fell, outcome.verdict.passed


PUSH_STEP = 2.0  # [N s] grid of the push scan


def largest_push(name: str, direction: str, mode: str, high: float) -> float:
    """The largest impulse [N s] up to which every impulse on a :data:`PUSH_STEP` grid is survived: pushes
    of 2, 4, 6 ... N s until the first fall (up to ``high``). Not a bisection: survival is not monotonic in
    the impulse (HUBO sideways with the stabilizer survives 10 and 16 N s but falls at 12 and 14)."""
    survived = 0.0
    impulse = PUSH_STEP
    while impulse <= high:
        if run((name, direction, mode, impulse))[4]:
            break
        survived, impulse = impulse, impulse + PUSH_STEP
    return survived


def grid_job(job: tuple[str, str, str, float, bool]) -> tuple[str, str, str, float, bool]:
    """(robot, push, mode, impulse, batch) -> (..., fell): one push of the ``--grid`` scan."""
    name, direction, mode, value, batch = job
    if batch:
        import zmpwalk.walk

        zmpwalk.walk.through_controller = lambda spec: False  # the reference loop, in this worker only
    return name, direction, mode, value, run((name, direction, mode, value))[4]


def push_job(job: tuple[str, str, str, float]) -> tuple[str, str, str, float]:
    name, direction, mode, high = job
    return name, direction, mode, largest_push(name, direction, mode, high)


def _impulse(value: float | None) -> str:
    """A scan's figure [N s], or "-" where that loop was not scanned (``--modes``)."""
    return "-" if value is None else f"{value:.0f}"


def _ratio(value: float | None, open_loop: float | None) -> str:
    if value is None or open_loop is None:
        return "-"
    return f"{value / open_loop:.1f}" if open_loop > 0 else "inf"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="HUBO only, no pushes")
    parser.add_argument("--no-push", action="store_true", help="the conditions only, no push search")
    parser.add_argument("--push-only", action="store_true", help="the push search only, no conditions")
    parser.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES), help="the push search's loops")
    parser.add_argument("--grid", type=float, help="also scan every push on this grid [N s] and count the survived")
    parser.add_argument("--batch", action="store_true", help="walk the pushes in the batch closed loop")
    args = parser.parse_args()
    if args.batch:
        import zmpwalk.walk

        zmpwalk.walk.through_controller = lambda spec: False  # the workers fork after this
    robots = ["hubo", "hubo-soft"] + ([] if args.quick or not TALOS.is_file() else ["talos"])
    conditions = [("latency", 10.0), ("mass", 0.05), ("mass", -0.05), ("tilt-pitch", 2.0), ("tilt-pitch", -2.0),
                  ("tilt-roll", 2.0)]
    jobs = [(r, c, m, v) for r in robots for c, v in conditions for m in ("off", "stabilizer")]
    with ProcessPoolExecutor(max_workers=os.cpu_count()) as pool:
        if not args.push_only:
            print("| robot | condition | stabilizer | fell | verdict |")
            print("|---|---|---|---|---|")
            for name, condition, mode, value, fell, passed in pool.map(run, jobs):
                unit = {"latency": " ms", "mass": "", "tilt-pitch": " deg", "tilt-roll": " deg"}[condition]
                shown = f"{value:+.0%}" if condition == "mass" else f"{value:g}{unit}"
                print(f"| {name} | {condition} {shown} | {'on' if mode != 'off' else 'off'} | "
                      f"{'yes' if fell else 'no'} | {'pass' if passed else 'FAIL'} |", flush=True)
        if args.quick or args.no_push:
            return
        print("\n| robot | push | every push survived up to, open loop [N s] | with the stabilizer [N s] | ratio "
              "| with the stabilizer and capture steps [N s] | ratio |")
        print("|---|---|---|---|---|---|---|")
        pushed = [r for r in robots if r != "hubo-soft"]
        pushes = [(r, d, m, 96.0 if r == "talos" else 64.0) for r in pushed
                  for d in ("push-forward", "push-backward", "push-sideways") for m in args.modes]
        found = {(n, d, m): v for n, d, m, v in pool.map(push_job, pushes)}
        for r in pushed:
            for d in ("push-forward", "push-backward", "push-sideways"):
                off, on, capture = (found.get((r, d, m)) for m in MODES)
                cells = [_impulse(off), _impulse(on), _ratio(on, off), _impulse(capture), _ratio(capture, off)]
                print(f"| {r} | {d[5:]} | {' | '.join(cells)} |", flush=True)
        if args.grid:
            print_grid(pool, pushes, args.grid, args.batch)


def print_grid(pool: ProcessPoolExecutor, pushes: list[tuple[str, str, str, float]], step: float,
               batch: bool) -> None:
    """Every push on the ``step`` grid up to each search's ceiling: the falls and the count survived."""
    jobs = [(r, d, m, step * k, batch) for r, d, m, high in pushes for k in range(1, int(high / step) + 1)]
    marks: dict[tuple[str, str, str], list[str]] = {}
    for name, direction, mode, _, fell in pool.map(grid_job, jobs):
        marks.setdefault((name, direction, mode), []).append("x" if fell else ".")
    print(f"\n| robot | push | loop | every push on a {step:g} N s grid (. survived, x fell) | survived |")
    print("|---|---|---|---|---|")
    for (name, direction, mode), row in marks.items():
        print(f"| {name} | {direction[5:]} | {mode} | `{''.join(row)}` | {row.count('.')} / {len(row)} |")


if __name__ == "__main__":
    main()
