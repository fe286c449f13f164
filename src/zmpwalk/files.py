"""Files zmpwalk reads from and writes for the user: one clear error for each bad file, no partial output.

Input files (steps, robot, schedule and motor files) are TOML in UTF-8; a UTF-8 byte-order mark is
accepted. Output files are written to a temporary file beside the target and renamed onto it when
complete, so an interrupted or failed write leaves no partial file.
"""

from __future__ import annotations

import codecs
import os
import tempfile
import tomllib
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from zmpwalk.errors import FileFormatError


def read_toml(path: str | Path) -> dict[str, Any]:
    """The tables of a TOML file.

    Raises:
        FileFormatError: No such file, a folder, unreadable, not UTF-8 text (UTF-16, latin-1, binary), not
            valid TOML, or nested too deeply; the message names the file and says what to do.
    """
    path = Path(path)
    source = str(path)
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise FileFormatError(source, "no such file") from None
    except IsADirectoryError:
        raise FileFormatError(source, "is a folder, not a file") from None
    except OSError as error:
        raise FileFormatError(source, f"cannot be read: {error.strerror or error}") from None
    if raw.startswith(codecs.BOM_UTF8):
        raw = raw[len(codecs.BOM_UTF8):]
    elif raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        raise FileFormatError(source, "is UTF-16 text; zmpwalk reads UTF-8: save the file as UTF-8")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        raise FileFormatError(source, f"is not UTF-8 text (byte {error.start} is not UTF-8): save it as UTF-8 "
                              "text (a binary or latin-1 file cannot be read)") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise FileFormatError(source, f"not valid TOML: {error}") from None
    except RecursionError:
        raise FileFormatError(source, "is nested too deeply to be read (tables or arrays inside each other)") from None


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """A temporary path to write ``path``'s content to; renamed onto ``path`` when the block ends without error.

    Raises:
        FileFormatError: The folder does not exist, the path is a folder, or the disk refuses the write.
    """
    path = Path(path)
    if path.is_dir():
        raise FileFormatError(str(path), "is a folder: give a file name to write")
    if not path.parent.is_dir():
        raise FileFormatError(str(path), f"cannot be written: the folder {path.parent} does not exist")
    try:
        handle, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    except OSError as error:
        raise FileFormatError(str(path), f"cannot be written: {error.strerror or error}") from None
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        os.replace(temporary, path)
    except OSError as error:
        raise FileFormatError(str(path), f"cannot be written: {error.strerror or error}") from None
    finally:
        if temporary.exists():
            temporary.unlink()


def write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_output`)."""
    with atomic_output(path) as temporary:
        temporary.write_bytes(data)


def write_text(path: str | Path, text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` atomically (see :func:`atomic_output`)."""
    write_bytes(path, text.encode("utf-8"))
