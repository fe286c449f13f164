"""Step commands as operators give them, for the control-loop fuzz tests: ordinary ones and hostile ones, and a
budget clock that makes every part of a command's check cost a chosen time."""

from __future__ import annotations

import math

import pytest
from hypothesis import strategies as st

HOSTILE_STEPS = st.sampled_from([
    {"duration": 0.0, "forward": 0.1},  # zero step time: refused when the command is made
    {"duration": math.nan},
    {"duration": 0.8, "forward": 0.9},  # beyond the legs' reach
    {"duration": 0.8, "forward": -0.9},
    {"duration": 0.15, "forward": 0.3},  # too fast for the foot speed limit
    {"duration": 0.8, "forward": 0.1, "foot_lift": 0.4},  # lifted too high
    {"duration": 1.0, "forward": 0.3, "foot_lift": 0.15},  # its stop leaves the ankle pitch range
    {"duration": 0.8, "side": -0.2},  # feet that would overlap
    {"duration": 0.8, "turn": 1.5},
])
ORDINARY_STEPS = st.one_of(
    st.builds(lambda d, f: {"duration": d, "forward": f}, st.floats(0.6, 1.0), st.floats(-0.1, 0.25)),
    st.builds(lambda d, a: {"duration": d, "side": a}, st.floats(0.7, 1.0), st.floats(-0.06, 0.06)),
    st.builds(lambda d, t: {"duration": d, "forward": 0.05, "turn": t}, st.floats(0.7, 1.0), st.floats(-0.2, 0.2)),
)


def parts_clock(monkeypatch: pytest.MonkeyPatch, part: float) -> None:
    """The walker's budget clock advances ``part`` [s] a call: every part of a check costs ``part``."""
    now = [0.0]

    def clock() -> float:
        now[0] += part
        return now[0]

    monkeypatch.setattr("zmpwalk.online._clock", clock)
