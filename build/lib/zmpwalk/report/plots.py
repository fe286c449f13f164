"""Plots in the style of the papers' figures, as PNG bytes (matplotlib, no display needed)."""

from __future__ import annotations

import io
from collections.abc import Sequence

import matplotlib

matplotlib.use("Agg")  # no display needed; before pyplot is imported
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from zmpwalk.footsteps import Pose2D, foot_corners
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import JOINT_NAMES
from zmpwalk.sim.contact import LOADED_FRACTION
from zmpwalk.sim.motors import Motor, motor_for
from zmpwalk.sim.run import SimulationResult
from zmpwalk.sim.verdict import COP_MARGIN, TOUCHDOWN_WINDOW

DPI = 100


def _png(figure: Figure) -> bytes:
    buffer = io.BytesIO()
    figure.tight_layout()
    figure.savefig(buffer, format="png", dpi=DPI)
    plt.close(figure)
    return buffer.getvalue()


def zmp_path(pattern: WalkingPattern, result: SimulationResult | None) -> bytes:
    """The ZMP path over the footprints (Figs. 20-22 of Park et al.), world x-y [m]."""
    figure, axes = plt.subplots(figsize=(9, 4.5))
    for step in pattern.steps:
        x, y, yaw = step.landing
        side = 1 if step.swing == "left" else -1
        corners = foot_corners(Pose2D(x, y, yaw), side, pattern.robot)
        axes.add_patch(Polygon(corners, closed=True, fill=False, color="0.55", lw=1))
    first = pattern.support_phases[0]
    for pose, side in first.feet:
        axes.add_patch(Polygon(foot_corners(pose, side, pattern.robot), closed=True, fill=False, color="0.55", lw=1))
    axes.plot(pattern.zmp_in_world[:, 0], pattern.zmp_in_world[:, 1], color="C0", lw=1.2, label="reference ZMP")
    axes.plot(pattern.position_pelvis_in_world[:, 0], pattern.position_pelvis_in_world[:, 1], color="C2", lw=1,
              ls="--", label="pelvis")
    if result is not None:
        axes.plot(result.cop[:, 0], result.cop[:, 1], color="C3", lw=0.8, alpha=0.8, label="measured CoP (simulation)")
        if result.ankle_positions is not None:
            planned = [step.landing for step in pattern.steps]
            axes.plot([p[0] for p in planned], [p[1] for p in planned], "k+", markersize=8, label="planned ankles")
            final = result.ankle_positions[-1]
            landed = _landings(result)
            axes.plot(landed[:, 0], landed[:, 1], "x", color="C3", markersize=6, label="simulated ankles at landing")
            axes.plot(final[:, 0], final[:, 1], "o", color="C3", mfc="none", markersize=7,
                      label="simulated, at the end")
    axes.set_aspect("equal")
    axes.set_xlabel("x [m]")
    axes.set_ylabel("y [m]")
    axes.set_title("ZMP over the footprints")
    axes.legend(loc="upper left", fontsize=8)
    axes.autoscale_view()
    return _png(figure)


def _landings(result: SimulationResult) -> np.ndarray:
    """Simulated ankle positions (x, y) where each sole became loaded, (k, 2)."""
    if result.ankle_positions is None:
        return np.zeros((0, 2))
    weight = result.robot.mass * result.robot.gravity
    points = []
    for foot, force in enumerate((result.force_left, result.force_right)):
        loaded = force > LOADED_FRACTION * weight
        for start in (np.flatnonzero(loaded[1:] & ~loaded[:-1]) + 1).tolist():
            points.append(result.ankle_positions[min(int(start) + 50, len(force) - 1), foot, :2])
    return np.array(points).reshape(-1, 2)


def zmp_time(pattern: WalkingPattern, result: SimulationResult | None) -> bytes:
    """ZMP (and CoP) against time with the support polygon's bounds (Figs. 21, 27-31)."""
    return zmp_time_axis(pattern, result)[0]


def _time_axis(figure: Figure, axes: Sequence[Axes]) -> dict[str, float]:
    """Where the time axis of stacked ``axes`` lies in the image, as fractions from its left and top edges, and
    its limits [s] (for the page's time cursor)."""
    figure.tight_layout()
    first, last = axes[0].get_position(), axes[-1].get_position()
    t0, t1 = axes[0].get_xlim()
    return {"left": first.x0, "right": first.x1, "top": 1 - first.y1, "bottom": 1 - last.y0, "t0": t0, "t1": t1}


