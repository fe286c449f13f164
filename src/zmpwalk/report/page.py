"""The report folder: generate, check, simulate, plot, animate, and write one self-contained ``index.html``.

Everything the page shows is embedded (PNG figures as data URIs; the interactive replay's data, script and
three.js inline, see :mod:`zmpwalk.report.replay`; the GIF, only with ``gif=True``), so it opens offline from
any folder. The page marks ``<body data-images-loaded="yes">``
once every image has decoded, which the tests read in a headless browser.
"""

from __future__ import annotations

import base64
import html
import json
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from zmpwalk.commands import StepCommand
from zmpwalk.files import write_bytes, write_text
from zmpwalk.patterns.result import WalkingPattern
from zmpwalk.robots.model import RobotModel
from zmpwalk.schedule import Schedule
from zmpwalk.sim.actuators import IMPACT_WINDOW, ActuatorRow, actuator_markdown, write_actuator_csv
from zmpwalk.sim.motors import Motor, MotorFit
from zmpwalk.sim.run import SimulationResult, write_result_csv
from zmpwalk.sim.verdict import FAIL, PASS, SKIP, WARN, Verdict
from zmpwalk.walk import PlannedWalk, Progress, WalkSpec, run_walk

STAGES = ("pattern", "joints", "simulation", "plots", "animation", "page")


@dataclass
class Report:
    """What :func:`build_report` made.

    Attributes:
        folder: The report folder.
        index: Its ``index.html``.
        seconds: Wall time of each stage [s].
        summary: The numbers on the page (SI).
        verdict: The simulated walk's verdict (every criterion with its figure).
    """

    folder: Path
    index: Path
    seconds: dict[str, float] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)
    verdict: Verdict = field(default_factory=lambda: Verdict(()))


def _data_uri(kind: str, payload: bytes) -> str:
    return f"data:{kind};base64,{base64.b64encode(payload).decode('ascii')}"


def step_margins(pattern: WalkingPattern) -> list[tuple[int, str, str, float, float, float]]:
    """Per swing: number, kind, swing foot, start [s], duration [s], smallest ZMP margin [m]."""
    margin = pattern.zmp_margin()
    rows = []
    for number, step in enumerate(pattern.steps, start=1):
        mask = (pattern.time >= step.start) & (pattern.time <= step.start + step.duration)
        rows.append((number, step.kind, step.swing, step.start, step.duration, float(np.nanmin(margin[mask]))))
    return rows




def build_report(
    robot: RobotModel,
    commands: Sequence[StepCommand],
    folder: Path,
    *,
    title: str,
    generator: str | None = None,
    animate: bool = True,
    gif: bool = False,
    progress: Progress | None = None,
    labels: Sequence[str] | None = None,
    balance: bool = True,
    latency: float = 0.0,
    schedule: Schedule | None = None,
    motors: list[Motor] | None = None,
    pelvis: str = "cubic",
    planned: PlannedWalk | None = None,
) -> Report:
    """Generate, check, simulate and report a walk into ``folder`` (``generator``: None for the robot's own;
    ``pelvis``: the polynomial generator's pelvis curves, ``"cubic"`` or ``"quintic"``). ``animate``: the
    interactive replay (three.js); ``gif``: also the offscreen-rendered GIF (``walk.gif``, shown where WebGL is
    missing). ``planned``: this very walk already planned (its ``WalkSpec`` the one made of these arguments, with
    ``check_limits``: :func:`zmpwalk.ready_fit.fit_ready_posture`'s), not planned again.

    Raises:
        ZmpwalkError: The walk cannot be generated (the message says why).
    """
    folder.mkdir(parents=True, exist_ok=True)
    report = Report(folder, folder / "index.html")
    spec = WalkSpec(robot, commands, labels, generator=generator, schedule=schedule, pelvis=pelvis,
                    check_limits=True, balance=balance, latency=latency, motors=motors)
    walk = run_walk(spec, progress=None if progress is None else _walk_progress(progress), planned=planned)
    pattern, result, rows, report.verdict = walk.pattern, walk.result, walk.rows, walk.verdict
    clock = time.perf_counter()
    pattern.write_csv(folder / "pattern.csv")
    write_actuator_csv(rows, folder / "actuators.csv")
    write_result_csv(result, folder / "simulation.csv")
    report.seconds.update(pattern=walk.seconds["pattern"], joints=walk.seconds["joints"],
                          simulation=walk.seconds["simulation"] + walk.seconds["measures"])

    def done(stage: str) -> None:
        nonlocal clock
        now = time.perf_counter()
        report.seconds[stage] = report.seconds.get(stage, 0.0) + now - clock
        clock = now
        if progress:
            progress(stage, STAGES.index(stage) + 1, len(STAGES))

    done("simulation")
    images, time_axes = _figures(pattern, result, motors)
    for index, payload in enumerate(images.values()):
        write_bytes(folder / f"figure{index + 1}.png", payload)
    done("plots")
    animation, animation_note = _animation(robot, result, folder, progress) if gif else (None, "")
    replay = _replay(robot, pattern, result, animation, animation_note) if animate else ""
    done("animation")
    fits = walk.fits
    report.summary = _summary(pattern, result, report.verdict, fits, spec.generator_name, walk.controller)
    movie = replay or _movie(animation, animation_note)
    page = _page(title, robot, report.summary, _figure_html(images, time_axes if replay else {}), movie,
                 step_margins(pattern), rows, report.verdict, fits, _step_list(commands, labels))
    write_text(report.index, page)
    write_text(folder / "summary.json", json.dumps(report.summary, indent=2))
    done("page")
    return report


