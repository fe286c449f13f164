"""Pattern generators: each turns step commands into the shared :class:`~zmpwalk.patterns.result.WalkingPattern`."""

from __future__ import annotations

from collections.abc import Callable

from zmpwalk.errors import UnknownNameError
from zmpwalk.patterns.result import WalkingPattern

Generator = Callable[..., WalkingPattern]
GENERATORS = ("polynomial", "hyperbolic", "preview")


def generator(name: str) -> Generator:
    """The generator called ``name``: ``generate(robot, commands, rate=..., labels=...)``.

    Raises:
        UnknownNameError: Lists the known generators.
    """
    from zmpwalk.patterns.lipm import generate_hyperbolic
    from zmpwalk.patterns.polynomial import generate
    from zmpwalk.patterns.preview import generate_preview

    known: dict[str, Generator] = {"polynomial": generate, "hyperbolic": generate_hyperbolic,
                                   "preview": generate_preview}
    if name not in known:
        raise UnknownNameError("generator", name, known)
    return known[name]


__all__ = ["GENERATORS", "Generator", "generator"]
