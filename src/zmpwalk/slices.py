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
COST_DECAY = 0.75  # [-] a part's remembered cost falls to this share of itself at each shorter run of it
LONGEST_CALL = 2.0  # [-] of its budget: with costs, run_for begins no part expected to end after this, but its first


def next_site(parts: Parts[Any]) -> tuple[object, int]:
    """Where a sliced computation stands between two parts (its innermost generator's code and instruction): the
    part it runs next."""
    generator: Any = parts
    while True:
        inner = generator.gi_yieldfrom
        if inner is None or not hasattr(inner, "gi_yieldfrom"):
            break
        generator = inner
    frame = generator.gi_frame
    return (None, -1) if frame is None else (frame.f_code, frame.f_lasti)


def run_for(parts: Parts[T], budget: float, quota: int = 1,
            clock: Callable[[], float] = time.perf_counter, costs: dict[tuple[object, int], float] | None = None,
            ) -> tuple[T | object, int]:
    """Run parts of a sliced computation within ``budget`` [s] of ``clock``: one, then more while the next one,
    taken as long as the mean of those run so far, ends within ``budget``, or (up to ``quota`` parts) while
    ``budget`` is not spent. No part begins after ``budget`` is spent, so the time taken is bounded by
    ``budget`` and one part, whatever the computation; a part marked :data:`ALONE` begins only while at most
    :data:`LONG_PART_START` of ``budget`` is spent (so it begins the next call instead of ending this one).

    With ``costs`` (kept by the caller from call to call) the time [s] each part (:func:`next_site`) last took is
    remembered, the longest of its recent runs (an older, longer one weighs :data:`COST_DECAY` less at each
    shorter run), and a part expected to end after :data:`LONGEST_CALL` times ``budget`` begins the next call
    instead: a long part runs first in a call, not after the budget's worth of shorter ones, so that a call takes
    at most about the longer of that and the longest part.

    Returns:
        Its result (:data:`UNFINISHED` while it has parts left), and the number of parts run.
    """
    begin = clock()
    count = 0
    site = next_site(parts) if costs is not None else (None, -1)
    last = begin
    while True:
        try:
            mark = next(parts)
        except StopIteration as done:
            result: T = done.value
            return result, count + 1
        count += 1
        now = clock()
        elapsed = now - begin
        if costs is not None:
            taken = now - last
            costs[site] = max(taken, COST_DECAY * costs.get(site, 0.0))
            site, last = next_site(parts), now
            if elapsed + costs.get(site, 0.0) > LONGEST_CALL * budget:
                return UNFINISHED, count
        if elapsed >= budget or (count >= quota and elapsed * (count + 1) > budget * count) or (
                mark is ALONE and elapsed > LONG_PART_START * budget):
            return UNFINISHED, count


def whole(parts: Callable[P, Parts[T]], name: str) -> Callable[P, T]:
    """The function ``name`` that runs a sliced computation to its end, with the same arguments and docstring."""
    @functools.wraps(parts)
    def run(*args: P.args, **kwargs: P.kwargs) -> T:
        return run_to_end(parts(*args, **kwargs))

    run.__name__ = run.__qualname__ = name
    run.__signature__ = inspect.signature(parts).replace(  # type: ignore[attr-defined]
        return_annotation=inspect.Signature.empty)
    return run
