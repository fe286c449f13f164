"""The kernels compiled when the package is built (setup.py): the compile step of the build, run on a copy of the
package, leaves numba's cache in the package's ``__pycache__`` folders, and a second copy of that folder (new file
times, as an installed wheel's) loads every kernel from it without compiling anything."""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _compile_code() -> str:
    """setup.py's ``COMPILE``: the code its build step runs from the build folder."""
    tree = ast.parse((ROOT / "setup.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "COMPILE" for t in node.targets):
            return str(ast.literal_eval(node.value))
    raise AssertionError("setup.py has no COMPILE")


def _run(code: str, package_root: Path) -> str:
    env = {key: value for key, value in os.environ.items() if key not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    env.update(PYTHONPATH=str(package_root), NUMBA_DEBUG_CACHE="1", PYTHONDONTWRITEBYTECODE="1")
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600,
                          check=True, cwd=package_root)
    return done.stdout + done.stderr


@pytest.mark.slow
def test_the_build_compiles_into_the_package_and_a_copy_loads_without_compiling(tmp_path: Path) -> None:
    build = tmp_path / "build"
    shutil.copytree(ROOT / "src" / "zmpwalk", build / "zmpwalk",
                    ignore=shutil.ignore_patterns("__pycache__"))
    first = _run(_compile_code(), build)
    assert "data saved to" in first  # compiled, into the copy
    cached = sorted(p.name for p in (build / "zmpwalk").rglob("*.nbi"))
    assert any(name.startswith("balance_kernel.tick-") for name in cached)
    assert any(name.startswith("whole_body_ik.base_under_com") for name in cached)
    assert any(name.startswith("whole_body_ik.joint_rates") for name in cached)
    installed = tmp_path / "installed"
    shutil.copytree(build, installed, copy_function=shutil.copy)  # new file times, as a wheel's install gives
    second = _run(_compile_code(), installed)
    assert "data saved to" not in second  # nothing compiled
    assert "data loaded from" in second and str(installed) in second
