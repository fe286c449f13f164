"""The walking controller's ticks in pushed walks with capture steps: per-tick CPU time of ``update()``.

Each case walks a robot through the walking controller in MuJoCo (:func:`zmpwalk.sim.loop.simulate_controller`,
1 kHz, the stabilizer, the plant's feedforward, ``CaptureSettings()``; the walker's budget on the machine's clock,
as a robot's loop has it) with a push in the middle of the fifth step's single support, and times every
``WalkingController.update`` with ``time.thread_time_ns()`` (this thread's CPU time: other processes on a shared
machine do not count). Printed per case: the captures taken, the ticks' median, p99 and max, the count over 200 us
and over 1 ms, and the largest tick within 0.1 s of a capture's trigger (where its plan runs).

``--before DIR`` runs every case also against another source tree (``DIR/src`` on ``PYTHONPATH``), in the same
run, side by side. TALOS needs ../shared/robots (skipped when absent).

Run: ``python bench/bench_capture_ticks.py [--before /tmp/zmpwalk-before]``. Prints figures; asserts nothing.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

TALOS = Path(__file__).resolve().parents[2] / "shared" / "robots" / "pal_talos" / "scene_position.xml"
CASES = {  # name: (robot, push impulse [N s] (x, y; y towards the swinging foot's side))
    "HUBO, 36 N s backward": ("hubo", (-36.0, 0.0)),
    "HUBO, 20 N s forward": ("hubo", (20.0, 0.0)),
    "HUBO, 30 N s sideways": ("hubo", (0.0, 30.0)),
    "TALOS, 40 N s backward": ("talos", (-40.0, 0.0)),
}


def run_case(name: str) -> dict[str, object]:
    """Walk one case, timing every update; its figures."""
    import time

    from zmpwalk import StepCommand, load_robot
    from zmpwalk.capture import CaptureSettings
    from zmpwalk.control import WalkingController
    from zmpwalk.online import START_DELAY
    from zmpwalk.patterns.polynomial import generate
    from zmpwalk.scenarios import load_scenario
    from zmpwalk.sim.disturbances import Disturbances
    from zmpwalk.sim.loop import simulate_controller
    from zmpwalk.sim.mujoco_plant import MujocoPlant

    robot_name, (px, py) = CASES[name]
    if robot_name == "talos":
        robot = load_robot(TALOS)
        commands = [StepCommand(duration=1.0, forward=0.1)] * 8
    else:
        robot = load_robot("hubo")
        commands = load_scenario("fig10")[:1] + [StepCommand(duration=0.95, forward=0.2)] * 8
    pattern = generate(robot, commands, rate=1000.0)
    step = pattern.steps[4]
    side = 1.0 if step.swing == "left" else -1.0
    push = Disturbances(push_time=step.start + step.duration / 2 + START_DELAY, push_impulse=(px, side * py, 0.0))
    ticks: list[int] = []
    triggers: list[int] = []

    class Timed(WalkingController):
        def update(self, measurement):  # type: ignore[no-untyped-def]
            begin = time.thread_time_ns()
            targets = super().update(measurement)
            ticks.append(time.thread_time_ns() - begin)
            return targets

    plant = MujocoPlant(robot, 1000.0, disturbances=push)
    # the walker's budget on the machine's clock, as a robot's loop runs it (the simulator counts parts instead,
    # which bounds the parts per tick but not their time)
    controller = Timed(robot, 1000.0, capture=CaptureSettings(), feedforward=plant.feedforward())
    if controller._capture is not None:  # the trigger ticks, in either version of the policy
        policy = controller._capture
        for method in ("start", "plan"):
            if hasattr(policy, method):
                original = getattr(policy, method)

                def traced(tick, *args, _original=original):  # type: ignore[no-untyped-def]
                    triggers.append(tick)
                    return _original(tick, *args)

                setattr(policy, method, traced)
    gc.collect()
    gc.freeze()
    run = simulate_controller(robot, commands, controller=controller, plant=plant)
    us = np.array(ticks) / 1e3
    near = [us[max(t - 5, 0):t + 100].max() for t in triggers]
    return {"captures": len(run.result.captures), "fell": run.result.fell, "ticks": len(us),
            "median": float(np.median(us)), "p99": float(np.percentile(us, 99)), "max": float(us.max()),
            "over_200": int((us > 200).sum()), "over_1000": int((us > 1000).sum()),
            "near_capture": float(max(near)) if near else float("nan"),
            "parts_per_tick": getattr(controller._capture, "parts_per_tick", None)}


def child(name: str, source: str | None) -> dict[str, object]:
    """One case in its own process (``source``: another tree's ``src``)."""
    env = dict(os.environ)
    if source is not None:
        env["PYTHONPATH"] = source
    out = subprocess.run([sys.executable, __file__, "--child", name], capture_output=True, text=True, env=env,
                         check=True)
    return json.loads(out.stdout.splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", help="another checkout (its src/ is run too, side by side)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(run_case(args.child)))
        return
    trees = [("now", None)] + ([("before", str(Path(args.before) / "src"))] if args.before else [])
    print("| case | tree | captures | fell | median [us] | p99 [us] | max [us] | > 200 us | > 1 ms "
          "| max within 0.1 s of a trigger [us] | plan parts per tick |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in CASES:
        if CASES[name][0] == "talos" and not TALOS.is_file():
            continue
        for tree, source in trees:
            f = child(name, source)
            print(f"| {name} | {tree} | {f['captures']} | {'yes' if f['fell'] else 'no'} | {f['median']:.1f} | "
                  f"{f['p99']:.1f} | {f['max']:.0f} | {f['over_200']} | {f['over_1000']} | "
                  f"{f['near_capture']:.0f} | {f['parts_per_tick'] if f['parts_per_tick'] is not None else '-'} |",
                  flush=True)


if __name__ == "__main__":
    main()
