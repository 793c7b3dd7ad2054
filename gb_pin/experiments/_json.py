"""JSON helpers shared by the experiment files (trial sets, sweeps, trial journals).

Writing goes through :mod:`gb_pin._files` (atomic); this module only reads and
canonicalises values.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from gb_pin.exceptions import ResultFileError


def read_json(path: str) -> Any:
    """The parsed JSON content of ``path``.

    Raises:
        ResultFileError: the file is missing, unreadable or not JSON (the message names it).
    """
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh)
    except FileNotFoundError as exc:
        raise ResultFileError(f"{path}: no such file") from exc
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ResultFileError(f"{path}: not a readable JSON file ({exc})") from exc


def plain(value: Any) -> Any:
    """numpy scalars as Python numbers (for JSON, labels and journal keys); other values unchanged."""
    return value.item() if isinstance(value, np.generic) else value
