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


def read_archive(
    path: str, kind: str, fmt: str, max_version: int, required: tuple[str, ...] = ()
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Read every array and the JSON header of a gb_pin ``.npz`` file (no pickle).

    Args:
        path: the file.
        kind: what the file should be, for messages (``"result file"``, ``"checkpoint"``).
        fmt: the expected ``format`` entry of the header.
        max_version: the newest ``format_version`` this gb_pin reads.
        required: array names that must be present.

    Returns:
        (arrays, header).

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file.
    """
    try:
        loaded = np.load(path, allow_pickle=False)
        if not isinstance(loaded, np.lib.npyio.NpzFile):
            raise ResultFileError(f"{path}: not a gb_pin {kind} (an .npy array, not an .npz archive)")
        with loaded as archive:
            arrays = {k: archive[k] for k in archive.files}
    except FileNotFoundError as exc:
        raise ResultFileError(f"{path}: no such {kind}") from exc
    except ResultFileError:
        raise
    except (OSError, ValueError, TypeError, zipfile.BadZipFile, zlib.error, EOFError, KeyError) as exc:
        raise ResultFileError(f"{path}: unreadable or corrupted {kind} ({exc})") from exc
    try:
        meta = json.loads(str(arrays.pop("meta")))
    except (KeyError, ValueError) as exc:
        raise ResultFileError(f"{path}: not a gb_pin {kind} (no readable header)") from exc
    if not isinstance(meta, dict) or meta.get("format") != fmt:
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
