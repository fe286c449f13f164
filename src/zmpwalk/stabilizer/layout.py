"""The layout of the compiled stabilizer's arrays: which named value sits where in ``params``, ``state`` and ``log``.

Each table is generated from a list of (name, size) fields, laid out one after the other; its offsets are a named
tuple (:data:`P`, :data:`S`, :data:`L`) that the compiled loops index with (``params[P.dcm]``): numba takes a
module's global tuple as a constant, so a named offset costs what a literal index does. The parameters are every
field of :class:`~zmpwalk.stabilizer_gains.StabilizerGains`, by name, then the robot's constants
(:data:`ROBOT_CONSTANTS`): a new gain is a new field of the dataclass and its use in its loop.

numba's disk cache keeps each compiled function's constants and is renewed only when the function's own source
file changes; :data:`LAYOUT_KEY` fingerprints the tables so that the tick can tell a compiled function that was
built against other offsets (:func:`zmpwalk.stabilizer.freshness.renew_stale`).
"""

from __future__ import annotations

import dataclasses
import math
import zlib
from collections import namedtuple
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from zmpwalk.errors import InvalidParameterError
from zmpwalk.sides import Support
from zmpwalk.stabilizer_gains import StabilizerGains

if TYPE_CHECKING:
    from zmpwalk.leg_chain import LegChain

# The pattern's support codes as plain integers, the constants the compiled loops compare with
DOUBLE_SUPPORT, LEFT_SUPPORT, RIGHT_SUPPORT = int(Support.DOUBLE), int(Support.LEFT), int(Support.RIGHT)

Fields = tuple[tuple[str, int], ...]

ROBOT_CONSTANTS: Fields = (  # after the gains in params, (name, size)
    ("dt", 1),  # [s] control period
    ("omega", 1),  # [1/s] sqrt(g / l)
    ("mass", 1),  # [kg]
    ("rest_moment", 3),  # mass times CoM of everything but the legs, in the base frame [kg m]
    ("half_length", 1),  # [m] of the sole
    ("half_width", 1),  # [m]
    ("ankle_height", 1),  # [m]
    ("pendulum_length", 1),  # [m]
    ("sole_center_x", 1),  # [m] the sole's centre ahead of the ankle
    ("sole_center_y", 1),  # [m] outwards of the left ankle (mirrored for the right)
    ("load_threshold", 1),  # [N] a sole carries load above this normal force
    ("ankle_offset", 6),  # (2, 3) the ankle point in the last frame of each leg [m]
    ("servo_gain", 12),  # outer-loop gain per joint column [-]
    ("stiffen", 1),  # 1 when any servo gets the outer loop
    ("sole_stiffness", 1),  # [N/m^e] k of the sole's contact law f = k x^e (0: a rigid sole)
    ("sole_exponent", 1),  # [-] e
    ("sole_normal", 6),  # (2, 3) each sole's normal in the last frame of its leg (the sole frame's z axis) [-]
    ("ankle_roll", 1),  # 1 when both legs have an ankle roll joint, 0 for five-joint legs (a virtual one)
)
GAIN_FIELDS: Fields = tuple((f.name, 1) for f in dataclasses.fields(StabilizerGains))

STATE_FIELDS: Fields = (  # the filters and offsets that carry from tick to tick
    ("started", 1),  # 1 once the first tick has set the filters
    ("previous_reference", 2),  # the CoM reference of the last tick [m]
    ("previous_relative", 6),  # (2, 3) each measured ankle in the base frame, last tick [m]
    ("com_velocity", 2),  # filtered [m/s]
    ("offset", 2),  # CoM admittance offset [m]
    ("offset_rate", 2),  # [m/s]
    ("ankle", 4),  # (2, 2) foot turns (roll, pitch) [rad]
    ("height", 1),  # height difference [m]
    ("feet", 4),  # (2, 2) estimated ankles in world (leg odometry) [m]
    ("landing", 4),  # (2, 2) landing corrections in world [m]
    ("landing_yaw", 2),  # [rad]
    ("anchor", 1),  # the reference sole of the odometry (0 left, 1 right)
    ("floor_normal", 3),  # filtered, in world
    ("sole_normals", 4),  # (2, 2) horizontal parts of each sole's normal in world, last tick
    ("landing_height", 2),  # height corrections of the swinging feet [m]
    ("lifted", 2),  # 1 once the swinging sole has carried no load in this single support
    ("airborne", 2),  # how long each sole has carried no load, up to this tick [s]
)

