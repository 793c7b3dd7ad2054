"""Learning curves of one run or of trials: E^X and D^home over movements, in the paper's style.

:func:`plot_result` draws one run (``BabbleResult.plot``, ``gb-pin plot run.npz``);
:func:`plot_quantiles` the median and quartiles of trials (``TrialSet.plot``,
``gb-pin plot trials.json``), as the paper's Figs. 4 and 7: (a) E^X [m] and (b) D^home [rad]
over movements r, log axes, median bold, 25-75 % filled, 10 % and 90 % thin.

matplotlib (the ``plots`` extra) is imported inside the functions only, so importing this module,
or :mod:`gb_pin.runs.result`, does not load it; figures are ``matplotlib.figure.Figure`` objects
with the Agg renderer (never pyplot's global state), written through :func:`gb_pin._files.atomic_write`.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from gb_pin._files import atomic_write
from gb_pin._names import printable
from gb_pin.exceptions import GbPinError, InvalidArgumentError

if TYPE_CHECKING:
    from gb_pin.learn.history import History
    from gb_pin.runs.result import BabbleResult

ERROR_COLOR = "#1f4e9c"
HOME_COLOR = "#c0392b"
#: Quantiles drawn for trials: 10 %, 25 %, median, 75 %, 90 %.
QUANTILES = (0.1, 0.25, 0.5, 0.75, 0.9)
FORMATS = ("png", "svg", "pdf")


def _figure(width: float, height: float) -> Any:
    """A constrained-layout ``Figure`` (Agg); GbPinError naming the ``plots`` extra without matplotlib."""
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise GbPinError(f"plotting needs matplotlib: pip install 'gb_pin[plots]' ({exc})") from exc
    return Figure(figsize=(width, height), layout="constrained")


def _axes(ax: Any) -> tuple[Any, Any, Any]:
    """(figure, E^X axes, D^home axes): two panels of a new figure, or ``ax`` and its twin."""
    if ax is None:
        fig = _figure(10.0, 3.8)
        left, right = fig.subplots(1, 2)
        return fig, left, right
    _figure(1, 1)  # the same error as without ``ax`` if matplotlib is missing
    return ax.figure, ax, ax.twinx()


def _style(err_ax: Any, home_ax: Any, twin: bool) -> None:
    """Log axes, units and grids of the two curves (E^X with nothing positive to show stays linear)."""
    err_ax.set_xscale("log")
    if _positive(err_ax):
        err_ax.set_yscale("log")
    err_ax.set_xlabel("movements r")
    err_ax.set_ylabel("performance error $E^X$ [m]", color=ERROR_COLOR if twin else "black")
    home_ax.set_ylabel("distance from home $D^{home}$ [rad]", color=HOME_COLOR if twin else "black")
    err_ax.grid(True, which="major", alpha=0.3)
    if not twin:
        home_ax.set_xscale("log")
        home_ax.set_xlabel("movements r")
        home_ax.grid(True, which="major", alpha=0.3)
        err_ax.set_title("(a)", loc="left")
        home_ax.set_title("(b)", loc="left")


def _positive(ax: Any) -> bool:
    """Whether the curves drawn on ``ax`` have a positive finite value (a log axis needs one)."""
    for line in ax.get_lines():
        y = np.asarray(line.get_ydata(), dtype=float)
        if np.any(np.isfinite(y) & (y > 0)):
            return True
    return False


def _finish(
    fig: Any, axes: tuple[Any, Any], title: str, path: str | os.PathLike[str] | None, twin: bool
) -> Any:
    """Legends, the title, and the file if ``path`` is given; returns the figure."""
    err_ax, home_ax = axes
    if twin:
        lines = err_ax.get_lines() + home_ax.get_lines()
        labelled = [ln for ln in lines if not ln.get_label().startswith("_")]
        # On the twin (drawn above the first axes), where E^X has fallen and D^home not yet risen.
        home_ax.legend(
            labelled,
            [ln.get_label() for ln in labelled],
            fontsize=8,
            loc="lower center",
            ncol=2,
            framealpha=0.9,
        )
        err_ax.set_title(title, fontsize=10)
    else:
        err_ax.legend(fontsize=8, loc="lower left")
        home_ax.legend(fontsize=8, loc="lower right")
        fig.suptitle(title)
    if path is not None:
        save_figure(fig, path)
    return fig


def save_figure(fig: Any, path: str | os.PathLike[str]) -> str:
    """Write ``fig`` atomically; the format is the extension's (png, svg or pdf). Returns the path.

    Raises:
        InvalidArgumentError: another extension.
    """
    path = os.fspath(path)
    ext = os.path.splitext(path)[1][1:].lower()
    if ext not in FORMATS:
        raise InvalidArgumentError(f"figure path {path!r}: the extension must be one of {', '.join(FORMATS)}")
    meta = {"Date": None} if ext == "svg" else {}
    with atomic_write(path) as fh:
        fig.savefig(fh, format=ext, dpi=130, metadata=meta)
    return path


def plot_result(result: BabbleResult, path: str | os.PathLike[str] | None = None, ax: Any = None) -> Any:
    """E^X and D^home of one run over movements (log axes), titled with robot, movements and final E^X.

    See :func:`plot_history` (``result``'s history, robot name and movements).
    """
    name = result.robot or result.target.name
    return plot_history(result.history, name, result.movements, path, ax, initial_error=result.initial_error)


def plot_history(
    history: History,
    name: str,
    movements: int,
    path: str | os.PathLike[str] | None = None,
    ax: Any = None,
    initial_error: float | None = None,
) -> Any:
    """E^X and D^home of one run over movements (log axes), titled with robot, movements and final E^X.

    Args:
        history: the run's E^X and D^home (:class:`~gb_pin.learn.history.History`).
        name: the robot's name, for the title.
        movements: movements run, for the title.
        path: write the figure there (``.png``, ``.svg`` or ``.pdf``), if given.
        ax: draw into these matplotlib axes (E^X on them, D^home on a twin axis); default: a new
            figure with two panels.
        initial_error: E_0 [m] when the history does not start from the home estimate (a run that
            continued another: :attr:`BabbleResult.initial_error`); default the history's movement 0.

    Returns:
        The ``matplotlib.figure.Figure``.

    Raises:
        GbPinError: matplotlib is not installed (``pip install 'gb_pin[plots]'``).
    """
    h = history
    keep = h.movements > 0  # movement 0 has no place on a log axis
    x = h.movements[keep]
    fig, err_ax, home_ax = _axes(ax)
    twin = ax is not None
    e0 = (
        h.initial_error if initial_error is None else initial_error
    )  # NaN if movement 0 was not recorded; 0 if home reaches every target
    err_ax.plot(x, h.error[keep], color=ERROR_COLOR, lw=2.0, label="$E^X$")
    if e0 > 0:  # on a log axis, E_0 = 0 has no place (and no ratio)
        err_ax.axhline(e0, color="0.4", lw=0.8, ls="--", label=f"$E_0$ = {e0:.3g} m")
        err_ax.axhline(0.1 * e0, color="0.4", lw=0.8, ls=":", label="0.1 $E_0$")
        share = f"{float(h.error[-1]) / e0:.1%} of $E_0$"
    else:
        share = "$E_0$ = 0" if e0 == 0 else "$E_0$ not recorded"
    home_ax.plot(x, h.home_distance[keep], color=HOME_COLOR, lw=2.0, label="$D^{home}$")
    _style(err_ax, home_ax, twin)
    error, home = float(h.error[-1]), float(h.home_distance[-1])
    title = (
        f"{printable(name, 80)}: {movements} movements, final $E^X$ = {error:.4g} m "
        f"({share}), $D^{{home}}$ = {home:.3g} rad"
    )
    return _finish(fig, (err_ax, home_ax), title, path, twin)


def quantile_band(ax: Any, x: NDArray[Any], q: NDArray[np.float64], color: str, label: str) -> None:
    """Quantiles (5, T) of :data:`QUANTILES`: median bold, 25-75 % filled, 10 % and 90 % thin."""
    ax.fill_between(x, q[1], q[3], color=color, alpha=0.25, linewidth=0, label=f"{label} 25-75 %")
    ax.plot(x, q[0], color=color, linewidth=0.7, label=f"{label} 10 %, 90 %")
    ax.plot(x, q[4], color=color, linewidth=0.7)
    ax.plot(x, q[2], color=color, linewidth=2.2, label=f"{label} median")


def plot_quantiles(
    title: str,
    movements: NDArray[np.int64],
    error: NDArray[np.float64],
    home_distance: NDArray[np.float64],
    path: str | os.PathLike[str] | None = None,
    ax: Any = None,
) -> Any:
    """Median and quartiles over trials of E^X and D^home (10 % and 90 % thin), log axes.

    Args:
        title: the figure's title (robot, trials, parameters).
        movements: (T,) recorded movement counts.
        error: (trials, T) E^X [m].
        home_distance: (trials, T) D^home [rad].
        path: write the figure there (``.png``, ``.svg`` or ``.pdf``), if given.
        ax: draw into these axes (E^X on them, D^home on a twin axis); default: two panels.

    Returns:
        The ``matplotlib.figure.Figure``.

    Raises:
        GbPinError: matplotlib is not installed (``pip install 'gb_pin[plots]'``).
        InvalidArgumentError: arrays of inconsistent shapes.
    """
    mv = np.asarray(movements)
    err, home = np.atleast_2d(error), np.atleast_2d(home_distance)
    if err.shape != home.shape or err.shape[1:] != mv.shape:
        raise InvalidArgumentError(
            f"error {err.shape}, home_distance {home.shape} and movements {mv.shape} do not match"
        )
    keep = mv > 0
    fig, err_ax, home_ax = _axes(ax)
    quantile_band(err_ax, mv[keep], np.quantile(err[:, keep], QUANTILES, axis=0), ERROR_COLOR, "$E^X$")
    quantile_band(home_ax, mv[keep], np.quantile(home[:, keep], QUANTILES, axis=0), HOME_COLOR, "$D^{home}$")
    _style(err_ax, home_ax, ax is not None)
    return _finish(fig, (err_ax, home_ax), title, path, ax is not None)
