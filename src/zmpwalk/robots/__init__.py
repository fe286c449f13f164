"""Built-in robots as data files, and the loader for them and for the user's own."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from zmpwalk.errors import UnknownNameError
from zmpwalk.robots.model import JOINT_NAMES, RobotModel, robot_from_dict, robot_from_toml

__all__ = ["JOINT_NAMES", "RobotModel", "list_robots", "load_robot", "robot_from_dict"]


def _data_dir() -> Path:
    return Path(str(resources.files("zmpwalk.robots") / "data"))


def list_robots() -> list[str]:
    """Names of the built-in robots."""
    return sorted(path.stem for path in _data_dir().glob("*.toml"))


def load_robot(name_or_path: str | Path) -> RobotModel:
    """Load a built-in robot by name (``"hubo"``) or a robot file by path.

    Raises:
        UnknownNameError: Not a built-in name and not an existing file.
        FileFormatError: The file is malformed.
    """
    path = Path(name_or_path)
    if path.suffix == ".toml" and path.is_file():
        return robot_from_toml(path)
    builtin = _data_dir() / f"{name_or_path}.toml"
    if builtin.is_file():
        return robot_from_toml(builtin)
    raise UnknownNameError("robot", str(name_or_path), list_robots())
