"""Reading and writing files with clear errors; every write is atomic.

An output file is either written completely or not touched at all: content goes to a temporary
file in the same directory, is flushed to disk, and replaces the target in one rename.  Several
outputs are staged together and renamed only when every one is on disk (:func:`write_together`).
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path
from typing import Callable, Sequence

from .errors import FileAccessError


#: The path that stands for standard input (as for most command-line tools).
STDIN = "-"


def read_bytes(path: str | os.PathLike) -> bytes:
    """The file's bytes (``-``: all of standard input), or :class:`FileAccessError` saying why
    not."""
    if str(path) == STDIN:
        import sys
        return sys.stdin.buffer.read()
    path = Path(path)
    try:
        return path.read_bytes()
    except FileNotFoundError:
        raise FileAccessError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise FileAccessError(f"{path}: is a directory, not a file") from None
    except PermissionError:
        raise FileAccessError(f"{path}: permission denied") from None
    except OSError as error:
        raise FileAccessError(f"{path}: cannot be read ({error.strerror})") from None


def read_text(path: str | os.PathLike) -> str:
    """The file's text (UTF-8, BOM accepted), or :class:`FileAccessError` saying why not."""
    try:
        return read_bytes(path).decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise FileAccessError(f"{path}: not a UTF-8 text file ({error.reason} at byte "
                              f"{error.start})") from None


def parse_json(text: str, where: str):
    """The JSON document in ``text``, or :class:`FileFormatError` naming ``where``: not JSON
    (line and column), or nested deeper than any file this reads (Python's parser recurses)."""
    import json
    from .errors import FileFormatError
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise FileFormatError(f"{where}: not valid JSON ({error.msg} at line {error.lineno}, "
                              f"column {error.colno})") from None
    except RecursionError:
        raise FileFormatError(f"{where}: JSON nested too deep to be a targets, tour or plan "
                              "file") from None


def read_json(path: str | os.PathLike):
    """The JSON document in the file (:func:`read_text`, :func:`parse_json`)."""
    return parse_json(read_text(path), str(path))


def check_replaceable(path: str | os.PathLike) -> None:
    """:class:`FileAccessError` unless ``path`` is absent or a regular file (an output never
    replaces a device, a FIFO, a socket or a folder)."""
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        return
    except OSError as error:
        raise FileAccessError(f"{path}: cannot be checked ({error.strerror})") from None
    if not stat.S_ISREG(mode):
        kind = ("a folder" if stat.S_ISDIR(mode) else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
                else "a FIFO" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode)
                else "not a regular file")
        raise FileAccessError(f"{path} is {kind}: outputs only replace regular files")


def write_atomic(path: str | os.PathLike, content: str | bytes) -> Path:
    """Write ``content`` to ``path`` so that readers see the old file or the whole new one."""
    return write_together([(path, content)])[0]


def write_together(outputs: Sequence[tuple[str | os.PathLike, str | bytes]],
                   before_commit: Callable[[], None] | None = None,
                   remove: Sequence[str | os.PathLike] = ()) -> list[Path]:
    """Write every output or none.

    Each content is written and flushed to a temporary file beside its target; only when all
    are written (and ``before_commit``, if given, has returned -- an upload, say) are they
    renamed into place, one after the other, and then the files of ``remove`` (outputs of an
    earlier run that these make stale) deleted.  If anything fails first, the temporary files
    are removed and no target is touched.  A target that exists must be a regular file."""
    staged: list[tuple[Path, str]] = []
    try:
        for path, content in outputs:
            staged.append((Path(path), _stage(Path(path), content)))
        if before_commit is not None:
            before_commit()
        for path, temporary in staged:
            check_replaceable(path)
            try:
                os.replace(temporary, path)
            except OSError as error:
                raise FileAccessError(f"{path}: cannot be written ({error.strerror})") from None
        for path in remove:
            try:
                os.unlink(path)
            except FileNotFoundError:
                pass
            except OSError as error:
                raise FileAccessError(f"{path}: a stale output of an earlier run cannot be "
                                      f"removed ({error.strerror})") from None
    finally:
        for _, temporary in staged:
            try:
                os.unlink(temporary)
            except OSError:
                pass
    return [path for path, _ in staged]


def _stage(path: Path, content: str | bytes) -> str:
    """A temporary file beside ``path`` holding ``content``, flushed to disk."""
    data = content.encode("utf-8") if isinstance(content, str) else content
    check_replaceable(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise FileAccessError(f"{path}: directory {directory} does not exist")
    try:
        handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                             dir=directory)
    except OSError as error:
        raise FileAccessError(f"{path}: cannot write in {directory} ({error.strerror})") from None
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temporary, 0o644)
    except BaseException as error:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        if isinstance(error, OSError):
            raise FileAccessError(f"{path}: cannot be written ({error.strerror})") from None
        raise
    return temporary
