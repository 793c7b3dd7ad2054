"""One place for gb_pin's ``.npz`` files: atomic writes, and reads that fail only with ResultFileError."""

from __future__ import annotations

import hashlib
import json
import struct
import zipfile
import zlib
from typing import IO, Any

import numpy as np

from gb_pin._files import atomic_write
from gb_pin._reading import open_regular, read_npy
from gb_pin.exceptions import ResultFileError


def atomic_savez(
    path: str, arrays: dict[str, Any], meta: dict[str, Any], compress: bool = False, digest: bool = False
) -> None:
    """Write ``arrays`` and a JSON header ``meta`` to ``path`` atomically (``gb_pin._files.atomic_write``).

    A crash at any moment leaves either the previous file or the new one, never half a file.
    ``digest``: the header also holds the :func:`content_digest` of the arrays and the header,
    which :func:`check_digest` verifies on reading.
    """
    from gb_pin import __version__

    header = {**meta, "gb_pin_version": __version__}
    header.pop(DIGEST, None)
    if digest:
        header[DIGEST] = content_digest(arrays, header)
    with atomic_write(path) as fh:
        (np.savez_compressed if compress else np.savez)(fh, meta=np.array(json.dumps(header)), **arrays)


DIGEST = "digest"
"""The header entry holding :func:`content_digest` (files whose format requires one)."""


def content_digest(arrays: dict[str, Any], header: dict[str, Any]) -> str:
    """``"sha256:HEX"`` of a file's header (less its digest) and of every array: name, dtype, shape, bytes.

    The header is hashed as canonical JSON (sorted keys), which its round trip through the file
    keeps; the arrays in name order, so the digest is the same for the arrays written and read.
    """
    h = hashlib.sha256()
    h.update(json.dumps({k: v for k, v in header.items() if k != DIGEST}, sort_keys=True).encode())
    for name in sorted(arrays):
        a = np.asarray(arrays[name])
        h.update(b"\0" + name.encode("utf-8", "surrogateescape") + b"\0" + a.dtype.str.encode())
        h.update(repr(a.shape).encode() + b"\0")
        h.update(a.tobytes())
    return "sha256:" + h.hexdigest()


def check_digest(path: str, kind: str, arrays: dict[str, Any], header: dict[str, Any]) -> None:
    """Refuse a file whose arrays or header differ from what the digest written with them says.

    Raises:
        ResultFileError: no digest, or one that does not match (naming the file).
    """
    recorded = header.get(DIGEST)
    if not isinstance(recorded, str):
        raise ResultFileError(f"{path}: a gb_pin {kind} of format version {header.get('format_version')} "
                              "without its digest (edited, or not written by gb_pin)")  # fmt: skip
    if recorded != content_digest(arrays, header):
        raise ResultFileError(
            f"{path}: its contents do not match the digest gb_pin wrote with them: the {kind} was "
            "edited or corrupted after it was written, and is not read"
        )


# Limits on what a file may declare, checked before anything is read or allocated: a file is
# untrusted input, and a few bytes of zip header can claim gigabytes.
MAX_FILE_BYTES = 1 << 30  # 1 GiB of arrays (decompressed) in one file
MAX_MEMBERS = 256
MAX_HEADER_BYTES = 1 << 20  # the JSON header
MAX_DISK_BYTES = MAX_FILE_BYTES + (1 << 24)  # the file itself: its arrays and the zip's and .npy's headers
_EOCD_SIZE = 22  # bytes of a zip's end-of-central-directory record
_MAX_ENTRY_BYTES = 1024  # a generous bound on one central directory entry of a gb_pin file


def _reject_constant(name: str) -> Any:
    raise ValueError(f"non-finite number {name} in the header")


def _check_directory(fh: IO[bytes], size: int, path: str, kind: str) -> None:
    """Check the zip's end record (member count, directory size) before zipfile parses the directory.

    zipfile reads the whole central directory and builds an object per member: a forged end
    record could otherwise make it parse millions of entries.
    """
    tail = min(size, _EOCD_SIZE + 0xFFFF)  # the end record, then a comment of at most 64 KiB
    fh.seek(size - tail)
    data = fh.read(tail)
    pos = data.rfind(b"PK\x05\x06")
    if pos < 0 or len(data) - pos < _EOCD_SIZE:
        raise ResultFileError(f"{path}: not a gb_pin {kind} (not a zip archive)")
    entries, directory = struct.unpack("<HI", data[pos + 10 : pos + 16])
    if entries > MAX_MEMBERS or directory > MAX_MEMBERS * _MAX_ENTRY_BYTES:
        raise ResultFileError(
            f"{path}: declares {entries} members in a directory of {directory} bytes; a gb_pin {kind} "
            f"has at most {MAX_MEMBERS} (gb_pin.runs.archive.MAX_MEMBERS)"
        )
    fh.seek(0)


