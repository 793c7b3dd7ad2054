"""Reproduce the paper's experiments (Sec. III, Figs. 3-8): trials, figures, numbers and a report.

``gb-pin reproduce all --trials 100 --out docs/figures`` runs every condition the
figures need as one sweep (:func:`gb_pin.run_sweep`, locally or on a Dask cluster),
then writes, for each figure, a PNG and an SVG in the paper's style (median bold,
10 % and 90 % quantiles thin, 25-75 % filled), the numbers as CSV and JSON, and
``results.md``: the table "paper vs gb_pin" and the run lengths each number used.

Run lengths. The paper runs 10^6 (Fig. 8) and 10^7 (Fig. 5) movements per trial for
its final errors; ``movements`` (default 10^4) sets ours. Fig. 5 runs each learning
rate eta < 0.01 for N * 0.01 / eta movements (the budget eta * r of eta = 0.01), so that
the slowest rates reach 10 % of the initial error at all; its final errors are read at ``movements``
for every rate. The raw trials are cached in ``OUT/trials/`` (git-ignored), so that
figures sharing a condition (e.g. planar5 at eta 0.1 in Figs. 4, 5 and 8) run it once.

Matplotlib is needed (``pip install "gb_pin[plots]"``); figures are drawn on
``matplotlib.figure.Figure`` objects with the Agg renderer, never through pyplot's
global state.
"""

from __future__ import annotations

import json
import math
import os
import platform
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import GbPinError, InvalidArgumentError, ResultFileError
from gb_pin.experiments.trials import Condition, TrialSet, run_sweep, run_trials
from gb_pin.learn.body.chain import body_forward
from gb_pin.learn.metrics import evaluation_schedule
from gb_pin.runs.api import babble

FIGURES = ("fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "throughput")
QUANTILES = (0.1, 0.25, 0.5, 0.75, 0.9)
LEARNING_RATES = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5)  # Fig. 5
JOINTS = (2, 3, 5, 7, 10, 15, 20, 30, 50)  # Fig. 8
SNAPSHOTS = (10, 100, 1000, 10000)  # Figs. 3 and 6
FIG4_RATES = (0.1, 0.01)
FIG7_ROBOTS = ("planar20", "planar50")
MEDIAN_LEVEL = 0.04  # [m], Sec. III-A: "a median level of 0.04"
PER_DECADE = 100  # recorded movement counts per decade beyond 1000 (every movement before)
COLORS = ("#1f4e9c", "#c0392b", "#2e8b57", "#8e44ad")

# The paper's numbers (Sec. III) and the acceptance ranges.
PAPER = {
    "e100": 0.04,
    "first_median_le_004": 2000,
    "speedup": 20,
    "s50_eta05": 34,
    "s50_m50": 128,
    "s90_m50": 364,
}


@dataclass(frozen=True)
class Settings:
    """What every statistic of a reproduction used.

    Attributes:
        trials: trials per condition (the paper: 100).
        movements: run length N of Figs. 4, 7, 8 and the length at which final errors
            are read (Fig. 5 runs low learning rates longer, see the module doc).
        seed: seed of trial 0 (trial i uses seed + i); also the seed of the snapshot trial.
        out: output folder.
    """

    trials: int = 100
    movements: int = 10_000
    seed: int = 0
    out: str = "reproduction"

    def as_dict(self) -> dict[str, Any]:
        """The settings as a plain dict."""
        return {"trials": self.trials, "movements": self.movements, "seed": self.seed}


@dataclass(frozen=True)
class Reproduction:
    """What :func:`reproduce` wrote and measured.

    Attributes:
        files: paths written (figures, CSV, JSON, ``results.md``).
        numbers: per figure, the numbers shown (also in ``OUT/results.json``).
        wall_time: seconds of the whole call [s].
    """

    files: tuple[str, ...]
    numbers: dict[str, Any] = field(default_factory=dict)
    wall_time: float = 0.0


# -- conditions -------------------------------------------------------------------------------------
def _schedule(length: int, also: int) -> tuple[int, ...]:
    at = evaluation_schedule(length, per_decade=PER_DECADE)
    if also < length:
        at = np.union1d(at, [also])
    return tuple(int(a) for a in at)


def fig5_length(learning_rate: float, movements: int) -> int:
    """Run length of Fig. 5 for a learning rate: N, and N * 0.01 / eta for eta < 0.01.

    Rates below 0.01 thus get the learning "budget" eta * r of eta = 0.01; at N = 10^4
    that is 100 / eta movements, which lets the slowest rates reach 10 % of E_0.
    """
    return max(movements, math.ceil(movements * 0.01 / learning_rate - 1e-9))


