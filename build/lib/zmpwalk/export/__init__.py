"""Reference motions for learning: walks over a grid of commands, simulated in MuJoCo, exported and verified.

:func:`export_motions` (:mod:`zmpwalk.export.run`) writes per command the simulated and the planned motion,
whole and cyclic, in the model's own joint names and ``qpos`` order (the free base first; quaternions w, x, y, z)
as mjlab's motion npz (:mod:`~zmpwalk.export.mjlab`), a LocoMuJoCo-style npz (:mod:`~zmpwalk.export.locomujoco`),
AMP JSON (:mod:`~zmpwalk.export.amp`) and CSV (:mod:`~zmpwalk.export.table`), each replayed from its file and
checked (:mod:`~zmpwalk.export.verify`), with a manifest. docs/export.md describes the formats.
"""

from zmpwalk.export.clips import Clip, Command
from zmpwalk.export.run import ClipRecord, ExportResult, Grid, export_motions
from zmpwalk.export.verify import ReplayCheck, replay_check

__all__ = ["Clip", "ClipRecord", "Command", "ExportResult", "Grid", "ReplayCheck", "export_motions", "replay_check"]
