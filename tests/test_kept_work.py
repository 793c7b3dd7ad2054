"""Reliability, third round (issue 24): no finished work lost to a failed write, processes, the viewer server.

Classes 4 (a write that fails after the work goes elsewhere, said where), 5 (killed writers,
Ctrl-C, locks) and 7 (the viewer server bounded and quiet); tests/test_fuzz_files.py probes
them end to end (full tmpfs disks, real SIGINT and SIGKILL, 300 idle connections).
"""

from __future__ import annotations

import argparse
import errno
import logging
import os
import socket
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin import _files
from gb_pin.exceptions import GbPinWarning, InvalidArgumentError
from gb_pin.experiments.journal import fallback_journals


def _full_under(monkeypatch: Any, directory: Path) -> None:
    """fsync fails with ENOSPC for files under ``directory`` (a full disk, as the writers see it)."""
    real = os.fsync

    def fsync(fd: int) -> None:
        if os.readlink(f"/proc/self/fd/{fd}").startswith(str(directory) + os.sep):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real(fd)

    monkeypatch.setattr(os, "fsync", fsync)


# -- 4. failed writes --------------------------------------------------------------------------------
def test_a_journal_that_fills_the_disk_moves_with_every_finished_trial(
    tmp_path: Path, monkeypatch: Any
) -> None:
    """The append fails: the journal is rewritten elsewhere (named in a warning), the trials go on."""
    disk, here = tmp_path / "disk", tmp_path / "here"
    disk.mkdir()
    here.mkdir()
    monkeypatch.chdir(here)
    monkeypatch.setenv("GB_PIN_CACHE", str(tmp_path / "cache"))
    journal = disk / "j.jsonl"
    first = gb_pin.run_trials("planar5", trials=2, movements=10, seed=0, workers=1, checkpoint=journal)
    _full_under(monkeypatch, disk)
    with pytest.warns(
        GbPinWarning, match=r"trial journal .*No space left.*3 finished trials are in"
    ) as caught:
        more = gb_pin.run_trials("planar5", trials=4, movements=10, seed=0, workers=1, checkpoint=journal)
    moved = Path(fallback_journals(journal)[0])  # a place of its own, which the rerun reads
    assert str(moved) in str(caught[0].message) and "a rerun with the same journal" in str(caught[0].message)
    np.testing.assert_array_equal(more.error[:2], first.error)
    assert len(moved.read_text().splitlines()) == 1 + 4
    monkeypatch.undo()
    monkeypatch.setenv("GB_PIN_CACHE", str(tmp_path / "cache"))
    again = gb_pin.run_trials("planar5", trials=4, movements=10, seed=0, workers=1, checkpoint=journal)
    np.testing.assert_array_equal(again.error, more.error)  # all four read from the fallback ...
    assert len(journal.read_text().splitlines()) == 1 + 4 and not moved.exists()  # ... and brought home


def test_a_journals_torn_last_line_is_cut_and_a_whole_one_kept(tmp_path: Path) -> None:
    path = tmp_path / "j.jsonl"
    ts = gb_pin.run_trials("planar5", trials=2, movements=5, workers=1, checkpoint=path)
    whole = path.read_text()
    path.write_text(whole + '{"key": "torn')
    gb_pin.run_trials("planar5", trials=2, movements=5, workers=1, checkpoint=path)
    assert path.read_text() == whole
    path.write_text(whole.rstrip("\n"))  # a whole last trial without its newline: kept, newline added
    again = gb_pin.run_trials("planar5", trials=3, movements=5, workers=1, checkpoint=path)
    np.testing.assert_array_equal(again.error[:2], ts.error)
    assert len(path.read_text().splitlines()) == 1 + 3


def test_write_or_fallback_tries_every_place_and_names_each(tmp_path: Path, monkeypatch: Any) -> None:
    monkeypatch.chdir(tmp_path)
    gone = tmp_path / "gone"
    gone.mkdir()
    target = gone / "r.json"
    _files.check_writable(target)
    gone.rmdir()  # removed during the work: check_writable now refuses it, the result still goes somewhere
    assert _files.write_or_fallback(target, lambda p: _files.write_json(_files.check_writable(p), 1)) == str(
        tmp_path / "r.json"
    )
    tried: list[str] = []

    def failing(path: Any) -> None:
        tried.append(os.fspath(path))
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError, match=r"cannot write .*r\.json.* nor .*r\.1\.json"):
        _files.write_or_fallback(target, failing)
    assert len(tried) == 3  # the path, the current directory, the temp directory
    with pytest.warns(GbPinWarning, match="saved to"):
        _files.save_or_fallback(target, lambda p: _files.write_json(_files.check_writable(p), 2), "the table")


def test_outputs_that_cannot_be_written_are_refused_before_the_work(tmp_path: Path, monkeypatch: Any) -> None:
    os.mkfifo(tmp_path / "fifo.npz")
    with pytest.raises(InvalidArgumentError, match="not a regular file"):
        _files.check_writable(tmp_path / "fifo.npz", "--out")
    with pytest.raises(InvalidArgumentError, match="name of 250 bytes"):
        _files.check_writable(tmp_path / ("x" * 250), "--out")

    class Full:
        f_bfree = f_bavail = 0
        f_frsize = 4096
        f_blocks = 100

    monkeypatch.setattr(os, "statvfs", lambda path: Full)
    with pytest.raises(InvalidArgumentError, match="file system is full"):
        _files.check_writable(tmp_path / "r.npz", "--out")


