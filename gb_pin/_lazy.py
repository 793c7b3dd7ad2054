"""Lazy exports of a package's public names (PEP 562), shared by ``gb_pin`` and its sub-packages.

A package lists ``{public name: defining module}`` (or ``(module, attribute)`` for an alias) and
gets a module ``__getattr__`` that imports the defining module on first use, so importing the
package itself stays cheap (no numba, pinocchio or meshcat until a name that needs them is used).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any


def lazy_exports(
    package: str, exports: Mapping[str, str | tuple[str, str]], namespace: dict[str, Any]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """(``__getattr__``, ``__dir__``) for ``package``, whose module globals are ``namespace``."""

    def getattr_(name: str) -> Any:
        where = exports.get(name)
        if where is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attribute = (where, name) if isinstance(where, str) else where
        value = getattr(importlib.import_module(module), attribute)
        namespace[name] = value  # the next access is a plain global
        return value

    def dir_() -> list[str]:
        return sorted({*namespace, *exports})

    return getattr_, dir_
