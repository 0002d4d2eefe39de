"""Reading and writing files with clear errors; every write is atomic.

An output file is either written completely or not touched at all: content goes to a temporary
file in the same directory, is flushed to disk, and replaces the target in one rename.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

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
    path = Path(path)
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
        os.replace(temporary, path)
    except BaseException as error:
        try:
            os.unlink(temporary)
        except OSError:
            pass
        if isinstance(error, OSError):
            raise FileAccessError(f"{path}: cannot be written ({error.strerror})") from None
        raise
    return path
