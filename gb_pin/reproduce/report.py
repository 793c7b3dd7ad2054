"""What a reproduction writes besides the figures: CSV numbers, ``results.json`` and ``results.md``.

``results.md`` opens with the table "paper vs gb_pin" (:func:`paper_table`, the paper's side
from :mod:`gb_pin.reproduce.paper`), then every figure's numbers. Every file is written
atomically through :mod:`gb_pin._files`.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from typing import Any

from gb_pin._files import write_text
from gb_pin.exceptions import ResultFileError
from gb_pin.experiments._json import read_json
from gb_pin.experiments.trials import TrialSet
from gb_pin.reproduce.conditions import QUANTILES
from gb_pin.reproduce.paper import PAPER

FORMAT = "gb_pin.reproduction"  # the "format" of results.json


# -- CSV --------------------------------------------------------------------------------------------
def write_curves_csv(path: str, ts: TrialSet) -> str:
    """Figs. 4 and 7: the five quantiles of E^X and D^home at every recorded movement count."""
    e = ts.quantiles(QUANTILES, "error")
    d = ts.quantiles(QUANTILES, "home_distance")
    head = ["movements"] + [f"error_q{int(q * 100)}" for q in QUANTILES]
    head += [f"home_distance_q{int(q * 100)}" for q in QUANTILES]
    lines = [",".join(head)]
    for j, r in enumerate(ts.movements):
        vals = [f"{v:.6g}" for v in (*e[:, j], *d[:, j])]
        lines.append(",".join([str(int(r)), *vals]))
    write_text(path, "\n".join(lines) + "\n")
    return path


def write_rows_csv(path: str, key: str, xs: Sequence[float], rows: Sequence[dict[str, Any]]) -> str:
    """Figs. 5 and 8: per value of ``key``, S(Q, 0.1 E_0) (Eq. 11) and the final quantiles."""
    head = [key, "length", "initial_error"] + [f"S_{q:g}" for q in QUANTILES]
    head += [f"final_error_q{int(q * 100)}" for q in QUANTILES]
    head += [f"final_home_distance_q{int(q * 100)}" for q in QUANTILES]
    lines = [",".join(head)]
    for x, r in zip(xs, rows, strict=True):
        s = ["" if r["speed"][f"{q:g}"] is None else str(r["speed"][f"{q:g}"]) for q in QUANTILES]
        vals = [f"{v:.6g}" for v in (*r["final_error"], *r["final_home_distance"])]
        lines.append(",".join([f"{x:g}", str(r["length"]), f"{r['initial_error']:.6g}", *s, *vals]))
    write_text(path, "\n".join(lines) + "\n")
    return path


# -- results.json -----------------------------------------------------------------------------------
def read_numbers(path: str) -> dict[str, Any]:
    """The numbers of an earlier ``results.json`` (kept for figures not made again), or {}."""
    if not os.path.exists(path):
        return {}
    try:
        numbers = read_json(path).get("numbers", {})  # a regular file, in bounds
        return dict(numbers) if isinstance(numbers, dict) else {}
    except (ResultFileError, AttributeError):
        return {}


def write_results(out: str, numbers: dict[str, Any], meta: dict[str, Any]) -> list[str]:
    """Write ``OUT/results.json`` and ``OUT/results.md``; returns their paths."""
    results_path = os.path.join(out, "results.json")
    write_text(results_path, json.dumps({"format": FORMAT, "meta": meta, "numbers": numbers}, indent=1))
    md = os.path.join(out, "results.md")
    write_text(md, render_results(numbers, meta))
    return [results_path, md]


# -- the table "paper vs gb_pin" --------------------------------------------------------------------
def _fmt(v: Any, digits: int = 3) -> str:
    if v is None:
        return "not reached"
    if isinstance(v, float):
        return f"{v:.{digits}g}"
    return f"{v:,}" if isinstance(v, int) else str(v)


def _vs(v: Any, paper: float) -> str:
    """A number with its relative difference to the paper's, e.g. ``0.039 (-3 %)``."""
    if v is None:
        return "not reached"
    return f"{_fmt(v)} ({100.0 * (v - paper) / paper:+.0f} %)"


def _row(claim: str, run: str, value: Any = None, shown: str | None = None) -> list[str]:
    """A table row: quantity, paper, gb_pin (``shown``, else ``value`` vs the paper's), range, within, run."""
    c = PAPER[claim]
    if shown is None:
        assert c.value is not None, claim
        shown = _vs(value, c.value)
    within = "" if not c.bounded else ("yes" if c.accepts(value) else "no" if value is None else "**no**")
    return [c.quantity, c.paper, shown, c.range, within, run]


