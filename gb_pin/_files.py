"""The one way gb_pin writes a file: a unique temporary file beside it, fsync, rename.

Every writer of the package (results, checkpoints, trial journals and sets, benchmark
tables, HTML exports) goes through :func:`atomic_write`, so that a crash at any moment
leaves either the previous file or the new one, never half a file. The temporary file is
created exclusively (``O_EXCL``, a random name) in the target's directory, so a planted
symlink or a second process cannot redirect or clobber it.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Iterator
from typing import IO, Any


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike[str], *, text: bool = False) -> Iterator[IO[Any]]:
    """Open a temporary file for writing that replaces ``path`` when the block ends without error.

    Args:
        path: the file to (re)place.
        text: open in text mode (UTF-8) instead of binary.

    Yields:
        The open temporary file. On an exception it is removed and ``path`` is untouched.

    Raises:
        OSError: the directory is missing or not writable (raised before anything is written).
    """
    path = os.fspath(path)
    directory = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{os.path.basename(path)}.", suffix=".tmp")
    try:
        # mkstemp creates the file for its owner only; give it the mode a plain open() would.
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(fd, 0o666 & ~umask)
        fh: IO[Any] = os.fdopen(fd, "w", encoding="utf-8") if text else os.fdopen(fd, "wb")
        with fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)
        raise
    _fsync_directory(directory)


def _fsync_directory(directory: str) -> None:
    """Make the rename itself durable (best effort: not every file system allows it)."""
    with contextlib.suppress(OSError):
        fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def write_text(path: str | os.PathLike[str], content: str) -> None:
    """Write ``content`` to ``path`` atomically (UTF-8)."""
    with atomic_write(path, text=True) as fh:
        fh.write(content)


def write_json(path: str | os.PathLike[str], data: Any) -> None:
    """Write ``data`` as JSON to ``path`` atomically."""
    with atomic_write(path, text=True) as fh:
        json.dump(data, fh)
