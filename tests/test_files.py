"""Atomic writes: a failed write leaves the old file as it was and no temporary behind."""

import pytest

from dtsp_mission.errors import FileAccessError
from dtsp_mission.files import write_atomic, write_together


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


def test_outputs_written_together_or_not_at_all(tmp_path):
    first, second = tmp_path / "a.plan", tmp_path / "b.waypoints"
    first.write_text("old a")
    with pytest.raises(FileAccessError, match="does not exist"):
        write_together([(first, "new a"), (tmp_path / "nope" / "c.json", "c")])
    assert first.read_text() == "old a"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.plan"]

    def upload_fails():
        raise ConnectionError("no vehicle")
    with pytest.raises(ConnectionError):
        write_together([(first, "new a"), (second, "b")], before_commit=upload_fails)
    assert first.read_text() == "old a" and not second.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.plan"]

    committed = []
    write_together([(first, "new a"), (second, b"b")],
                   before_commit=lambda: committed.append(first.read_text()))
    assert committed == ["old a"]           # the upload ran before any file changed
    assert first.read_text() == "new a" and second.read_bytes() == b"b"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.plan", "b.waypoints"]
