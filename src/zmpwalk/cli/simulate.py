"""``zmpwalk simulate``: a pattern walked in MuJoCo, with its falls, CoP, joint torques and powers, and its verdict."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

from zmpwalk.cli.options import (
    EXIT_FAILED,
    Commands,
    UsageError,
    add_generator_option,
    add_json_option,
    add_out_option,
    add_pelvis_option,
    add_robot_options,
    add_schedule_option,
    add_simulation_options,
    add_walk_options,
    balance_of,
    generator_words,
    load_robot_of,
    motors_of,
    pelvis_of,
    resolve_generator,
    schedule_of,
    walk_label,
    walk_of,
)
from zmpwalk.cli.printing import cop_margin_words, json_safe, margin_words, print_verdict, progress
from zmpwalk.files import write_text
from zmpwalk.robots.model import RobotModel
from zmpwalk.walk import WalkSpec

if TYPE_CHECKING:
    from zmpwalk.correction import ZmpCorrection
    from zmpwalk.sim.actuators import ActuatorRow
    from zmpwalk.sim.motors import MotorFit
    from zmpwalk.sim.run import SimulationResult
    from zmpwalk.sim.verdict import Verdict

NAMES = ("simulate",)


def add_parser(commands: Commands) -> None:
    """Add the simulate command."""
    parser = commands.add_parser(
        "simulate", help="walk a pattern in MuJoCo: falls, CoP, joint torques and powers",
        description="Generate the pattern of a steps file, a scenario or the paper example of Lim et al., "
        "walk it in MuJoCo with the robot's servos and ground contact, and write the measurements "
        "(simulation.csv, actuators.csv, actuators.md) to --out.",
        epilog="example: zmpwalk simulate --paper-example --robot mju-biped --json",
    )
    add_walk_options(parser, "steps file (TOML)", "a built-in scenario")
    parser.add_argument("--paper-example", action="store_true",
                        help="the walk of Lim et al. (start, 2 steady steps, stop; hyperbolic)")
    parser.add_argument("--steady-steps", type=int, default=2, help="steady steps of --paper-example")
    add_robot_options(parser)
    add_schedule_option(parser)
    add_pelvis_option(parser)
    add_simulation_options(parser)
    add_generator_option(parser)
    parser.add_argument("--mass-scale", type=float, default=1.0, help="multiply every mass (default 1)")
    parser.add_argument("--zmp-correction", action="store_true",
                        help="move the pelvis until the multibody ZMP (Eq. 3) follows the planned ZMP "
                        "(box models with [bodies]; off by default: docs/balance.md)")
    parser.add_argument("--push", type=float, nargs=3, metavar=("TIME", "X", "Y"),
                        help="push the torso at TIME [s] with an impulse X, Y [N s] in world over 0.1 s")
    parser.add_argument("--capture", action="store_true",
                        help="with the stabilizer: after a push, re-plan the rest of the walk as a capture "
                        "step and a stop once its DCM error passes 80 mm (zmpwalk.capture)")
    add_out_option(parser, "folder for the result files")
    add_json_option(parser, "print a JSON summary")


def walk_spec(args: argparse.Namespace, robot: RobotModel) -> WalkSpec:
    """The walk ``simulate`` runs: the paper example, a steps file or a scenario, with the options given."""
    from zmpwalk.capture import CaptureSettings

    resolve_generator(args, robot)
    if args.paper_example:
        if args.steps or args.scenario:
            raise UsageError("--paper-example takes no steps file or scenario")
        if args.steady_steps < 0:
            raise UsageError(f"--steady-steps = {args.steady_steps} must be >= 0")
        walk: dict[str, Any] = {"paper_steps": args.steady_steps}
    else:
        commands, labels = walk_of(args)
        walk = {"commands": commands, "labels": labels, "generator": args.generator, "schedule": schedule_of(args),
                "pelvis": pelvis_of(args), "source": walk_label(args)}
    balance = balance_of(args)
    if args.capture and not balance:
        raise UsageError("--capture needs the stabilizer (--balance on): its DCM estimate triggers the capture step")
    if args.capture and args.zmp_correction:
        raise UsageError("--capture plans the pattern's CoM point; it does not combine with --zmp-correction")
    disturbances = None
    if args.push is not None:
        from zmpwalk.sim.disturbances import Disturbances

        disturbances = Disturbances(push_time=args.push[0], push_impulse=(args.push[1], args.push[2], 0.0))
    return WalkSpec(robot, **walk, zmp_correction=args.zmp_correction, balance=balance,
                    latency=args.latency, mass_scale=args.mass_scale, disturbances=disturbances,
                    capture=CaptureSettings() if args.capture else None, motors=motors_of(args))


def run(args: argparse.Namespace) -> int:
    """``zmpwalk simulate``: walk the pattern, write the measurements to --out and print the walk and its verdict."""
    from zmpwalk.ready_fit import fit_ready_posture
    from zmpwalk.sim import actuator_markdown, write_actuator_csv
    from zmpwalk.sim.run import write_result_csv
    from zmpwalk.walk import run_walk

    show = None if args.json or not sys.stderr.isatty() else progress
    fitted = fit_ready_posture(walk_spec(args, load_robot_of(args)), lambda stretch: load_robot_of(args, stretch))
    robot = fitted.spec.robot
    with fitted.walking(say=not args.json):
        walk = run_walk(fitted.spec, progress=show, planned=fitted.planned)
    result, verdict, rows, fits, correction = walk.result, walk.verdict, walk.rows, walk.fits, walk.correction
    summary = {**simulation_summary(result, verdict, rows, fits, correction), "balance": walk.spec.balance,
               "generator": walk.pattern.generator, "controller": walk.controller,
               "ready_stretch": fitted.stretch, "ready_posture_refusal": fitted.refusal or None}
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        write_actuator_csv(rows, args.out / "actuators.csv")
        write_text(args.out / "actuators.md", actuator_markdown(rows) + "\n")
        write_result_csv(result, args.out / "simulation.csv")
    if args.json:
        print(json.dumps(json_safe(summary), indent=2, allow_nan=False))
    else:
        print("generator: " + ("hyperbolic (the paper example of Lim et al.)" if args.paper_example else
                               generator_words(args, robot)))
        print_simulation(result, verdict, rows, fits, correction, walk.controller)
    return 0 if verdict.passed else EXIT_FAILED


def simulation_summary(result: SimulationResult, verdict: Verdict, rows: list[ActuatorRow], fits: list[MotorFit],
                       correction: ZmpCorrection | None) -> dict[str, object]:
    """What ``simulate --json`` prints (SI)."""
    from zmpwalk.sim.actuators import planned_over_limit
    from zmpwalk.sim.verdict import cop_margin_outside_touchdowns

    rms, largest = result.cop_error_stats()
    return {
        "robot": result.robot.name, "fell": result.fell, "fall_time": result.fall_time,
        "duration": float(result.time[-1]), "distance": result.distance, "average_speed": result.average_speed,
        "foot_slip": result.foot_slip, "cop_error_rms": rms, "cop_error_max": largest,
        "min_cop_margin": float(np.nanmin(result.cop_margin)),
        "min_cop_margin_judged": cop_margin_outside_touchdowns(result),
        "plan_min_zmp_margin": result.plan_zmp_margin,
        "mass_scale": result.mass_scale,
        "final_feet_error": result.final_feet_error, "final_feet_yaw_error": result.final_feet_yaw_error,
        "end_min_sole_force": result.end_min_sole_force, "end_max_speed": result.end_max_speed,
        "end_attitude_range": result.end_attitude_range, "verdict": verdict.as_dict(),
        "captures": [{"time": c.time, "swing": c.swing, "swing_time": c.swing_time, "landing": list(c.landing),
                      "reached": c.reached} for c in result.captures],
        "zmp_correction": None if correction is None else {
            "passes": correction.passes, "multibody_error_rms_before": correction.before.rms,
            "multibody_error_rms_after": correction.after.rms},
        "motors": [{"joint": f.joint, "motor": f.motor, "rms_use": f.rms_use, "peak_use": f.peak_use,
                    "fits": f.fits} for f in fits],
        "actuators": [vars(row) for row in rows],
        "planned_over_limit": [row.joint for row in planned_over_limit(rows)],
        "warnings": list(verdict.warnings),
    }


def print_simulation(result: SimulationResult, verdict: Verdict, rows: list[ActuatorRow], fits: list[MotorFit],
                     correction: ZmpCorrection | None, controller: str) -> None:
    """What ``simulate`` prints: what ran (``controller``, in words), the walk, the plan's ZMP margin, the CoP, the
    motors, the warnings, the verdict."""
    from zmpwalk.sim.verdict import cop_margin_outside_touchdowns

    state = f"FELL at t = {result.fall_time:.3f} s" if result.fell else "walked to the end without falling"
    print(f"controller: {controller}")
    print(f"{result.robot.name}: {state}; distance {result.distance:.3f} m, average speed "
          f"{result.average_speed * 1e3:.1f} mm/s, foot slip {result.foot_slip * 1e3:.1f} mm")
    if correction is not None:
        print(f"multibody ZMP - planned ZMP: RMS {correction.before.rms * 1e3:.1f} mm as generated, "
              f"{correction.after.rms * 1e3:.1f} mm corrected (passes kept: {correction.passes})")
    if result.captures:
        last = result.captures[-1]
        print(f"capture steps planned: {len(result.captures)}, the first at t = {result.captures[0].time:.3f} s; "
              f"the walk ended on the last: {last.swing} foot to ({last.landing[0]:.3f}, {last.landing[1]:.3f}) "
              f"m at t = {last.time + last.swing_time:.3f} s, then standing (the commanded steps after it dropped)")
    print(f"plan: min ZMP margin {margin_words(result.plan_zmp_margin)}")
    rms, largest = result.cop_error_stats()
    print(f"CoP - reference ZMP: RMS {rms * 1e3:.1f} mm, max {largest * 1e3:.1f} mm; "
          + cop_margin_words(cop_margin_outside_touchdowns(result), float(np.nanmin(result.cop_margin))))
    top = max(rows, key=lambda r: r.peak_torque)
    power = max(rows, key=lambda r: r.peak_power)
    print(f"largest torque {top.peak_torque:.3g} N m at {top.joint}; largest power {power.peak_power:.3g} W "
          f"at {power.joint}")
    for fit in fits:
        if fit.fits:  # a motor that does not fit is a warning, printed with the verdict
            print(f"motor {fit.motor!r} at {fit.joint}: RMS {fit.rms_use * 100:.0f} % of rated, held peak "
                  f"{fit.peak_use * 100:.0f} % of the envelope: {fit.verdict}")
    print_verdict(verdict)
