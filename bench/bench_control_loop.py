"""The control loop's ticks under commands given at random times: per-tick CPU time of ``OnlineWalker``.

Each configuration (1 kHz with joints, 1 kHz without, 100 Hz with joints, 1 kHz with joints and the hyperbolic
generator) runs ``--ticks`` ticks of one :class:`~zmpwalk.OnlineWalker` (HUBO) with ``gc.collect();
gc.freeze()`` after setup, as the README's loop. In every step a command is given at a random tick, as an
operator gives it (a seeded rng): mostly ordinary steps, and hostile ones among them: beyond the legs' reach,
too fast for the foot speed limit, ``stop()`` and a zero step time (whose ``InvalidParameterError`` is caught,
as a loop would). While the walker stands the next walk is commanded after a random wait. Timed, with
``time.thread_time_ns()`` (this thread's CPU time, so that the other processes on a shared machine do not
count), is each loop iteration: the ``command()`` given in it, if any, and ``tick()``. Counted: the commands
given, those that walked (queued, then begun), rejected, ``stop()``, the zero step times caught, and the checks
restarted in a tick because the walk took another step first (the queued command, or the closing stop) while
they ran. Reading ``walker.rejection`` (which searches the largest stride that fits, tens of milliseconds) is
outside the timing, as the README advises.

A ``floor`` line times the same loop around a copy of a 39-float row and one object: what this machine
gives any Python loop. ``--before DIR`` runs every configuration also against another source tree
(``DIR/src`` on ``PYTHONPATH``, e.g. a ``git worktree`` of an older commit), in the same run, side by side.

``--gc disable`` also turns Python's garbage collector off for the loop (after the freeze).

Run: ``python bench/bench_control_loop.py [--ticks 50000] [--seed 1] [--before /tmp/zmpwalk-before] [--gc disable]``.
Prints figures; asserts nothing. Goals: max <= 200 us, median <= 10 us, no tick over 1 ms.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

TALOS = Path(__file__).resolve().parents[2] / "shared" / "robots" / "pal_talos" / "scene_position.xml"
CONFIGURATIONS = {  # name: (rate [Hz], joints, generator, the whole controller, robot)
    "1 kHz, joints": (1000.0, True, "polynomial", False, "hubo"),
    "1 kHz, no joints": (1000.0, False, "polynomial", False, "hubo"),
    "100 Hz, joints": (100.0, True, "polynomial", False, "hubo"),
    "1 kHz, joints, hyperbolic": (1000.0, True, "hyperbolic", False, "hubo"),
    "controller 1 kHz": (1000.0, True, "polynomial", True, "hubo"),
    "controller 100 Hz": (100.0, True, "polynomial", True, "hubo"),
    "TALOS controller 1 kHz": (1000.0, True, "polynomial", True, str(TALOS)),  # an imported robot's legs
}
HOSTILE_KINDS = ("reach", "fast", "stop", "zero")
HOSTILE_SHARE = 0.2  # [-] of the commands
KINDS = ("no check", "step", *HOSTILE_KINDS)  # what a tick's check was of


def draw_command(rng: np.random.Generator) -> tuple[str, dict[str, float] | None]:
    """A command as an operator or a policy gives it: its kind and the StepCommand's fields (None: stop())."""
    duration = float(rng.uniform(0.7, 1.0))
    if rng.random() < HOSTILE_SHARE:
        kind = HOSTILE_KINDS[int(rng.integers(len(HOSTILE_KINDS)))]
        if kind == "reach":
            return kind, {"duration": duration, "forward": float(rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 1.0))}
        if kind == "fast":
            return kind, {"duration": float(rng.uniform(0.1, 0.25)), "forward": float(rng.uniform(0.2, 0.3))}
        if kind == "zero":
            return kind, {"duration": 0.0, "forward": 0.1}
        return kind, None
    mode = int(rng.integers(3))
    if mode == 0:
        return "step", {"duration": duration, "forward": float(rng.uniform(-0.1, 0.2))}
    if mode == 1:
        return "step", {"duration": duration, "forward": float(rng.uniform(0.0, 0.1)),
                        "side": float(rng.uniform(-0.05, 0.05))}
    return "step", {"duration": duration, "forward": float(rng.uniform(0.0, 0.1)),
                    "turn": float(rng.uniform(-0.15, 0.15))}