def _fig4_rows(f4: dict[str, Any]) -> list[list[str]]:
    c1, c01 = f4["curves"]["0.1"], f4["curves"]["0.01"]
    tr = f"{f4['settings']['trials']} trials"
    peak = (
        f"peak {c1['home_distance_median_peak']:.3f} rad at r = {c1['home_distance_median_peak_at']:,}, "
        f"{c1['final_home_distance'][2]:.3f} rad at r = {c1['final_movements']:,}"
    )
    return [
        _row("e100", tr, c1["median_error_at_100"]),
        _row("first_median_le_004", f"{tr}, run to {c01['length']:,}", c01["first_median_le_0.04"]),
        _row("speedup", tr, f4["speedup"]),
        _row("home_distance_peak", tr, shown=peak),
    ]


def _fig5_rows(f5: dict[str, Any]) -> list[list[str]]:
    r05 = dict(zip(f5["learning_rates"], f5["rows"], strict=True))[0.5]
    finals = [r["final_error"][2] for r in f5["rows"]]
    dh = [r["final_home_distance"][2] for r in f5["rows"]]
    fm = f5["rows"][0]["final_movements"]
    return [
        _row("s50_eta05", f"{f5['settings']['trials']} trials", r05["speed"]["0.5"]),
        _row(
            "fig5_final_error",
            "Fig. 5b",
            shown=f"{1000 * min(finals):.2f}-{1000 * max(finals):.1f} after {fm:,}",
        ),
        _row(
            "fig5_home_distance",
            f"after {fm:,}",
            shown=f"{dh[0]:.3f} rad at η 0.001 … {dh[-1]:.3f} rad at η 0.5",
        ),
    ]


def _fig8_rows(f8: dict[str, Any]) -> list[list[str]]:
    r50 = dict(zip(f8["joints"], f8["rows"], strict=True))[50]
    tr = f"{f8['settings']['trials']} trials"
    known = [s for s in (r["speed"]["0.5"] for r in f8["rows"]) if s is not None]
    finals = [r["final_error"][2] for r in f8["rows"]]
    fm = f8["rows"][0]["final_movements"]
    return [
        _row("s50_m50", tr, r50["speed"]["0.5"]),
        _row("s90_m50", tr, r50["speed"]["0.9"]),
        _row("fig8_speed_constant", tr, shown=f"{min(known)}-{max(known)}" if known else "not reached"),
        _row("fig8_final_error", tr, shown=f"{1000 * min(finals):.2f}-{1000 * max(finals):.2f} after {fm:,}"),
    ]


def paper_table(numbers: dict[str, Any]) -> list[list[str]]:
    """Rows of the table "paper vs gb_pin" from the numbers of the figures made so far.

    Args:
        numbers: per figure, the numbers of ``results.json``.

    Returns:
        Rows of quantity, the paper's number (:data:`gb_pin.reproduce.paper.PAPER`), gb_pin's
        (with its difference to the paper's), the issue's range, whether gb_pin's is within it,
        and the run it came from.
    """
    rows: list[list[str]] = []
    if numbers.get("fig4"):
        rows += _fig4_rows(numbers["fig4"])
    if numbers.get("fig5"):
        rows += _fig5_rows(numbers["fig5"])
    if numbers.get("fig8"):
        rows += _fig8_rows(numbers["fig8"])
    f7 = numbers.get("fig7")
    if f7:
        c20, c50 = f7["curves"]["20"], f7["curves"]["50"]
        shown = f"{c20['median_error_at_100']:.4f} vs {c50['median_error_at_100']:.4f}"
        rows.append(_row("fig7_identical", f"{f7['settings']['trials']} trials", shown=shown))
    tp = numbers.get("throughput")
    if tp:
        rows.append(
            _row("throughput", f"{tp['cpu_count']} cores", tp["wall_time"], shown=f"{tp['wall_time']:.1f}")
        )
    return rows


# -- results.md -------------------------------------------------------------------------------------
def _md_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def _speed_cells(row: dict[str, Any]) -> list[str]:
    return [_fmt(row["speed"][f"{q:g}"]) for q in QUANTILES]


