"""Drawing the figures in the paper's style; the only module of gb_pin that imports matplotlib.

Quantiles over trials are drawn as in the paper's Figs. 4, 5, 7 and 8: median bold, 10 %
and 90 % thin, 25-75 % filled. Figures are ``matplotlib.figure.Figure`` objects with the
Agg renderer, never pyplot's global state; matplotlib is imported inside the functions,
so that importing :mod:`gb_pin.reproduce` does not load it. Every file is written through
:func:`gb_pin._files.atomic_write`.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._files import atomic_write
from gb_pin.exceptions import GbPinError
from gb_pin.experiments.trials import TrialSet
from gb_pin.reproduce.conditions import QUANTILES

COLORS = ("#1f4e9c", "#c0392b", "#2e8b57", "#8e44ad")


def new_figure(width: float, height: float) -> Any:
    """A ``matplotlib.figure.Figure`` of ``width`` x ``height`` inches, constrained layout.

    Raises:
        GbPinError: matplotlib is not installed.
    """
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise GbPinError(
            f'drawing the figures needs matplotlib: pip install "gb_pin[plots]" ({exc})'
        ) from exc
    return Figure(figsize=(width, height), layout="constrained")


def require_matplotlib() -> None:
    """Fail early, before any trial runs, if matplotlib is missing (raises :class:`GbPinError`)."""
    new_figure(1, 1)


def save_figure(fig: Any, out: str, name: str, formats: Sequence[str]) -> list[str]:
    """Write ``fig`` as ``OUT/name.EXT`` for each format (png, svg, pdf); returns the paths."""
    from matplotlib import rc_context

    paths = []
    # A fixed hash salt and no date keep the SVG identical across runs of the same numbers.
    with rc_context({"svg.hashsalt": "gb_pin", "svg.fonttype": "none"}):
        for ext in formats:
            path = os.path.join(out, f"{name}.{ext}")
            meta = {"Date": None} if ext == "svg" else {}
            with atomic_write(path) as fh:
                fig.savefig(fh, format=ext, dpi=130, metadata=meta, bbox_inches="tight")
            paths.append(path)
    return paths


def quantile_band(
    ax: Any, x: NDArray[Any], q: NDArray[np.float64], color: str, label: str, marker: str | None = None
) -> None:
    """Draw quantiles (5, T) in the paper's style: median bold, 10/90 % thin, 25-75 % filled."""
    ax.fill_between(x, q[1], q[3], color=color, alpha=0.25, linewidth=0)
    ax.plot(x, q[0], color=color, linewidth=0.7)
    ax.plot(x, q[4], color=color, linewidth=0.7)
    ax.plot(x, q[2], color=color, linewidth=2.2, label=label, marker=marker, markersize=4)


def draw_curves(
    sets: Sequence[tuple[str, TrialSet]], title: str, out: str, name: str, formats: Sequence[str]
) -> list[str]:
    """Figs. 4 and 7: (a) E^X and (b) D^home over movements, one band per labelled condition."""
    fig = new_figure(10.0, 3.8)
    axes = fig.subplots(1, 2)
    for k, (label, ts) in enumerate(sets):
        x = ts.movements[1:]  # movement 0 has no place on a log axis
        color = COLORS[k % len(COLORS)]
        quantile_band(axes[0], x, ts.quantiles(QUANTILES, "error")[:, 1:], color, label)
        quantile_band(axes[1], x, ts.quantiles(QUANTILES, "home_distance")[:, 1:], color, label)
    axes[0].set_yscale("log")
    axes[0].set_ylabel("performance error $E^X_r$ [m]")
    axes[1].set_ylabel("distance from home $D^{home}_r$ [rad]")
    for ax, letter in zip(axes, "ab", strict=True):
        ax.set_xscale("log")
        ax.set_xlabel("movements r")
        ax.grid(True, which="major", alpha=0.3)
        ax.set_title(f"({letter})", loc="left")
        ax.legend()
    fig.suptitle(title)
    return save_figure(fig, out, name, formats)