def _walk_progress(progress: Progress) -> Progress:
    """The walk's stages (:func:`zmpwalk.walk.run_walk`) as the report's: each stage reported done as the next
    starts, the simulation's percentage passed on."""
    previous = {"joints": "pattern", "simulation": "joints"}

    def walking(stage: str, done: int, total: int) -> None:
        if stage == "simulation" and total == 100:
            progress(stage, done, total)
        elif stage in previous:
            progress(previous[stage], STAGES.index(previous[stage]) + 1, len(STAGES))

    return walking


ZMP_TIME = "ZMP and measured CoP against time, with the support polygon's bounds (Figs. 21, 27-31)"


def _figures(pattern: WalkingPattern, result: SimulationResult,
             motors: list[Motor] | None) -> tuple[dict[str, bytes], dict[str, dict[str, float]]]:
    """The page's figures (PNG) by caption, and where the time axis lies in those that have the replay's time
    cursor (see :func:`zmpwalk.report.plots.zmp_time_axis`)."""
    from zmpwalk.report import plots

    zmp_time, axis = plots.zmp_time_axis(pattern, result)
    images = {
        "ZMP over the footprints (Figs. 20-22 of Park et al.)": plots.zmp_path(pattern, result),
        ZMP_TIME: zmp_time,
        "Ankles relative to the pelvis (Figs. 10-11, 16-17)": plots.trajectories(pattern),
        "Both legs: joint angles, torques and powers in the simulation (Figs. 12-14 of Lim et al.)":
            plots.joints(result),
        "Pelvis x, y and yaw, planned and simulated; the CoP margin over time": plots.pelvis(pattern, result),
    }
    if result.balance is not None:
        images["The stabilizer: pattern ZMP, desired ZMP and measured CoP; its corrections"] = plots.balance(result)
    if motors:
        images["Torque-speed operating points against the motors' envelopes (joint side)"] = \
            plots.motor_envelopes(result, motors)
    return images, {ZMP_TIME: axis}


def _figure_html(images: dict[str, bytes], time_axes: dict[str, dict[str, float]]) -> str:
    """The figures as HTML; those in ``time_axes`` carry it (``data-time-axis``) for the replay's time cursor."""
    esc = html.escape

    def axis(caption: str) -> str:
        where = time_axes.get(caption)
        return f" data-time-axis='{json.dumps(where)}'" if where else ""

    return "\n".join(
        f"<figure><img src='{_data_uri('image/png', payload)}' alt='{esc(caption)}'{axis(caption)}>"
        f"<figcaption>{esc(caption)}</figcaption></figure>" for caption, payload in images.items())


def _animation(robot: RobotModel, result: SimulationResult, folder: Path,
               progress: Progress | None) -> tuple[bytes | None, str]:
    """The walk as a GIF (written to ``walk.gif``), or None and why it could not be rendered."""
    from zmpwalk.report.animation import render_gif

    try:
        animation = render_gif(robot, result, progress=None if progress is None else
                               lambda done: progress("animation", round(100 * done), 100))
    except Exception as error:  # no OpenGL context on this machine: say so on the page
        return None, f"The animation could not be rendered here: {error}. Set MUJOCO_GL=egl or osmesa."
    write_bytes(folder / "walk.gif", animation)
    return animation, ""


def _movie(animation: bytes | None, note: str) -> str:
    """The GIF as a figure, or the note why there is none (empty when none was asked for)."""
    if animation:
        return (f"<figure><img id='walk' src='{_data_uri('image/gif', animation)}' alt='the simulated walk'>"
                f"<figcaption>The walk in MuJoCo, replayed from the simulation</figcaption></figure>")
    return f"<p class='bad'>{html.escape(note)}</p>" if note else ""


