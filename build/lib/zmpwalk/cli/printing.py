"""What several ``zmpwalk`` commands print: strict JSON, a progress bar, ZMP and CoP margins, a walk's verdict."""

from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from zmpwalk.sim.verdict import Verdict


def json_safe(value: object) -> object:
    """NaN and infinity (e.g. no loaded sole) become null, so the output is strict JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {key: json_safe(item) for key, item in value.items()}
    if isinstance(value, list):
        return [json_safe(item) for item in value]
    return value


def progress(stage: str, done: int, total: int) -> None:
    """A progress bar on standard error: ``done`` of ``total`` in ``stage``, a new line once all are done."""
    width = 24
    filled = width * done // total
    print(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{total} {stage:<10}", end="" if done < total else "\n",
          file=sys.stderr, flush=True)


def margin_words(margin: float, at: float | None = None) -> str:
    """A ZMP margin [m] as ``plan`` prints it: signed (positive inside), and whether it leaves the polygon."""
    if not math.isfinite(margin):
        return "not measured"
    where = "inside the support polygon" if margin >= 0 else "OUTSIDE the support polygon"
    return f"{margin * 1e3:+.1f} mm" + ("" if at is None else f" at t = {at:.3f} s") + f" ({where})"


def cop_margin_words(judged: float, every: float) -> str:
    """The CoP margin [m] two ways, each saying which samples it covers (the verdict judges the first)."""
    from zmpwalk.sim.verdict import TOUCHDOWN_WINDOW

    return (f"least CoP margin (positive inside) {judged * 1e3:+.1f} mm outside the {TOUCHDOWN_WINDOW * 1e3:g} ms "
            f"after each touchdown (the verdict's), {every * 1e3:+.1f} mm over every sample")


def print_verdict(verdict: Verdict) -> None:
    """The warnings, the outcome and every criterion: what the page shows too."""
    for warning in verdict.warnings:
        print(f"warning: {warning}")
    print(f"verdict: {verdict.state}: the walk {verdict.outcome()}")
    for line in verdict.lines():
        print(f"  {line}")