class Operator:
    """Who gives the commands: one at a random tick of every step (after a random wait while standing), drawn by
    :func:`draw_command` from a seeded rng, and the counts of what became of them (outside the timing)."""

    def __init__(self, rate: float, seed: int, ticks: int) -> None:
        from zmpwalk import StepCommand

        self.rate = rate
        self.rng = np.random.default_rng(seed)
        self.counts = dict.fromkeys(("given", "caught", "rejected", "walked", "restarted", "stops"), 0)
        # per tick: the kind of the command whose check ran in it (an index of KINDS), preallocated: a list grown
        # in the loop would be traversed by every pass of the garbage collector
        self.kinds = np.zeros(ticks, dtype=np.int8)
        self.tick = 0
        self.last = "no check"  # the kind of the last command given
        self.support, self.give_at, self.since = "double", int(self.rng.integers(1, int(0.5 * rate) + 2)), 0
        self.kind, self.fields = draw_command(self.rng)
        self.command = StepCommand(**self.fields) if self.fields and self.kind != "zero" else None
        self.rejection: object = None
        self.queued: object = None

    def give(self, target: object) -> bool:
        """Give the command due at this tick, if any, to ``target`` (a walker or a controller); whether one was."""
        if self.since != self.give_at:
            return False
        if self.command is not None:
            target.command(self.command)  # type: ignore[attr-defined]
        elif self.kind == "stop":
            target.stop()  # type: ignore[attr-defined]
        return True

    def after(self, walker: object, sample: object, given: bool, job: object) -> None:
        """After the timed iteration: count, draw the next command and the tick to give it at."""
        from zmpwalk import StepCommand, ZmpwalkError

        counts, rate = self.counts, self.rate
        counts["restarted"] += job is not None and walker._job is not None and walker._job is not job
        if given:
            self.last = self.kind
        self.kinds[self.tick] = KINDS.index(self.last) if job is not None else 0
        self.tick += 1
        self.since += 1
        if given:
            counts["given"] += 1
            counts["stops"] += self.kind == "stop"
            if self.kind == "zero":
                try:
                    StepCommand(**self.fields)  # type: ignore[arg-type]
                except ZmpwalkError:
                    counts["caught"] += 1
            self.kind, self.fields = draw_command(self.rng)
            self.command = StepCommand(**self.fields) if self.fields and self.kind != "zero" else None
            self.give_at = -1
        if walker.queued is not self.queued:
            counts["walked"] += self.queued is not None and walker.queued is None
            self.queued = walker.queued
        if walker.rejection is not self.rejection:  # names the rejection the first time (outside the timing)
            self.rejection = walker.rejection
            counts["rejected"] += self.rejection is not None
        if sample.support != self.support:
            if sample.support == "double" and self.support in ("left", "right"):  # a landing: a new step
                self.give_at, self.since = int(self.rng.integers(1, int(0.8 * rate) + 1)), 0
            self.support = sample.support
        elif self.give_at < 0 and not walker.walking and walker.checking is None:  # standing: the next walk
            self.give_at, self.since = int(self.rng.integers(1, int(0.5 * rate) + 2)), 0


def collect(collector: str) -> None:
    """``gc.collect(); gc.freeze()`` after setup, as the README's loop (and the collector off with ``disable``)."""
    gc.collect()
    gc.freeze()
    if collector == "disable":
        gc.disable()


def run_loop(rate: float, joints: bool, ticks: int, seed: int, generator: str = "polynomial",
             collector: str = "freeze") -> dict[str, object]:
    """The walker's loop of the module docstring; per-tick CPU times [us] and counts. ``collector``: ``"freeze"``
    (``gc.collect(); gc.freeze()`` after setup) or ``"disable"`` (and the collector off during the loop)."""
    from zmpwalk import OnlineWalker, load_robot

    walker = OnlineWalker(load_robot("hubo"), rate=rate, joints=joints, generator=generator)
    operator = Operator(rate, seed, ticks)
    times = np.empty(ticks, dtype=np.int64)
    collect(collector)
    clock = time.thread_time_ns
    for index in range(ticks):
        start = clock()
        given = operator.give(walker)
        job = walker._job  # private: to count the checks restarted in this tick
        sample = walker.tick()
        times[index] = clock() - start
        operator.after(walker, sample, given, job)
    gc.enable()
    gc.unfreeze()
    return {"us": (times / 1e3).tolist(), "kinds": operator.kinds.tolist(), **operator.counts}


def run_controller(rate: float, ticks: int, seed: int, generator: str = "polynomial",
                   collector: str = "freeze", robot_name: str = "hubo") -> dict[str, object]:
    """The whole controller's loop: a :class:`~zmpwalk.control.WalkingController` (pattern, legs, stabilizer) on
    a :class:`~zmpwalk.control.MockPlant`; timed per iteration: ``plant.measure()``, the command given in it, if
    any, ``controller.update()`` and ``plant.apply()``; and apart, the controller's own work: the command given, if
    any, and ``update()`` (the mock plant's ``measure`` and ``apply`` stand for a robot's driver). ``robot_name``:
    a built-in robot or a model's path."""
    from zmpwalk import load_robot
    from zmpwalk.control import MockPlant, WalkingController

    robot = load_robot(robot_name if robot_name == "hubo" else Path(robot_name))
    controller = WalkingController(robot, rate=rate, generator=generator)
    plant = MockPlant(robot, rate)
    walker = controller.walker
    operator = Operator(rate, seed, ticks)
    times, inner = np.empty(ticks, dtype=np.int64), np.empty(ticks, dtype=np.int64)
    collect(collector)
    clock = time.thread_time_ns
    for index in range(ticks):
        start = clock()
        measurement = plant.measure()
        begin = clock()
        given = operator.give(controller)
        job = walker._job  # private: to count the checks restarted in this tick (an attribute read, ~30 ns)
        targets = controller.update(measurement)
        end = clock()
        plant.apply(targets)
        times[index] = clock() - start
        inner[index] = end - begin
        plant.step()
        operator.after(walker, targets.sample, given, job)
    gc.enable()
    gc.unfreeze()
    return {"us": (times / 1e3).tolist(), "update_us": (inner / 1e3).tolist(), "kinds": operator.kinds.tolist(),
            "faults": controller.faults, **operator.counts}