def _replay(robot: RobotModel, pattern: WalkingPattern, result: SimulationResult, animation: bytes | None,
            note: str) -> str:
    """The interactive replay's section, with the GIF (or a note) as its fallback where WebGL is missing."""
    from zmpwalk.report.replay import replay_html, replay_payload

    fallback = _movie(animation, note) or ("<p class='none'>This browser has no WebGL for the interactive replay; "
                                           "<code>zmpwalk report --gif</code> adds a GIF of the walk.</p>")
    return replay_html(replay_payload(robot, pattern, result), fallback)


def _summary(pattern: WalkingPattern, result: SimulationResult, verdict: Verdict, fits: list[MotorFit],
             generator: str, controller: str) -> dict[str, Any]:
    """The numbers on the page (SI), as ``summary.json`` and ``report --json`` give them."""
    margin, at = pattern.min_zmp_margin()
    rms, largest = result.cop_error_stats()
    return {
        "robot": result.robot.name, "generator": generator, "duration": pattern.duration,
        "swings": len(pattern.steps), "min_zmp_margin": margin, "min_zmp_margin_time": at, "fell": result.fell,
        "fall_time": result.fall_time, "distance": result.distance, "average_speed": result.average_speed,
        "foot_slip": result.foot_slip, "cop_error_rms": rms, "cop_error_max": largest,
        "balance": result.balance is not None, "controller": controller,
        "verdict": verdict.as_dict(), "warnings": list(verdict.warnings),
        "motors": [{"joint": f.joint, "motor": f.motor, "rms_use": f.rms_use, "peak_use": f.peak_use,
                    "fits": f.fits} for f in fits],
    }


STATE_CLASS = {PASS: "good", WARN: "warn", FAIL: "bad", SKIP: "none"}
STATE_WORD = {PASS: "pass", WARN: "warning", FAIL: "FAIL", SKIP: "not measured"}


def _outcome_class(verdict: Verdict) -> str:
    """Green only when every criterion passed with its figure and nothing is warned of."""
    if verdict.state == FAIL:
        return "bad"
    if verdict.clean:
        return "good"
    return "warn" if verdict.state == WARN else "none"


def actuator_html(rows: list[ActuatorRow]) -> str:
    """The motor table's HTML rows, header first: the cells of :func:`actuator_markdown`, so the header and
    every row have as many cells."""
    esc = html.escape
    lines = actuator_markdown(rows).splitlines()
    header, body = lines[0], lines[2:]

    def cells(line: str) -> list[str]:
        return [esc(cell.strip()) for cell in line.strip().strip("|").split("|")]

    return "\n".join(["<tr>" + "".join(f"<th>{cell}</th>" for cell in cells(header)) + "</tr>"]
                     + ["<tr>" + "".join(f"<td>{cell}</td>" for cell in cells(line)) + "</tr>" for line in body])


def _step_list(commands: Sequence[StepCommand], labels: Sequence[str] | None) -> str:
    """The commanded steps as table rows."""
    esc = html.escape
    return "\n".join(
        f"<tr><td>{n}</td><td>{esc(labels[n - 1] if labels and n <= len(labels) else f'step {n}')}</td>"
        f"<td>{c.duration:.3g}</td><td>{c.forward:+.3g}</td><td>{c.side:+.3g}</td><td>{c.turn:+.3g}</td>"
        f"<td>{'yes' if c.stop else ''}</td></tr>" for n, c in enumerate(commands, start=1))


STYLE = """<style>
body { font-family: system-ui, sans-serif; max-width: 980px; margin: 2em auto; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
td, th { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th { background: #f3f3f3; } td:first-child { text-align: left; }
.good { color: #1a7f37; } .bad { color: #c0392b; } .warn { color: #b36b00; } .none { color: #666; }
figure { margin: 1.5em 0; } img { max-width: 100%; } figcaption { color: #555; font-size: 0.9em; }
</style>"""
SCRIPT = """<script>
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images);
  var ok = images.length > 0 && images.every(function (i) { return i.complete && i.naturalWidth > 0; });
  document.body.setAttribute("data-images-loaded", ok ? "yes" : "no");
  document.body.setAttribute("data-image-count", String(images.length));
});
</script>"""


