"""Names in messages: "did you mean" (close matches of a misspelt name), and names made printable.

Names come from untrusted files (a URDF's links and joints, a result file's robot source): one
printed raw could write escape sequences to the user's terminal, so every name a message lists
goes through :func:`printable`.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def printable(text: object, limit: int = 200) -> str:
    r"""``text`` with every non-printable character escaped (``\x1b``), cut to ``limit`` characters."""
    raw = str(text)
    clean = "".join(c if c.isprintable() else _escape(ord(c)) for c in raw[: 4 * limit])
    return clean[:limit] + ("..." if len(clean) > limit or len(raw) > 4 * limit else "")


def _escape(code: int) -> str:
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}" if code < 0x10000 else f"\\U{code:08x}"


def listing(names: Iterable[object], sep: str = ", ") -> str:
    """``names`` joined by ``sep``, each made :func:`printable`."""
    return sep.join(printable(n) for n in names)


def closest(name: object, valid: Iterable[str], n: int = 5) -> list[str]:
    """Up to ``n`` names of ``valid`` close to ``name`` (difflib ratio >= 0.5), best first."""
    return difflib.get_close_matches(str(name), list(valid), n=n, cutoff=0.5)


def suggest(name: object, valid: Iterable[str], n: int = 5, shown: int = 20) -> str:
    """``"closest: a, b"`` when some names are close, else ``"valid: ..."`` (at most ``shown`` names)."""
    names = list(valid)
    close = closest(name, names, n)
    if close:
        return "closest: " + listing(close)
    return "valid: " + listing(names[:shown]) + (", ..." if len(names) > shown else "")
