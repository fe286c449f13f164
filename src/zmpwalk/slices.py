"""Work in bounded slices, for a control loop that must never wait long.

A computation written as a generator that yields between parts of bounded cost (``Parts[T]``, returning
``T``) can run whole (:func:`run_to_end`: the batch paths) or a few parts per control tick
(:class:`zmpwalk.online.OnlineWalker`), with the same code and the same result.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import TypeVar

T = TypeVar("T")
Parts = Generator[None, None, T]


def run_to_end(parts: Parts[T]) -> T:
    """Run every part of a sliced computation; its result."""
    while True:
        try:
            next(parts)
        except StopIteration as done:
            result: T = done.value
            return result