def _verdict_html(verdict: Verdict, summary: dict[str, Any]) -> str:
    """The outcome (green only when :attr:`Verdict.clean`), every criterion with its state, figure and limit, and
    every warning the console prints."""
    esc = html.escape
    outcome = (f"<b class='{_outcome_class(verdict)}'>{esc(verdict.outcome())}</b>"
               + (f" <b class='bad'>(fell at t = {summary['fall_time']:.2f} s)</b>" if summary["fell"] else ""))
    criteria_rows = "\n".join(
        f"<tr><td>{esc(c.name)}</td><td class='{STATE_CLASS[c.state]}'>{STATE_WORD[c.state]}</td>"
        f"<td>{esc(c.text())} ({esc(c.rule)})</td></tr>" for c in verdict.criteria)
    warnings = ("<ul id='warnings'>" + "".join(f"<li class='warn'>warning: {esc(w)}</li>" for w in verdict.warnings)
                + "</ul>" if verdict.warnings else "")
    return (f'<p id="verdict">In the MuJoCo simulation the walk {outcome}.</p>\n'
            '<table id="criteria"><tr><th>criterion</th><th>result</th><th>figure (limit; how it is judged)</th></tr>\n'
            f"{criteria_rows}\n</table>\n{warnings}")


def _fit_table(fits: list[MotorFit]) -> str:
    """Each joint against its motor (empty without a motor file)."""
    esc = html.escape
    fit_rows = "\n".join(
        f"<tr><td>{esc(f.joint)}</td><td>{esc(f.motor)}</td><td>{f.rms_use * 100:.0f}</td>"
        f"<td>{f.peak_use * 100:.0f}</td><td class='{'good' if f.fits else 'bad'}'>{esc(f.verdict)}</td></tr>"
        for f in fits)
    return ("<table><tr><th>joint</th><th>motor</th><th>RMS torque [% of rated]</th>"
            f"<th>held peak [% of envelope]</th><th>verdict</th></tr>\n{fit_rows}\n</table>" if fits else "")


def _page(title: str, robot: RobotModel, summary: dict[str, Any], figures: str,
          movie: str, margins: list[tuple[int, str, str, float, float, float]],
          rows: list[ActuatorRow], verdict: Verdict, fits: list[MotorFit], steps: str) -> str:
    esc = html.escape
    margin_rows = "\n".join(
        f"<tr><td>{n}</td><td>{esc(kind)}</td><td>{esc(swing)}</td><td>{start:.2f}</td><td>{duration:.2f}</td>"
        f"<td class='{'good' if m >= 0 else 'bad'}'>{m * 1e3:+.1f}</td></tr>"
        for n, kind, swing, start, duration, m in margins)
    actuator_rows = actuator_html(rows)
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{esc(title)}</title>
{STYLE}</head>
<body data-images-loaded="no">
<h1>{esc(title)}</h1>
<p>{esc(robot.description)}. Pattern: {esc(str(summary['generator']))} generator,
{summary['swings']} swings over {summary['duration']:.2f} s, sampled at 1 kHz.
Controller: {esc(str(summary['controller']))}.</p>
<h2>Does it walk?</h2>
{_verdict_html(verdict, summary)}
<p>Distance {summary['distance']:.3f} m, average speed
{float(summary['average_speed']) * 1e3:.1f} mm/s, largest foot slip {float(summary['foot_slip']) * 1e3:.1f} mm;
centre of pressure against the reference ZMP: RMS {float(summary['cop_error_rms']) * 1e3:.1f} mm,
max {float(summary['cop_error_max']) * 1e3:.1f} mm.
The pattern's cart-table ZMP stays {float(summary['min_zmp_margin']) * 1e3:+.1f} mm from the edge of the
support polygon at its closest (t = {float(summary['min_zmp_margin_time']):.2f} s; positive inside, negative
outside: {'inside' if float(summary['min_zmp_margin']) >= 0 else 'OUTSIDE'}).</p>
{movie}
<p>The simulated time series (every millisecond, SI units): <a id="series" href="simulation.csv">simulation.csv</a>;
the pattern: <a href="pattern.csv">pattern.csv</a>; the motor table: <a href="actuators.csv">actuators.csv</a>.</p>
<h2>The walk commanded</h2>
<table id="steps"><tr><th>#</th><th>step</th><th>step time [s]</th><th>forward [m]</th><th>side [m]</th>
<th>turn [rad]</th><th>stop</th></tr>
{steps}
</table>
<h2>Which motors?</h2>
<p>Peaks are those held for at least {IMPACT_WINDOW * 1e3:g} ms (what sizes a motor); the largest single-sample
torque, at touchdown impacts, has its own column.</p>
<table id="actuators">
{actuator_rows}
</table>
{_fit_table(fits)}
<h2>ZMP margin per step</h2>
<table><tr><th>#</th><th>kind</th><th>swing</th><th>start [s]</th><th>duration [s]</th><th>min margin [mm]</th></tr>
{margin_rows}
</table>
<h2>Figures</h2>
{figures}
{SCRIPT}
</body></html>
"""