LOG_FIELDS: Fields = (  # what zmpwalk.balance.BalanceState shows (views into the log)
    ("zmp_desired", 2),
    ("zmp_measured", 2),
    ("dcm_error", 2),
    ("com_offset", 2),
    ("ankle_offsets", 4),  # (2, 2)
    ("height_difference", 1),
    ("pelvis_turn", 2),
    ("slope_offset", 2),
    ("whole_body_offset", 2),
)


def _offsets(name: str, fields: Fields) -> tuple[Any, int]:
    """The named tuple of each field's first index, and the table's length."""
    names = [field for field, _ in fields]  # a name given twice: namedtuple's ValueError
    starts = np.concatenate([[0], np.cumsum([size for _, size in fields])])
    table = namedtuple(name, names)  # type: ignore[misc]
    return table(*[int(i) for i in starts[:-1]]), int(starts[-1])


P, PARAMETERS = _offsets("Parameters", GAIN_FIELDS + ROBOT_CONSTANTS)
S, STATE_SIZE = _offsets("State", STATE_FIELDS)
L, LOG_SIZE = _offsets("Log", LOG_FIELDS)
LAYOUT_KEY = zlib.crc32(repr((P, S, L)).encode())  # changes with any name, size or order of the tables


def pack_parameters(gains: StabilizerGains, **constants: object) -> NDArray[np.float64]:
    """``params`` (:data:`PARAMETERS`): every gain's field by name, then each of :data:`ROBOT_CONSTANTS` from
    ``constants`` (a number, or an array of the field's size), by name; one named like a gain replaces it.

    Raises:
        InvalidParameterError: A constant is missing or unknown.
        ValueError: A constant is of the wrong size.
    """
    params = np.zeros(PARAMETERS)
    values: dict[str, object] = {name: getattr(gains, name) for name, _ in GAIN_FIELDS}
    names = dict(GAIN_FIELDS + ROBOT_CONSTANTS)
    unknown = set(constants) - set(names)
    missing = {name for name, _ in ROBOT_CONSTANTS} - set(constants)
    if unknown or missing:
        raise InvalidParameterError("constants", sorted(constants), f"each of the robot constants once (unknown: "
                                    f"{sorted(unknown)}, missing: {sorted(missing)})")
    values.update(constants)
    for name, size in names.items():
        at = getattr(P, name)
        params[at:at + size] = np.asarray(values[name], dtype=np.float64).reshape(size)
    return params


def initial_state(state: NDArray[np.float64], log: NDArray[np.float64]) -> None:
    """Reset ``state`` and ``log`` in place (the next tick starts from the reference)."""
    state[:] = 0.0
    state[S.floor_normal + 2] = 1.0
    log[:] = 0.0
    log[L.zmp_measured:L.zmp_measured + 2] = math.nan


def chain_table(chains: Sequence[LegChain]) -> NDArray[np.float64]:
    """The compiled leg's table (2, 6, 11) of both leg chains (:mod:`zmpwalk.stabilizer.leg`): per leg and chain
    joint its axis and a point on it in the base frame at zero angles [m], its link's CoM [m] and mass [kg], and
    its role-ordered column."""
    chain = np.empty((2, 6, 11))
    for leg, leg_chain in enumerate(chains):
        chain[leg, :, 0:3] = leg_chain.axes
        chain[leg, :, 3:6] = leg_chain.points
        chain[leg, :, 6:9] = leg_chain.link_coms
        chain[leg, :, 9] = leg_chain.link_masses
        chain[leg, :, 10] = np.argsort(np.asarray(leg_chain.role_order))  # chain joint -> role column
    return chain
