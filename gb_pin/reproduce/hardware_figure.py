"""The tables and figures of ``gb-pin reproduce hardware`` (:mod:`gb_pin.reproduce.hardware`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from gb_pin.reproduce.figures import new_figure, save_figure

WAYS = (("urdf", "exact IK on the URDF", "#7f8c8d"), ("open", "learned inverse, open loop", "#1f4e9c"),
        ("feedback", "learned + feedback (5 readings)", "#2e8b57"))  # fmt: skip


def _per_arm(rows: Sequence[dict[str, Any]], way: str, at: str, stat: int = 0) -> np.ndarray:
    """Each arm's median (stat 0) or 90 % (stat 1) error [m] of one way to reach, at ``at`` movements."""
    if way == "urdf":
        return np.array([r["urdf"][stat] for r in rows])
    return np.array([r[way][at][stat] for r in rows if at in r[way]])


def _groups(rows: Sequence[dict[str, Any]]) -> dict[tuple[str, float, float], list[dict[str, Any]]]:
    out: dict[tuple[str, float, float], list[dict[str, Any]]] = {}
    for r in rows:
        c = r["condition"]
        out.setdefault((c["robot"], c["noise"], c["loss"]), []).append(r)
    return out


def _cell(group: Sequence[dict[str, Any]], way: str, at: str) -> str:
    med = 1000 * np.median(_per_arm(group, way, at, 0))
    q90 = 1000 * np.median(_per_arm(group, way, at, 1))
    return f"{med:.2f} / {q90:.2f}"


def tables(rows: Sequence[dict[str, Any]]) -> tuple[str, str]:
    """(markdown, csv): per robot and tracker, the median over arms of each arm's median / 90 % error [mm]."""
    snapshots = sorted({int(k) for r in rows for k in r["open"]})
    md = ["| robot | tracker noise | lost | arms | URDF IK | " + " | ".join(
        f"learned @{s:,} | feedback @{s:,}" for s in snapshots) + " |"]  # fmt: skip
    md.append("|" + "---|" * (5 + 2 * len(snapshots)))
    csv = ["robot,noise_mm,loss,arms,way,movements,median_mm,q90_mm,observed_reach_mm,prototypes"]
    for (robot, noise, loss), group in _groups(rows).items():
        cells = [robot, f"{noise * 1000:g} mm", f"{loss:.0%}", str(len(group))]
        cells.append(_cell(group, "urdf", ""))
        for s in snapshots:
            cells += [_cell(group, "open", str(s)), _cell(group, "feedback", str(s))]
        md.append("| " + " | ".join(cells) + " |")
        prefix = f"{robot},{noise * 1000:g},{loss:g},{len(group)}"
        csv.append(f"{prefix},urdf,,{1000 * np.median(_per_arm(group, 'urdf', '', 0)):.4f},"
                   f"{1000 * np.median(_per_arm(group, 'urdf', '', 1)):.4f},,")  # fmt: skip
        for way in ("open", "feedback"):
            for s in snapshots:
                reach = 1000 * np.median([g["reach"][str(s)] for g in group])
                protos = np.median([g["prototypes"][str(s)] for g in group])
                med = 1000 * np.median(_per_arm(group, way, str(s), 0))
                q90 = 1000 * np.median(_per_arm(group, way, str(s), 1))
                csv.append(f"{prefix},{way},{s},{med:.4f},{q90:.4f},{reach:.4f},{protos:g}")
    note = (
        "\nEach cell: the median over the arms of each arm's median / 90 % reach error on the 27-point "
        "test grid [mm], measured on the true (mis-calibrated) body.\n"
    )
    return "\n".join(md) + "\n" + note, "\n".join(csv) + "\n"


FLOOR = 0.05  # [mm]: errors below are drawn on the floor (feedback from exact readings reaches ~1e-5 mm)


