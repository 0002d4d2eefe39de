"""Atomic writes: a failed write leaves the old file as it was and no temporary behind."""

import pytest

from dtsp_mission.errors import FileAccessError
from dtsp_mission.files import write_atomic


def test_write_replaces_whole_file(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    write_atomic(target, "new content")
    assert target.read_text() == "new content"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_failed_write_leaves_nothing_half_written(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")

    with pytest.raises(TypeError):
        write_atomic(target, 12345)   # not text or bytes: fails after the temporary is made
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_missing_directory_is_a_clear_error(tmp_path):
    with pytest.raises(FileAccessError, match="does not exist"):
        write_atomic(tmp_path / "nope" / "out.txt", "x")