def conditions_for(figure: str, movements: int) -> list[Condition]:
    """The conditions a figure needs, with their run lengths and recorded movement counts."""

    def planar(robot: str, eta: float, length: int) -> Condition:
        return Condition(
            robot=robot,
            parameters={"learning_rate": eta},
            movements=length,
            schedule=_schedule(length, movements),
        )

    if figure == "fig4":
        return [planar("planar5", eta, movements) for eta in FIG4_RATES]
    if figure == "fig5":
        return [planar("planar5", eta, fig5_length(eta, movements)) for eta in LEARNING_RATES]
    if figure == "fig7":
        return [planar(r, 0.1, movements) for r in FIG7_ROBOTS]
    if figure == "fig8":
        return [planar(f"planar{m}", 0.1, movements) for m in JOINTS]
    return []


def _cache_path(out: str, condition: Condition, settings: Settings) -> str:
    params = "_".join(f"{k}-{v:g}" for k, v in sorted(condition.parameters.items()))
    name = f"{condition.robot}_{params}_n{condition.movements}_t{settings.trials}_s{settings.seed}.json"
    return os.path.join(out, "trials", name)


def collect(
    conditions: Sequence[Condition],
    settings: Settings,
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    fresh: bool = False,
) -> dict[Condition, TrialSet]:
    """Trials of every condition: read from ``OUT/trials/`` where cached, the rest run as one sweep."""
    cache_dir = os.path.join(settings.out, "trials")
    os.makedirs(cache_dir, exist_ok=True)
    ignore = os.path.join(cache_dir, ".gitignore")
    if not os.path.exists(ignore):
        with open(ignore, "w", encoding="utf-8") as fh:
            fh.write("# raw trials (several MB each): a cache of gb-pin reproduce, not committed\n*\n")
    found: dict[Condition, TrialSet] = {}
    missing: list[Condition] = []
    for c in dict.fromkeys(conditions):
        path = _cache_path(settings.out, c, settings)
        if not fresh and os.path.exists(path):
            try:
                ts = TrialSet.load(path)
            except ResultFileError:
                ts = None
            if (
                ts is not None
                and ts.trials == settings.trials
                and ts.seed == settings.seed
                and ts.parameters == dict(c.parameters)
                and c.schedule is not None
                and np.array_equal(ts.movements, c.schedule)
            ):
                found[c] = ts
                continue
        missing.append(c)
    if missing:
        sweep = run_sweep(
            missing,
            trials=settings.trials,
            movements=settings.movements,
            seed=settings.seed,
            workers=workers,
            scheduler=scheduler,
            progress=progress,
        )
        for c, ts in sweep:
            ts.save(_cache_path(settings.out, c, settings))
            found[c] = ts
    return found


# -- numbers ----------------------------------------------------------------------------------------
def _opt(value: Any) -> Any:
    return None if value is None else int(value)


def first_median_below(ts: TrialSet, level: float) -> int | None:
    """First recorded movement count at which the median E^X over trials is <= ``level`` [m]."""
    med = np.median(ts.error, axis=0)
    hit = np.flatnonzero(med <= level)
    return int(ts.movements[hit[0]]) if hit.size else None


def speeds(ts: TrialSet, fraction: float = 0.1) -> dict[str, int | None]:
    """S(Q, fraction * E_0) (Eq. 11) for the five quantiles Q."""
    return {f"{q:g}": _opt(ts.speed(q, fraction * ts.initial_error)) for q in QUANTILES}


def _quantiles_at(ts: TrialSet, movements: int, metric: str) -> list[float]:
    col = ts.at(movements)
    return [float(v) for v in np.quantile(getattr(ts, metric)[:, col], QUANTILES)]


def curve_numbers(ts: TrialSet, movements: int) -> dict[str, Any]:
    """The numbers of one E^X / D^home-over-movements curve (Figs. 4 and 7)."""
    med_d = np.median(ts.home_distance, axis=0)
    peak = int(np.argmax(med_d))
    out: dict[str, Any] = {
        "robot": ts.robot,
        "learning_rate": ts.parameters.get("learning_rate"),
        "length": int(ts.movements[-1]),
        "initial_error": ts.initial_error,
        "speed": speeds(ts),
        "median_error_at_100": float(np.median(ts.error[:, ts.at(100)])) if movements >= 100 else None,
        "first_median_le_0.04": first_median_below(ts, MEDIAN_LEVEL),
        "home_distance_median_peak": float(med_d[peak]),
        "home_distance_median_peak_at": int(ts.movements[peak]),
        "final_movements": movements,
        "final_error": _quantiles_at(ts, movements, "error"),
        "final_home_distance": _quantiles_at(ts, movements, "home_distance"),
    }
    return out


