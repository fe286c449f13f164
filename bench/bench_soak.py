"""Soak: an online walk of many steps at 1 kHz with random commands; resident memory and landing exactness.

One :class:`~zmpwalk.OnlineWalker` at 1 kHz walks ``--steps`` steps. In every step a random command (step time,
stride forward or backward, side step, turn; some beyond the legs' reach, which the walker rejects) is given
at a random tick, checked in parts while the step goes on, as a robot's loop gives it. A command the walker
rejects is followed at once by a plain one, and the walker closes its stance with its automatic stop when no
command is ready in time (one step in a hundred gets none), so every kind of step and stop occurs.

Measured:

- **resident memory** (``/proc/self/statm``) after ``--warm-up`` steps (the allocator's pools fill over the first
  few thousand steps) and its largest growth beyond that over the rest of the walk [MB], checked every 1000
  steps; goal: under 5 MB; and its value at every tenth of the walk, where a leak would show as a slope;
- **landings**: at every touchdown the landed ankle's position [m] and yaw [rad] against the footstep that the
  accepted commands give, composed independently here with :func:`zmpwalk.footsteps.plan_command` from the
  ready stance; goal: within 1e-9 m (and rad) after any number of steps.

Run: ``python bench/bench_soak.py [--steps 100000] [--seed 7]``. Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import math
import os
import time
from dataclasses import dataclass, field, replace

import numpy as np

from zmpwalk import OnlineWalker, StepCommand, load_robot
from zmpwalk.footsteps import Pose2D, Stance, plan_command
from zmpwalk.schedule import Schedule
from zmpwalk.sides import Side

PAGE = os.sysconf("SC_PAGE_SIZE")  # [B]
PLAIN = StepCommand(duration=0.8, forward=0.1)


def resident_mb() -> float:
    """The process's resident memory now [MB]."""
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * PAGE / 1e6


def random_command(rng: np.random.Generator) -> StepCommand:
    """A command as an operator or a policy might give it: mostly ordinary, one in ten beyond reach."""
    duration = float(rng.uniform(0.7, 1.0))
    if rng.random() < 0.1:
        return StepCommand(duration=duration, forward=float(rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.0)))
    kind = rng.integers(3)
    if kind == 0:
        return StepCommand(duration=duration, forward=float(rng.uniform(-0.1, 0.2)))
    if kind == 1:
        side = float(rng.uniform(-0.05, 0.05))
        return StepCommand(duration=duration, forward=float(rng.uniform(0.0, 0.1)), side=side)
    return StepCommand(duration=duration, forward=float(rng.uniform(0.0, 0.1)), turn=float(rng.uniform(-0.15, 0.15)))


@dataclass
class Footsteps:
    """The landings the accepted commands give, composed from the ready stance."""

    robot: object
    schedule: Schedule
    stance: Stance
    expected: list[tuple[int, Pose2D]] = field(default_factory=list)  # (swinging foot, landing) in order

    def take(self, command: StepCommand) -> None:
        stages, self.stance = plan_command(self.stance, command, self.robot, self.schedule)  # type: ignore[arg-type]
        if command.stop:  # at rest either foot may swing first (as zmpwalk.patterns.polynomial.plan_next)
            self.stance = replace(self.stance, next_swing=0)
        self.expected += [(stage.swing, stage.swing_end) for stage in stages if stage.kind != "settle"]


def error_of(sample: object, foot: int, pose: Pose2D) -> tuple[float, float]:
    """Horizontal distance [m] and yaw difference [rad] of ``foot``'s ankle in ``sample`` from ``pose``."""
    if foot == Side.LEFT:
        position, yaw = sample.position_left_ankle_in_world, sample.yaw_left_foot_in_world  # type: ignore[attr-defined]
    else:
        position, yaw = sample.position_right_ankle_in_world, sample.yaw_right_foot_in_world  # type: ignore[attr-defined]
    return math.hypot(position[0] - pose.x, position[1] - pose.y), abs(yaw - pose.yaw)


def soak(steps: int, warm_up: int, seed: int) -> dict[str, object]:
    robot = load_robot("hubo")
    schedule = Schedule.hubo()
    walker = OnlineWalker(robot, rate=1000, schedule=schedule)
    footsteps = Footsteps(robot, schedule, Stance.ready(robot))
    rng = np.random.default_rng(seed)
    landings = rejected = stops = 0
    worst_position = worst_yaw = 0.0
    queued: StepCommand | None = None
    support, give_at, tick_in_step = "double", 1, 0
    base = peak = math.nan
    trajectory: list[tuple[int, float]] = []  # (landings, resident memory [MB]) every tenth of the walk
    start = time.process_time()
    while landings < steps:
        sample = walker.tick()
        tick_in_step += 1
        if walker.queued is not queued:
            if queued is not None and walker.queued is None:
                footsteps.take(queued)  # it has begun
            queued = walker.queued
        if sample.support != support:
            if sample.support == "double" and support in ("left", "right"):
                if not footsteps.expected:  # no command was ready: the automatic stop
                    footsteps.take(StepCommand(duration=PLAIN.duration, stop=True))
                    stops += 1
                foot, pose = footsteps.expected.pop(0)
                distance, yaw = error_of(sample, foot, pose)
                worst_position, worst_yaw = max(worst_position, distance), max(worst_yaw, yaw)
                landings += 1
                if landings == warm_up:
                    base = peak = resident_mb()
                elif landings > warm_up and landings % 1000 == 0:
                    peak = max(peak, resident_mb())
                if landings % max(steps // 10, 1) == 0:
                    trajectory.append((landings, resident_mb()))
            support, tick_in_step = sample.support, 0
            give_at = int(rng.integers(1, 400)) if rng.random() > 0.01 else -1  # -1: none, the walker stops
        if walker.rejection is not None:
            rejected += 1
            walker.command(PLAIN)
        elif tick_in_step == give_at and walker.queued is None and walker.checking is None:
            walker.command(random_command(rng))
    return {"steps": landings, "ticks": round(walker.time * walker.rate), "cpu_s": time.process_time() - start,
            "rejected": rejected, "automatic_stops": stops, "worst_landing_m": worst_position,
            "worst_landing_yaw_rad": worst_yaw, "resident_after_warm_up_mb": base, "growth_mb": peak - base,
            "trajectory": trajectory}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000, help="landings to walk (default 100000)")
    parser.add_argument("--warm-up", type=int, default=10_000,
                        help="landings before memory growth is measured (default 10000)")
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    r = soak(args.steps, min(args.warm_up, args.steps), args.seed)
    print(f"{r['steps']} landings, {r['ticks']} ticks at 1 kHz ({r['ticks'] / 3.6e6:.1f} h of walking), "
          f"{r['cpu_s']:.0f} s CPU; {r['rejected']} commands rejected, {r['automatic_stops']} automatic stops")
    print(f"landings: worst {r['worst_landing_m']:.2e} m, {r['worst_landing_yaw_rad']:.2e} rad from the footsteps "
          f"(goal 1e-9)")
    print(f"resident memory: {r['resident_after_warm_up_mb']:.1f} MB after the warm-up, largest growth after it "
          f"{r['growth_mb']:+.2f} MB (goal < 5 MB)")
    print("resident memory [MB] by landings: " + ", ".join(f"{n}: {mb:.1f}" for n, mb in r["trajectory"]))


if __name__ == "__main__":
    main()
