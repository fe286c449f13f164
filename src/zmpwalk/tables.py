"""ZMP check of the tuned conditions: walk each row of the parameter tables and measure the margin."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.patterns.polynomial import generate
from zmpwalk.patterns.result import SUPPORT_NAMES
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule


@dataclass(frozen=True)
class ConditionMargin:
    """Smallest ZMP margin of one tabulated condition walked for ``steps`` steps.

    Attributes:
        mode: ``"forward"`` or ``"side"``.
        duration: Step time [s].
        stride: Forward stride or side step [m].
        steps: Commands walked.
        min_margin: Smallest signed distance of the cart-table ZMP to the support polygon [m].
        time: When it occurs [s].
        support: Support phase then (``"double"``, ``"left"``, ``"right"``).
    """

    mode: str
    duration: float  # [s]
    stride: float  # [m]
    steps: int
    min_margin: float  # [m]
    time: float  # [s]
    support: str


def condition_margins(
    robot: RobotModel, schedule: Schedule | None = None, steps: int = 10, rate: float = 1000.0,
    pelvis: str = "cubic",
) -> list[ConditionMargin]:
    """Walk ``steps`` commands of every tabulated condition and report the smallest ZMP margin of each
    (``pelvis``: the cubic or quintic pelvis curves of :func:`zmpwalk.patterns.polynomial.plan_walk`)."""
    schedule = schedule or Schedule.hubo()
    results = []
    for mode, duration, stride in schedule.conditions():
        if mode == "forward":
            command = StepCommand(duration=duration, forward=stride)
        else:
            command = StepCommand(duration=duration, side=stride)
        pattern = generate(robot, [command] * steps, rate=rate, schedule=schedule, pelvis=pelvis)
        margin = pattern.zmp_margin()
        index = int(np.nanargmin(margin))
        results.append(ConditionMargin(mode, duration, stride, steps, float(margin[index]),
                                       float(pattern.time[index]), SUPPORT_NAMES[int(pattern.support[index])]))
    return results


def margins_markdown(results: list[ConditionMargin]) -> str:
    """The margins as a Markdown table (mm and s)."""
    lines = ["| mode | step time [s] | stride [m] | min ZMP margin [mm] | at t [s] | support |",
             "|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r.mode} | {r.duration:.2f} | {r.stride:.2f} | {r.min_margin * 1e3:+.1f} | "
                     f"{r.time:.3f} | {r.support} |")
    return "\n".join(lines)
