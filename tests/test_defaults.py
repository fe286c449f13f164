"""The default pattern generator per robot: a robot built from its own model walks with the
generator that passed every measured walk (bench/bench_defaults.py, docs/design-log/defaults.md), the box models
keep the papers' polynomial pattern, a robot file may choose, and ``--generator`` always wins."""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pytest

from zmpwalk.cli import main
from zmpwalk.errors import FileFormatError
from zmpwalk.files import read_toml
from zmpwalk.patterns import GENERATORS
from zmpwalk.robots import load_robot, robot_from_dict
from zmpwalk.robots.model import BOX_MODEL_GENERATOR, GENERATOR_NAMES, OWN_MODEL_GENERATOR

ROBOTS = Path(__file__).resolve().parents[2] / "shared" / "robots"
T1 = ROBOTS / "booster_t1" / "scene.xml"
N1 = ROBOTS / "fourier_n1" / "scene.xml"
needs_robots = pytest.mark.skipif(not T1.is_file() or not N1.is_file(), reason="../shared/robots is absent")
TURN = Path(__file__).resolve().parents[1] / "examples" / "steps_turn_15deg.toml"


def _hubo_data() -> dict[str, object]:
    return read_toml(Path(str(resources.files("zmpwalk") / "robots" / "data" / "hubo.toml")))


def _plan_generator(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    """The generator ``zmpwalk plan ... --json`` ran."""
    assert main(["plan", *argv, "--rate", "100", "--allow-outside", "--json"]) == 0
    return str(json.loads(capsys.readouterr().out)["generator"])


def test_the_robots_list_of_generators_is_the_patterns():
    assert GENERATOR_NAMES == GENERATORS  # robots/ keeps the names without importing patterns/
    assert (OWN_MODEL_GENERATOR, BOX_MODEL_GENERATOR) == ("hyperbolic", "polynomial")


@pytest.mark.parametrize("name", ["hubo", "mju-biped"])
def test_box_models_keep_the_polynomial_pattern(capsys, name):
    assert load_robot(name).default_generator == "polynomial"
    assert _plan_generator(capsys, "--robot", name, "--scenario", "fig30") == "polynomial"
    assert _plan_generator(capsys, "--robot", name, "--scenario", "fig30", "--generator", "hyperbolic") == "hyperbolic"


def test_a_box_robot_file_chooses_its_generator(tmp_path):
    data = _hubo_data()
    data["walking"] = {**data["walking"], "generator": "hyperbolic"}  # type: ignore[dict-item]
    assert robot_from_dict(data).default_generator == "hyperbolic"
    data["walking"] = {**data["walking"], "generator": "lipm"}  # type: ignore[dict-item]
    with pytest.raises(FileFormatError, match=r"\[walking\] unknown generator 'lipm'; known: hyperbolic, "
                       "polynomial, preview"):
        robot_from_dict(data, "hubo_copy.toml")


@needs_robots
def test_a_robot_from_its_own_model_walks_with_hyperbolic_unless_told(tmp_path, capsys):
    assert load_robot(T1).default_generator == "hyperbolic"
    assert _plan_generator(capsys, "--robot", str(T1), str(TURN)) == "hyperbolic"
    assert _plan_generator(capsys, "--robot", str(T1), str(TURN), "--generator", "polynomial") == "polynomial"
    assert main(["plan", "--robot", str(T1), str(TURN), "--rate", "100"]) == 0
    assert "generator: hyperbolic (the default for a robot's own model; --generator to choose)" in \
        capsys.readouterr().out
    # the polynomial pattern's cubic or quintic pelvis is its own option: asked of the default, the error says how
    assert main(["plan", "--robot", str(T1), str(TURN), "--pelvis", "quintic"]) == 2
    assert "default generator is hyperbolic: give --generator polynomial" in capsys.readouterr().err


@needs_robots
def test_a_model_robot_file_overrides_the_default_and_the_command_line_wins(tmp_path, capsys):
    robot_file = tmp_path / "t1.toml"
    robot_file.write_text(f'[model]\nfile = "{T1.as_posix()}"\n\n[walking]\ngenerator = "polynomial"\n'
                          "dsp_time = 0.1\n")
    robot = load_robot(robot_file)
    assert (robot.default_generator, robot.dsp_time) == ("polynomial", 0.1)  # the other overrides still read
    assert _plan_generator(capsys, "--robot", str(robot_file), str(TURN)) == "polynomial"
    assert _plan_generator(capsys, "--robot", str(robot_file), str(TURN), "--generator", "preview") == "preview"
    assert main(["plan", "--robot", str(robot_file), str(TURN), "--rate", "100", "--allow-outside"]) == 0
    assert "generator: polynomial (the robot file's [walking] generator" in capsys.readouterr().out
    robot_file.write_text(f'[model]\nfile = "{T1.as_posix()}"\n\n[walking]\ngenerator = "zmp"\n')
    with pytest.raises(FileFormatError, match="unknown generator 'zmp'; known: hyperbolic, polynomial, preview"):
        load_robot(robot_file)


@pytest.mark.slow
@needs_robots
def test_an_imported_robot_walks_with_the_defaults(tmp_path, capsys):
    """Fourier N1, 3 x 10 cm at 0.8 s, nothing but the defaults: it passes (with the polynomial pattern on HUBO's
    tables its plan leaves the soles by 31.7 mm and the walk fails, docs/design-log/defaults.md)."""
    steps = tmp_path / "steps.toml"
    steps.write_text("[[steps]]\nduration = 0.8\nforward = 0.1\nrepeat = 3\n")
    assert main(["simulate", "--robot", str(N1), str(steps), "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["generator"] == "hyperbolic"
    assert summary["verdict"]["passed"] and not summary["fell"]
    assert summary["plan_min_zmp_margin"] == pytest.approx(0.0291, abs=1e-3)  # the plan alone: measured 29.1 mm
    assert summary["final_feet_error"] <= 0.020  # the verdict's limit (measured 5.2 mm)
    assert summary["cop_error_rms"] <= 0.020  # measured 14.5 mm; the polynomial pattern's 46.9 mm
