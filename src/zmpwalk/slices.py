"""Work in bounded slices, for a control loop that must never wait long.

A computation written as a generator that yields between parts of bounded cost (``Parts[T]``, returning
``T``) can run whole (:func:`run_to_end`: the batch paths) or a few parts per control tick within a time
budget (:func:`run_for`: :class:`zmpwalk.online.OnlineWalker`), with the same code and the same result.
It yields None between parts, or :data:`ALONE` before a part known to be long (one that calls code not cut
into parts, such as the footstep planner), which :func:`run_for` begins only early in a call (within
:data:`LONG_PART_START` of its budget), else in the next one.
"""

from __future__ import annotations

import functools
import inspect
import time
from collections.abc import Callable, Generator
from typing import Any, ParamSpec, TypeVar

T = TypeVar("T")
P = ParamSpec("P")
ALONE = "alone"  # yielded before a long part: run_for begins it only early in a call
LONG_PART_START = 0.25  # [-] of its budget: run_for begins a part marked ALONE only before this much is spent
Parts = Generator[Any, None, T]  # yields None (or ALONE) between parts, returns T


def run_to_end(parts: Parts[T]) -> T:
    """Run every part of a sliced computation; its result."""
    while True:
        try:
            next(parts)
        except StopIteration as done:
            result: T = done.value
            return result


UNFINISHED = object()  # what :func:`run_for` returns while the computation has parts left


def run_for(parts: Parts[T], budget: float, quota: int = 1, clock: Callable[[], float] = time.perf_counter,
            cap: float | None = None) -> tuple[T | object, int]:
    """Run parts of a sliced computation within ``budget`` [s] of ``clock``: one, then more while the next one,
    taken as long as the mean of those run so far, ends within ``budget``, or (up to ``quota`` parts) while
    ``budget`` is not spent, or, given a ``cap`` [s] (above ``budget``), while the next one is expected to end
    within ``cap`` (a computation behind its pace catches up, within the cap). No part begins
    after ``budget`` (or ``cap``) is spent, so the time taken is bounded by it and one part, whatever the
    computation; a part marked :data:`ALONE` begins only while at most :data:`LONG_PART_START` of ``budget`` is
    spent (so it begins the next call instead of ending this one).

    Returns:
        Its result (:data:`UNFINISHED` while it has parts left), and the number of parts run.
    """
    begin = clock()
    count = 0
    limit = budget if cap is None else max(cap, budget)
    while True:
        try:
            mark = next(parts)
        except StopIteration as done:
            result: T = done.value
            return result, count + 1
        count += 1
        elapsed = clock() - begin
        expected = elapsed * (count + 1) / count  # when the next part would end
        if count >= quota:
            stop = elapsed >= budget or expected > budget
        else:  # its share: while the budget is not spent, or the next part ends within the cap
            stop = elapsed >= limit or (elapsed >= budget and expected > limit)
        if stop or (mark is ALONE and elapsed > LONG_PART_START * budget):
            return UNFINISHED, count


class CountingClock:
    """A clock that advances ``step`` [s] at every reading: a time budget read with it counts parts (:func:`run_for`
    reads it once before the first part and once after each), the same on every machine and under any load. For
    simulations, whose results must not depend on how busy the machine running them is. It counts its readings
    in an integer, so its time is the count times ``step`` however long it has run.

    Args:
        step: [s] per reading.
    """

    def __init__(self, step: float) -> None:
        self.step = float(step)
        self.readings = 0

    def __call__(self) -> float:
        self.readings += 1
        return self.readings * self.step


def whole(parts: Callable[P, Parts[T]], name: str) -> Callable[P, T]:
    """The function ``name`` that runs a sliced computation to its end, with the same arguments and docstring."""
    @functools.wraps(parts)
    def run(*args: P.args, **kwargs: P.kwargs) -> T:
        return run_to_end(parts(*args, **kwargs))

    run.__name__ = run.__qualname__ = name
    run.__signature__ = inspect.signature(parts).replace(  # type: ignore[attr-defined]
        return_annotation=inspect.Signature.empty)
    return run
