"""The one way gb_pin writes a file: a unique temporary file beside it, fsync, rename.

Every writer of the package (results, checkpoints, trial journals and sets, benchmark
tables, HTML exports) goes through :func:`atomic_write`, so that a crash at any moment
leaves either the previous file or the new one, never half a file. The temporary file is
created exclusively (``O_EXCL``, a random name) in the target's directory, so a planted
symlink or a second process cannot redirect or clobber it; it is locked (``flock``) until renamed,
so that the temporary file of a writer killed mid-write (SIGKILL) is recognised, and removed by
the next write to the same path (:func:`remove_stale_temporaries`).

Outputs are checked before the work (:func:`check_writable`), and a finished result whose write
fails goes elsewhere (:func:`write_or_fallback`) rather than being lost.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import re
import stat
import tempfile
import time
import warnings
from collections.abc import Iterator
from typing import IO, Any

from gb_pin.exceptions import GbPinWarning, InvalidArgumentError

_SYSTEM_DIRS = ("/proc", "/sys", "/dev")
_TEMP_EXTRA = 16  # the temporary file's name adds ".", ".XXXXXXXX.tmp" to the file's (the lock ".lock")
STALE_SECONDS = 2.0
"""A temporary file of an earlier write older than this, whose writer holds no lock on it, is removed.

The lock is what tells a live writer (it holds it from creating the file to renaming it); the age
only covers the instant between a writer's ``mkstemp`` and its ``flock``. It was 60 s: a session
killed and restarted at once left its temporary file behind for its whole next run.
"""
_CLEANED: set[str] = set()  # paths whose directory was cleaned of stale temporaries by this process


def check_writable(path: Any, what: str = "output file") -> str:
    """Check, before any work, that ``path`` can be written as a file; return it as a string.

    The parent directory must exist and be a writable directory on a file system that is not
    full, ``path`` must not be a directory nor another file that is not a regular one (a FIFO, a
    socket, a device), nor lie under ``/proc``, ``/sys`` or ``/dev``, and its name must leave room
    for the temporary file's.

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
    elif os.path.exists(full) and not os.path.isfile(full):  # a FIFO, socket or device (through links too)
        reason = "exists and is not a regular file (a FIFO, socket or device)"
    elif not os.path.isdir(parent):
        reason = f"is in {parent!r}, which is not an existing directory"
    elif not os.access(parent, os.W_OK | os.X_OK):
        reason = f"is in {parent!r}, which is not writable"
    else:
        reason = _room(parent, os.path.basename(full))
    if reason is not None:
        raise InvalidArgumentError(f"{what} {text!r} cannot be written: it {reason}")
    return text


def _room(parent: str, name: str) -> str | None:
    """Why a file ``name`` cannot be created in ``parent`` (name too long, file system full), or None."""
    try:
        name_max = os.pathconf(parent, "PC_NAME_MAX")
        fs = os.statvfs(parent)
    except (OSError, ValueError):
        return None
    if len(os.fsencode(name)) > name_max - _TEMP_EXTRA:
        return f"has a name of {len(os.fsencode(name))} bytes; at most {name_max - _TEMP_EXTRA} here"
    free = (fs.f_bfree if os.geteuid() == 0 else fs.f_bavail) * fs.f_frsize
    if free == 0 and fs.f_blocks > 0:
        return f"is in {parent!r}, whose file system is full (0 bytes free)"
    return None


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


def fallback_paths(path: str | os.PathLike[str]) -> Iterator[str]:
    """Where to put a finished result whose own path failed: the current directory, then the temp dir.

    The name is ``path``'s, made unique (``name.1.npz``, ...), so no file is overwritten; a directory
    that cannot be written is skipped, and so is the one whose write just failed (its disk may be full).
    """
    base = os.path.basename(os.fspath(path)) or "gb_pin_result"
    stem, ext = os.path.splitext(base)
    failed = os.path.dirname(os.path.abspath(os.fspath(path)))
    for directory in dict.fromkeys((os.getcwd(), tempfile.gettempdir())):
        if os.path.abspath(directory) == failed or not os.access(directory, os.W_OK | os.X_OK):
            continue
        for i in range(1000):
            candidate = os.path.join(directory, base if i == 0 else f"{stem}.{i}{ext}")
            if not os.path.lexists(candidate):
                yield candidate
                break