def zmp_time_axis(pattern: WalkingPattern, result: SimulationResult | None) -> tuple[bytes, dict[str, float]]:
    """:func:`zmp_time` and where its time axis lies (:func:`_time_axis`)."""
    polygons = pattern.support_polygons()
    begins = np.array([p.begin for p in pattern.support_phases])
    which = np.clip(np.searchsorted(begins, pattern.time, side="right") - 1, 0, len(begins) - 1)
    bounds = np.array([[polygons[k][:, i].min() for i in (0, 1)] + [polygons[k][:, i].max() for i in (0, 1)]
                       for k in range(len(polygons))])[which]
    figure, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for i, label in enumerate(("x", "y")):
        axes[i].fill_between(pattern.time, bounds[:, i], bounds[:, i + 2], color="0.9", step="post",
                             label="support polygon bounds")
        axes[i].plot(pattern.time, pattern.zmp_in_world[:, i], color="C0", lw=1.2, label="reference ZMP")
        if result is not None:
            axes[i].plot(result.time, result.cop[:, i], color="C3", lw=0.8, alpha=0.8, label="measured CoP")
        axes[i].set_ylabel(f"{label} [m]")
    axes[0].legend(loc="upper left", fontsize=8)
    axes[1].set_xlabel("t [s]")
    axes[0].set_title("ZMP against time")
    where = _time_axis(figure, axes)
    return _png(figure), where