def run_floor(ticks: int) -> dict[str, object]:
    """The same timing around a copy of a 39-float row and one object per iteration."""
    row = np.zeros(39)
    times = np.empty(ticks, dtype=np.int64)
    gc.collect()
    gc.freeze()
    clock = time.thread_time_ns
    for index in range(ticks):
        start = clock()
        copy = row.copy()
        sample = (float(copy[0]), copy[0:3], copy[15:27])
        times[index] = clock() - start
    del sample
    gc.unfreeze()
    return {"us": (times / 1e3).tolist()}


def figures(us: np.ndarray) -> str:
    return (f"median {np.median(us):6.2f}  p99 {np.percentile(us, 99):7.1f}  p99.9 {np.percentile(us, 99.9):7.1f}  "
            f"max {us.max():8.1f}  >200us {int((us > 200).sum()):5d}  >1ms {int((us > 1000).sum()):3d}")


def by_kind(us: np.ndarray, kinds: list[int]) -> str:
    """The max and the count over 200 us of the ticks in which no check ran, and of those in which the check of
    each kind of command ran."""
    codes = np.array(kinds)
    parts = []
    for code, label in enumerate(KINDS):
        chosen = us[codes == code]
        if len(chosen):
            parts.append(f"{label} ({len(chosen)}): max {chosen.max():.0f}, >200us {int((chosen > 200).sum())}")
    return "    ticks by the check they ran: " + "; ".join(parts)


def child(configuration: str, ticks: int, seed: int, source: str | None, collector: str) -> dict[str, object]:
    """One configuration in a fresh process (``source``: a src directory put first on PYTHONPATH)."""
    environment = dict(os.environ)
    if source is not None:
        environment["PYTHONPATH"] = source + os.pathsep + environment.get("PYTHONPATH", "")
    result = subprocess.run([sys.executable, __file__, "--child", configuration, "--ticks", str(ticks),
                             "--seed", str(seed), "--gc", collector], env=environment, capture_output=True,
                            text=True, check=True)
    data: dict[str, object] = json.loads(result.stdout.splitlines()[-1])
    return data


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=50_000, help="ticks per configuration (default 50000)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--before", help="another checkout (its src/ is run too, side by side)")
    parser.add_argument("--only", choices=[*CONFIGURATIONS, "floor"], action="append",
                        help="run only these configurations")
    parser.add_argument("--gc", choices=["freeze", "disable"], default="freeze",
                        help="after setup gc.collect(); gc.freeze() (default, the README's loop), and with "
                             "'disable' the collector off during the loop")
    parser.add_argument("--by-kind", action="store_true",
                        help="also the max of the ticks by the kind of command whose check ran in them")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        if args.child == "floor":
            result = run_floor(args.ticks)
        else:
            rate, joints, generator, whole, robot = CONFIGURATIONS[args.child]
            result = (run_controller(rate, args.ticks, args.seed, generator, args.gc, robot) if whole
                      else run_loop(rate, joints, args.ticks, args.seed, generator, args.gc))
        import zmpwalk

        result["source"] = str(Path(zmpwalk.__file__).parent.parent)
        print(json.dumps(result))
        return
    trees: list[tuple[str, str | None]] = [("now", None)]
    if args.before:
        trees.insert(0, ("before", str(Path(args.before) / "src")))
    print(f"per-iteration CPU time [us] (the walker: command() given in it, if any, and tick(); the controller: "
          f"plant.measure(), command(), update(), plant.apply()), {args.ticks} ticks each, seed {args.seed}, garbage "
          f"collector: {args.gc}")
    for configuration in args.only or ["floor", *CONFIGURATIONS]:
        if configuration != "floor" and CONFIGURATIONS[configuration][4] != "hubo" \
                and not Path(CONFIGURATIONS[configuration][4]).is_file():
            continue  # ../shared/robots absent
        for name, source in trees if configuration != "floor" else [("", None)]:
            result = child(configuration, args.ticks, args.seed, source, args.gc)
            counts = "" if configuration == "floor" else (
                f"  ({result['given']} commands: {result['walked']} walked, {result['rejected']} rejected, "
                f"{result['stops']} stop(), {result['caught']} errors caught; {result['restarted']} checks "
                f"restarted, the walk having taken another step)")
            label = f"{configuration} {name}".strip()
            print(f"{label:38} {figures(np.array(result['us']))}{counts}", flush=True)
            if "update_us" in result:
                print(f"{'  of which command() + update()':38} {figures(np.array(result['update_us']))}", flush=True)
            if args.by_kind and configuration != "floor":
                print(by_kind(np.array(result["us"]), result["kinds"]), flush=True)


if __name__ == "__main__":
    main()
