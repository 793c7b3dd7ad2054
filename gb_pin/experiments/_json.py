"""JSON helpers shared by the experiment files (trial sets, sweeps, trial journals).

Writing goes through :mod:`gb_pin._files` (atomic); this module only reads and
canonicalises values.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import Any

import numpy as np

from gb_pin._reading import open_regular, read_bytes
from gb_pin.exceptions import ResultFileError

MAX_JSON_BYTES = 64 * 2**20
"""The largest trial set or sweep file read (checked before reading): parsed whole, a JSON file of
numbers takes 6 to 12 times its size in memory while it is converted (0.4 to 0.8 GB at 64 MiB)."""
MAX_JOURNAL_BYTES = 256 * 2**20
"""The largest trial journal read: it is read line by line, keeping only the parsed curves."""
MAX_LINE_BYTES = 16 * 2**20
"""The longest line of a trial journal (one trial's curves; a longer line is ignored, so recomputed)."""


def read_json(path: str) -> Any:
    """The parsed JSON content of ``path``, a regular file of at most :data:`MAX_JSON_BYTES`.

    Raises:
        ResultFileError: the file is missing, unreadable, not a regular file, too large or not
            JSON (the message names it).
    """
    data = read_bytes(path, path, "JSON file", MAX_JSON_BYTES, ResultFileError)
    try:
        return json.loads(data.decode("utf-8"))
    except RecursionError as exc:
        raise ResultFileError(f"{path}: JSON nested too deeply") from exc
    except (UnicodeDecodeError, ValueError, MemoryError) as exc:
        raise ResultFileError(f"{path}: not a readable JSON file ({str(exc)[:120]})") from exc


def read_lines(path: str, what: str) -> Iterator[tuple[bytes, int]]:
    """The lines of a regular file of at most :data:`MAX_JOURNAL_BYTES`: (line, its length in bytes).

    A line is read only up to :data:`MAX_LINE_BYTES`: a longer one is skipped and given as ``b""``
    (with its length), so that memory is bounded by one line, not by the file.

    Raises:
        ResultFileError: missing, unreadable, not a regular file or too large.
    """
    fh, _ = open_regular(path, path, what, MAX_JOURNAL_BYTES, ResultFileError)
    with fh:
        try:
            while True:
                line = fh.readline(MAX_LINE_BYTES + 1)
                if len(line) <= MAX_LINE_BYTES:
                    if not line:
                        return
                    yield line, len(line)
                    continue
                length = len(line)
                while line and not line.endswith(b"\n"):  # skip the rest of an over-long line
                    line = fh.readline(MAX_LINE_BYTES + 1)
                    length += len(line)
                yield b"", length
        except OSError as exc:
            raise ResultFileError(f"{path}: cannot read it ({exc.strerror or exc})") from exc


def plain(value: Any) -> Any:
    """numpy scalars as Python numbers (for JSON, labels and journal keys); other values unchanged."""
    return value.item() if isinstance(value, np.generic) else value
