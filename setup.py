"""Packaging: everything is in pyproject.toml but one step, the compiled kernels built with the package.

``pip install .`` builds the wheel on the machine it installs on, so the stabilizer's tick
(:mod:`zmpwalk.balance_kernel`) and an imported robot's legs (:mod:`zmpwalk.stabilizer.whole_body_ik`), both
numba, are compiled there, once, into the package's own ``__pycache__`` folders, which the wheel carries: the first
walk after the install loads them (under a second) instead of compiling them (10-20 s each on two cores). numba
(0.68 on) checks each cached function against its source's content, its own version and the CPU it runs on, and
compiles again where any of them differs (a wheel moved to another machine, a numba upgraded since), so the step
only saves time. numba reads a cache only from a folder it may write to: an install the user cannot write to
compiles at first use, into numba's cache in the user's home. The step is skipped for editable installs (the
source tree's caches are filled on first use) and where ``ZMPWALK_NO_PRECOMPILE`` is set; a failure leaves the
wheel as it was (the first walk compiles).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

# the stabilizer's tick (compiled on import: it has a signature) and an imported robot's legs (compiled for the
# types a fill gives them)
COMPILE = "import zmpwalk.balance_kernel; from zmpwalk.whole_body import compile_kernel; compile_kernel()"


class BuildPyCompiled(build_py):
    """``build_py``, then the kernels compiled from the build folder, filling its numba caches."""

    def run(self) -> None:
        super().run()
        if self.editable_mode or os.environ.get("ZMPWALK_NO_PRECOMPILE") or self.dry_run:
            return
        build_lib = Path(self.build_lib).resolve()
        for stale in [*build_lib.rglob("*.nbi"), *build_lib.rglob("*.nbc")]:  # a build folder used before
            stale.unlink()
        env = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}  # next to the sources
        # the build folder first, then the PYTHONPATH pip's isolated build environment gives (numba, numpy); no .pyc
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(build_lib), os.environ.get("PYTHONPATH")]))
        env["PYTHONDONTWRITEBYTECODE"] = "1"
        self.announce("compiling the stabilizer and the legs' kernel (numba), once for this machine", level=2)
        try:
            subprocess.run([sys.executable, "-c", COMPILE], env=env, check=True, timeout=600)
        except (OSError, subprocess.SubprocessError) as error:
            self.warn(f"the kernels were not compiled ahead ({error}); the first walk compiles them")


setup(cmdclass={"build_py": BuildPyCompiled})
