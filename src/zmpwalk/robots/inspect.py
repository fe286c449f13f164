"""What zmpwalk derived from a robot, for a builder to check against the CAD: ``zmpwalk robot PATH``."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from zmpwalk.robots.collision import tilt_of
from zmpwalk.robots.description import (
    HUBO_FOOT_LIFT,
    LIFT_RANGE_MARGIN,
    PD_BANDWIDTH,
    PD_DAMPING_RATIO,
    PD_LOAD_STIFFNESS,
    PD_STEP_LIMIT,
    PD_WEAK_ANKLE_LOAD_STIFFNESS,
    PHYSICS_STEP,
    Actuator,
    ModelPlant,
)
from zmpwalk.robots.model import JOINT_COLUMNS, RobotModel
from zmpwalk.robots.posture import READY_STRETCH


class StaticTorques(Protocol):
    """What the sheet reads of the ready posture's static torques (:class:`zmpwalk.sim.statics.StaticTorques`,
    which the simulation layer computes): each leg joint's torque [N m], (12,) in the leg-column order, on both
    feet, on either foot and on the larger of the two, and the joints held over their limit standing."""

    @property
    def both_feet(self) -> NDArray[np.float64]: ...

    @property
    def on_left(self) -> NDArray[np.float64]: ...

    @property
    def on_right(self) -> NDArray[np.float64]: ...

    @property
    def one_foot(self) -> NDArray[np.float64]: ...

    @property
    def over_limit(self) -> list[str]: ...


def robot_summary(robot: RobotModel, statics: StaticTorques | None = None) -> dict[str, Any]:
    """The derived values as plain data (SI units: m, kg, rad, N m).

    Args:
        statics: The static torques of the ready posture (:func:`zmpwalk.sim.statics.static_torques`), listed
            per joint when given.
    """
    summary: dict[str, Any] = {
        "name": robot.name, "description": robot.description, "mass": robot.mass, "height": robot.height,
        "hips": {side: list(robot.hip_in_pelvis(s)) for side, s in (("left", 1), ("right", -1))},
        "hip_x": robot.hip_x, "hip_spacing": robot.hip_spacing, "hip_drop": robot.hip_drop,
        "thigh_length": robot.thigh_length, "shank_length": robot.shank_length, "ankle_height": robot.ankle_height,
        "sole": {"length": robot.foot_length, "width": robot.foot_width, "center_x": robot.sole_center_x,
                 "center_y": robot.sole_center_y},
        "pelvis_height": robot.pelvis_height, "pendulum_length": robot.pendulum_length,
        "com_offset": list(robot.com_offset), "schedule_scale": list(robot.schedule_scale),
        "walking": {"dsp_time": robot.dsp_time, "foot_lift": robot.foot_lift,
                    "lateral_velocity": robot.lateral_velocity},
        "limits": {column: list(robot.limits_of(column)) for column in JOINT_COLUMNS},
    }
    # The hips in the base frame (the pattern's point is com_offset ahead of the base origin).
    summary["hips"] = {side: [robot.hip_x, s * robot.hip_spacing / 2, -robot.hip_drop]
                       for side, s in (("left", 1), ("right", -1))}
    if robot.plant is not None and robot.legs is not None:
        plant = robot.plant
        summary["model"] = str(plant.path)
        summary["base_body"] = plant.base_body
        summary["root_body"] = plant.root_body or plant.base_body
        summary["feet"] = list(plant.feet)
        summary["keyframe"] = plant.keyframe
        summary["ready_stretch"] = plant.ready_stretch  # [-] hip-to-ankle distance over the straight leg
        summary["physics_step"] = plant.physics_step  # [s] the simulation's step, the PD layer's period
        summary["load_stiffness"] = plant.load_stiffness  # [-] the PD rule's kappa
        summary["ankle_roll_torque"] = plant.ankle_roll_torque  # [N m] the weaker ankle roll's limit
        summary["sole_edge_moment"] = plant.sole_edge_moment  # [N m] the weight at the sole's nearer side edge
        summary["posture_set_by"] = plant.posture_set_by or None
        summary["held_joints"] = list(plant.held_joints)
        summary["coupled_joints"] = list(plant.coupled_joints)
        summary["sole_polygon"] = [list(p) for p in plant.sole_polygon]
        summary["ik"] = {chain.label: ("closed form" if chain.closed_form else "numeric") for chain in robot.legs}
        summary["sole_tilt"] = {chain.label: {"zero": list(tilt_of(chain.sole_rotation[:, 2])),
                                              "reference": list(chain.sole_tilt_reference)} for chain in robot.legs}
        summary["five_joint"] = {chain.label: chain.virtual is not None for chain in robot.legs}
        summary["hip_axes_offset"] = {chain.label: chain.hip_axes_offset for chain in robot.legs}
        summary["ankle_axes_offset"] = {chain.label: chain.ankle_axes_offset for chain in robot.legs}
        summary["joints"] = [
            {"column": column, "name": joint.name, "axis": list(joint.axis), "sign": joint.sign,
             "zero_offset": joint.zero_offset, "limits": list(joint.limits),
             "actuator": None if joint.actuator is None else _actuator_summary(joint.actuator)}
            for column, joint in zip(JOINT_COLUMNS, plant.joints, strict=True)]
        legs = {joint.name for joint in plant.joints}
        summary["pd_joints"] = {name: _actuator_summary(actuator) for name, actuator in plant.pd_joints
                                if name not in legs}
        if statics is not None:
            for i, joint in enumerate(summary["joints"]):
                joint["static_torque"] = {"both_feet": float(statics.both_feet[i]),
                                          "on_left": float(statics.on_left[i]), "on_right": float(statics.on_right[i])}
            summary["static_torque_over_limit"] = statics.over_limit
    return summary


def _ankle_words(summary: dict[str, Any], leg: str) -> str:
    """How far apart a leg's ankle axes are, or that it has none to roll (a five-joint leg, with the bound on
    the sole roll it may leave)."""
    if not summary["five_joint"][leg]:
        return f"ankle {summary['ankle_axes_offset'][leg] * 1e3:.1f} mm"
    column = next(joint for joint in summary["joints"] if joint["column"] == f"{leg}_ankle_roll")
    return f"5 joints: no ankle roll, the sole roll the IK leaves within {column['limits'][1]:.4f} rad"


def _tilt_line(summary: dict[str, Any]) -> str:
    """The soles' tilt (roll, pitch) [rad] at zero joint angles and in the reference posture."""
    tilts = summary["sole_tilt"]

    def pair(values: list[float]) -> str:
        return "(" + ", ".join(f"{round(v, 4) + 0.0:+.4f}" for v in values) + ")"  # no "-0.0000"

    return ("sole tilt (roll, pitch) [rad]: at zero angles " + ", ".join(f"{leg} {pair(t['zero'])}" for leg, t in
                                                                       tilts.items())
            + f"; in the reference posture ({summary['keyframe'] or 'zero pose'}) "
            + ", ".join(f"{leg} {pair(t['reference'])}" for leg, t in tilts.items())
            + " (the IK keeps the sole frame level)")


