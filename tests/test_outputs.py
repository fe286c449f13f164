"""Output files: written where the user points, nothing else replaced, a refused write is one error."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from zmpwalk.errors import FileFormatError
from zmpwalk.files import atomic_output, read_toml, write_text


@pytest.fixture
def umask_022():
    previous = os.umask(0o022)
    yield
    os.umask(previous)


def test_a_new_file_follows_the_umask(tmp_path: Path, umask_022: None) -> None:
    write_text(tmp_path / "new.txt", "walk")
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o644
    os.umask(0o077)
    write_text(tmp_path / "private.txt", "walk")
    assert stat.S_IMODE((tmp_path / "private.txt").stat().st_mode) == 0o600


def test_a_replaced_file_keeps_its_mode_and_no_temporary_is_left(tmp_path: Path, umask_022: None) -> None:
    target = tmp_path / "pattern.csv"
    target.write_text("old")
    target.chmod(0o640)
    write_text(target, "new")
    assert target.read_text() == "new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pattern.csv"]


def test_a_symlink_stays_a_link_and_its_target_is_written(tmp_path: Path) -> None:
    target = tmp_path / "data" / "pattern.csv"
    target.parent.mkdir()
    target.write_text("old")
    link = tmp_path / "latest.csv"
    link.symlink_to(target)
    write_text(link, "new")
    assert link.is_symlink() and link.resolve() == target.resolve()
    assert target.read_text() == "new"
    dangling = tmp_path / "dangling.csv"
    dangling.symlink_to(tmp_path / "data" / "made.csv")
    write_text(dangling, "made")
    assert dangling.is_symlink() and (tmp_path / "data" / "made.csv").read_text() == "made"


@pytest.mark.skipif(not Path("/dev/null").exists(), reason="no /dev/null")
def test_a_character_device_is_written_through_not_replaced() -> None:
    before = os.stat("/dev/null")
    write_text("/dev/null", "x" * 100_000)
    after = os.stat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and after.st_rdev == before.st_rdev and after.st_ino == before.st_ino


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
def test_a_full_device_is_one_error_and_stays_a_device() -> None:
    with pytest.raises(FileFormatError, match=r"^/dev/full: cannot be written: No space left on device$"):
        write_text("/dev/full", "x" * 100_000)
    with pytest.raises(FileFormatError, match="No space left"), atomic_output("/dev/full") as output, \
            output.open("w", newline="") as handle:
        handle.write("time,x\n" * 10_000)
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


def test_a_fifo_is_written_through(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # a reader, so that the writer does not wait
    try:
        write_text(fifo, "walk")
        assert os.read(reader, 100) == b"walk"
    finally:
        os.close(reader)
    assert stat.S_ISFIFO(fifo.stat().st_mode)


def test_a_folder_or_a_missing_folder_is_refused(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match="is a folder"):
        write_text(tmp_path, "x")
    with pytest.raises(FileFormatError, match="does not exist"):
        write_text(tmp_path / "nowhere" / "x.csv", "x")


@pytest.mark.parametrize("text, field", [
    ("mass = " + "9" * 400, "mass"),
    ("[legs]\nthigh_length = -" + "1" * 310, "legs.thigh_length"),
    ("[[steps]]\nduration = 0.8\n[[steps]]\nforward = 1e400", "steps[1].forward"),
    ("[walking]\nrows = [[0.8, 0.1, -1e309]]", "walking.rows[0][2]"),
])
def test_a_number_beyond_a_float_is_one_error_naming_file_and_field(tmp_path: Path, text: str, field: str) -> None:
    path = tmp_path / "robot.toml"
    path.write_text(text)
    with pytest.raises(FileFormatError) as info:
        read_toml(path)
    message = str(info.value)
    assert message.startswith(f"{path}: {field} ") and "float's range" in message


def test_ordinary_numbers_and_nan_still_read(tmp_path: Path) -> None:
    path = tmp_path / "schedule.toml"
    path.write_text("rows = [[0.95, 0, 0.038, nan, 0.47]]\nbig = 123456789012345678901234567890\n")
    data = read_toml(path)
    assert data["rows"][0][2] == 0.038 and data["big"] == 123456789012345678901234567890


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full")
def test_the_command_line_on_a_full_device_exits_2_with_one_line() -> None:
    import subprocess
    import sys

    result = subprocess.run([sys.executable, "-m", "zmpwalk.cli", "plan", "--scenario", "fig10", "--out", "/dev/full"],
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].endswith("/dev/full: cannot be written: No space left on device")
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


def test_the_command_line_writes_through_a_symlink(tmp_path: Path) -> None:
    from zmpwalk.cli import main

    target = tmp_path / "fig10.csv"
    target.write_text("")
    link = tmp_path / "latest.csv"
    link.symlink_to(target)
    assert main(["plan", "--scenario", "fig10", "--out", str(link)]) == 0
    assert link.is_symlink() and target.read_text().startswith("t,support,")
