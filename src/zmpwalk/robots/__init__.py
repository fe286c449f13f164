"""Built-in robots as data files, and the loader for them and for the user's own."""

from __future__ import annotations

from functools import cache
from importlib import resources
from pathlib import Path

from zmpwalk.errors import FileFormatError, InvalidParameterError, UnknownNameError
from zmpwalk.robots.model import JOINT_NAMES, RobotModel, robot_from_dict
from zmpwalk.robots.robot_file import robot_from_toml

__all__ = ["JOINT_NAMES", "MODEL_SUFFIXES", "RobotModel", "list_robots", "load_robot", "loaded_robot",
           "robot_from_dict"]


def _data_dir() -> Path:
    return Path(str(resources.files("zmpwalk.robots") / "data"))


def list_robots() -> list[str]:
    """Names of the built-in robots."""
    return sorted(path.stem for path in _data_dir().glob("*.toml"))


MODEL_SUFFIXES = (".xml", ".urdf")


def load_robot(name_or_path: str | Path, *, feet: tuple[str, str] | None = None, keyframe: str | None = None,
               package_paths: tuple[Path, ...] = (), ready_stretch: float | None = None) -> RobotModel:
    """Load a built-in robot by name (``"hubo"``), a robot file (``.toml``) or the robot's own model
    (MJCF ``.xml`` or URDF ``.urdf``, see :func:`zmpwalk.robots.imported.import_robot`) by path.

    Args:
        name_or_path: The name or the file.
        feet: Foot body names (left, right) of a model whose tree is ambiguous.
        keyframe: The model's keyframe of the reference pose (default: its first).
        package_paths: Folders holding the packages of a URDF's ``package://`` paths.
        ready_stretch: A robot's own model (or a robot file with ``[model]``) only: the ready posture's
            hip-to-ankle distance over the straight leg [-] instead of the keyframe's (what
            :func:`zmpwalk.ready_fit.fit_ready_posture` tries).

    Raises:
        UnknownNameError: Not a built-in name and not a file path.
        FileFormatError: No such file, or the file or model is malformed (names what is missing).
        InvalidParameterError: ``ready_stretch`` out of its range, or given for a box model or a robot file
            that sets its posture.
    """
    path = Path(name_or_path)
    if path.suffix.lower() in MODEL_SUFFIXES:
        from zmpwalk.robots.imported import import_robot

        overrides = None if ready_stretch is None else {"ready_stretch": ready_stretch}
        return import_robot(path, feet=feet, keyframe=keyframe, package_paths=package_paths, overrides=overrides)
    if path.suffix == ".toml":
        if not path.is_file():
            raise FileFormatError(str(path), "no such file")
        return robot_from_toml(path, ready_stretch)
    if ready_stretch is not None:
        raise InvalidParameterError("ready_stretch", ready_stretch, "None for a built-in box model (a robot's "
                                    "own model only)")
    builtin = _data_dir() / f"{name_or_path}.toml"
    if builtin.is_file():
        return robot_from_toml(builtin)
    raise UnknownNameError("robot", str(name_or_path), list_robots())


@cache
def loaded_robot(spec: str) -> RobotModel:
    """:func:`load_robot` of a name or path, loaded once per process (workers of a sweep or a tuning run load
    the robot themselves and reuse it)."""
    return load_robot(spec)