def _actuator_summary(actuator: Actuator) -> dict[str, Any]:
    """One actuator as plain data: ``kind`` the model's (position, motor, general, none), ``drive`` in words
    (position servo, torque motor + PD, PD (no actuator)), ``pd_layer``, gains [N m/rad, N m s/rad], the torque
    limit [N m] and, for the PD layer, the reflected inertia its gains come from [kg m^2]."""
    return {"name": actuator.name, "kind": actuator.kind, "drive": actuator.label, "pd_layer": actuator.pd_layer,
            "kp": actuator.kp, "kv": actuator.kv, "force_limit": actuator.force_limit, "inertia": actuator.inertia}


def _mm(value: float) -> str:
    return f"{value * 1e3:+.1f}"


def robot_table(robot: RobotModel, statics: StaticTorques | None = None) -> str:
    """The derived values as a table (lengths in mm for reading; the files and JSON are in SI), with the static
    torques of the ready posture where ``statics`` is given."""
    s = robot_summary(robot, statics)
    lines = [f"{robot.name}: {robot.description}"]
    if "model" in s:
        below = (f" (below the floating {s['root_body']!r}, its waist held at the reference pose)"
                 if s["root_body"] != s["base_body"] else "")
        lines.append(f"model {s['model']}; base {s['base_body']!r}{below}; feet {s['feet'][0]!r}, {s['feet'][1]!r}; "
                     f"reference pose: {s['keyframe'] or 'zero pose'}")
    lines += [
        f"mass {robot.mass:.3f} kg, height {robot.height:.3f} m",
        "hips in the base frame [mm]: left (" + ", ".join(_mm(v) for v in s["hips"]["left"]) + "), right ("
        + ", ".join(_mm(v) for v in s["hips"]["right"]) + ")",
        f"thigh {robot.thigh_length * 1e3:.1f} mm, shank {robot.shank_length * 1e3:.1f} mm, "
        f"ankle above the sole {robot.ankle_height * 1e3:.1f} mm",
        f"sole {robot.foot_length * 1e3:.1f} x {robot.foot_width * 1e3:.1f} mm, centre "
        f"({_mm(robot.sole_center_x)}, {_mm(robot.sole_center_y)}) mm from the ankle",
        f"ready posture: base {robot.pelvis_height:.4f} m above the ground, centre of mass "
        f"{robot.pendulum_length:.4f} m high and ({_mm(robot.com_offset[0])}, {_mm(robot.com_offset[1])}) mm "
        "from the base origin" + (f"; hips {robot.plant.ready_stretch:.3f} of the straight leg above the ankles"
                                  if robot.plant is not None else ""),
        "HUBO tables scaled by: time x{:.3f}, stride x{:.3f}, lateral x{:.3f}".format(*robot.schedule_scale),
        _lift_line(robot),
    ]
    if "joints" in s:
        lines.append("IK: " + ", ".join(f"{k} {v} (hip axes {s['hip_axes_offset'][k] * 1e3:.1f} mm apart, "
                                        + _ankle_words(s, k) + ")" for k, v in s["ik"].items()))
        lines.append(_tilt_line(s))
        lines.append("")
        lines += _joint_lines(s["joints"], statics)
        if any(joint["actuator"] and joint["actuator"]["pd_layer"] for joint in s["joints"]) or s["pd_joints"]:
            kappa = robot.plant.load_stiffness if robot.plant is not None else PD_LOAD_STIFFNESS
            step, own = ((robot.plant.physics_step, robot.plant.model_step) if robot.plant is not None
                         else (PHYSICS_STEP, PHYSICS_STEP))
            shortened = (f", shortened from the model's {own * 1e3:g} ms, where the bound held a leg joint below "
                         "the rule" if step < own * (1 - 1e-9) else "")
            lines.append(f"PD layer (the firmware's joint loop, run at the physics step dt = {step * 1e3:g} ms"
                         f"{shortened}; clipped at 'max'): kp = min(max(I w^2, {kappa:g} W), I ({PD_STEP_LIMIT:g} / "
                         f"dt)^2) with w = 2 pi x {PD_BANDWIDTH / (2 * math.pi):g} Hz, "
                         f"W = m g l = {robot.mass * robot.gravity * robot.pendulum_length:.1f} N m for a leg joint; "
                         f"kv = 2 x {PD_DAMPING_RATIO:g} sqrt(kp I); I [kg m^2] its reflected inertia "
                         "(docs/robot-import.md), or the robot file's [pd]")
            if robot.plant is not None:
                lines.append(_kappa_line(robot.plant))
        if s["pd_joints"]:
            lines.append("held by the PD layer (kp [N m/rad], kv [N m s/rad], max [N m]): " + ", ".join(
                f"{name} {a['kp']:.1f}/{a['kv']:.2f}/{a['force_limit']:.3g}" for name, a in s["pd_joints"].items()))
        if statics is not None:
            lines.append("2 feet, 1 foot: static torque [N m] holding the ready posture on both feet, and on one foot "
                         "with the centre of mass over its sole (the larger of the two feet)")
            over = statics.over_limit
            lines.append("over the actuator's limit standing still: " + (", ".join(over) if over else "none"))
        if s["held_joints"]:
            lines.append(f"held at the reference pose: {', '.join(s['held_joints'])}")
        if s["coupled_joints"]:
            lines.append("moved through an equality by a joint the PD layer drives (not held): "
                         + ", ".join(s["coupled_joints"]))
    return "\n".join(lines)