def draw_rows(
    xs: Sequence[float],
    rows: Sequence[dict[str, Any]],
    xlabel: str,
    log_x: bool,
    title: str,
    out: str,
    name: str,
    formats: Sequence[str],
) -> list[str]:
    """Figs. 5 and 8: (a) S(Q, 0.1 E_0) of Eq. 11, (b) final E^X, (c) final D^home over a parameter."""
    fig = new_figure(13.0, 3.8)
    axes = fig.subplots(1, 3)
    x = np.asarray(xs, dtype=float)
    s = np.array(
        [[np.nan if r["speed"][f"{q:g}"] is None else r["speed"][f"{q:g}"] for r in rows] for q in QUANTILES]
    )
    final_movements = rows[0]["final_movements"]
    quantile_band(axes[0], x, s, COLORS[0], "S(0.5, 0.1 $E_0$)", "o")
    quantile_band(axes[1], x, np.array([r["final_error"] for r in rows]).T, COLORS[0], "median", "o")
    quantile_band(axes[2], x, np.array([r["final_home_distance"] for r in rows]).T, COLORS[0], "median", "o")
    axes[0].set_yscale("log")
    axes[0].set_ylabel("movements to 10 % of $E_0$: S(Q, 0.1 $E_0$)")
    axes[1].set_yscale("log")
    axes[1].set_ylabel(f"$E^X$ after {final_movements:,} movements [m]")
    axes[2].set_ylabel(f"$D^{{home}}$ after {final_movements:,} movements [rad]")
    for ax, letter in zip(axes, "abc", strict=True):
        if log_x:
            ax.set_xscale("log")
        ax.set_xlabel(xlabel)
        ax.grid(True, which="major", alpha=0.3)
        ax.set_title(f"({letter})", loc="left")
    fig.suptitle(title)
    return save_figure(fig, out, name, formats)


class Panel(NamedTuple):
    """One panel of Figs. 3 and 6: the learner after ``movements`` movements.

    Attributes:
        movements: the movement count r.
        error: E^X_r [m].
        reached: (targets, 2) effector positions f(g(x*)) [m].
        arms: for a few targets, the (m + 1, 2) joint positions of the posture g(x*) [m].
    """

    movements: int
    error: float
    reached: NDArray[np.float64]
    arms: Sequence[NDArray[np.float64]]


def grid_shape(X: NDArray[np.float64]) -> tuple[int, int] | None:
    """(rows, cols) if X is a full grid listed with the first axis slowest, else None."""
    if X.shape[1] != 2:
        return None
    nx, ny = len(np.unique(X[:, 0])), len(np.unique(X[:, 1]))
    if nx * ny != X.shape[0]:
        return None
    g = X.reshape(nx, ny, 2)
    if np.ptp(g[:, :, 0], axis=1).max() > 1e-12 or np.ptp(g[:, :, 1], axis=0).max() > 1e-12:
        return None
    return nx, ny


def _draw_grid(ax: Any, P: NDArray[np.float64], shape: tuple[int, int] | None, **style: Any) -> None:
    if shape is None:
        ax.plot(P[:, 0], P[:, 1], "o", markersize=3, **style)
        return
    g = P.reshape(shape[0], shape[1], 2)
    for i in range(shape[0]):
        ax.plot(g[i, :, 0], g[i, :, 1], **style)
    for j in range(shape[1]):
        ax.plot(g[:, j, 0], g[:, j, 1], **style)


def draw_snapshots(
    panels: Sequence[Panel],
    targets: NDArray[np.float64],
    home: NDArray[np.float64],
    title: str,
    out: str,
    name: str,
    formats: Sequence[str],
) -> list[str]:
    """Figs. 3 and 6: per panel, the target grid (gray), the reached grid (black), postures (blue).

    Args:
        panels: one per movement count, left to right.
        targets: (targets, 2) the targets X* [m].
        home: (m + 1, 2) joint positions of the home posture [m], drawn dashed.
        title: the figure's title.
        out: output folder.
        name: file name without extension.
        formats: file formats.
    """
    shape = grid_shape(targets)
    fig = new_figure(3.4 * len(panels), 3.9)
    axes = np.atleast_1d(fig.subplots(1, len(panels), sharex=True, sharey=True))
    for ax, panel in zip(axes, panels, strict=True):
        _draw_grid(ax, targets, shape, color="0.7", linewidth=1.5)
        _draw_grid(ax, panel.reached, shape, color="black", linewidth=0.9)
        ax.plot(home[:, 0], home[:, 1], color="0.6", linewidth=1.0, linestyle="--")
        for pts in panel.arms:
            ax.plot(pts[:, 0], pts[:, 1], color=COLORS[0], linewidth=1.1, alpha=0.8, marker=".", markersize=2)
        ax.plot([0.0], [0.0], "ks", markersize=5)
        ax.set_aspect("equal")
        ax.set_title(f"r = {panel.movements:,}: $E^X$ = {1000 * panel.error:.1f} mm")
        ax.set_xlabel("x [m]")
    axes[0].set_ylabel("y [m]")
    fig.suptitle(title)
    return save_figure(fig, out, name, formats)


def log_norm(vmin: float, vmax: float) -> Any:
    """A logarithmic colour scale from ``vmin`` to ``vmax`` (``matplotlib.colors.LogNorm``)."""
    from matplotlib.colors import LogNorm

    return LogNorm(vmin=vmin, vmax=vmax)


def no_minor_ticks(axis: Any) -> None:
    """Remove the minor ticks of one axis (``ax.xaxis``), e.g. when its major ticks are set by hand."""
    from matplotlib.ticker import NullLocator

    axis.set_minor_locator(NullLocator())
