"""Independent trials and sweeps of goal babbling, run in parallel on local cores or on a Dask cluster.

This module gathers the public names of the experiment layer, defined by concept in:

- :mod:`~gb_pin.experiments.trialset`: :class:`TrialSet`, the trials of one condition;
- :mod:`~gb_pin.experiments.conditions`: :class:`Condition`, :func:`conditions_grid`,
  :class:`Sweep` and :data:`BABBLE_ARGS` (the hyperparameter table's names);
- :mod:`~gb_pin.experiments.journal`: :class:`TrialJournal`, finished trials on disk;
- :mod:`~gb_pin.experiments.execute`: :func:`run_trials`, :func:`run_sweep` and the
  executors (one process, a local process pool, or Dask via
  :mod:`~gb_pin.experiments.distributed`).

Trial i of a condition uses seed ``seed + i``, so a set of trials gives the same
numbers whatever runs it.
"""

from __future__ import annotations

from gb_pin.experiments.conditions import BABBLE_ARGS, Condition, Sweep, conditions_grid
from gb_pin.experiments.execute import resolve_schedule, run_one_trial, run_sweep, run_trials
from gb_pin.experiments.journal import TrialJournal, TrialOutput, TrialTask
from gb_pin.experiments.trialset import TrialSet

__all__ = [
    "BABBLE_ARGS",
    "Condition",
    "Sweep",
    "TrialJournal",
    "TrialOutput",
    "TrialSet",
    "TrialTask",
    "conditions_grid",
    "resolve_schedule",
    "run_one_trial",
    "run_sweep",
    "run_trials",
]
