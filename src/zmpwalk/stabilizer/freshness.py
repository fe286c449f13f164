"""Whether numba's disk cache of the compiled stabilizer is current, and its renewal where it is not.

numba renews a cached function only when its own source file changes; it keeps the constants it was compiled with
(the named offsets of :mod:`zmpwalk.stabilizer.layout`) and the code of the functions it calls from other modules.
So a gain added to :class:`~zmpwalk.stabilizer_gains.StabilizerGains`, or a loop changed in one module, would leave
the tick's cached code as it was. :data:`BUILD_KEY` fingerprints the layout and the sources of every compiled module
of the stabilizer; each module compiles it into its ``compiled_key()``, and :func:`renew_stale` recompiles every
function of the modules once any of them answers another key.
"""

from __future__ import annotations

import zlib
from pathlib import Path
from types import ModuleType

from numba.core.dispatcher import Dispatcher

from zmpwalk.stabilizer.layout import LAYOUT_KEY

_PACKAGE = Path(__file__).resolve().parent
SOURCES = (*sorted(_PACKAGE.glob("*.py")), _PACKAGE.parent / "balance_kernel.py",  # the compiled modules' files
           _PACKAGE.parent / "sides.py",  # the support codes they compare with
           _PACKAGE.parent / "leg_chain" / "numeric.py")  # and the IK's tolerances (whole_body_ik)


def _fingerprint() -> int:
    key = zlib.crc32(str(LAYOUT_KEY).encode())
    for path in SOURCES:
        try:
            key = zlib.crc32(path.read_bytes(), key)
        except OSError:  # a source that cannot be read: its name only
            key = zlib.crc32(path.name.encode(), key)
    return key


BUILD_KEY = _fingerprint()


def renew_stale(modules: tuple[ModuleType, ...]) -> bool:
    """Recompile every compiled function of ``modules`` (callees' modules first; each has a ``compiled_key()``)
    when one of them was built from other sources or another layout than :data:`BUILD_KEY`'s. Returns whether it
    recompiled."""
    if all(module.compiled_key() == BUILD_KEY for module in modules):
        return False
    for module in modules:
        for value in list(vars(module).values()):
            if isinstance(value, Dispatcher) and value.py_func.__module__ == module.__name__:
                value.recompile()
    return True
