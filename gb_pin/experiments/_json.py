"""JSON helpers shared by the experiment files (trial sets, sweeps, trial journals).

Writing goes through :mod:`gb_pin._files` (atomic); this module only reads and
canonicalises values.
"""

from __future__ import annotations

import json
import os
from typing import Any

import numpy as np

from gb_pin.exceptions import ResultFileError

MAX_JSON_BYTES = 256 * 2**20
"""The largest trial set, sweep or trial journal read (checked before reading)."""


def check_size(path: str) -> None:
    """Raise ResultFileError if ``path`` is larger than :data:`MAX_JSON_BYTES` (missing files pass)."""
    try:
        size = os.stat(path).st_size
    except OSError:
        return
    if size > MAX_JSON_BYTES:
        raise ResultFileError(
            f"{path}: {size} bytes; gb_pin reads JSON files of at most {MAX_JSON_BYTES} "
            "(gb_pin.experiments._json.MAX_JSON_BYTES)"
        )


def read_json(path: str) -> Any:
    """The parsed JSON content of ``path``.

    Raises:
        ResultFileError: the file is missing, unreadable or not JSON (the message names it).
    """
    check_size(path)
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh)
    except FileNotFoundError as exc:
        raise ResultFileError(f"{path}: no such file") from exc
    except RecursionError as exc:
        raise ResultFileError(f"{path}: JSON nested too deeply") from exc
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ResultFileError(f"{path}: not a readable JSON file ({exc})") from exc


def plain(value: Any) -> Any:
    """numpy scalars as Python numbers (for JSON, labels and journal keys); other values unchanged."""
    return value.item() if isinstance(value, np.generic) else value
