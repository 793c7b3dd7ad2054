"""The entry point :func:`reproduce`: check the arguments, run (or read) the trials, make each figure, report.

The trials of every figure asked for run first, as one sweep (cached in ``OUT/trials/``);
then each figure is made from them in drawing order; last, ``results.json`` and
``results.md`` are written with the numbers of this call and those kept from earlier calls
into the same folder.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from datetime import UTC, datetime
from typing import Any

from gb_pin import _validation as check
from gb_pin._files import check_directory
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.experiments.trials import Condition, TrialSet
from gb_pin.reproduce.builders import figure4, figure5, figure7, figure8, throughput
from gb_pin.reproduce.cache import collect
from gb_pin.reproduce.conditions import Settings, conditions_for, expand
from gb_pin.reproduce.figures import require_matplotlib
from gb_pin.reproduce.report import read_numbers, write_results
from gb_pin.reproduce.snapshots import snapshot_figure

FORMATS = ("png", "svg", "pdf")
Builder = Callable[[], tuple[list[str], Any]]


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


def _check(names: Sequence[str], movements: int, formats: Sequence[str]) -> None:
    for ext in formats:
        if ext not in FORMATS:
            raise InvalidArgumentError(f"figure format must be png, svg or pdf, got {ext!r}")
    if any(n in ("fig4", "fig7", "fig3", "fig6") for n in names) and movements < 100:
        raise InvalidArgumentError(f"movements must be >= 100 for Figs. 3, 4, 6 and 7, got {movements}")


def _builders(
    data: dict[Condition, TrialSet], st: Settings, formats: Sequence[str], workers: int | None, scheduler: Any
) -> dict[str, Builder]:
    """Per figure name, the call that makes it (Fig. 3: planar5, Fig. 6: planar20)."""
    return {
        "fig3": lambda: snapshot_figure("fig3", "planar5", st, formats),
        "fig4": lambda: figure4(data, st, formats),
        "fig5": lambda: figure5(data, st, formats),
        "fig6": lambda: snapshot_figure("fig6", "planar20", st, formats),
        "fig7": lambda: figure7(data, st, formats),
        "fig8": lambda: figure8(data, st, formats),
        "throughput": lambda: throughput(st, workers, scheduler),
    }


def _meta(
    command: str | None, figures: Sequence[str], st: Settings, timing: dict[str, float]
) -> dict[str, Any]:
    """The command, date, machine and wall times cited in ``results.md``."""
    return {
        "command": command
        or f"gb-pin reproduce {' '.join(figures)} --trials {st.trials} --movements {st.movements} "
        f"--seed {st.seed} --out {st.out}",
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "timing": timing,
    }


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

    Raises:
        InvalidArgumentError: an unknown figure or format, or a bad count.
        GbPinError: matplotlib is missing (raised before any trial runs).
    """
    start = time.perf_counter()
    names = expand(figures)
    trials = check.positive_int("trials", trials)
    movements = check.positive_int("movements", movements)
    seed = check.positive_int("seed", seed, minimum=0)
    _check(names, movements, formats)
    require_matplotlib()
    check_directory(out, "out")
    st = Settings(trials=trials, movements=movements, seed=seed, out=os.fspath(out))
    os.makedirs(st.out, exist_ok=True)
    say = log or (lambda _line: None)
    timing: dict[str, float] = {}

    conditions = list(dict.fromkeys(c for n in names for c in conditions_for(n, movements)))
    data: dict[Condition, TrialSet] = {}
    if conditions:
        t0 = time.perf_counter()
        cache = os.path.join(st.out, "trials")
        say(f"trials: {len(conditions)} conditions x {trials} trials (cached ones are read from {cache})")
        data = collect(conditions, st, workers=workers, scheduler=scheduler, progress=progress, fresh=fresh)
        timing["trials"] = time.perf_counter() - t0

    numbers = read_numbers(os.path.join(st.out, "results.json"))
    files: list[str] = []
    builders = _builders(data, st, formats, workers, scheduler)
    for name in names:
        t0 = time.perf_counter()
        made, numbers[name] = builders[name]()
        timing[name] = time.perf_counter() - t0
        say(f"{name}: {', '.join(os.path.basename(f) for f in made) or 'measured'} ({timing[name]:.0f} s)")
        files += made
    timing["total"] = time.perf_counter() - start
    files += write_results(st.out, numbers, _meta(command, figures, st, timing))
    return Reproduction(files=tuple(files), numbers=numbers, wall_time=timing["total"])
