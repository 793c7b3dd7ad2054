"""The paper's numbers (Sec. III), read from ``paper.toml``: the one place they are written down.

Each :class:`Claim` is one row of the table "paper vs gb_pin" of ``results.md``
(:func:`gb_pin.reproduce.report.paper_table`): what the paper states, where, and the
reproduction issue's acceptance range for gb_pin's number.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, fields
from importlib import resources
from types import MappingProxyType
from typing import Any

from gb_pin.exceptions import GbPinError

DATA = "paper.toml"


@dataclass(frozen=True)
class Claim:
    """One statement of the paper that the reproduction checks.

    Attributes:
        id: gb_pin's key for it (e.g. ``"s50_m50"``).
        figure: the figure of ``gb-pin reproduce`` whose numbers it needs (e.g. ``"fig8"``).
        quantity: the label of its row in ``results.md``.
        source: where the paper states it (section, figure, equation).
        value: the paper's number, or None where the paper states the claim in words only.
        approx: the paper says "about" ``value``.
        text: the claim in words, shown where there is no ``value``.
        low: lower end of the issue's acceptance range for gb_pin's number, or None.
        high: upper end of that range, or None.
    """

    id: str
    figure: str
    quantity: str
    source: str
    value: float | None = None
    approx: bool = False
    text: str = ""
    low: float | None = None
    high: float | None = None

    @property
    def paper(self) -> str:
        """The paper's column of the table: ``"≈ 0.04"``, ``"34"`` or the claim in words."""
        if self.value is None:
            return self.text
        return f"≈ {self.value:g}" if self.approx else f"{self.value:g}"

    @property
    def bounded(self) -> bool:
        """Whether the issue gives an acceptance range for this number."""
        return self.low is not None or self.high is not None

    @property
    def range(self) -> str:
        """The acceptance range as shown: ``"[95, 175]"``, ``"≤ 55"``, ``"≥ 1"`` or ``""``."""
        if self.low is not None and self.high is not None:
            return f"[{self.low:g}, {self.high:g}]"
        if self.high is not None:
            return f"≤ {self.high:g}"
        return "" if self.low is None else f"≥ {self.low:g}"

    def accepts(self, measured: float | None) -> bool:
        """Whether ``measured`` lies in the acceptance range (ends included); None never does."""
        if measured is None:
            return False
        return (self.low is None or measured >= self.low) and (self.high is None or measured <= self.high)


def _claim(raw: Any) -> Claim:
    if not isinstance(raw, dict):
        raise TypeError(f"a claim must be a table, got {raw!r}")
    known = {f.name for f in fields(Claim)}
    unknown = sorted(set(raw) - known)
    if unknown:
        raise KeyError(f"unknown keys {unknown} in claim {raw.get('id')!r}")
    floats = {k: float(raw[k]) for k in ("value", "low", "high") if k in raw}
    return Claim(**{**raw, **floats})


def load(text: str | None = None) -> tuple[float, Mapping[str, Claim]]:
    """Read the paper's numbers.

    Args:
        text: TOML in the format of ``paper.toml``; default the packaged file.

    Returns:
        The median level [m] of Sec. III-A and the claims by id, in table order.

    Raises:
        GbPinError: the data is malformed.
    """
    if text is None:
        text = resources.files("gb_pin.reproduce").joinpath(DATA).read_text(encoding="utf-8")
    try:
        raw = tomllib.loads(text)
        level = float(raw["median_level"])
        claims = [_claim(c) for c in raw["claim"]]
    except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError) as exc:
        raise GbPinError(f"the paper's numbers ({DATA}) are malformed: {exc}") from exc
    by_id = {c.id: c for c in claims}
    if len(by_id) != len(claims):
        raise GbPinError(f"the paper's numbers ({DATA}) repeat a claim id")
    return level, MappingProxyType(by_id)


# MEDIAN_LEVEL [m]: Sec. III-A's "a median level of 0.04"; PAPER: every Claim by id, in table order.
MEDIAN_LEVEL, PAPER = load()
