"""The simulation's ranges: a number inside is taken, anything else is one error naming the parameter."""

import pytest

from zmpwalk.errors import InvalidParameterError
from zmpwalk.sim.ranges import RANGES, check_range


@pytest.mark.parametrize("name", sorted(RANGES))
def test_each_range_takes_its_ends_and_refuses_beyond_and_non_numbers(name: str) -> None:
    low, high, allowed = RANGES[name]
    assert check_range(name, low) == low and check_range(name, high) == high
    for bad in (low - 1e-9, high * 1.000001 + 1e-9, "1", None, True, float("nan")):
        with pytest.raises(InvalidParameterError) as raised:
            check_range(name, bad)
        assert raised.value.parameter == name and allowed in str(raised.value)


def test_a_latency_is_whole_control_periods() -> None:
    """The sensors are read once a millisecond: 2 ms and 10 ms are delays, 2.5 ms is refused by name (the batch
    walk used to round it silently)."""
    assert check_range("latency", 0.002) == 0.002 and check_range("latency", 0.01) == 0.01
    with pytest.raises(InvalidParameterError, match=r"latency = 0\.0025"):
        check_range("latency", 0.0025)