def row_numbers(ts: TrialSet, movements: int) -> dict[str, Any]:
    """The numbers of one point of Figs. 5 and 8: S(Q, 0.1 E_0), final E^X and D^home quantiles."""
    return {
        "robot": ts.robot,
        "learning_rate": ts.parameters.get("learning_rate"),
        "length": int(ts.movements[-1]),
        "initial_error": ts.initial_error,
        "speed": speeds(ts),
        "final_movements": movements,
        "final_error": _quantiles_at(ts, movements, "error"),
        "final_home_distance": _quantiles_at(ts, movements, "home_distance"),
        "end_error": [float(v) for v in np.quantile(ts.error[:, -1], QUANTILES)],
    }


# -- drawing ----------------------------------------------------------------------------------------
def _figure(width: float, height: float) -> Any:
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:
        raise GbPinError(
            f'drawing the figures needs matplotlib: pip install "gb_pin[plots]" ({exc})'
        ) from exc
    return Figure(figsize=(width, height), layout="constrained")


def _save(fig: Any, out: str, name: str, formats: Sequence[str]) -> list[str]:
    from matplotlib import rc_context

    paths = []
    # A fixed hash salt and no date keep the SVG identical across runs of the same numbers.
    with rc_context({"svg.hashsalt": "gb_pin", "svg.fonttype": "none"}):
        for ext in formats:
            path = os.path.join(out, f"{name}.{ext}")
            meta = {"Date": None} if ext == "svg" else {}
            fig.savefig(path, dpi=130, metadata=meta, bbox_inches="tight")
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


def _curves_figure(
    sets: Sequence[tuple[str, TrialSet]], title: str, out: str, name: str, formats: Sequence[str]
) -> list[str]:
    fig = _figure(10.0, 3.8)
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
    return _save(fig, out, name, formats)


def _rows_figure(
    xs: Sequence[float],
    rows: Sequence[dict[str, Any]],
    xlabel: str,
    log_x: bool,
    title: str,
    out: str,
    name: str,
    formats: Sequence[str],
) -> list[str]:
    fig = _figure(13.0, 3.8)
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
    return _save(fig, out, name, formats)


def _write_curves_csv(path: str, ts: TrialSet) -> str:
    e = ts.quantiles(QUANTILES, "error")
    d = ts.quantiles(QUANTILES, "home_distance")
    head = ["movements"] + [f"error_q{int(q * 100)}" for q in QUANTILES]
    head += [f"home_distance_q{int(q * 100)}" for q in QUANTILES]
    lines = [",".join(head)]
    for j, r in enumerate(ts.movements):
        vals = [f"{v:.6g}" for v in (*e[:, j], *d[:, j])]
        lines.append(",".join([str(int(r)), *vals]))
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


def _write_rows_csv(path: str, key: str, xs: Sequence[float], rows: Sequence[dict[str, Any]]) -> str:
    head = [key, "length", "initial_error"] + [f"S_{q:g}" for q in QUANTILES]
    head += [f"final_error_q{int(q * 100)}" for q in QUANTILES]
    head += [f"final_home_distance_q{int(q * 100)}" for q in QUANTILES]
    lines = [",".join(head)]
    for x, r in zip(xs, rows, strict=True):
        s = ["" if r["speed"][f"{q:g}"] is None else str(r["speed"][f"{q:g}"]) for q in QUANTILES]
        vals = [f"{v:.6g}" for v in (*r["final_error"], *r["final_home_distance"])]
        lines.append(",".join([f"{x:g}", str(r["length"]), f"{r['initial_error']:.6g}", *s, *vals]))
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")
    return path


