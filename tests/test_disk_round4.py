"""Writes on a full disk: gb_pin's own error naming the file (and still an OSError for fallbacks)."""

from __future__ import annotations

import errno
from pathlib import Path
from typing import Any

import pytest

import gb_pin
from gb_pin.exceptions import FileWriteError


def test_an_explicit_checkpoint_on_a_full_disk_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    session = gb_pin.babble_session("planar5", movements=20, seed=0)
    session.tell(session.target.forward(session.ask()))

    def full(path: Any, state: Any, info: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("gb_pin.runs.checkpoint.write_checkpoint", full)
    where = tmp_path / "run.ckpt"
    with pytest.raises(
        FileWriteError, match=r"cannot write the checkpoint .*run.ckpt.*No space left"
    ) as info:
        session.save_checkpoint(where)
    assert isinstance(info.value, OSError) and info.value.errno == errno.ENOSPC


def test_reproduce_journals_a_conditions_trials_beside_its_cache_file(tmp_path: Path) -> None:
    """Ctrl-C after some trials: the finished ones are in the journal a rerun reads; removed once cached."""
    from gb_pin.experiments.conditions import Condition
    from gb_pin.experiments.journal import TrialJournal
    from gb_pin.reproduce import goals

    cond = Condition(robot="planar2", movements=20, schedule=(10, 20))
    ts = goals.run_condition(str(tmp_path), "tiny", cond, trials=2, seed=0, workers=1, progress=False)
    cache = Path(goals._cache_file(str(tmp_path), "tiny", cond, 2, 0))
    journal = Path(str(cache)[: -len(".json")] + ".journal.jsonl")
    assert cache.exists() and not journal.exists() and ts.trials == 2
    cache.unlink()
    calls = []
    real = goals.run_sweep

    def interrupted(*args: Any, **kwargs: Any) -> Any:
        calls.append(kwargs["checkpoint"])
        real(*args, **{**kwargs, "trials": 1})  # one trial finishes and is journaled ...
        raise KeyboardInterrupt  # ... then Ctrl-C

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(goals, "run_sweep", interrupted)
        with pytest.raises(KeyboardInterrupt):
            goals.run_condition(str(tmp_path), "tiny", cond, trials=2, seed=0, workers=1, progress=False)
    assert calls == [str(journal)] and len(TrialJournal(journal).done) == 1
