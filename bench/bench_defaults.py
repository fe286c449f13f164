"""Defaults chosen by data: every generator on every handed-over robot's own model, on the three walks of
examples/ (10 x 10 cm forward at 0.8 s, 4 x 5 cm side at 0.9 s, 3 x 15 deg turn at 1.0 s), each walked by
``zmpwalk simulate --robot MODEL --generator G STEPS --json`` with every other setting at its default (the
stabilizer on, HUBO's tables scaled, 1 s settle, 2 s hold); and whether ``zmpwalk plan --joints`` (as ``report`` and
``demo``, which check the planned joints against their ranges; ``simulate`` does not) plans it.

Run: python bench/bench_defaults.py [--robot talos-servos ...] [--generator preview ...] [--walk turn ...]
[--json FILE]. Prints a Markdown table (docs/design-log/defaults.md) and, per generator, how many walks pass;
asserts nothing. The robots need ../shared/robots (those absent are skipped). One walk at a time: each run is
a fresh process, exactly as a user runs it.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
ROBOT_DIR = ROOT.parent / "shared" / "robots"
ROBOTS = {
    "talos-servos": ROBOT_DIR / "pal_talos" / "scene_position.xml",
    "talos-motors": ROBOT_DIR / "pal_talos" / "scene_motor.xml",
    "t1": ROBOT_DIR / "booster_t1" / "scene.xml",
    "n1": ROBOT_DIR / "fourier_n1" / "scene.xml",
}
GENERATORS = ("polynomial", "hyperbolic", "preview")
WALKS = {  # the walk's arguments to ``zmpwalk simulate``
    "forward": [str(ROOT / "examples" / "steps_forward_10cm.toml")],
    "side": [str(ROOT / "examples" / "steps_side_5cm.toml")],
    "turn": [str(ROOT / "examples" / "steps_turn_15deg.toml")],
}
FORWARD_15CM = "[[steps]]\nduration = 0.8   # [s]\nforward = 0.15   # [m]\nrepeat = 10\n"
HARDER = {  # --harder: the tie-break when generators pass the three walks alike
    "forward 15 cm": ["STEPS"],  # 10 x 15 cm at 0.8 s (FORWARD_15CM, written to a temporary file)
    "turn45": ["--scenario", "turn45"],  # 3 x 15 deg at 0.95 s
    "demo": ["--scenario", "demo"],  # on the spot, 20 cm steps at 0.95 -> 0.8 s, a curved turn, a side step
}
JOINTS = "the joints stay within their actuators' limits"


def walk(model: Path, generator: str, steps: list[str]) -> dict[str, Any]:
    """One ``zmpwalk simulate --json`` run of the walk ``steps`` (its arguments): its exit status and the figures of
    the table (SI), or its error."""
    command = [sys.executable, "-m", "zmpwalk.cli", "simulate", "--robot", str(model), "--generator", generator,
               *steps, "--json"]
    started = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    row: dict[str, Any] = {"exit": done.returncode, "seconds": time.perf_counter() - started}
    if done.returncode not in (0, 3):
        row["error"] = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}"
        return row
    summary = json.loads(done.stdout)
    verdict = summary["verdict"]
    joint = next(c for c in verdict["criteria"] if c["name"] == JOINTS)
    row.update({
        "state": verdict["state"], "failed": [c["name"] for c in verdict["criteria"] if c["state"] == "FAIL"],
        "fall_time": summary["fall_time"], "cop_error_rms": summary["cop_error_rms"],
        "final_feet_error": summary["final_feet_error"], "plan_min_zmp_margin": summary["plan_min_zmp_margin"],
        "min_cop_margin_judged": summary["min_cop_margin_judged"],
        "joint_use": joint["figure"], "joint_note": joint["note"],
    })
    return row


def plan_joints(model: Path, generator: str, steps: list[str], folder: Path) -> str:
    """``zmpwalk plan --joints`` of the walk: "ok", or why it refuses (a joint outside its range, out of reach)."""
    command = [sys.executable, "-m", "zmpwalk.cli", "plan", "--robot", str(model), "--generator", generator, *steps,
               "--joints", "--allow-outside", "--out", str(folder / "plan.csv")]
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode == 0:
        return "ok"
    last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else f"exit {done.returncode}"
    return last.removeprefix("zmpwalk: error: ").split(": ", 1)[-1]  # without the steps file's path


def _mm(value: float | None, signed: bool = False) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value * 1e3:+.1f}" if signed else f"{value * 1e3:.1f}"


def _joint(row: dict[str, Any]) -> str:
    if row.get("joint_use") is None:
        return "-"
    worst = str(row["joint_note"]).split(";")[0].split(" (")[0]  # the joint held most: "JOINT held A of B N m"
    return f"{row['joint_use'] * 100:.0f} % ({worst})"


def _verdict(row: dict[str, Any]) -> str:
    if "error" in row:
        return f"error: {row['error']}"
    if row["fall_time"] is not None:
        return f"{row['exit']}, FAIL (falls at {row['fall_time']:.2f} s)"
    failed = ", ".join(row["failed"])
    return f"{row['exit']}, {row['state']}" + (f" ({failed})" if failed else "")


def table(rows: list[dict[str, Any]]) -> str:
    """The Markdown table: one line per robot, generator and walk."""
    lines = ["| robot | generator | walk | exit, verdict (failing criteria) | CoP - ZMP RMS [mm] | final feet [mm] "
             "| plan's ZMP margin [mm] | CoP margin judged [mm] | joints: largest use (where) "
             "| planned joints in range | wall [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['robot']} | {r['generator']} | {r['walk']} | {_verdict(r)} | {_mm(r.get('cop_error_rms'))} "
                     f"| {_mm(r.get('final_feet_error'))} | {_mm(r.get('plan_min_zmp_margin'), True)} "
                     f"| {_mm(r.get('min_cop_margin_judged'), True)} | {_joint(r)} | {r.get('plan_joints', '-')} "
                     f"| {r['seconds']:.0f} |")
    return "\n".join(lines)


def tally(rows: list[dict[str, Any]]) -> str:
    """Per generator: the walks that pass (simulate's exit 0 and the planned joints in range, so that report and demo
    walk them too) out of those walked, and which fail."""
    lines = []
    for name in dict.fromkeys(r["generator"] for r in rows):
        mine = [r for r in rows if r["generator"] == name]
        failing = [f"{r['robot']} {r['walk']}" + ("" if r["exit"] == 0 else " (simulate)")
                   + ("" if r.get("plan_joints", "ok") == "ok" else " (joint range)")
                   for r in mine if r["exit"] != 0 or r.get("plan_joints", "ok") != "ok"]
        lines.append(f"{name}: {len(mine) - len(failing)} of {len(mine)} pass"
                     + (f"; fail: {', '.join(failing)}" if failing else ""))
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--robot", nargs="+", choices=ROBOTS, default=list(ROBOTS))
    parser.add_argument("--generator", nargs="+", choices=GENERATORS, default=list(GENERATORS))
    parser.add_argument("--walk", nargs="+", choices=[*WALKS, "none"], default=list(WALKS))
    parser.add_argument("--harder", action="store_true", help="also (or with --walk none: only) the harder walks: "
                        + ", ".join(HARDER))
    parser.add_argument("--json", type=Path, help="also write the rows as JSON")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        steps = Path(folder) / "forward_15cm.toml"
        steps.write_text(FORWARD_15CM)
        walks = {name: WALKS[name] for name in args.walk if name in WALKS}
        if args.harder:
            walks |= {name: [str(steps)] if words == ["STEPS"] else words for name, words in HARDER.items()}
        rows = run(args, walks, Path(folder))
    print(table(rows))
    print()
    print(tally(rows))


def run(args: argparse.Namespace, walks: dict[str, list[str]], folder: Path) -> list[dict[str, Any]]:
    """Every robot x generator x walk, one at a time, in that order."""
    rows = []
    for robot in args.robot:
        if not ROBOTS[robot].is_file():
            print(f"{robot}: {ROBOTS[robot]} is absent, skipped", file=sys.stderr)
            continue
        for name in args.generator:
            for walk_name, words in walks.items():
                row = {"robot": robot, "generator": name, "walk": walk_name, **walk(ROBOTS[robot], name, words),
                       "plan_joints": plan_joints(ROBOTS[robot], name, words, folder)}
                print(f"{robot} {name} {walk_name}: {_verdict(row)}; planned joints {row['plan_joints']} "
                      f"({row['seconds']:.0f} s)", file=sys.stderr, flush=True)
                rows.append(row)
                if args.json:  # after every walk: a long run stopped half-way keeps what it measured
                    args.json.write_text(json.dumps(rows, indent=2) + "\n")
    return rows


if __name__ == "__main__":
    main()
