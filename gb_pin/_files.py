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

from gb_pin.exceptions import InvalidArgumentError

_SYSTEM_DIRS = ("/proc", "/sys", "/dev")


def check_writable(path: Any, what: str = "output file") -> str:
    """Check, before any work, that ``path`` can be written as a file; return it as a string.

    The parent directory must exist and be a writable directory, ``path`` must not be a
    directory, nor lie under ``/proc``, ``/sys`` or ``/dev``.

    Args:
        path: the file to be written (str or path-like).
        what: what the file is, for the message (``"--out"``, ``"checkpoint"``, ...).

    Raises:
        InvalidArgumentError: naming ``what``, the path and the reason.
    """
    if isinstance(path, bool) or not isinstance(path, str | os.PathLike):
        raise InvalidArgumentError(f"{what} must be a file path (str or os.PathLike), got {path!r}")
    text = os.fspath(path)
    if not isinstance(text, str) or not text or "\0" in text:
        raise InvalidArgumentError(f"{what} must be a non-empty file path, got {path!r}")
    full = os.path.realpath(os.path.abspath(text))
    parent = os.path.dirname(full)
    reason = None
    if any(full == d or full.startswith(d + os.sep) for d in _SYSTEM_DIRS):
        reason = "is under a system directory (/proc, /sys, /dev)"
    elif os.path.isdir(full):
        reason = "is a directory"
    elif not os.path.isdir(parent):
        reason = f"is in {parent!r}, which is not an existing directory"
    elif not os.access(parent, os.W_OK | os.X_OK):
        reason = f"is in {parent!r}, which is not writable"
    if reason is not None:
        raise InvalidArgumentError(f"{what} {text!r} cannot be written: it {reason}")
    return text


def check_directory(path: Any, what: str = "output folder") -> str:
    """Check, before any work, that ``path`` is a writable directory or can be created; return it.

    Raises:
        InvalidArgumentError: naming ``what``, the path and the reason.
    """
    if os.path.isdir(path) if isinstance(path, str | os.PathLike) else False:
        text = os.fspath(path)
        if not os.access(text, os.W_OK | os.X_OK):
            raise InvalidArgumentError(f"{what} {text!r} is a directory that is not writable")
        return str(text)
    return check_writable(path, what)  # not there yet: its parent must be a writable directory


def fallback_path(path: str | os.PathLike[str]) -> str:
    """Where to put a finished result whose own path failed: the current directory, else the temp dir.

    The name is ``path``'s, made unique (``name.1.npz``, ...), so no file is overwritten. The
    directory that failed is not tried again (its disk may be full).
    """
    base = os.path.basename(os.fspath(path)) or "gb_pin_result"
    stem, ext = os.path.splitext(base)
    failed = os.path.dirname(os.path.abspath(os.fspath(path)))
    for directory in (os.getcwd(), tempfile.gettempdir()):
        if os.path.abspath(directory) == failed or not os.access(directory, os.W_OK | os.X_OK):
            continue
        for i in range(1000):
            candidate = os.path.join(directory, base if i == 0 else f"{stem}.{i}{ext}")
            if not os.path.exists(candidate):
                return candidate
    return os.path.join(tempfile.mkdtemp(prefix="gb_pin_"), base)


def write_or_fallback(path: str | os.PathLike[str], write: Any) -> str:
    """Call ``write(path)``; if it fails with OSError, ``write`` to :func:`fallback_path` instead.

    For results computed at length: a failed final write must not lose them.

    Returns:
        The path written (``path`` or the fallback).

    Raises:
        OSError: the fallback failed too (the message names both paths).
    """
    try:
        write(path)
        return os.fspath(path)
    except OSError as first:
        other = fallback_path(path)
        try:
            write(other)
        except OSError as second:
            raise OSError(f"cannot write {os.fspath(path)!r} ({first}) nor {other!r} ({second})") from second
        return other


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