def cache_root() -> str:
    """gb_pin's folder of the user's cache: ``$GB_PIN_CACHE``, else ``$XDG_CACHE_HOME/gb_pin`` (~/.cache)."""
    return os.environ.get("GB_PIN_CACHE") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "gb_pin"
    )


def free_name(path: str | os.PathLike[str]) -> str:
    """``path`` if nothing is there, else the first free ``name.1.npz``, ``name.2.npz``, ... beside it."""
    text = os.fspath(path)
    stem, ext = os.path.splitext(text)
    i = 0
    while os.path.lexists(text):
        i += 1
        text = f"{stem}.{i}{ext}"
    return text


def fallback_path(path: str | os.PathLike[str]) -> str:
    """The first of :func:`fallback_paths` (else a new directory in the temp dir)."""
    for candidate in fallback_paths(path):
        return candidate
    return os.path.join(tempfile.mkdtemp(prefix="gb_pin_"), os.path.basename(os.fspath(path)) or "result")


def write_or_fallback(path: str | os.PathLike[str], write: Any) -> str:
    """Call ``write(path)``; if it fails, ``write`` to each of :func:`fallback_paths` until one works.

    For results computed at length: a failed final write (disk full, directory removed meanwhile,
    permissions changed) must not lose them. The caller says where the file went.

    Returns:
        The path written (``path`` or a fallback).

    Raises:
        OSError: every place failed (the message names each path and why).
    """
    try:
        write(path)
        return os.fspath(path)
    except (OSError, InvalidArgumentError) as first:
        failures = [f"{os.fspath(path)!r} ({first})"]
    for other in fallback_paths(path):
        try:
            write(other)
        except (OSError, InvalidArgumentError) as exc:
            failures.append(f"{other!r} ({exc})")
            continue
        return other
    raise OSError(f"cannot write {' nor '.join(failures)}")


def save_or_fallback(path: str | os.PathLike[str], write: Any, what: str) -> str:
    """:func:`write_or_fallback`, with a :class:`~gb_pin.exceptions.GbPinWarning` saying where ``what`` went.

    Returns:
        The path written.

    Raises:
        OSError: every place failed.
    """
    where = write_or_fallback(path, write)
    if where != os.fspath(path):
        warnings.warn(
            f"could not write {what} {os.fspath(path)!r}; saved to {where!r} instead",
            GbPinWarning,
            stacklevel=2,
        )
    return where


def remove_stale_temporaries(path: str | os.PathLike[str]) -> list[str]:
    """Remove the temporary files of earlier writes to ``path`` whose writer is gone; return them.

    A write killed mid-way (SIGKILL, power loss) leaves its ``.NAME.XXXXXXXX.tmp`` beside ``path``.
    Such a file is removed only if it has this naming, is a regular file of this user, is older
    than :data:`STALE_SECONDS` and no process holds its lock (every writer :func:`atomic_write`
    ``flock``s its temporary file until it is renamed, and a lock dies with its process). Done once
    per process and path, on the first write to it.
    """
    full = os.path.abspath(os.fspath(path))
    if full in _CLEANED:
        return []
    _CLEANED.add(full)
    directory, base = os.path.split(full)
    pattern = re.compile(r"\." + re.escape(base) + r"\.[A-Za-z0-9_]{8}\.tmp")
    try:
        with os.scandir(directory) as entries:
            names = [e.name for e in entries if pattern.fullmatch(e.name)]
    except OSError:
        return []
    removed = []
    for name in names:
        tmp = os.path.join(directory, name)
        with contextlib.suppress(OSError):
            fd = os.open(tmp, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
            try:
                info = os.fstat(fd)
                if (
                    stat.S_ISREG(info.st_mode)
                    and info.st_uid == os.geteuid()
                    and time.time() - info.st_mtime > STALE_SECONDS
                ):
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # raises while a writer holds it
                    if os.stat(tmp, follow_symlinks=False).st_ino == info.st_ino:
                        os.remove(tmp)
                        removed.append(tmp)
            finally:
                os.close(fd)
    return removed


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
    remove_stale_temporaries(path)
    fd, tmp = tempfile.mkstemp(dir=directory, prefix=f".{os.path.basename(path)}.", suffix=".tmp")
    lock = os.dup(fd)  # holds the temporary file's lock until it is renamed (see remove_stale_temporaries)
    try:
        with contextlib.suppress(OSError):
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
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
    finally:
        os.close(lock)
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
