"""Robot files (``.toml``): a box model's own description (:func:`zmpwalk.robots.model.robot_from_dict`), or a
``[model]`` table naming the robot's own MJCF or URDF with what the file adds to it (written by
``zmpwalk robot --write``): posture and walking overrides (``[walking] generator`` among them: the pattern generator
the robot walks with by default), the joint PD layer's gains (``[pd]``) and tuned
stabilizer gains (``[stabilizer]``), which every robot file may carry."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import Any

from zmpwalk.errors import FileFormatError, InvalidParameterError
from zmpwalk.files import read_toml
from zmpwalk.robots.imported import import_robot
from zmpwalk.robots.model import RobotModel, checked_generator, robot_from_dict, stabilizer_gains
from zmpwalk.robots.pd import check_load_stiffness
from zmpwalk.robots.posture import check_stretch, posture_set_by


def robot_from_toml(path: Path, ready_stretch: float | None = None) -> RobotModel:
    """Read a robot data file.

    Args:
        path: The file.
        ready_stretch: A file with ``[model]`` that does not set its posture (``[posture]``): the ready posture's
            hip-to-ankle distance over the straight leg [-]; None: the file's or the keyframe's.

    Raises:
        FileFormatError: Missing, unknown or out-of-range fields (names the field).
        InvalidParameterError: ``ready_stretch`` given for a box model (no ``[model]``) or a file that sets the
            posture.
    """
    data = read_toml(path)
    if "model" in data:
        return _robot_from_model_table(data, path, ready_stretch)
    if ready_stretch is not None:
        raise InvalidParameterError("ready_stretch", ready_stretch, "None for a box model (a robot file with "
                                    "[model] only)")
    return robot_from_dict(data, str(path))


_MODEL_OVERRIDES = {"posture": ("pelvis_height", "ready_stretch"),
                    "walking": ("dsp_time", "foot_lift", "lateral_velocity", "foot_speed_limit",
                                "foot_acceleration_limit", "sole_roll_limit")}


def _robot_from_model_table(data: dict[str, Any], path: Path, ready_stretch: float | None) -> RobotModel:
    """A robot file whose ``[model]`` names the robot's own MJCF or URDF (written by ``zmpwalk robot --write``)."""
    source = str(path)
    table = data["model"]
    known = {"file", "feet", "keyframe", "package_paths", "name"}
    if not isinstance(table, dict) or "file" not in table or set(table) - known:
        raise FileFormatError(source, f"[model] needs file = \"MODEL.xml\" and may have: {', '.join(sorted(known))}")
    feet = table.get("feet")
    if feet is not None and (not isinstance(feet, list) or len(feet) != 2 or not all(isinstance(f, str) for f in feet)):
        raise FileFormatError(source, "[model] feet must be two body names: [left, right]")
    overrides: dict[str, float] = {}
    generator = None
    for section, names in _MODEL_OVERRIDES.items():
        values = data.get(section, {})
        if not isinstance(values, dict):
            raise FileFormatError(source, f"[{section}] must be a table")
        for key, value in values.items():
            if section == "walking" and key == "generator":  # a name, not a number: kept on the model as it is
                generator = checked_generator(value, source)
                continue
            if key not in names:
                raise FileFormatError(source, f"[{section}] unknown field {key!r} for a model robot; known: "
                                      f"{', '.join((*names, 'generator') if section == 'walking' else names)}")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0:
                raise FileFormatError(source, f"[{section}] {key} = {value!r} must be a number > 0")
            overrides[key] = float(value)
    unknown = set(data) - {"model", "pd", "stabilizer", *_MODEL_OVERRIDES}
    if unknown:
        raise FileFormatError(source, f"unknown table(s) {', '.join(sorted(unknown))} in a robot file with [model]")
    packages = tuple(path.parent / str(p) for p in table.get("package_paths", []))
    gains = stabilizer_gains(data.get("stabilizer"), source)
    pd_gains, load_stiffness = _pd_table(data.get("pd"), source)
    if load_stiffness is not None:
        overrides["load_stiffness"] = load_stiffness
    try:
        given = posture_set_by(overrides)
    except InvalidParameterError:
        raise FileFormatError(source, "[posture] ready_stretch and pelvis_height both set the ready posture; give "
                              "one of them") from None
    if ready_stretch is not None:
        ready_stretch = check_stretch(ready_stretch)  # the argument's error, not the file's
        if given:
            raise InvalidParameterError("ready_stretch", ready_stretch, f"None: {source} sets the ready posture "
                                        f"([posture] {given})")
        overrides["ready_stretch"] = ready_stretch
    try:
        robot = import_robot(path.parent / str(table["file"]), feet=(feet[0], feet[1]) if feet else None,
                             keyframe=table.get("keyframe"), package_paths=packages, name=table.get("name"),
                             overrides=overrides, pd_gains=pd_gains)
    except InvalidParameterError as error:
        section = "posture" if error.parameter == "ready_stretch" else "pd"
        raise FileFormatError(source, f"[{section}] {error}") from None
    if gains:
        robot = replace(robot, stabilizer_gains=gains)
    return robot if generator is None else replace(robot, generator=generator)


def _pd_table(table: object, source: str) -> tuple[dict[str, tuple[float, float | None]], float | None]:
    """The ``[pd]`` table of a model robot file: the joint PD layer's gains per model joint,
    ``JOINT = {kp = [N m/rad], kv = [N m s/rad]}`` (``kv`` may be left out: critical damping), and the rule's
    ``load_stiffness = kappa`` for the joints it does not name (None where not given)."""
    if table is None:
        return {}, None
    if not isinstance(table, dict):
        raise FileFormatError(source, "[pd] must be a table: JOINT = {kp = N m/rad, kv = N m s/rad}")
    gains: dict[str, tuple[float, float | None]] = {}
    load_stiffness = None
    if "load_stiffness" in table and not isinstance(table["load_stiffness"], dict):  # a table: a joint of that name
        try:
            load_stiffness = check_load_stiffness(table["load_stiffness"])
        except InvalidParameterError as error:
            raise FileFormatError(source, f"[pd] {error}") from None
    for joint, entry in table.items():
        if joint == "load_stiffness" and load_stiffness is not None:
            continue
        if not isinstance(entry, dict) or "kp" not in entry or set(entry) - {"kp", "kv"}:
            raise FileFormatError(source, f"[pd] {joint} must be {{kp = N m/rad, kv = N m s/rad}} (kv may be left "
                                  "out: critical damping)")
        values: list[float | None] = []
        for key in ("kp", "kv"):
            value = entry.get(key)
            if value is None:
                values.append(None)
            elif isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or not value > 0:
                raise FileFormatError(source, f"[pd] {joint} {key} = {value!r} must be a finite number > 0")
            else:
                values.append(float(value))
        kp = values[0]
        if kp is None:  # pragma: no cover - "kp" is required above
            raise FileFormatError(source, f"[pd] {joint} needs kp")
        gains[str(joint)] = (kp, values[1])
    return gains, load_stiffness