def _joint_lines(joints: list[dict[str, Any]], statics: StaticTorques | None) -> list[str]:
    """The leg joints' table: column, model joint, axis, sign, zero, range, what drives it and its gains, the
    torque limit, and the static torques where given."""
    header = (f"{'column':<18} {'model joint':<22} {'axis':<16} {'sign':>4} {'zero':>7} {'range [rad]':>17} "
              f"{'actuator':<17} {'kp':>8} {'kv':>7} {'I':>7} {'max [N m]':>9}"
              + (f" {'2 feet':>7} {'1 foot':>7}" if statics is not None else ""))
    lines = [header, "-" * len(header)]
    for index, joint in enumerate(joints):
        actuator = joint["actuator"] or {"drive": "none", "kp": math.nan, "kv": math.nan, "force_limit": math.nan,
                                         "inertia": math.nan}
        axis = "(" + ", ".join(f"{v:+.2f}" for v in joint["axis"]) + ")"
        inertia = "-" if math.isnan(actuator["inertia"]) else f"{actuator['inertia']:.4f}"
        lines.append(f"{joint['column']:<18} {joint['name']:<22} {axis:<16} {joint['sign']:>+4d} "
                     f"{joint['zero_offset']:>+7.3f} [{joint['limits'][0]:>+7.3f}, {joint['limits'][1]:>+7.3f}] "
                     f"{actuator['drive']:<17} {actuator['kp']:>8.1f} {actuator['kv']:>7.2f} {inertia:>7} "
                     f"{actuator['force_limit']:>9.1f}"
                     + (f" {abs(statics.both_feet[index]):>7.1f} {statics.one_foot[index]:>7.1f}"
                        if statics is not None else ""))
    return lines