def _curves_section(numbers: dict[str, Any]) -> list[str]:
    """Figs. 4 and 7: one row per curve."""
    rows = []
    for fig, key in (("fig4", "η"), ("fig7", "m")):
        for c in numbers.get(fig, {}).get("curves", {}).values():
            rows.append(
                [f"{c['robot']}, η {c['learning_rate']:g}" if key == "η" else f"{c['robot']}, η 0.1",
                 f"{c['initial_error']:.4f}", _fmt(c["median_error_at_100"]),
                 _fmt(c["first_median_le_0.04"]), *_speed_cells(c),
                 f"{1000 * c['final_error'][2]:.2f} ({c['final_movements']:,})",
                 f"{c['home_distance_median_peak']:.3f} @ {c['home_distance_median_peak_at']:,}",
                 f"{c['final_home_distance'][2]:.3f}"]
            )  # fmt: skip
    q_head = [f"S({q:g})" for q in QUANTILES]
    table = _md_table(
        ["condition", "E_0 [m]", "median E^X @100", "median ≤ 0.04 m at", *q_head,
         "final median E^X [mm] (at)", "peak median D^home [rad] @ r", "final median D^home"],
        rows,
    )  # fmt: skip
    return ["", "## Figs. 4 and 7: curves", "", table, "", "S(Q) is S(Q, 0.1 E_0) of Eq. 11 in movements."]


def _rows_section(fig: str, label: str, key: str, f: dict[str, Any]) -> list[str]:
    """Figs. 5 and 8: one row per learning rate or number of joints."""
    rows = []
    for x, r in zip(f[key], f["rows"], strict=True):
        rows.append(
            [f"{x:g}", f"{r['length']:,}", *_speed_cells(r),
             " / ".join(f"{1000 * r['final_error'][i]:.2f}" for i in (0, 2, 4)),
             " / ".join(f"{r['final_home_distance'][i]:.3f}" for i in (0, 2, 4))]
        )  # fmt: skip
    fm = f["rows"][0]["final_movements"]
    q_head = [f"S({q:g})" for q in QUANTILES]
    table = _md_table(
        ["η" if fig == "fig5" else "m", "run length", *q_head,
         f"E^X after {fm:,} [mm] (10/50/90 %)", f"D^home after {fm:,} [rad] (10/50/90 %)"],
        rows,
    )  # fmt: skip
    note = f"S(Q) is S(Q, 0.1 E_0) of Eq. 11 in movements, over {f['settings']['trials']} trials."
    return ["", f"## {label}", "", table, "", note]


def _snapshots_section(fig: str, f: dict[str, Any]) -> list[str]:
    """Figs. 3 and 6: E^X and D^home of the one trial at each snapshot."""
    table = _md_table(
        ["movements", "E^X [mm]", "D^home [rad]"],
        [[f"{s['movements']:,}", f"{1000 * s['error']:.2f}", f"{s['home_distance']:.3f}"]
         for s in f["snapshots"]],
    )  # fmt: skip
    return ["", f"## Fig. {fig[3:]}: one trial of {f['robot']} (seed {f['settings']['seed']})", "", table]


def render_results(numbers: dict[str, Any], meta: dict[str, Any]) -> str:
    """``results.md``: the paper-vs-gb_pin table, then every figure's numbers.

    Args:
        numbers: per figure, the numbers of ``results.json``.
        meta: ``command``, ``date`` and ``machine`` to cite, optionally ``timing`` (seconds per stage).
    """
    out = ["# gb_pin reproduction: numbers", ""]
    out.append(f"Written by `{meta['command']}` ({meta['date']}, {meta['machine']}).")
    out += ["", "## Paper vs gb_pin", ""]
    head = ["quantity", "paper", "gb_pin", "issue's range", "within", "run"]
    out.append(_md_table(head, paper_table(numbers)))
    figs = [f for f in ("fig3", "fig4", "fig5", "fig6", "fig7", "fig8") if f in numbers]
    if figs:
        out += ["", "## Figures", ""]
        for f in figs:
            out += [f"![{f}]({f}.png)", ""]
    if "fig4" in numbers or "fig7" in numbers:
        out += _curves_section(numbers)
    for fig, label, key in (
        ("fig5", "Fig. 5: learning rates", "learning_rates"),
        ("fig8", "Fig. 8: joints", "joints"),
    ):
        if fig in numbers:
            out += _rows_section(fig, label, key, numbers[fig])
    for fig in ("fig3", "fig6"):
        if fig in numbers:
            out += _snapshots_section(fig, numbers[fig])
    if "timing" in meta:
        out += ["", "## Wall time of this command", ""]
        out.append(_md_table(["stage", "seconds"], [[k, f"{v:.0f}"] for k, v in meta["timing"].items()]))
    return "\n".join(out) + "\n"
