"""The table and figures of ``gb-pin reproduce workspace`` (:mod:`gb_pin.reproduce.workspace`).

Per robot one figure a user reads at a glance: the test points of the region f = 0.5 seen from
above and from the side, each coloured by its reach error after 10^4 movements (seed 0; the colour
scale logarithmic from 1 mm to 10 cm, the home position marked), and the median and 90 % error over
movements for every fraction (the line the median over seeds, the band their 25-75 %).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from gb_pin.reproduce.figures import log_norm, new_figure, no_minor_ticks, save_figure

SHOWN_FRACTION = 0.5
SHOWN_COUNT = "10000"
COLOURS = {0.25: "#2e8b57", 0.5: "#1f4e9c", 1.0: "#b03a2e"}


def _groups(rows: Sequence[dict[str, Any]]) -> dict[tuple[str, float], list[dict[str, Any]]]:
    out: dict[tuple[str, float], list[dict[str, Any]]] = {}
    for r in rows:
        c = r["condition"]
        out.setdefault((c["robot"], float(c["fraction"])), []).append(r)
    return out


def _stat(group: Sequence[dict[str, Any]], at: str, key: str) -> np.ndarray:
    return np.array([r["snapshots"][at][key] for r in group if at in r["snapshots"]], dtype=float)


def table(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown: per robot and fraction, over seeds, median (and range) of each run's median / 90 % [mm]."""
    snapshots = sorted({int(k) for r in rows for k in r["snapshots"]})
    head = ["robot", "f", "seeds", "parts", "L [m]", "radius [m]"] + [
        f"@{s:,}: median / 90 % [mm]" for s in snapshots
    ]
    head += [f"@{snapshots[-1]:,}: within 1 cm / 2 mm", "K", "CPU s / run"]
    md = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for (robot, f), group in _groups(rows).items():
        radius = float(np.median([g["radius"] for g in group]))
        extent = float(np.median([g.get("extent", g["radius"] / 0.08) for g in group]))
        parts = "/".join(str(p) for p in sorted({int(g.get("parts", 1)) for g in group}))
        cells = [robot, f"{f:g}", str(len(group)), parts, f"{extent:.2f}", f"{radius:.3f}"]
        for s in snapshots:
            med, p90 = 1000 * _stat(group, str(s), "median"), 1000 * _stat(group, str(s), "p90")
            cells.append(f"{np.median(med):.2f} / {np.median(p90):.1f} "
                         f"({med.min():.2f}-{med.max():.2f} / {p90.min():.0f}-{p90.max():.0f})")  # fmt: skip
        last = str(snapshots[-1])
        cover = np.array([g["snapshots"][last]["coverage"] for g in group if last in g["snapshots"]])
        cells.append(f"{np.median(cover[:, 0]):.1%} / {np.median(cover[:, 1]):.1%}")
        cells.append(f"{np.median(_stat(group, last, 'prototypes')):.0f}")
        cells.append(f"{np.median([g['cpu_seconds'] for g in group]):.1f}")
        md.append("| " + " | ".join(cells) + " |")
    note = (
        "\nEach cell: the median over the seeds of each run's median / 90 % reach error on 300 test points "
        "of the region (never learnt), with the range over the seeds in brackets. L: the extent of the goal "
        "region (diagonal of its 5-95 % box); parts: learners (parts=auto); K: prototypes of all parts.\n"
    )
    return "\n".join(md) + "\n" + note


def _parts_drawn(robot: str, run: dict[str, Any], X: np.ndarray) -> Any:
    """(the part homes' hand positions (P, 3), the cuts as segments) of a run in parts, else None."""
    parts = int(run.get("parts", 1))
    if parts < 2:
        return None
    from gb_pin.robot.presets import load_robot
    from gb_pin.robot.workspace import WorkspaceRegion
    from gb_pin.robot.workspace_parts import region_parts

    arm = load_robot(robot)
    split = region_parts(arm, WorkspaceRegion(run["condition"]["fraction"], parts=parts))
    o, u, v, edges = split.sectors
    reach = float(np.max(np.linalg.norm(X - o, axis=1)))
    cuts = [(o, o + reach * (np.cos(a) * u + np.sin(a) * v)) for a in (*edges, np.pi)]
    return arm.forward(split.homes), cuts


