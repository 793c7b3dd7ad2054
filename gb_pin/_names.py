"""The one "did you mean" helper: close matches of a misspelt name, for error messages."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def closest(name: object, valid: Iterable[str], n: int = 5) -> list[str]:
    """Up to ``n`` names of ``valid`` close to ``name`` (difflib ratio >= 0.5), best first."""
    return difflib.get_close_matches(str(name), list(valid), n=n, cutoff=0.5)


def suggest(name: object, valid: Iterable[str], n: int = 5, shown: int = 20) -> str:
    """``"closest: a, b"`` when some names are close, else ``"valid: ..."`` (at most ``shown`` names)."""
    names = list(valid)
    close = closest(name, names, n)
    if close:
        return "closest: " + ", ".join(close)
    return "valid: " + ", ".join(names[:shown]) + (", ..." if len(names) > shown else "")
