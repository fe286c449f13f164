"""An imported robot's legs over a sampled motion, in parts: the base under the pattern's centre of mass, both legs'
angles there and their rates, :data:`IK_CHUNK` samples a part.

The work is the compiled kernel's (:mod:`zmpwalk.stabilizer.whole_body_ik`: damped least squares on the compiled
leg, sample by sample, each from the last one's angles and base); this module holds each robot's arrays for it and
drives it chunk by chunk, so that a control loop runs a step's legs a few tens of microseconds at a time
(:func:`zmpwalk.kinematics.joint_trajectory_in_parts`, :class:`zmpwalk.online.OnlineWalker`, a capture step).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.robots.model import RobotModel
from zmpwalk.slices import Parts
from zmpwalk.stabilizer.layout import PARAMETERS, P, chain_table

Array = NDArray[np.float64]

IK_CHUNK = 8  # samples per part (TALOS, T1, N1: about 3.2 us a sample with the rates, 25 us a part)
COM_TOLERANCE = 1e-9  # [m] the base is placed until the whole-body CoM is this close to the pattern's


@dataclass(frozen=True)
class _Arrays:
    """One robot's arrays for the kernel: ``params`` (the robot's mass, the rest of the body's mass moment, the
    ankle offsets), ``chain`` (2, 6, 11), ``sole_back`` (2, 3, 3) each sole frame transposed, ``posture`` (12,)
    the legs' reference angles [rad] and ``offset`` (2,) the base's offset from the CoM in the base frame [m]."""

    params: Array
    chain: Array
    sole_back: Array
    posture: Array
    offset: Array


_ARRAYS: dict[int, tuple[weakref.ref[RobotModel], _Arrays]] = {}  # by id(robot)


def _arrays(robot: RobotModel) -> _Arrays:
    """The kernel's arrays of ``robot`` (an imported one: leg chains and masses), built once per robot."""
    kept = _ARRAYS.get(id(robot))
    if kept is not None and kept[0]() is robot:
        return kept[1]
    legs, plant = robot.legs, robot.plant
    if legs is None or plant is None:
        raise InvalidParameterError("robot", robot.name, "an imported robot (leg chains and masses)")
    params = np.zeros(PARAMETERS)
    params[P.mass] = plant.rest_mass + sum(float(leg.link_masses.sum()) for leg in legs)
    params[P.rest_moment:P.rest_moment + 3] = plant.rest_mass * np.asarray(plant.rest_com)
    params[P.ankle_offset:P.ankle_offset + 6] = np.concatenate([leg.ankle for leg in legs])
    arrays = _Arrays(
        params=params, chain=chain_table(legs),
        sole_back=np.ascontiguousarray([leg.sole_rotation.T for leg in legs], dtype=np.float64),
        posture=np.concatenate([np.asarray(leg.reference, dtype=np.float64)[list(leg.role_order)] for leg in legs]),
        offset=-np.asarray(robot.com_offset[:2], dtype=np.float64))
    _ARRAYS[id(robot)] = (weakref.ref(robot), arrays)
    return arrays


