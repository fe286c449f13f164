"""AMP / DeepMimic-style motion JSON.

``{"LoopMode": "Wrap" | "None", "FrameDuration": 1 / fps [s], "EnableCycleOffsetPosition": true,
"EnableCycleOffsetRotation": true, "QuaternionOrder": "wxyz", "FrameLayout": [...], "Frames": [[...], ...]}``.

Each frame: the root position x, y, z [m] in world, the root rotation quaternion **w, x, y, z** (unit norm),
then every joint angle [rad] (or slide [m]) in the model's joint order (``qpos[7:]``): the model's ``qpos`` row
as it is. ``FrameLayout`` names the columns. A cyclic clip (its first frame repeated by its last, the loop
points) is ``"Wrap"``; a start-to-stop clip ``"None"``. (Peng et al.'s ``motion_imitation`` files order the
quaternion x, y, z, w: reorder for them.)
"""

from __future__ import annotations

import json

import mujoco
import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import FileFormatError
from zmpwalk.export.names import qpos_names

Array = NDArray[np.float64]


def amp_json(model: mujoco.MjModel, qpos: Array, fps: float, cyclic: bool) -> bytes:
    """The clip as AMP-style JSON (module docstring)."""
    document = {"LoopMode": "Wrap" if cyclic else "None", "FrameDuration": 1.0 / fps,
                "EnableCycleOffsetPosition": True, "EnableCycleOffsetRotation": True, "QuaternionOrder": "wxyz",
                "FrameLayout": qpos_names(model), "Frames": [[round(float(v), 7) for v in row] for row in qpos]}
    return json.dumps(document).encode("utf-8")


def read_amp(path: str) -> tuple[Array, float]:
    """A clip's ``qpos`` rows and frame rate [Hz] back from :func:`amp_json`'s file.

    Raises:
        FileFormatError: Not such a file.
    """
    with open(path, encoding="utf-8") as handle:
        document = json.load(handle)
    try:
        return np.asarray(document["Frames"], dtype=np.float64), 1.0 / float(document["FrameDuration"])
    except (KeyError, TypeError, ValueError, ZeroDivisionError) as error:
        raise FileFormatError(path, f"is not an AMP motion file ({error})") from None