def draw_robot(
    rows: Sequence[dict[str, Any]], robot: str, out: str, formats: Sequence[str] = ("png",)
) -> list[str]:
    """Top view, side view (test points coloured by error) and the curves of one robot; returns the files."""
    groups = {f: g for (r, f), g in _groups(rows).items() if r == robot}
    fig = new_figure(13.5, 4.2)
    ax_top, ax_side, ax_curve = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1, 1, 1.15]})
    shown = sorted(
        groups.get(SHOWN_FRACTION, next(iter(groups.values()))), key=lambda r: r["condition"]["seed"]
    )[0]
    at = SHOWN_COUNT if SHOWN_COUNT in shown["snapshots"] else max(shown["snapshots"], key=int)
    X = np.asarray(shown["test"])
    e = np.asarray(shown["snapshots"][at]["errors"]) * 1000
    home = np.asarray(shown["home_position"])
    order = np.argsort(e)  # the worst points drawn last, on top
    parted = _parts_drawn(robot, shown, X)
    norm = log_norm(1.0, 100.0)
    for ax, (i, j), title in ((ax_top, (0, 1), "top view (x, y)"), (ax_side, (0, 2), "side view (x, z)")):
        colour = np.clip(e[order], 1.0, 100.0)
        sc = ax.scatter(
            X[order, i], X[order, j], c=colour, cmap="viridis_r", norm=norm, s=14, edgecolors="none"
        )
        ax.plot(*home[[i, j]], marker="*", color="#b03a2e", markersize=13, linestyle="none", label="home")
        ax.plot(0.0, 0.0, marker="+", color="k", markersize=10, linestyle="none", label="base origin")
        if parted is not None:
            homes, cuts = parted
            ax.plot(homes[:, i], homes[:, j], marker="*", color="#e67e22", markersize=10, linestyle="none",
                    markeredgecolor="k", markeredgewidth=0.5, label="part homes")  # fmt: skip
            if j == 1:  # the cuts between the parts, seen from above
                for c, (start, end) in enumerate(cuts):
                    ax.plot([start[0], end[0]], [start[1], end[1]], color="#e67e22", linewidth=1.2,
                            linestyle="--", label=None if c else "cuts between parts")  # fmt: skip
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]" if j == 1 else "z [m]")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
    ax_top.legend(loc="best", fontsize=8)
    bar = fig.colorbar(sc, ax=[ax_top, ax_side], location="bottom", shrink=0.6, pad=0.02, aspect=40)
    bar.set_label(f"reach error after {int(at):,} movements [mm]")
    for f, group in sorted(groups.items()):
        counts = sorted({int(k) for g in group for k in g["snapshots"]})
        colour = COLOURS.get(f, "#555555")
        for key, style, label in (("median", "-", "median"), ("p90", "--", "90 %")):
            per = np.array([[1000 * g["snapshots"][str(c)][key] for c in counts] for g in group])
            ax_curve.plot(counts, np.median(per, axis=0), style, color=colour, marker="o", markersize=3,
                          label=f"f = {f:g}, {label}")  # fmt: skip
            ax_curve.fill_between(counts, *np.percentile(per, [25, 75], axis=0), color=colour, alpha=0.15)
    ax_curve.set_xscale("log")
    ax_curve.set_yscale("log")
    shown_counts = sorted({int(k) for g in rows for k in g["snapshots"]})
    ax_curve.set_xticks(shown_counts, [f"{c:,}" for c in shown_counts])
    no_minor_ticks(ax_curve.xaxis)
    ax_curve.set_xlabel("movements")
    ax_curve.set_ylabel("reach error on the test points [mm]")
    ax_curve.grid(alpha=0.3, which="both")
    ax_curve.legend(fontsize=8)
    seeds = len(groups.get(SHOWN_FRACTION, next(iter(groups.values()))))
    ax_curve.set_title(f"over {seeds} seeds (line: median, band: 25-75 %)", fontsize=10)
    fig.suptitle(f"{robot}: half of every joint's range (f = {shown['condition']['fraction']:g}), "
                 f"300 test points, seed {shown['condition']['seed']}", fontsize=11)  # fmt: skip
    return save_figure(fig, out, f"workspace_{robot}", formats)