def test_a_benchmark_document_without_markers_is_refused_before_the_work(
    tmp_path: Path, monkeypatch: Any
) -> None:
    from gb_pin.experiments import robot_bench

    doc = tmp_path / "doc.md"
    doc.write_text("no markers here\n")
    monkeypatch.setattr(robot_bench, "benchmark_robot", lambda *a, **k: pytest.fail("ran the benchmark"))
    with pytest.raises(gb_pin.GbPinError, match="no benchmark markers"):
        robot_bench.run(["planar5"], trials=1, movements=5, doc=str(doc), progress=False)


def test_a_checkpoint_that_cannot_be_written_anywhere_does_not_end_the_run(
    tmp_path: Path, monkeypatch: Any
) -> None:
    from gb_pin.runs import checkpoint as module

    monkeypatch.chdir(tmp_path)

    def failing(path: Any, state: Any, info: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(module, "write_checkpoint", failing)
    with pytest.warns(GbPinWarning, match="nor anywhere else; the run goes on"):
        res = gb_pin.babble(
            "planar5", movements=20, seed=0, checkpoint=tmp_path / "c.npz", checkpoint_every=5
        )
    assert res.movements == 20 and res.history.error.shape[0] > 1


# -- 5. processes --------------------------------------------------------------------------------------
def test_stale_temporaries_of_dead_writers_are_removed_and_nothing_else(tmp_path: Path) -> None:
    path = tmp_path / "r.json"
    old = time.time() - 2 * _files.STALE_SECONDS
    stale = tmp_path / ".r.json.abcd1234.tmp"  # a writer killed mid-write: no one holds its lock
    young = tmp_path / ".r.json.efgh5678.tmp"  # too recent to judge
    other = tmp_path / ".other.json.abcd1234.tmp"  # another file's
    for p in (stale, young, other):
        p.write_text("x")
    os.utime(stale, (old, old))
    os.utime(other, (old, old))
    (tmp_path / "link").symlink_to(stale)
    with _files.atomic_write(path, text=True) as fh:  # our own temporary, locked, is never taken
        assert _files.remove_stale_temporaries(path) == []  # once per process and path
        fh.write("new")
    assert not stale.exists() and young.exists() and other.exists() and path.read_text() == "new"


def test_a_planted_symlink_at_the_lock_is_not_followed(tmp_path: Path) -> None:
    from gb_pin.runs.checkpoint import checkpoint_lock

    (tmp_path / ".c.npz.lock").symlink_to(tmp_path / "elsewhere")
    with (
        pytest.raises(InvalidArgumentError, match="cannot create its lock"),
        checkpoint_lock(tmp_path / "c.npz"),
    ):
        pass
    assert not (tmp_path / "elsewhere").exists()


def test_ctrl_c_without_a_message_prints_a_useful_line() -> None:
    from gb_pin.cli import _interrupted

    babble = argparse.Namespace(command="babble", checkpoint=None, resume=None)
    assert "nothing was saved (--checkpoint FILE" in _interrupted(babble)
    assert _interrupted(argparse.Namespace(command="plot")) == "interrupted (Ctrl-C) during gb-pin plot"


def test_the_trials_interruption_message_says_how_far_and_where() -> None:
    from gb_pin.experiments.execute import _interrupted

    class Journal:
        writing = "j.jsonl"

    out = (np.zeros(1), np.zeros(1), 1, None)
    assert _interrupted([out, None, out], Journal(), "") == (  # type: ignore[arg-type]
        "interrupted: 2 of 3 trials finished, journaled in j.jsonl; run the same command again to compute "
        "only the others"
    )
    # without a journal: no option named (reproduce has no --checkpoint; issue 33)
    assert "not journaled" in _interrupted([None], None, "") and "--" not in _interrupted([None], None, "")


# -- 7. the viewer server ------------------------------------------------------------------------------
def test_notes_are_rate_limited_and_count_what_they_left_out(caplog: Any) -> None:
    from gb_pin.viewer.listener import Notes

    notes = Notes(logging.getLogger("gb_pin.viewer.test"), every=60.0)
    with caplog.at_level(logging.WARNING, logger="gb_pin.viewer.test"):
        for _ in range(1000):
            notes.warn("cap", "too many \x1b[31mconnections")
        notes.warn("other", "another kind")
    assert [r.getMessage() for r in caplog.records] == ["too many \\x1b[31mconnections", "another kind"]


def test_the_viewer_caps_connections_closing_the_oldest_plain_one(monkeypatch: Any) -> None:
    """At the cap the oldest connection that is not a browser's websocket is closed; a GET still works."""
    pytest.importorskip("tornado")
    from gb_pin.viewer import listener
    from gb_pin.viewer.server import LocalServer

    monkeypatch.setattr(listener, "MAX_CONNECTIONS", 8)
    with warnings.catch_warnings(), LocalServer() as server:
        warnings.simplefilter("ignore")
        idle = [socket.create_connection(("127.0.0.1", server.port), timeout=5) for _ in range(20)]
        with socket.create_connection(("127.0.0.1", server.port), timeout=5) as c:
            c.sendall(b"GET /static/ HTTP/1.1\r\nHost: 127.0.0.1:%d\r\n\r\n" % server.port)
            assert c.recv(16).startswith(b"HTTP/1.1 200")
        assert idle[0].recv(1) == b""  # the oldest was closed to make room
        for c in idle:
            c.close()
