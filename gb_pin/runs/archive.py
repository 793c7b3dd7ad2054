"""One place for gb_pin's ``.npz`` files: atomic writes, and reads that fail only with ResultFileError."""

from __future__ import annotations

import json
import zipfile
import zlib
from typing import Any

import numpy as np

from gb_pin._files import atomic_write
from gb_pin.exceptions import ResultFileError


def atomic_savez(path: str, arrays: dict[str, Any], meta: dict[str, Any], compress: bool = False) -> None:
    """Write ``arrays`` and a JSON header ``meta`` to ``path`` atomically (``gb_pin._files.atomic_write``).

    A crash at any moment leaves either the previous file or the new one, never half a file.
    """
    from gb_pin import __version__

    header = {**meta, "gb_pin_version": __version__}
    with atomic_write(path) as fh:
        (np.savez_compressed if compress else np.savez)(fh, meta=np.array(json.dumps(header)), **arrays)


# Limits on what a file may declare, checked before anything is read or allocated: a file is
# untrusted input, and a few bytes of zip header can claim gigabytes.
MAX_FILE_BYTES = 1 << 30  # 1 GiB of arrays (decompressed) in one file
MAX_MEMBERS = 256
MAX_HEADER_BYTES = 1 << 20  # the JSON header


def _reject_constant(name: str) -> Any:
    raise ValueError(f"non-finite number {name} in the header")


def _read_members(path: str, kind: str) -> dict[str, Any]:
    """Every ``.npy`` member of the zip archive, after checking what each declares."""
    with zipfile.ZipFile(path) as archive:
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
            with archive.open(info) as fh:
                version = np.lib.format.read_magic(fh)
                if version == (1, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
                elif version == (2, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
                else:
                    raise ResultFileError(f"{path}: member {info.filename!r} has .npy version {version}")
                if dtype.hasobject:
                    raise ResultFileError(f"{path}: member {info.filename!r} holds Python objects")
                count = 1
                for d in shape:
                    count *= int(d)
                if count * dtype.itemsize > info.file_size:
                    raise ResultFileError(
                        f"{path}: member {info.filename!r} claims shape {shape} of {dtype} "
                        f"({count * dtype.itemsize} bytes) in {info.file_size} bytes"
                    )
                data = fh.read(count * dtype.itemsize)
                if len(data) != count * dtype.itemsize:
                    raise ResultFileError(f"{path}: member {info.filename!r} is truncated")
                arr = np.frombuffer(data, dtype=dtype).copy()
                arr = arr.reshape(shape[::-1]).transpose() if fortran else arr.reshape(shape)
            arrays[info.filename[: -len(".npy")]] = arr
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
    try:
        with open(path, "rb") as fh:
            magic = fh.read(6)
        if magic == b"\x93NUMPY":
            raise ResultFileError(f"{path}: not a gb_pin {kind} (an .npy array, not an .npz archive)")
        arrays = _read_members(path, kind)
    except FileNotFoundError as exc:
        raise ResultFileError(f"{path}: no such {kind}") from exc
    except IsADirectoryError as exc:
        raise ResultFileError(f"{path}: a directory, not a gb_pin {kind}") from exc
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
