"""Writes on a full disk: gb_pin's own error naming the file (and still an OSError for fallbacks)."""

from __future__ import annotations

import errno
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from test_kept_work import _full_under  # fsync fails with ENOSPC under a folder: a full disk

import gb_pin
from gb_pin.exceptions import FileWriteError

_REAL_FSYNC = __import__("os").fsync


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


def test_reproduce_on_a_disk_that_fills_keeps_every_finished_trial_for_the_rerun(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The journal moves to its fallback (named in the warning); the rerun reads it and computes nothing."""
    from gb_pin.experiments import execute
    from gb_pin.experiments.conditions import Condition
    from gb_pin.experiments.journal import fallback_journals
    from gb_pin.reproduce import goals

    out, here = tmp_path / "out", tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    monkeypatch.setenv("GB_PIN_CACHE", str(tmp_path / "cache"))
    cond = Condition(robot="planar2", movements=20, schedule=(10, 20))
    ran: list[int] = []
    real = execute.run_one_trial

    def counted(*task: Any) -> Any:
        ran.append(task[2])
        if len(ran) == 2:  # the disk fills after the first trial was journaled
            _full_under(monkeypatch, out)
        return real(*task)

    monkeypatch.setattr(execute, "run_one_trial", counted)
    with pytest.warns(gb_pin.GbPinWarning) as caught:
        first = goals.run_condition(str(out), "tiny", cond, trials=3, seed=0, workers=1, progress=False)
    cache = Path(goals._cache_file(str(out), "tiny", cond, 3, 0))
    journal = str(cache)[: -len(".json")] + ".journal.jsonl"
    moved = fallback_journals(journal)[0]
    said = " ".join(str(w.message) for w in caught)
    assert f"are in {moved!r}" in said and "a rerun with the same journal reads them" in said
    assert not cache.exists() and len(ran) == 3  # the cache file went to the current directory ...
    assert (here / cache.name).exists()  # ... (save_or_fallback), and the journal was kept
    assert len(Path(moved).read_text().splitlines()) == 1 + 3
    import os

    monkeypatch.setattr(os, "fsync", _REAL_FSYNC)  # the disk has room again
    again = goals.run_condition(str(out), "tiny", cond, trials=3, seed=0, workers=1, progress=False)
    assert len(ran) == 3  # every trial read back, none recomputed
    np.testing.assert_array_equal(again.error, first.error)
    assert cache.exists() and not os.path.exists(journal) and not os.path.exists(moved)


def test_a_journal_that_cannot_be_created_starts_in_its_fallback(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from gb_pin.experiments.journal import TrialJournal, fallback_journals

    monkeypatch.setenv("GB_PIN_CACHE", str(tmp_path / "cache"))
    disk = tmp_path / "disk"
    disk.mkdir()
    _full_under(monkeypatch, disk)
    with pytest.warns(gb_pin.GbPinWarning, match="cannot create the trial journal .*a rerun"):
        journal = TrialJournal(disk / "j.jsonl")
    assert journal.writing == fallback_journals(disk / "j.jsonl")[0]