def trajectories(pattern: WalkingPattern) -> bytes:
    """Pelvis and ankles relative to the pelvis (Figs. 10-11, 16-17 of Park et al.)."""
    figure, axes = plt.subplots(3, 1, figsize=(9, 6.5), sharex=True)
    left, right = pattern.position_left_ankle_in_pelvis, pattern.position_right_ankle_in_pelvis
    for i, label in enumerate(("x", "y", "z")):
        axes[i].plot(pattern.time, left[:, i], color="C0", lw=1, label="left ankle")
        axes[i].plot(pattern.time, right[:, i], color="C1", lw=1, label="right ankle")
        axes[i].set_ylabel(f"{label} in pelvis [m]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[2].set_xlabel("t [s]")
    axes[0].set_title("Ankles relative to the pelvis")
    return _png(figure)


def joints(result: SimulationResult) -> bytes:
    """Both legs' joint angles, torques and powers (Figs. 12-14 of Lim et al.), left and right side by side."""
    figure, axes = plt.subplots(3, 2, figsize=(11, 7.5), sharex=True, sharey="row")
    for side, label in enumerate(("left", "right")):
        for j in range(6):
            column = 6 * side + j
            short = result.joint_names[column].replace(f"{label}_", "")
            axes[0, side].plot(result.time, result.joint_angles[:, column], lw=1, label=short)
            axes[1, side].plot(result.time, result.joint_torques[:, column], lw=1, label=short)
            axes[2, side].plot(result.time, result.joint_power[:, column], lw=1, label=short)
        axes[0, side].set_title(f"{label} leg (simulation)")
        axes[2, side].set_xlabel("t [s]")
    axes[0, 0].set_ylabel("angle [rad]")
    axes[1, 0].set_ylabel("torque [N m]")
    axes[2, 0].set_ylabel("power [W]")
    axes[0, 1].legend(loc="upper right", fontsize=7, ncol=2)
    return _png(figure)


def pelvis(pattern: WalkingPattern, result: SimulationResult) -> bytes:
    """Pelvis x, y and yaw against time, planned and simulated, and the CoP margin."""
    figure, axes = plt.subplots(4, 1, figsize=(9, 8), sharex=True)
    for i, label in enumerate(("x [m]", "y [m]")):
        axes[i].plot(pattern.time, pattern.position_pelvis_in_world[:, i], color="0.3", lw=1.2, label="planned")
        axes[i].plot(result.time, result.torso_position[:, i], color="C3", lw=0.9, label="simulated (base)")
        axes[i].set_ylabel(f"pelvis {label}")
    axes[2].plot(pattern.time, pattern.yaw_pelvis_in_world, color="0.3", lw=1.2, label="planned")
    axes[2].plot(result.time, result.torso_rpy[:, 2], color="C3", lw=0.9, label="simulated")
    axes[2].set_ylabel("pelvis yaw [rad]")
    axes[3].plot(result.time, result.cop_margin * 1e3, color="C0", lw=0.8, label="every sample")
    axes[3].axhline(0.0, color="k", lw=0.6)
    axes[3].axhline(COP_MARGIN * 1e3, color="C3", lw=0.8, ls="--",
                    label=f"the verdict's limit (touchdowns' {TOUCHDOWN_WINDOW * 1e3:g} ms not judged)")
    axes[3].set_ylabel("CoP margin [mm]\n(> 0 inside)")
    axes[3].legend(loc="lower right", fontsize=7)
    axes[3].set_xlabel("t [s]")
    axes[0].legend(loc="upper left", fontsize=8)
    axes[0].set_title("Pelvis against time; CoP distance inside the loaded soles")
    return _png(figure)


def balance(result: SimulationResult) -> bytes:
    """The stabilizer at work: reference ZMP, desired ZMP and measured CoP (x, y), and its corrections."""
    if result.balance is None:
        raise ValueError("the walk was simulated open loop (no stabilizer log)")
    log = result.balance
    figure, axes = plt.subplots(3, 1, figsize=(9, 7.5), sharex=True)
    for axis, (index, label) in zip(axes[:2], ((0, "x"), (1, "y")), strict=True):
        axis.plot(result.time, result.reference_zmp[:, index], label="pattern ZMP", color="0.4")
        axis.plot(result.time, log["zmp_desired"][:, index], label="desired ZMP (DCM feedback)", color="tab:orange")
        axis.plot(result.time, result.cop[:, index], label="measured CoP", color="tab:blue", linewidth=0.8)
        axis.set_ylabel(f"{label} [m]")
        axis.legend(loc="upper left", fontsize=8)
    axes[2].plot(result.time, log["com_offset"][:, 0] * 1e3, label="CoM offset x [mm]")
    axes[2].plot(result.time, log["com_offset"][:, 1] * 1e3, label="CoM offset y [mm]")
    axes[2].plot(result.time, np.degrees(log["ankle_offsets"][:, 0]), label="left ankle roll offset [deg]")
    axes[2].plot(result.time, np.degrees(log["ankle_offsets"][:, 1]), label="left ankle pitch offset [deg]")
    axes[2].plot(result.time, log["height_difference"] * 1e3, label="foot height difference [mm]")
    axes[2].set_xlabel("t [s]")
    axes[2].legend(loc="upper left", fontsize=8, ncol=2)
    return _png(figure)


def motor_envelopes(result: SimulationResult, motors: list[Motor]) -> bytes:
    """Each joint's torque-speed operating points against its motor's envelope (joint side)."""
    figure, axes = plt.subplots(2, 3, figsize=(10, 6))
    for axis, role in zip(axes.ravel(), JOINT_NAMES, strict=True):
        motor = None
        for index, column in enumerate(result.joint_names):
            if not column.endswith(role):
                continue
            motor = motor_for(motors, column) or motor
            axis.plot(np.abs(result.joint_velocities[:, index]), np.abs(result.joint_torques[:, index]), ".",
                      markersize=1, alpha=0.4, label=column.split("_")[0])
        if motor is not None:
            speed = np.linspace(0.0, motor.joint_no_load_speed, 50)
            axis.plot(speed, motor.joint_peak_torque * (1 - speed / motor.joint_no_load_speed), "k-", label="peak")
            axis.axhline(motor.joint_rated_torque, color="k", linestyle="--", label="rated")
            axis.set_xlim(0, min(motor.joint_no_load_speed, 1.5 * max(1e-3, float(np.abs(
                result.joint_velocities).max()))))
        axis.set_title(role.replace("_", " "), fontsize=9)
        axis.set_xlabel("|speed| [rad/s]", fontsize=8)
        axis.set_ylabel("|torque| [N m]", fontsize=8)
        axis.legend(fontsize=7)
    return _png(figure)
