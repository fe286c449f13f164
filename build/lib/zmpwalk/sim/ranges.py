"""What a simulated walk accepts for its settle, hold, sensor latency and mass scale: one table, one check,
read by :func:`zmpwalk.sim.run.simulate`, :func:`zmpwalk.sim.loop.simulate_controller` and
:class:`zmpwalk.walk.WalkSpec`."""

from __future__ import annotations

import numbers

from zmpwalk.errors import InvalidParameterError

CONTROL_RATE = 1000.0  # [Hz] the simulated walks' control rate: servo references and measurements

RANGES: dict[str, tuple[float, float, str]] = {  # name: lowest, highest, the allowed values in words
    "settle": (0.0, 10.0, "a time in [0, 10] s"),  # [s] standing before the walk
    "hold": (0.0, 60.0, "a time in [0, 60] s"),  # [s] standing after the walk
    "latency": (0.0, 0.1, "a delay in [0, 0.1] s, a whole number of 1 ms control periods"),  # [s] of the sensors
    "mass_scale": (0.01, 100.0, "a value in [0.01, 100]"),  # [-] of every mass and inertia
}


def check_range(name: str, value: object) -> float:
    """``value`` as a float where it is a number within :data:`RANGES` ``[name]``.

    Raises:
        InvalidParameterError: Anything else (names the parameter, its value and the range).
    """
    low, high, allowed = RANGES[name]
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not low <= float(value) <= high:
        raise InvalidParameterError(name, value, allowed)
    if name == "latency" and abs(float(value) * CONTROL_RATE - round(float(value) * CONTROL_RATE)) > 1e-6:
        raise InvalidParameterError(name, value, allowed)  # the sensors are read once a control period
    return float(value)
