"""Files zmpwalk reads from and writes for the user: one clear error for each bad file, no partial output.

Input files (steps, robot, schedule and motor files) are TOML in UTF-8; a UTF-8 byte-order mark is
accepted, and every number must fit a float (a 400-digit integer or ``1e400`` is refused, naming the field).

Output goes where the user points it, and nothing else is replaced:

- a new path or a regular file is written to a temporary file beside it and renamed onto it when complete,
  so an interrupted or failed write leaves no partial file; a new file's mode follows the umask
  (``0o666 & ~umask``), a replaced file keeps its mode;
- a symbolic link is followed: its target is written by these rules, and the link stays;
- anything else (a character device such as ``/dev/null`` or ``/dev/stdout``, a FIFO) is written through,
  in place: it is never replaced by a regular file.

A write that the system refuses or cuts short (a full disk, ``ENOSPC``; a read-only file system) raises one
:class:`~zmpwalk.errors.FileFormatError` naming the path and the reason.
"""

from __future__ import annotations

import codecs
import os
import stat
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
            valid TOML, nested too deeply, or a number beyond a float's range; the message names the file
            (and the field) and says what to do.
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
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise FileFormatError(source, f"not valid TOML: {error}") from None
    except RecursionError:
        raise FileFormatError(source, "is nested too deeply to be read (tables or arrays inside each other)") from None
    _check_numbers(data, "", source)
    return data


def _check_numbers(value: object, field: str, source: str) -> None:
    """Refuse an integer no float can hold, or a float literal beyond a float's range (``1e400`` reads as inf)."""
    if isinstance(value, dict):
        for key, item in value.items():
            _check_numbers(item, f"{field}.{key}" if field else str(key), source)
    elif isinstance(value, list):
        for index, item in enumerate(value):
            _check_numbers(item, f"{field}[{index}]", source)
    elif isinstance(value, int) and not isinstance(value, bool):
        try:
            float(value)
        except OverflowError:
            raise FileFormatError(source, f"{field} is an integer of {len(str(abs(value)))} digits, beyond a "
                                  "float's range (about 1.8e308): give a number of ordinary size") from None
    elif isinstance(value, float) and value in (float("inf"), float("-inf")):
        raise FileFormatError(source, f"{field} = {value} is beyond a float's range (about 1.8e308): give a "
                              "finite number")


def _umask() -> int:
    """The process's file-mode creation mask (read without changing it where /proc allows)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _cannot_write(path: Path, error: OSError) -> FileFormatError:
    return FileFormatError(str(path), f"cannot be written: {error.strerror or error}")


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """A path to write ``path``'s content to: a temporary file renamed onto a regular (or new) file when the
    block ends without error, or the target itself where it is a device or a FIFO (see the module docstring).

    Raises:
        FileFormatError: The folder does not exist, the path is a folder, or the system refuses or cuts short
            the write (a full disk included).
    """
    path = Path(path)
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    if target.is_dir():
        raise FileFormatError(str(path), "is a folder: give a file name to write")
    if target.exists() and not target.is_file():
        try:
            yield target  # a device or a FIFO: written through, never replaced
        except OSError as error:
            raise _cannot_write(path, error) from None
        return
    if not target.parent.is_dir():
        raise FileFormatError(str(path), f"cannot be written: the folder {path.parent} does not exist")
    mode = stat.S_IMODE(target.stat().st_mode) if target.exists() else 0o666 & ~_umask()
    try:
        handle, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    except OSError as error:
        raise _cannot_write(path, error) from None
    os.close(handle)
    temporary = Path(name)
    try:
        yield temporary
        _sync(temporary)
        os.chmod(temporary, mode)
        os.replace(temporary, target)
    except OSError as error:
        raise _cannot_write(path, error) from None
    finally:
        if temporary.exists():
            temporary.unlink()


def _sync(path: Path) -> None:
    """Flush ``path``'s data to the disk, so that a disk that cannot hold it says so before the rename."""
    descriptor = os.open(path, os.O_RDONLY)
    try:
        os.fsync(descriptor)
    finally:
        os.close(descriptor)


def write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` (see :func:`atomic_output`); a refused or short write raises."""
    with atomic_output(path) as output, output.open("wb") as handle:
        handle.write(data)


def write_text(path: str | Path, text: str) -> None:
    """Write UTF-8 ``text`` to ``path`` (see :func:`atomic_output`)."""
    write_bytes(path, text.encode("utf-8"))