def robot_toml(robot: RobotModel, folder: Path) -> str:
    """A robot file that loads the robot's own model (``[model]``), with the values a builder may change
    (``[posture]``, ``[walking]``) and the derived geometry as comments to check against the CAD.

    Args:
        folder: Where the file will be written (the model path is written relative to it).
    """
    lines = [f"# zmpwalk robot file of {robot.name}, derived from its model by 'zmpwalk robot'.",
             "# Units: SI (m, kg, rad, s). Values under [posture] and [walking] replace the derived ones."]
    if robot.plant is not None:
        plant = robot.plant
        try:
            model_path = os.path.relpath(plant.path, folder.resolve())
        except ValueError:  # another drive
            model_path = str(plant.path)
        lines += ["", "[model]", f"file = {_quote(model_path)}",
                  f"feet = [{_quote(plant.feet[0])}, {_quote(plant.feet[1])}]"]
        if plant.keyframe:
            lines.append(f"keyframe = {_quote(plant.keyframe)}")
        if plant.package_paths:
            lines.append("package_paths = [" + ", ".join(_quote(str(p)) for p in plant.package_paths) + "]")
        lines.append(f"name = {_quote(robot.name)}")
    given = robot.plant.file_values if robot.plant is not None else None

    def field(name: str, value: float, comment: str) -> str:  # a derived value of a model robot: commented out
        return f"{'' if given is None or name in given else '# '}{name} = {value:.6g}   # {comment}"

    posture = [field("pelvis_height", robot.pelvis_height, "[m] base origin above the ground, ready posture")]
    if robot.plant is not None:
        posture.insert(0, field("ready_stretch", robot.plant.ready_stretch, "[-] hip-to-ankle distance over the "
                                f"straight leg (the keyframe's, at most {READY_STRETCH:g}); either set keeps the "
                                "posture for every walk, else a walk is fitted one (docs/robot-import.md)"))
    lines += ["", "[posture]", *posture, "", "[walking]",
              field("dsp_time", robot.dsp_time, "[s] double-support time d (HUBO's 0.1 s, time-scaled)"),
              field("foot_lift", robot.foot_lift, "[m] swing apex height (HUBO's 0.04 m, length-scaled, lowered "
                    f"where a pitch joint would come within {LIFT_RANGE_MARGIN:g} rad of its range)"),
              field("lateral_velocity", robot.lateral_velocity, "[m] V_y of Eq. 20 (HUBO's 0.1 m, lateral-scaled)")]
    if robot.legs is not None and robot.legs[0].virtual is not None:  # five-joint legs: the sole roll they may leave
        bound = robot.joint_limits["left_ankle_roll"][1]
        lines.append(field("sole_roll_limit", bound, "[rad] the sole roll a walk may leave (no ankle roll); raise "
                           "it for a foot that rolls on its centre line (docs/robot-import.md)"))
    if robot.plant is not None and robot.plant.pd_joints:
        lines += ["", "[pd]",
                  "# The joint PD layer (the firmware's joint loop) of each torque motor or unactuated joint, derived",
                  "# by zmpwalk's rule (docs/robot-import.md): kp = max(I w^2, kappa W), critical damping. Set the",
                  "# rule's kappa here, or give a joint's own (uncommented: the robot file's) with your firmware's:",
                  "# kp [N m/rad], kv [N m s/rad] (kv may be left out: critical damping).",
                  f"{'' if robot.plant.load_stiffness != robot.plant.derived_load_stiffness else '# '}load_stiffness = "
                  f"{robot.plant.load_stiffness:.12g}   # [-] the rule's kappa for every joint not given below"]
        lines += [f"{'' if name in robot.plant.pd_given else '# '}{_quote(name)} = "
                  f"{{kp = {actuator.kp:.6g}, kv = {actuator.kv:.6g}}}" for name, actuator in robot.plant.pd_joints]
    lines += ["", "# Derived from the model (for checking; edit the model, not these lines):"]
    lines += [f"#   {line}" if line else "#" for line in robot_table(robot).splitlines()]
    return "\n".join(lines) + "\n"


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _kappa_line(plant: ModelPlant) -> str:
    """Which ``kappa`` the PD rule took and why: the robot file's, or the derived one (the ankle rolls against the
    weight at the sole's side edge, :attr:`~zmpwalk.robots.description.ModelPlant.derived_load_stiffness`)."""
    derived = plant.derived_load_stiffness
    hold = (f"the ankle rolls hold {plant.ankle_roll_torque:.3g} N m, the weight at the sole's side edge "
            f"{plant.sole_edge_moment:.3g} N m" if plant.ankle_roll_torque > 0 else "no ankle roll joint")
    why = ("the hips carry the sideways balance on one foot" if derived == PD_WEAK_ANKLE_LOAD_STIFFNESS
           else "the ankles hold it")
    if plant.load_stiffness != derived:
        return f"kappa = {plant.load_stiffness:g}: the robot file's (derived: {derived:g}, {hold})"
    return f"kappa = {derived:g} ({hold}: {why})"


def _lift_line(robot: RobotModel) -> str:
    """The foot lift, and why where it is below HUBO's scaled one."""
    scaled = HUBO_FOOT_LIFT * robot.schedule_scale[1]  # [m]
    words = f"foot lift {robot.foot_lift * 1e3:.1f} mm"
    if robot.foot_lift < scaled - 1e-9:
        words += (f" (HUBO's {scaled * 1e3:.1f} mm length-scaled, lowered so that the hip pitch, knee and ankle pitch "
                  f"keep {LIFT_RANGE_MARGIN:g} rad of their ranges with the foot raised level from the ready posture)")
    return words