# -- the figures ------------------------------------------------------------------------------------
def figure4(data: dict[Condition, TrialSet], st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 4: planar5, eta 0.1 and 0.01, E^X and D^home over movements."""
    conds = conditions_for("fig4", st.movements)
    files = []
    numbers: dict[str, Any] = {"settings": st.as_dict(), "curves": {}}
    sets = []
    for c in conds:
        ts = data[c]
        eta = c.parameters["learning_rate"]
        sets.append((f"η = {eta:g}", ts))
        numbers["curves"][f"{eta:g}"] = curve_numbers(ts, st.movements)
        files.append(_write_curves_csv(os.path.join(st.out, f"fig4_planar5_eta{eta:g}.csv"), ts))
    fast, slow = (numbers["curves"][f"{eta:g}"]["first_median_le_0.04"] for eta in FIG4_RATES)
    numbers["speedup"] = None if fast is None or slow is None else slow / fast
    title = f"Fig. 4: planar5, {st.trials} trials, learning rates 0.1 and 0.01"
    files += _curves_figure(sets, title, st.out, "fig4", formats)
    return files, numbers


def figure7(data: dict[Condition, TrialSet], st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 7: planar20 vs planar50 (sigma by Eq. 12), E^X and D^home over movements."""
    files = []
    numbers: dict[str, Any] = {"settings": st.as_dict(), "curves": {}}
    sets = []
    for c in conditions_for("fig7", st.movements):
        ts = data[c]
        m = c.robot.removeprefix("planar")
        sets.append((f"m = {m}", ts))
        numbers["curves"][m] = curve_numbers(ts, st.movements)
        files.append(_write_curves_csv(os.path.join(st.out, f"fig7_{c.robot}.csv"), ts))
    title = f"Fig. 7: 20 and 50 joints, η = 0.1, {st.trials} trials"
    files += _curves_figure(sets, title, st.out, "fig7", formats)
    return files, numbers


def figure5(data: dict[Condition, TrialSet], st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 5: S(Q, 0.1 E_0), final E^X and D^home over learning rates."""
    rows = [row_numbers(data[c], st.movements) for c in conditions_for("fig5", st.movements)]
    numbers = {"settings": st.as_dict(), "learning_rates": list(LEARNING_RATES), "rows": rows}
    files = [_write_rows_csv(os.path.join(st.out, "fig5.csv"), "learning_rate", LEARNING_RATES, rows)]
    title = f"Fig. 5: planar5, learning rates 0.001-0.5, {st.trials} trials"
    files += _rows_figure(LEARNING_RATES, rows, "learning rate η", True, title, st.out, "fig5", formats)
    return files, numbers


def figure8(data: dict[Condition, TrialSet], st: Settings, formats: Sequence[str]) -> tuple[list[str], Any]:
    """Fig. 8: S(Q, 0.1 E_0), final E^X and D^home over the number of joints m."""
    rows = [row_numbers(data[c], st.movements) for c in conditions_for("fig8", st.movements)]
    numbers = {"settings": st.as_dict(), "joints": list(JOINTS), "rows": rows}
    files = [_write_rows_csv(os.path.join(st.out, "fig8.csv"), "joints", JOINTS, rows)]
    title = f"Fig. 8: 2-50 joints, η = 0.1, σ by Eq. 12, {st.trials} trials"
    files += _rows_figure(JOINTS, rows, "joints m", False, title, st.out, "fig8", formats)
    return files, numbers


class _Snapshots:
    """A babble() observer that stores the inverse estimate g(X*) at given movement counts."""

    def __init__(self, at: Sequence[int]) -> None:
        self.at = set(at)
        self.postures: dict[int, NDArray[np.float64]] = {}
        self.targets: NDArray[np.float64] = np.empty((0, 2))

    def start(self, target: Any, targets: NDArray[np.float64]) -> None:
        self.targets = np.asarray(targets, dtype=float)

    def update(self, state: Any) -> None:
        if state.movements in self.at:
            self.postures[state.movements] = state.llm.predict(self.targets)


def arm_points(chain: Any, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Positions of every joint and of the effector on the task axes, (m + 1, n) [m].

    Computed by the compiled forward kinematics read from the Pinocchio model
    (:class:`~gb_pin.learn.body.chain.KinematicChain`): its workspace holds each joint's world position.
    """
    body = chain.kernel()
    tip = np.empty(chain.n_task)
    body_forward(np.ascontiguousarray(q, dtype=float), body, tip)
    pos_ws = body.pos_ws
    return np.vstack([pos_ws[:, chain.task_axes], tip])


def _grid_shape(X: NDArray[np.float64]) -> tuple[int, int] | None:
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


def snapshot_figure(
    figure: str,
    robot: str,
    st: Settings,
    formats: Sequence[str],
    at: Sequence[int] = SNAPSHOTS,
    learning_rate: float = 0.1,
) -> tuple[list[str], Any]:
    """Figs. 3 and 6: one trial after each count in ``at``: target grid, reached grid, postures."""
    at = sorted(check.positive_int("snapshot", a) for a in at)
    snaps = _Snapshots(at)
    step = math.gcd(*at)
    result = babble(
        robot,
        movements=at[-1],
        seed=st.seed,
        learning_rate=learning_rate,
        viewer=snaps,
        observe_every=step,
        schedule=[0, *at],
    )
    target = result.target
    X = snaps.targets
    shape = _grid_shape(X)
    rows, cols = shape if shape is not None else (1, X.shape[0])
    # Postures for a 3 x 3 subset of the grid (the paper shows "several" targets).
    pick = [
        i * cols + j
        for i in sorted({0, rows // 2, rows - 1})
        for j in sorted({0, cols // 2, cols - 1})
        if i * cols + j < X.shape[0]
    ]
    fig = _figure(3.4 * len(at), 3.9)
    axes = np.atleast_1d(fig.subplots(1, len(at), sharex=True, sharey=True))
    numbers: dict[str, Any] = {
        "settings": {**st.as_dict(), "trials": 1},
        "robot": robot,
        "learning_rate": learning_rate,
        "targets": X.tolist(),
        "snapshots": [],
    }
    home_pts = arm_points(target.chain, target.home)
    for ax, r in zip(axes, at, strict=True):
        Q = snaps.postures[r]
        reached = target.forward(target.clip(Q))
        error, home_distance = result.history.at(r)
        _draw_grid(ax, X, shape, color="0.7", linewidth=1.5)
        _draw_grid(ax, reached, shape, color="black", linewidth=0.9)
        ax.plot(home_pts[:, 0], home_pts[:, 1], color="0.6", linewidth=1.0, linestyle="--")
        for i in pick:
            pts = arm_points(target.chain, target.clip(Q[i]))
            ax.plot(pts[:, 0], pts[:, 1], color=COLORS[0], linewidth=1.1, alpha=0.8, marker=".", markersize=2)
        ax.plot([0.0], [0.0], "ks", markersize=5)
        ax.set_aspect("equal")
        ax.set_title(f"r = {r:,}: $E^X$ = {1000 * error:.1f} mm")
        ax.set_xlabel("x [m]")
        numbers["snapshots"].append(
            {
                "movements": r,
                "error": error,
                "home_distance": home_distance,
                "postures": Q.tolist(),
                "reached": reached.tolist(),
            }
        )
    axes[0].set_ylabel("y [m]")
    fig.suptitle(
        f"Fig. {figure[3:]}: one trial of {robot} (η = {learning_rate:g}, seed {st.seed})\n"
        "gray: targets X*, black: reached f(g(x*)), blue: postures g(x*), dashed: home posture"
    )
    files = _save(fig, st.out, figure, formats)
    path = os.path.join(st.out, f"{figure}.json")
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(numbers, fh)
    return [*files, path], {k: v for k, v in numbers.items() if k not in ("targets", "snapshots")} | {
        "snapshots": [
            {k: s[k] for k in ("movements", "error", "home_distance")} for s in numbers["snapshots"]
        ]
    }


def throughput(st: Settings, workers: int | None, scheduler: Any) -> tuple[list[str], Any]:
    """Wall time of 100 trials x 1000 movements of planar5 (the issue's benchmark), pool start included."""
    run_trials("planar2", trials=1, movements=1, workers=1)  # compile or load the kernels first
    start = time.perf_counter()
    ts = run_trials("planar5", trials=100, movements=1000, seed=st.seed, workers=workers, scheduler=scheduler)
    wall = time.perf_counter() - start
    return [], {
        "trials": ts.trials,
        "movements": 1000,
        "wall_time": wall,
        "workers": workers if scheduler is None else "dask",
        "cpu_count": os.cpu_count(),
        "steps_per_second": ts.trials * 1000 * 25 / wall,
    }


# -- the report -------------------------------------------------------------------------------------
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


def _within(v: Any, lo: float | None, hi: float | None) -> str:
    if v is None:
        return "no"
    ok = (lo is None or v >= lo) and (hi is None or v <= hi)
    return "yes" if ok else "**no**"


def paper_table(numbers: dict[str, Any]) -> list[list[str]]:
    """Rows of the table "paper vs gb_pin" from the numbers of the figures made so far."""
    rows: list[list[str]] = []
    f4 = numbers.get("fig4")
    if f4:
        n = f4["settings"]
        c1, c01 = f4["curves"]["0.1"], f4["curves"]["0.01"]
        tr = f"{n['trials']} trials"
        e100 = c1["median_error_at_100"]
        rows.append(
            ["planar5, η 0.1: median E^X after 100 movements [m]", "≈ 0.04",
             _vs(e100, 0.04), "[0.03, 0.055]", _within(e100, 0.03, 0.055), tr]
        )  # fmt: skip
        v = c01["first_median_le_0.04"]
        rows.append(
            ["planar5, η 0.01: first movement count with median E^X ≤ 0.04 m", "≈ 2000", _vs(v, 2000),
             "[1400, 3000]", _within(v, 1400, 3000), f"{tr}, run to {c01['length']:,}"]
        )  # fmt: skip
        rows.append(
            ["speed-up η 0.1 over η 0.01 (ratio of the counts to median 0.04 m)", "≈ 20",
             _vs(f4["speedup"], 20), "", "", tr]
        )  # fmt: skip
        rows.append(
            ["planar5, η 0.1: median D^home rises, then falls", "yes (Fig. 4b)",
             f"peak {c1['home_distance_median_peak']:.3f} rad at r = {c1['home_distance_median_peak_at']:,}, "
             f"{c1['final_home_distance'][2]:.3f} rad at r = {c1['final_movements']:,}", "", "", tr]
        )  # fmt: skip
    f5 = numbers.get("fig5")
    if f5:
        by_eta = dict(zip(f5["learning_rates"], f5["rows"], strict=True))
        r05 = by_eta[0.5]
        v = r05["speed"]["0.5"]
        rows.append(
            ["planar5, η 0.5: S(0.5, 0.1 E_0)", "34", _vs(v, 34), "≤ 55", _within(v, None, 55),
             f"{f5['settings']['trials']} trials"]
        )  # fmt: skip
        finals = [r["final_error"][2] for r in f5["rows"]]
        fm = f5["rows"][0]["final_movements"]
        rows.append(
            ["planar5, η 0.001-0.5: final median E^X [mm]", "mm range after 10^7 movements",
             f"{1000 * min(finals):.2f}-{1000 * max(finals):.1f} after {fm:,}", "", "",
             "Fig. 5b"]
        )  # fmt: skip
        dh = [r["final_home_distance"][2] for r in f5["rows"]]
        rows.append(
            ["planar5: final median D^home grows with η", "gradually (Fig. 5c)",
             f"{dh[0]:.3f} rad at η 0.001 … {dh[-1]:.3f} rad at η 0.5", "", "", f"after {fm:,}"]
        )  # fmt: skip
    f8 = numbers.get("fig8")
    if f8:
        by_m = dict(zip(f8["joints"], f8["rows"], strict=True))
        r50 = by_m[50]
        tr = f"{f8['settings']['trials']} trials"
        v = r50["speed"]["0.5"]
        rows.append(["planar50: S(0.5, 0.1 E_0)", "128", _vs(v, 128), "[95, 175]", _within(v, 95, 175), tr])
        v = r50["speed"]["0.9"]
        rows.append(["planar50: S(0.9, 0.1 E_0)", "364", _vs(v, 364), "≤ 500", _within(v, None, 500), tr])
        s50 = [r["speed"]["0.5"] for r in f8["rows"]]
        known = [s for s in s50 if s is not None]
        rows.append(
            ["S(0.5, 0.1 E_0) over m = 2…50", "virtually constant",
             f"{min(known)}-{max(known)}" if known else "not reached", "", "", tr]
        )  # fmt: skip
        finals = [r["final_error"][2] for r in f8["rows"]]
        fm = f8["rows"][0]["final_movements"]
        rows.append(
            ["final median E^X over m = 2…50 [mm]", "≈ 1 after 10^6 movements",
             f"{1000 * min(finals):.2f}-{1000 * max(finals):.2f} after {fm:,}", "", "", tr]
        )  # fmt: skip
    f7 = numbers.get("fig7")
    if f7:
        c20, c50 = f7["curves"]["20"], f7["curves"]["50"]
        rows.append(
            ["median E^X after 100 movements, m = 20 vs 50 [m]", "virtually identical (Fig. 7a)",
             f"{c20['median_error_at_100']:.4f} vs {c50['median_error_at_100']:.4f}", "", "",
             f"{f7['settings']['trials']} trials"]
        )  # fmt: skip
    tp = numbers.get("throughput")
    if tp:
        rows.append(
            ["100 trials x 1000 movements of planar5, wall time [s]", "", f"{tp['wall_time']:.1f}",
             "≤ 30", _within(tp["wall_time"], None, 30.0), f"{tp['cpu_count']} cores"]
        )  # fmt: skip
    return rows


def _md_table(head: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def _speed_cells(row: dict[str, Any]) -> list[str]:
    return [_fmt(row["speed"][f"{q:g}"]) for q in QUANTILES]


def render_results(numbers: dict[str, Any], meta: dict[str, Any]) -> str:
    """``results.md``: the paper-vs-gb_pin table, then every figure's numbers."""
    out = ["# gb_pin reproduction: numbers", ""]
    out.append(f"Written by `{meta['command']}` ({meta['date']}, {meta['machine']}).")
    out += ["", "## Paper vs gb_pin", ""]
    out.append(
        _md_table(
            ["quantity", "paper", "gb_pin", "issue's range", "within", "run"],
            paper_table(numbers),
        )
    )
    q_head = [f"S({q:g})" for q in QUANTILES]
    figs = [f for f in ("fig3", "fig4", "fig5", "fig6", "fig7", "fig8") if f in numbers]
    if figs:
        out += ["", "## Figures", ""]
        for f in figs:
            out += [f"![{f}]({f}.png)", ""]
    if "fig4" in numbers or "fig7" in numbers:
        out += ["", "## Figs. 4 and 7: curves", ""]
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
        out.append(
            _md_table(
                ["condition", "E_0 [m]", "median E^X @100", "median ≤ 0.04 m at", *q_head,
                 "final median E^X [mm] (at)", "peak median D^home [rad] @ r", "final median D^home"],
                rows,
            )
        )  # fmt: skip
        out.append("")
        out.append("S(Q) is S(Q, 0.1 E_0) of Eq. 11 in movements.")
    for fig, label, key in (
        ("fig5", "Fig. 5: learning rates", "learning_rates"),
        ("fig8", "Fig. 8: joints", "joints"),
    ):
        if fig not in numbers:
            continue
        f = numbers[fig]
        out += ["", f"## {label}", ""]
        rows = []
        for x, r in zip(f[key], f["rows"], strict=True):
            rows.append(
                [f"{x:g}", f"{r['length']:,}", *_speed_cells(r),
                 " / ".join(f"{1000 * r['final_error'][i]:.2f}" for i in (0, 2, 4)),
                 " / ".join(f"{r['final_home_distance'][i]:.3f}" for i in (0, 2, 4))]
            )  # fmt: skip
        fm = f["rows"][0]["final_movements"]
        out.append(
            _md_table(
                ["η" if fig == "fig5" else "m", "run length", *q_head,
                 f"E^X after {fm:,} [mm] (10/50/90 %)", f"D^home after {fm:,} [rad] (10/50/90 %)"],
                rows,
            )
        )  # fmt: skip
        out.append("")
        out.append(f"S(Q) is S(Q, 0.1 E_0) of Eq. 11 in movements, over {f['settings']['trials']} trials.")
    for fig in ("fig3", "fig6"):
        if fig in numbers:
            f = numbers[fig]
            out += ["", f"## Fig. {fig[3:]}: one trial of {f['robot']} (seed {f['settings']['seed']})", ""]
            out.append(
                _md_table(
                    ["movements", "E^X [mm]", "D^home [rad]"],
                    [[f"{s['movements']:,}", f"{1000 * s['error']:.2f}", f"{s['home_distance']:.3f}"]
                     for s in f["snapshots"]],
                )
            )  # fmt: skip
    if "timing" in meta:
        out += ["", "## Wall time of this command", ""]
        out.append(_md_table(["stage", "seconds"], [[k, f"{v:.0f}"] for k, v in meta["timing"].items()]))
    return "\n".join(out) + "\n"


# -- entry point ------------------------------------------------------------------------------------
def expand(figures: Sequence[str]) -> list[str]:
    """Figure names in drawing order; ``"all"`` stands for every figure and the throughput benchmark."""
    names: list[str] = []
    for f in figures:
        if f == "all":
            names += list(FIGURES)
        elif f in FIGURES:
            names.append(f)
        else:
            raise InvalidArgumentError(f"unknown figure {f!r}; valid: {', '.join(FIGURES)}, all")
    if not names:
        raise InvalidArgumentError(f"name at least one figure: {', '.join(FIGURES)} or all")
    return list(dict.fromkeys(names))


def reproduce(
    figures: Sequence[str] = ("all",),
    *,
    out: str = "reproduction",
    trials: int = 100,
    movements: int = 10_000,
    seed: int = 0,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    fresh: bool = False,
    formats: Sequence[str] = ("png", "svg"),
    command: str | None = None,
    log: Callable[[str], Any] | None = None,
) -> Reproduction:
    """Reproduce the paper's figures into ``out``.

    Args:
        figures: names among ``fig3``, ``fig4``, ``fig5``, ``fig6``, ``fig7``, ``fig8``,
            ``throughput``, or ``all``.
        out: output folder (created).
        trials: trials per condition (the paper: 100).
        movements: run length N; final errors are read at N (the paper: 10^6-10^7).
        seed: seed of trial 0 (trial i uses seed + i).
        workers: local processes (default all cores).
        scheduler: a Dask scheduler address or client to run the trials on.
        progress: progress bar.
        fresh: ignore cached trials in ``out/trials``.
        formats: figure file formats.
        command: the command line to cite in ``results.md``.
        log: called with one line per stage (e.g. ``print``).

    Returns:
        A :class:`Reproduction` listing the files written.
    """
    start = time.perf_counter()
    names = expand(figures)
    trials = check.positive_int("trials", trials)
    movements = check.positive_int("movements", movements)
    seed = check.positive_int("seed", seed, minimum=0)
    for ext in formats:
        if ext not in ("png", "svg", "pdf"):
            raise InvalidArgumentError(f"figure format must be png, svg or pdf, got {ext!r}")
    if any(n in ("fig4", "fig7", "fig3", "fig6") for n in names) and movements < 100:
        raise InvalidArgumentError(f"movements must be >= 100 for Figs. 3, 4, 6 and 7, got {movements}")
    _figure(1, 1)  # fail early if matplotlib is missing
    st = Settings(trials=trials, movements=movements, seed=seed, out=os.fspath(out))
    os.makedirs(st.out, exist_ok=True)
    say = log or (lambda _line: None)
    timing: dict[str, float] = {}

    conditions = [c for n in names for c in conditions_for(n, movements)]
    data: dict[Condition, TrialSet] = {}
    if conditions:
        t0 = time.perf_counter()
        unique = list(dict.fromkeys(conditions))
        say(f"trials: {len(unique)} conditions x {trials} trials (cached ones are read from {st.out}/trials)")
        data = collect(unique, st, workers=workers, scheduler=scheduler, progress=progress, fresh=fresh)
        timing["trials"] = time.perf_counter() - t0

    results_path = os.path.join(st.out, "results.json")
    numbers: dict[str, Any] = {}
    if os.path.exists(results_path):
        try:
            with open(results_path, encoding="utf-8") as fh:
                numbers = dict(json.load(fh).get("numbers", {}))
        except (OSError, ValueError, AttributeError):
            numbers = {}
    files: list[str] = []
    builders: dict[str, Callable[[], tuple[list[str], Any]]] = {
        "fig3": lambda: snapshot_figure("fig3", "planar5", st, formats),
        "fig4": lambda: figure4(data, st, formats),
        "fig5": lambda: figure5(data, st, formats),
        "fig6": lambda: snapshot_figure("fig6", "planar20", st, formats),
        "fig7": lambda: figure7(data, st, formats),
        "fig8": lambda: figure8(data, st, formats),
        "throughput": lambda: throughput(st, workers, scheduler),
    }
    for name in names:
        t0 = time.perf_counter()
        made, nums = builders[name]()
        timing[name] = time.perf_counter() - t0
        say(f"{name}: {', '.join(os.path.basename(f) for f in made) or 'measured'} ({timing[name]:.0f} s)")
        files += made
        numbers[name] = nums
    timing["total"] = time.perf_counter() - start
    meta = {
        "command": command
        or f"gb-pin reproduce {' '.join(figures)} --trials {trials} --movements {movements} --seed {seed} "
        f"--out {st.out}",
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "timing": timing,
    }
    with open(results_path, "w", encoding="utf-8") as fh:
        json.dump({"format": "gb_pin.reproduction", "meta": meta, "numbers": numbers}, fh, indent=1)
    md = os.path.join(st.out, "results.md")
    with open(md, "w", encoding="utf-8") as fh:
        fh.write(render_results(numbers, meta))
    files += [results_path, md]
    return Reproduction(files=tuple(files), numbers=numbers, wall_time=timing["total"])
