"""Steps files (TOML) and the built-in scenarios named after the paper's experiments.

A steps file is a list of tables ``[[steps]]`` with the fields of
:class:`~zmpwalk.commands.StepCommand` (``duration`` [s] required; ``forward``
[m], ``side`` [m], ``turn`` [rad], ``stop``, the shape-factor overrides) and an
optional ``repeat`` (how many times the step is taken). An optional top-level
``description`` says what the walk is::

    description = "three 20 cm steps"
    [[steps]]
    duration = 0.8
    forward = 0.2
    repeat = 3
"""

from __future__ import annotations

import tomllib
from dataclasses import fields
from importlib import resources
from pathlib import Path
from typing import Any

from zmpwalk.commands import StepCommand
from zmpwalk.errors import FileFormatError, UnknownNameError, ZmpwalkError
from zmpwalk.files import read_toml

_FIELDS = {item.name for item in fields(StepCommand)}
MAX_REPEAT = 100_000


def parse_steps(data: dict[str, Any], source: str) -> list[StepCommand]:
    """Step commands from a parsed steps file (``repeat`` expanded).

    Raises:
        FileFormatError: Naming the file, the step (1-based, as written) and the field.
    """
    return parse_steps_with_labels(data, source)[0]


def parse_steps_with_labels(data: dict[str, Any], source: str) -> tuple[list[StepCommand], list[str]]:
    """Step commands and, for each, how an error names it: by its ``[[steps]]`` table as the user counts them
    (from 1), ``[[steps]] 3`` or, for a table that repeats, ``[[steps]] 3, repeat 2 of 4``; an error in the
    file itself names the table the same way."""
    unknown = set(data) - {"steps", "description"}
    if unknown:
        raise FileFormatError(source, f"unknown top-level key {sorted(unknown)[0]!r}; expected [[steps]]")
    steps = data.get("steps")
    if not isinstance(steps, list) or not steps:
        raise FileFormatError(source, "no [[steps]] tables")
    commands: list[StepCommand] = []
    labels: list[str] = []
    for number, table in enumerate(steps, start=1):
        where = f"[[steps]] {number}"
        if not isinstance(table, dict):
            raise FileFormatError(source, f"{where}: expected a table")
        values = dict(table)
        repeat = values.pop("repeat", 1)
        if isinstance(repeat, bool) or not isinstance(repeat, int) or not 1 <= repeat <= MAX_REPEAT:
            raise FileFormatError(source, f"{where}: repeat = {repeat!r} must be a whole number in [1, {MAX_REPEAT}]")
        for key in values:
            if key not in _FIELDS:
                known = ", ".join(sorted(_FIELDS | {"repeat"}))
                raise FileFormatError(source, f"{where}: unknown field {key!r}; known: {known}")
        if "duration" not in values:
            raise FileFormatError(source, f"{where}: missing field 'duration' [s]")
        try:
            command = StepCommand(**values)
        except ZmpwalkError as error:
            raise FileFormatError(source, f"{where}: {error}") from None
        except TypeError as error:
            raise FileFormatError(source, f"{where}: {error}") from None
        for count in range(1, repeat + 1):
            commands.append(command)
            labels.append(where if repeat == 1 else f"{where}, repeat {count} of {repeat}")
    return commands, labels


def load_steps_file(path: str | Path) -> list[StepCommand]:
    """Read a steps file.

    Raises:
        FileFormatError: Unreadable, not TOML, or malformed steps.
    """
    return load_steps_file_with_labels(path)[0]


def load_steps_file_with_labels(path: str | Path) -> tuple[list[StepCommand], list[str]]:
    """Read a steps file: the commands and how errors name each (see :func:`parse_steps_with_labels`)."""
    path = Path(path)
    return parse_steps_with_labels(read_toml(path), str(path))


def _scenario_dir() -> Path:
    return Path(str(resources.files("zmpwalk") / "data" / "scenarios"))


def list_scenarios() -> dict[str, str]:
    """Built-in scenario names and their descriptions."""
    result = {}
    for path in sorted(_scenario_dir().glob("*.toml")):
        data = tomllib.loads(path.read_text(encoding="utf-8"))
        result[path.stem] = str(data.get("description", ""))
    return result


def load_scenario(name: str) -> list[StepCommand]:
    """Step commands of a built-in scenario.

    Raises:
        UnknownNameError: Lists the known scenarios.
    """
    return load_scenario_with_labels(name)[0]


def load_scenario_with_labels(name: str) -> tuple[list[StepCommand], list[str]]:
    """A built-in scenario's commands and how errors name each."""
    path = _scenario_dir() / f"{name}.toml"
    if not path.is_file():
        raise UnknownNameError("scenario", name, list_scenarios())
    return load_steps_file_with_labels(path)
