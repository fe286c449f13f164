"""The compiled stabilizer's parameters are packed from the gains by name: every field of StabilizerGains has its
place, a gain given to the stabilizer is the value its loop reads, and the robot constants go where the layout says."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from zmpwalk.balance import Stabilizer, StabilizerGains
from zmpwalk.errors import InvalidParameterError
from zmpwalk.robots import load_robot
from zmpwalk.stabilizer.layout import GAIN_FIELDS, PARAMETERS, ROBOT_CONSTANTS, P, pack_parameters


def test_every_gain_field_has_its_place_by_name() -> None:
    names = [f.name for f in dataclasses.fields(StabilizerGains)]
    assert [name for name, _ in GAIN_FIELDS] == names
    starts = [getattr(P, name) for name, _ in GAIN_FIELDS + ROBOT_CONSTANTS]
    sizes = [size for _, size in GAIN_FIELDS + ROBOT_CONSTANTS]
    assert starts == list(np.cumsum([0, *sizes[:-1]])) and starts[-1] + sizes[-1] == PARAMETERS


def test_the_stabilizer_packs_each_gain_where_its_loop_reads_it() -> None:
    robot = load_robot("hubo")
    values = {f.name: 0.5 + 0.01 * i for i, f in enumerate(dataclasses.fields(StabilizerGains))}
    gains = StabilizerGains(**values)
    stabilizer = Stabilizer(robot, 500.0, gains, com_reference="pelvis")
    for name, value in values.items():
        assert stabilizer._params[getattr(P, name)] == value, name
    assert stabilizer._params[P.dt] == 1.0 / 500.0
    assert np.array_equal(stabilizer._params[P.servo_gain:P.servo_gain + 12], stabilizer.servo_gain)
    whole_body = Stabilizer(robot, 500.0, gains, com_reference="whole_body")
    assert whole_body._params[P.whole_body_rest] == 0.0  # only against a pelvis point


def test_a_missing_or_unknown_robot_constant_is_rejected() -> None:
    constants: dict[str, object] = {name: np.zeros(size) for name, size in ROBOT_CONSTANTS}
    assert pack_parameters(StabilizerGains(), **constants).shape == (PARAMETERS,)
    with pytest.raises(InvalidParameterError, match="missing"):
        pack_parameters(StabilizerGains(), **{k: v for k, v in constants.items() if k != "dt"})
    with pytest.raises(InvalidParameterError, match="unknown"):
        pack_parameters(StabilizerGains(), **constants, wind=1.0)
