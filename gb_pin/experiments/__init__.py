"""Experiments on top of single runs: independent trials, sweeps, benchmarks.

- :mod:`~gb_pin.experiments.trials`: the public names of trials and sweeps
  (:func:`run_trials`, :func:`run_sweep`, :class:`TrialSet`, :class:`Condition`,
  :class:`Sweep`, :func:`conditions_grid`, :class:`TrialJournal`), defined in
  :mod:`~gb_pin.experiments.trialset`, :mod:`~gb_pin.experiments.conditions`,
  :mod:`~gb_pin.experiments.journal` and :mod:`~gb_pin.experiments.execute`;
- :mod:`~gb_pin.experiments.distributed`: the same on a Dask cluster (``scheduler=``);
- :mod:`~gb_pin.experiments.bench`: ``gb-pin bench``, microseconds per step;
- :mod:`~gb_pin.experiments.robot_bench`: the results table of ``docs/ROBOTS.md``.

The names are exported lazily (PEP 562), as by :mod:`gb_pin`: importing this package
loads neither pinocchio, Dask nor matplotlib.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gb_pin._lazy import lazy_exports

# public name -> the module that defines it
_EXPORTS: dict[str, str] = {
    "TrialSet": "gb_pin.experiments.trialset",
    "BABBLE_ARGS": "gb_pin.experiments.conditions",
    "Condition": "gb_pin.experiments.conditions",
    "Sweep": "gb_pin.experiments.conditions",
    "conditions_grid": "gb_pin.experiments.conditions",
    "TrialJournal": "gb_pin.experiments.journal",
    "run_sweep": "gb_pin.experiments.execute",
    "run_trials": "gb_pin.experiments.execute",
}

__all__ = [
    "BABBLE_ARGS",
    "Condition",
    "Sweep",
    "TrialJournal",
    "TrialSet",
    "conditions_grid",
    "run_sweep",
    "run_trials",
]


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # what the lazy exports resolve to, for type checkers
    from gb_pin.experiments.conditions import BABBLE_ARGS, Condition, Sweep, conditions_grid
    from gb_pin.experiments.execute import run_sweep, run_trials
    from gb_pin.experiments.journal import TrialJournal
    from gb_pin.experiments.trialset import TrialSet
