"""The two feet and the support phases, one definition each.

:class:`Side` names a foot by the sign of its lateral offset in the pelvis frame (left +y, right -y), so that
``side * half_width`` is the foot's lateral place; :attr:`Side.index` is its row in per-leg arrays (left 0,
right 1). :class:`Support` codes what is on the ground, as ``WalkingPattern.support`` and the stabilizer store
it (0 both feet, 1 the left foot alone, 2 the right foot alone). Both are ``IntEnum``: their members are the
integers that arrays and compiled code hold.
"""

from __future__ import annotations

from enum import IntEnum


class Side(IntEnum):
    """A foot: ``LEFT`` = +1, ``RIGHT`` = -1 (the sign of its lateral offset from the pelvis)."""

    LEFT = 1
    RIGHT = -1

    @property
    def other(self) -> Side:
        """The other foot."""
        return Side(-self.value)

    @property
    def index(self) -> int:
        """The foot's row in per-leg arrays: 0 left, 1 right."""
        return 0 if self is Side.LEFT else 1

    @property
    def label(self) -> str:
        """``"left"`` or ``"right"``, as files and messages spell it."""
        return self.name.lower()

    @property
    def single_support(self) -> Support:
        """The support phase with this foot alone on the ground."""
        return Support.LEFT if self is Side.LEFT else Support.RIGHT


class Support(IntEnum):
    """What is on the ground: ``DOUBLE`` (0) both feet, ``LEFT`` (1) or ``RIGHT`` (2) one foot alone."""

    DOUBLE = 0
    LEFT = 1
    RIGHT = 2

    @property
    def label(self) -> str:
        """``"double"``, ``"left"`` or ``"right"``, as the pattern's CSV and the walker's samples spell it."""
        return self.name.lower()

    @classmethod
    def of_label(cls, label: str) -> Support:
        """The support spelled ``label`` (:attr:`label`)."""
        return cls[label.upper()]


SUPPORT_LABELS = tuple(support.label for support in Support)  # indexed by the codes
SUPPORT_OF_LABEL = {support.label: support for support in Support}  # a walker sample's support as a code
