"""Work in bounded slices, for a control loop that must never wait long.

A computation written as a generator that yields between parts of bounded cost (``Parts[T]``, returning
``T``) can run whole (:func:`run_to_end`: the batch paths) or a few parts per control tick
(:class:`zmpwalk.online.OnlineWalker`), with the same code and the same result.
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Generator
from typing import ParamSpec, TypeVar

T = TypeVar("T")
P = ParamSpec("P")
Parts = Generator[None, None, T]


def run_to_end(parts: Parts[T]) -> T:
    """Run every part of a sliced computation; its result."""
    while True:
        try:
            next(parts)
        except StopIteration as done:
            result: T = done.value
            return result


def whole(parts: Callable[P, Parts[T]], name: str) -> Callable[P, T]:
    """The function ``name`` that runs a sliced computation to its end, with the same arguments and docstring."""
    @functools.wraps(parts)
    def run(*args: P.args, **kwargs: P.kwargs) -> T:
        return run_to_end(parts(*args, **kwargs))

    run.__name__ = run.__qualname__ = name
    run.__signature__ = inspect.signature(parts).replace(  # type: ignore[attr-defined]
        return_annotation=inspect.Signature.empty)
    return run
