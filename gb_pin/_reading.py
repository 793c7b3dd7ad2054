"""The one way gb_pin opens a file it reads: a regular file, of a size checked first, read in bounds.

Every reader of the package (result files and checkpoints, trial sets and journals, point files,
presets, URDFs) opens its file through :func:`open_regular`: a FIFO, a device (``/dev/zero``), a
socket or a directory, directly or through a symlink, is refused before a byte is read (the
open does not block on a FIFO), and so is a file larger than the reader's limit. ``.npy`` arrays
(alone or as members of an ``.npz``) are read by :func:`read_npy`, which checks what the header
declares (dtype, shape, size against the bytes really there) before allocating the array once.
"""

from __future__ import annotations

import contextlib
import functools
import os
import stat
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import GbPinError

_KINDS = {
    stat.S_IFDIR: "a directory",
    stat.S_IFIFO: "a FIFO (named pipe)",
    stat.S_IFCHR: "a character device",
    stat.S_IFBLK: "a block device",
    stat.S_IFSOCK: "a socket",
}
NPY_KINDS = "biufcU"
"""The array kinds a gb_pin file may hold: booleans, integers, reals, complex (refused later by the
fields that need reals) and text (JSON headers); never objects, bytes, records or dates."""
_CHUNK = 1 << 20  # bytes copied at a time into a preallocated array


def open_regular(
    path: str | os.PathLike[str], label: str, what: str, limit: int, error: type[GbPinError]
) -> tuple[IO[bytes], int]:
    """Open ``path`` for reading if it is a regular file of at most ``limit`` bytes.

    The open is non-blocking (a FIFO is refused, not waited on) and follows symlinks, so a
    symlink to ``/dev/zero`` is refused as ``/dev/zero`` is.

    Args:
        path: the file.
        label: how messages name it (``"run.npz"``, ``"--targets 'p.csv'"``).
        what: what it should be, for messages (``"result file"``).
        limit: the largest size accepted [bytes].
        error: the exception raised (``ResultFileError``, ``InvalidArgumentError``).

    Returns:
        (the file, open in binary mode, its size in bytes).

    Raises:
        error: missing, unreadable, not a regular file, or over ``limit`` bytes.
    """
    try:
        fd = os.open(os.fspath(path), os.O_RDONLY | os.O_NONBLOCK | os.O_CLOEXEC)
    except FileNotFoundError as exc:
        raise error(f"{label}: cannot read it (no such {what})") from exc
    except (OSError, TypeError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise error(f"{label}: cannot read it ({reason})") from exc
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            kind = _KINDS.get(stat.S_IFMT(info.st_mode), "not a regular file")
            raise error(f"{label}: {kind}, not a {what} (gb_pin reads regular files only)")
        if info.st_dev in _pseudo_devices():
            raise error(
                f"{label}: a file of the kernel (/proc or /sys; its reads may block), not a {what} "
                "(gb_pin reads regular files only)"
            )
        if info.st_size > limit:
            raise error(f"{label}: {info.st_size} bytes; gb_pin reads a {what} of at most {limit} bytes")
        os.set_blocking(fd, True)
        return os.fdopen(fd, "rb"), int(info.st_size)
    except BaseException:
        os.close(fd)
        raise


@functools.cache
def _pseudo_devices() -> frozenset[int]:
    """The devices of /proc and /sys: their files look regular (size 0) but a read may block forever."""
    devices = set()
    with contextlib.suppress(OSError):
        top = os.stat("/").st_dev
        for root in ("/proc", "/sys"):
            with contextlib.suppress(OSError):
                devices.add(os.stat(root).st_dev)
        devices.discard(top)  # a /sys that is only a folder of the root file system (not mounted)
    return frozenset(devices)


def read_bytes(
    path: str | os.PathLike[str], label: str, what: str, limit: int, error: type[GbPinError]
) -> bytes:
    """The content of a regular file of at most ``limit`` bytes (:func:`open_regular`).

    At most ``limit`` bytes are read even if the file grows meanwhile.
    """
    fh, _ = open_regular(path, label, what, limit, error)
    try:
        with fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise error(f"{label}: cannot read it ({exc.strerror or exc})") from exc
    if len(data) > limit:
        raise error(f"{label}: grew over {limit} bytes while read")
    return data


def read_npy(fh: IO[bytes], available: int, label: str, limit: int, error: type[GbPinError]) -> NDArray[Any]:
    """One ``.npy`` array from ``fh`` (a file or a zip member), checked before it is allocated.

    The header must parse (any failure of numpy's parser, a ``tokenize`` error of a header cut
    short included, is ``error``), declare a dtype of :data:`NPY_KINDS`, a shape of sizes >= 0, and
    a byte count within both ``limit`` and what remains of the ``available`` bytes; the array is
    then allocated once and filled in chunks (peak memory: the array and 1 MiB).

    Args:
        fh: positioned at the start of the ``.npy`` data.
        available: bytes of ``fh`` from its start (the file's or the member's size).
        label: how messages name the array (``"run.npz: member 'error.npy'"``).
        limit: the largest array accepted [bytes].
        error: the exception raised.

    Raises:
        error: a malformed header, a refused dtype or shape, too large, or truncated data.
    """
    try:
        start = fh.tell()
        version = np.lib.format.read_magic(fh)
        if version == (1, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
        elif version == (2, 0):
            shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
        else:
            raise error(f"{label}: .npy version {version} (gb_pin reads versions 1.0 and 2.0)")
        header = fh.tell() - start
    except GbPinError:
        raise
    except Exception as exc:  # numpy's parser raises ValueError, SyntaxError, tokenize's TokenError...
        raise error(f"{label}: unreadable .npy header ({type(exc).__name__}: {str(exc)[:80]})") from exc
    if dtype.hasobject or dtype.kind not in NPY_KINDS or dtype.itemsize == 0 or dtype.fields is not None:
        raise error(f"{label}: holds {dtype} values (gb_pin files hold numbers and text only)")
    count = 1
    for d in shape:
        if d < 0:
            raise error(f"{label}: declares the negative shape {shape}")
        count *= d
    nbytes = count * dtype.itemsize
    if nbytes > limit:
        raise error(
            f"{label}: declares shape {shape} of {dtype} ({nbytes} bytes); gb_pin reads at most {limit}"
        )
    if nbytes > available - header:
        raise error(
            f"{label}: declares shape {shape} of {dtype} ({nbytes} bytes) "
            f"in {max(available - header, 0)} bytes"
        )
    flat = np.empty(count, dtype=dtype)
    raw = flat.view(np.uint8)  # the array's own bytes: filled in place, never copied whole
    done = 0
    while done < nbytes:
        chunk = fh.read(min(_CHUNK, nbytes - done))
        if not chunk:
            break
        raw[done : done + len(chunk)] = np.frombuffer(chunk, dtype=np.uint8)
        done += len(chunk)
    if done != nbytes:
        raise error(f"{label}: truncated ({done} of {nbytes} bytes of data)")
    return flat.reshape(shape[::-1]).transpose() if fortran else flat.reshape(shape)
