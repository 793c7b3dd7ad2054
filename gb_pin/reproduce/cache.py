"""The cache of raw trials in ``OUT/trials/``: figures sharing a condition run it once.

A condition's trials (e.g. planar5 at eta 0.1, used by Figs. 4, 5 and 8) are saved as a
:class:`~gb_pin.experiments.trials.TrialSet` JSON file named after the condition and the
settings; a later reproduction with the same settings reads it instead of running the
trials again. The folder holds a ``.gitignore`` (the files are several MB each).
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

from gb_pin._files import save_or_fallback, write_json, write_text
from gb_pin.exceptions import ResultFileError
from gb_pin.experiments.trials import Condition, TrialSet, run_sweep
from gb_pin.reproduce.conditions import Settings

GITIGNORE = "# raw trials (several MB each): a cache of gb-pin reproduce, not committed\n*\n"


def cache_path(out: str, condition: Condition, settings: Settings) -> str:
    """Path of a condition's cached trials in ``OUT/trials/``.

    E.g. ``OUT/trials/planar5_learning_rate-0.1_n10000_t100_s0.json``.

    Args:
        out: output folder.
        condition: the condition (robot, parameters, run length).
        settings: trials and seed.
    """
    params = "_".join(f"{k}-{v:g}" for k, v in sorted(condition.parameters.items()))
    name = f"{condition.robot}_{params}_n{condition.movements}_t{settings.trials}_s{settings.seed}.json"
    return os.path.join(out, "trials", name)


def cached(condition: Condition, settings: Settings) -> TrialSet | None:
    """The cached trials of a condition, or None if missing, unreadable or run with other settings."""
    path = cache_path(settings.out, condition, settings)
    if not os.path.exists(path):
        return None
    try:
        ts = TrialSet.load(path)
    except ResultFileError:
        return None
    if (
        ts.trials == settings.trials
        and ts.seed == settings.seed
        and ts.parameters == dict(condition.parameters)
        and condition.schedule is not None
        and np.array_equal(ts.movements, condition.schedule)
    ):
        return ts
    return None


def collect(
    conditions: Sequence[Condition],
    settings: Settings,
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = False,
    fresh: bool = False,
) -> dict[Condition, TrialSet]:
    """Trials of every condition: read from ``OUT/trials/`` where cached, the rest run as one sweep.

    Args:
        conditions: the conditions (repeats are run once).
        settings: trials, seed and output folder.
        workers: local processes for the sweep (default all cores).
        scheduler: a Dask scheduler address or client to run the sweep on.
        progress: progress bar.
        fresh: ignore the cache (and overwrite it).

    Returns:
        The trials of each condition.
    """
    cache_dir = os.path.join(settings.out, "trials")
    os.makedirs(cache_dir, exist_ok=True)
    ignore = os.path.join(cache_dir, ".gitignore")
    if not os.path.exists(ignore):
        write_text(ignore, GITIGNORE)
    found: dict[Condition, TrialSet] = {}
    missing: list[Condition] = []
    for c in dict.fromkeys(conditions):
        ts = None if fresh else cached(c, settings)
        if ts is None:
            missing.append(c)
        else:
            found[c] = ts
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
            save_or_fallback(cache_path(settings.out, c, settings), ts.save, "the trials")  # never lost
            found[c] = ts
    return found


def run_cached(
    out: str,
    todo: Sequence[Any],
    filename: Callable[[Any], str],
    run: Callable[[Any], dict[str, Any]],
    workers: int | None,
    fresh: bool,
    progress: bool,
) -> dict[Any, dict[str, Any]]:
    """Each condition's summary, read from ``OUT/trials/FILENAME`` or run in worker processes and saved.

    The studies of one summary per condition (``reproduce hardware``, ``reproduce workspace``) share
    it: a cached file is read unless ``fresh``; the rest run in a process pool, each saved as it
    ends, so an interrupted study resumes from its last finished condition. ``run`` must be a
    module-level function (it is sent to the workers).
    """
    cache = os.path.join(out, "trials")
    os.makedirs(cache, exist_ok=True)
    write_text(os.path.join(cache, ".gitignore"), GITIGNORE)
    results: dict[Any, dict[str, Any]] = {}
    missing = []
    for cond in todo:
        path = os.path.join(cache, filename(cond))
        if not fresh and os.path.exists(path):
            with open(path, encoding="utf-8") as f:
                results[cond] = json.load(f)
        else:
            missing.append(cond)
    if missing:
        with ProcessPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
            futures = {cond: pool.submit(run, cond) for cond in missing}
            for i, (cond, future) in enumerate(futures.items()):
                results[cond] = future.result()
                write_json(os.path.join(cache, filename(cond)), results[cond])
                if progress:
                    print(f"  {i + 1}/{len(futures)} {cond.key}", flush=True)
    return results