def draw_robot(rows: Sequence[dict[str, Any]], robot: str, out: str) -> list[str]:
    """One panel per tracker noise: median reach error over movements, URDF IK vs learned vs feedback.

    Solid lines: no lost readings; dashed: 10 % lost. The band spans the arms' 25-75 % of the panel's
    first loss level (solid lines, or the dashed ones where no condition lost none); exact IK on the
    URDF reads no tracker, so it is drawn once per panel, whatever the losses.
    """
    import textwrap

    groups = {(n, p): g for (r, n, p), g in _groups(rows).items() if r == robot}
    noises = sorted({n for n, _ in groups})
    snapshots = sorted({int(k) for r in rows for k in r["open"]})
    width = max(3.6 * len(noises) + 0.6, 7.0)  # one panel: wide enough for the title and the legend
    fig = new_figure(width, 4.6)
    axes = np.atleast_1d(fig.subplots(1, len(noises), sharey=True))
    arms = max(len(g) for g in groups.values())
    for ax, noise in zip(axes, noises, strict=True):
        losses = sorted(p for n, p in groups if n == noise)
        for loss in losses:
            _draw_group(ax, groups[(noise, loss)], snapshots, loss, first=loss == losses[0])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(FLOOR * 0.8, 80)
        ax.set_xlabel("goal-babbling movements on the arm")
        ax.set_title(f"tracker noise {noise * 1000:g} mm per axis" if noise else "exact tracker", fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
        ax.axhline(1.0, color="k", lw=0.6, alpha=0.5)
    axes[0].set_ylabel("reach error on the true arm [mm]\n(median over the 27 test points; arms' median)")
    handles, labels = axes[0].get_legend_handles_labels()
    handles.append(axes[0].fill_between([], [], color="0.5", alpha=0.25, lw=0))  # the band's legend key
    labels.append(f"band: 25-75 % of the {arms} arms")
    fig.legend(
        handles, labels, loc="outside lower center", ncol=3 if len(noises) > 1 else 2, fontsize=8,
        frameon=False, handlelength=4.0,  # long enough to show a dashed line's dashes
    )  # fmt: skip
    title = (
        f"{robot}: {arms} mis-calibrated arms (joint offsets 3 deg, links 3 %), measured on the true arm; "
        f"points at the bottom: below {FLOOR:g} mm"
    )
    fig.suptitle("\n".join(textwrap.wrap(title, int(13 * width))), fontsize=10)
    return save_figure(fig, out, f"hardware_{robot}", ("png",))


def _draw_group(
    ax: Any, group: Sequence[dict[str, Any]], snapshots: list[int], loss: float, first: bool = True
) -> None:
    """One loss level of a panel; ``first``: the panel's first level, which draws URDF IK and the bands."""
    style: Any = "-" if loss == 0 else (0, (4, 2))
    for way, label, color in WAYS:
        if way == "urdf":
            if not first:
                continue  # exact IK does not read the tracker: once per panel
            per = _per_arm(group, way, "")
            y = np.full(len(snapshots), np.median(per))
            lo, hi = np.full_like(y, np.quantile(per, 0.25)), np.full_like(y, np.quantile(per, 0.75))
        else:
            cols = [_per_arm(group, way, str(s)) for s in snapshots]
            y = np.array([np.median(c) for c in cols])
            lo = np.array([np.quantile(c, 0.25) for c in cols])
            hi = np.array([np.quantile(c, 0.75) for c in cols])
        name = label if loss == 0 or way == "urdf" else f"{label}, {loss:.0%} of readings lost"
        shown = np.maximum(1000 * y, FLOOR)
        ax.plot(snapshots, shown, linestyle="-" if way == "urdf" else style, color=color, lw=2, marker="o",
                ms=4, label=name)  # fmt: skip
        if first:
            ax.fill_between(snapshots, np.maximum(1000 * lo, FLOOR), np.maximum(1000 * hi, FLOOR),
                            color=color, alpha=0.15, lw=0)  # fmt: skip


def acceptance(rows: Sequence[dict[str, Any]], robot: str, at: int = 3000) -> dict[str, float]:
    """Medians over arms at 1.5 mm / 10 % lost: learned open loop and URDF IK [m], their ratio."""
    group = [r for r in rows if r["condition"]["robot"] == robot and r["condition"]["noise"] == 0.0015
             and r["condition"]["loss"] == 0.1]  # fmt: skip
    learned = float(np.median(_per_arm(group, "open", str(at))))
    urdf = float(np.median(_per_arm(group, "urdf", "")))
    return {"learned": learned, "urdf": urdf, "ratio": urdf / learned if learned > 0 else math.inf}
