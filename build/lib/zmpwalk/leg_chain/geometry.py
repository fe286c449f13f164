"""What the leg's inverse-kinematics solvers read of a chain: its geometry and its forward kinematics.

The solvers (:mod:`~zmpwalk.leg_chain.paden_kahan`, :mod:`~zmpwalk.leg_chain.numeric`,
:mod:`~zmpwalk.leg_chain.straight`) take any object with these members; :class:`~zmpwalk.leg_chain.LegChain` is
the one the library builds. Positions and axes are in the pelvis frame [m], angles in [rad].
"""

from __future__ import annotations

from typing import Protocol

from zmpwalk.leg_chain.rotations import Array


class ChainGeometry(Protocol):
    """A six-joint leg from the pelvis to the sole (see :class:`~zmpwalk.leg_chain.LegChain` for each member)."""

    @property
    def axes(self) -> Array: ...  # (6, 3) unit joint axes at zero angles

    @property
    def points(self) -> Array: ...  # (6, 3) a point on each axis [m]

    @property
    def ankle(self) -> Array: ...  # (3,) the ankle point at zero angles [m]

    @property
    def reference(self) -> Array: ...  # (6,) the reference posture's angles [rad]

    @property
    def role_order(self) -> tuple[int, ...]: ...

    @property
    def sole_rotation(self) -> Array: ...  # (3, 3) the sole's frame in the last link's frame

    @property
    def virtual(self) -> int | None: ...

    @property
    def link_lengths(self) -> tuple[float, float] | None: ...  # [m]

    @property
    def hip(self) -> Array: ...

    @property
    def ankle_point(self) -> Array: ...

    def fk_chain(self, q: Array, transforms: tuple[Array, Array] | None = None) -> tuple[Array, Array]: ...

    def jacobian(self, q: Array, transforms: tuple[Array, Array] | None = None) -> Array: ...