class LegFill:
    r"""An imported robot's base and legs for a pattern that moves its whole-body CoM, filled chunk by chunk:
    :meth:`advance` solves the next :data:`IK_CHUNK` samples' base and angles and the chunk before's rates, so that
    rows ``[0, done)`` are complete.

    Args:
        time: [s], (n,).
        position_com_in_world, yaw_pelvis_in_world, velocity_com_in_world, yaw_rate_pelvis: the pattern's point
            (the whole-body CoM) [m] and [m/s], (n, 3), and the base's heading [rad] and its rate [rad/s], (n,).
        feet: For the left then the right foot: ankle position [m] (n, 3), foot yaw [rad] (n,), ankle velocity
            [m/s] (n, 3) and foot yaw rate [rad/s] (n,), all in world.
        robot: An imported robot (leg chains and masses).

    Attributes:
        base: The base positions (n, 3) [m] (the CoM's height kept: its vertical motion is what the pattern
            neglects too); its velocity is the CoM's plus the time derivative of their offset.
        angles, rates: (n, 12) [rad] and [rad/s] in :data:`~zmpwalk.kinematics.JOINT_COLUMNS` order.
        excess: Per leg and sample the IK's residual where it did not converge (or NaN), else -1 (2, n) [m] or
            [rad].
        done: The rows complete (each array's rows from ``done`` on are not set yet).

    Raises:
        InvalidParameterError: ``robot`` is not an imported one.
    """

    def __init__(self, time: Array, position_com_in_world: Array, yaw_pelvis_in_world: Array,
                 velocity_com_in_world: Array, yaw_rate_pelvis: Array,
                 feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]],
                 robot: RobotModel) -> None:
        self._fill(time, position_com_in_world, yaw_pelvis_in_world, velocity_com_in_world, yaw_rate_pelvis, feet,
                   _arrays(robot))

    def _fill(self, time: Array, position_com_in_world: Array, yaw_pelvis_in_world: Array,
              velocity_com_in_world: Array, yaw_rate_pelvis: Array,
              feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]],
              arrays: _Arrays) -> None:
        from zmpwalk.stabilizer import whole_body_ik  # compiles (or loads) the kernel: only where wanted

        self._kernel = whole_body_ik
        self._arrays = arrays
        n = len(time)
        self.time = np.ascontiguousarray(time, dtype=np.float64)
        self._com = np.ascontiguousarray(position_com_in_world, dtype=np.float64)
        self._velocity = np.ascontiguousarray(velocity_com_in_world, dtype=np.float64)
        self._yaw = np.ascontiguousarray(yaw_pelvis_in_world, dtype=np.float64)
        self._yaw_rate = np.ascontiguousarray(yaw_rate_pelvis, dtype=np.float64)
        # each foot's position, yaw, velocity and yaw rate as a (left, right) pair (copies only where not
        # contiguous float64)
        self._feet = tuple((np.ascontiguousarray(feet[0][i], dtype=np.float64),
                            np.ascontiguousarray(feet[1][i], dtype=np.float64)) for i in range(4))
        self._start = np.zeros(whole_body_ik.START_SIZE)
        self._start[:16] = np.concatenate([self._arrays.posture, self._arrays.offset, [1.0, 1.0]])
        # not written here: a fresh array's pages fault in when first written (1-10 us each on a virtual
        # machine), so the parts that fill the rows take them a few at a time
        self.base, self.angles, self.rates = np.empty((n, 3)), np.empty((n, 12)), np.empty((n, 12))
        self.excess = np.empty((2, n))
        self.done = 0
        self._solved = 0  # rows whose base and angles are solved

    @property
    def complete(self) -> bool:
        """Every row filled."""
        return self.done == len(self.time)

    def advance(self) -> None:
        """One part: the next chunk's base and angles, then the rates of the rows whose neighbours are solved."""
        n = len(self.time)
        if self._solved < n:
            last = min(self._solved + IK_CHUNK, n)
            self._solve(self._solved, last)
            self._solved = last
        ready = n if self._solved == n else self._solved - 1  # a row's rate reads the next row's base
        if ready > self.done:
            self._rates(self.done, ready)
            self.done = ready

    def _solve(self, first: int, last: int) -> None:
        arrays = self._arrays
        self._kernel.base_under_com(arrays.params, arrays.chain, arrays.sole_back, self._com, self._yaw,
                                    self._feet[0], self._feet[1], first, last, self._start, COM_TOLERANCE,
                                    self.base, self.angles, self.excess)

    def _rates(self, first: int, last: int) -> None:
        self._kernel.joint_rates(self._arrays.params, self._arrays.chain, self.time, self.angles, self.base,
                                 self._com, self._velocity, self._yaw, self._yaw_rate, self._feet[0],
                                 self._feet[2], self._feet[3], first, last, self.rates)

    def parts(self) -> Parts[None]:
        """:meth:`advance` until every row is filled, a part each."""
        while not self.complete:
            yield
            self.advance()


def imported_legs_in_parts(time: Array, position_com_in_world: Array, yaw_pelvis_in_world: Array,
                           velocity_com_in_world: Array, yaw_rate_pelvis: Array,
                           feet: tuple[tuple[Array, Array, Array, Array], tuple[Array, Array, Array, Array]],
                           robot: RobotModel) -> Parts[tuple[Array, Array, Array, Array]]:
    """:class:`LegFill` run to its end, in parts: the base (n, 3) [m], the angles (n, 12) [rad] and rates (n, 12)
    [rad/s], and the IK's residuals (2, n) [m] (arguments and errors: :class:`LegFill`'s)."""
    fill = LegFill(time, position_com_in_world, yaw_pelvis_in_world, velocity_com_in_world, yaw_rate_pelvis, feet,
                   robot)
    yield from fill.parts()  # (its first part begins with a yield: the fill's arrays are a part of their own)
    return fill.base, fill.angles, fill.rates, fill.excess


def compile_kernel() -> None:
    """Compile the kernel (or load it from numba's disk cache) for the argument types :class:`LegFill` gives it,
    without a robot: both of its functions called as a fill calls them, on zero arrays, for no sample."""
    one, three = np.zeros(1), np.zeros((1, 3))
    arrays = _Arrays(params=np.zeros(PARAMETERS), chain=np.zeros((2, 6, 11)), sole_back=np.zeros((2, 3, 3)),
                     posture=np.zeros(12), offset=np.zeros(2))
    fill = LegFill.__new__(LegFill)
    fill._fill(one, three, one, three, one, ((three, one, three, one), (three, one, three, one)), arrays)
    fill._solve(0, 0)
    fill._rates(0, 0)


def leg_parts(robot: RobotModel, samples: int) -> int:
    """The parts :func:`imported_legs_in_parts` takes for ``samples`` samples of ``robot``'s legs (0 for a robot
    file's robot, whose closed-form legs take a few parts whatever the samples): a check's or a plan's pacing."""
    return 0 if robot.legs is None else -(-samples // IK_CHUNK)


__all__ = ["COM_TOLERANCE", "IK_CHUNK", "LegFill", "compile_kernel", "imported_legs_in_parts", "leg_parts"]
