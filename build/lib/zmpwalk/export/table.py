"""CSV: one row per frame, ``time`` [s] then the model's ``qpos`` columns.

Header: ``time``, the free base's ``<name>_x, _y, _z`` [m] and ``_qw, _qx, _qy, _qz`` (quaternion **w, x, y, z**),
then the model's joint names in its order [rad or m].
"""

from __future__ import annotations

import io

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.export.names import qpos_names

Array = NDArray[np.float64]


def clip_csv(model: mujoco.MjModel, qpos: Array, fps: float) -> bytes:
    """The clip as CSV (module docstring)."""
    buffer = io.StringIO()
    time = np.arange(len(qpos)) / fps
    np.savetxt(buffer, np.column_stack([time, qpos]), delimiter=",", fmt="%.7g",
               header=",".join(["time", *qpos_names(model)]), comments="")
    return buffer.getvalue().encode("utf-8")


def read_csv(path: str) -> tuple[Array, float]:
    """A clip's ``qpos`` rows and frame rate [Hz] back from :func:`clip_csv`'s file."""
    rows = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    fps = 1.0 / float(rows[1, 0] - rows[0, 0]) if len(rows) > 1 else 0.0
    return rows[:, 1:], fps