def _read_members(fh: IO[bytes], size: int, path: str, kind: str) -> dict[str, Any]:
    """Every ``.npy`` member of the zip archive, after checking what each declares."""
    _check_directory(fh, size, path, kind)
    with zipfile.ZipFile(fh) as archive:
        infos = archive.infolist()
        if len(infos) > MAX_MEMBERS:
            raise ResultFileError(f"{path}: {len(infos)} members; a gb_pin {kind} has at most {MAX_MEMBERS}")
        declared = sum(i.file_size for i in infos)
        if declared > MAX_FILE_BYTES:
            raise ResultFileError(
                f"{path}: declares {declared} bytes of arrays; gb_pin reads at most {MAX_FILE_BYTES} "
                "(gb_pin.runs.archive.MAX_FILE_BYTES)"
            )
        arrays: dict[str, Any] = {}
        for info in infos:
            if not info.filename.endswith(".npy"):
                raise ResultFileError(f"{path}: unexpected member {info.filename[:60]!r}")
            label = f"{path}: member {info.filename[:60]!r}"
            limit = 4 * MAX_HEADER_BYTES if info.filename == "meta.npy" else MAX_FILE_BYTES
            with archive.open(info) as member:
                arrays[info.filename[: -len(".npy")]] = read_npy(
                    member, info.file_size, label, limit, ResultFileError
                )
    return arrays


# (format expected, format found): what the file is, and what to do with it.
_OTHER_FORMAT = {
    ("gb_pin.result", "gb_pin.checkpoint"): "a checkpoint, not a result file: finish its run with "
    "`gb-pin babble --resume FILE --out run.npz` (gb_pin.resume in Python), then use run.npz",
    ("gb_pin.checkpoint", "gb_pin.result"): "a result file, not a checkpoint: its run is finished; "
    "extend it with `gb-pin babble --continue FILE --movements N` (babble(init=load_result(...)))",
}


def read_archive(
    path: str, kind: str, fmt: str, max_version: int, required: tuple[str, ...] = ()
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Read every array and the JSON header of a gb_pin ``.npz`` file (no pickle).

    What the file declares (members, sizes, shapes, dtypes) is checked before anything is
    allocated (:data:`MAX_FILE_BYTES`, :data:`MAX_MEMBERS`, :data:`MAX_HEADER_BYTES`).

    Args:
        path: the file.
        kind: what the file should be, for messages (``"result file"``, ``"checkpoint"``).
        fmt: the expected ``format`` entry of the header.
        max_version: the newest ``format_version`` this gb_pin reads.
        required: array names that must be present.

    Returns:
        (arrays, header).

    Raises:
        ResultFileError: missing, truncated, corrupted, oversized, foreign or newer-version file.
    """
    fh, size = open_regular(path, path, kind, MAX_DISK_BYTES, ResultFileError)
    try:
        with fh:
            if fh.read(6) == b"\x93NUMPY":
                raise ResultFileError(f"{path}: not a gb_pin {kind} (an .npy array, not an .npz archive)")
            arrays = _read_members(fh, size, path, kind)
    except ResultFileError:
        raise
    except (OSError, ValueError, TypeError, zipfile.BadZipFile, zlib.error, EOFError, KeyError,
            NotImplementedError, OverflowError, MemoryError) as exc:  # fmt: skip
        raise ResultFileError(f"{path}: not a readable gb_pin {kind} ({type(exc).__name__}: {exc})") from exc
    meta = _header(path, kind, arrays.pop("meta", None))
    if meta.get("format") != fmt:
        hint = _OTHER_FORMAT.get((fmt, str(meta.get("format"))))
        if hint is not None:
            raise ResultFileError(f"{path}: {hint.replace('FILE', path)}")
        raise ResultFileError(f"{path}: not a gb_pin {kind} (header {str(meta)[:80]!r})")
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool):
        raise ResultFileError(f"{path}: corrupted header (format_version {version!r} is not an integer)")
    if version > max_version:
        raise ResultFileError(
            f"{path}: written by a newer gb_pin (format version {version}); "
            f"this gb_pin reads up to {max_version}"
        )
    missing = [k for k in required if k not in arrays]
    if missing:
        raise ResultFileError(f"{path}: incomplete {kind} (missing {missing})")
    return arrays, meta


def _header(path: str, kind: str, raw: Any) -> dict[str, Any]:
    """The JSON header: a 0-d string array holding a flat-enough JSON object of finite numbers."""
    if raw is None or raw.shape != () or raw.dtype.kind != "U":
        raise ResultFileError(f"{path}: not a gb_pin {kind} (no readable header)")
    text = str(raw)
    if len(text) > MAX_HEADER_BYTES:
        raise ResultFileError(f"{path}: header of {len(text)} characters (at most {MAX_HEADER_BYTES})")
    try:
        meta = json.loads(text, parse_constant=_reject_constant)
    except (ValueError, RecursionError) as exc:
        raise ResultFileError(f"{path}: not a gb_pin {kind} (unreadable header: {str(exc)[:80]})") from exc
    if not isinstance(meta, dict):
        raise ResultFileError(f"{path}: not a gb_pin {kind} (header {str(meta)[:80]!r})")
    return meta
