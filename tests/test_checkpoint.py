"""Checkpoints: atomic writes, bit-identical resume after a crash, SIGKILL or Ctrl-C, broken files."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.runs.checkpoint import read_checkpoint


class _CrashError(Exception):
    pass


def _same(a: gb_pin.BabbleResult, b: gb_pin.BabbleResult) -> None:
    np.testing.assert_array_equal(a.history.movements, b.history.movements)
    np.testing.assert_array_equal(a.history.error, b.history.error)
    np.testing.assert_array_equal(a.history.home_distance, b.history.home_distance)
    np.testing.assert_array_equal(a.model.prototypes_, b.model.prototypes_)
    np.testing.assert_array_equal(a.model.matrices_, b.model.matrices_)
    np.testing.assert_array_equal(a.model.offsets_, b.model.offsets_)
    assert a.steps == b.steps and a.movements == b.movements


@pytest.mark.parametrize(("crash_at", "every"), [(1, 1), (17, 4), (30, 10), (49, 7)])
def test_resume_after_a_crash_is_bit_identical(tmp_path: Path, crash_at: int, every: int) -> None:
    """A run that dies after any movement resumes from its last checkpoint to the uninterrupted result."""
    rec = gb_pin.Recording(every=3, first=5, last=40)
    full = gb_pin.babble("planar5", movements=50, seed=3, learning_rate=0.3, record=rec)
    path = tmp_path / "run.ckpt"

    def crash(r: int) -> None:
        if r >= crash_at:
            raise _CrashError

    with pytest.raises(_CrashError):
        gb_pin.babble(
            "planar5", movements=50, seed=3, learning_rate=0.3, record=rec,
            checkpoint=path, checkpoint_every=every, callback=crash,
        )  # fmt: skip
    state, info = read_checkpoint(path)
    assert state.movements == (crash_at // every) * every
    assert info.movements == 50 and info.seed == 3 and info.robot == "planar5"
    resumed = gb_pin.resume(path)
    _same(resumed, full)
    assert resumed.recording is not None and full.recording is not None
    np.testing.assert_array_equal(resumed.recording.posture, full.recording.posture)
    np.testing.assert_array_equal(resumed.recording.step, full.recording.step)
    assert read_checkpoint(path)[0].movements == 50  # the final state is written too


def test_resume_a_custom_target_needs_the_target(tmp_path: Path) -> None:
    """A run of a custom KinematicTarget resumes when given the target, and refuses another robot."""
    target = gb_pin.KinematicTarget(gb_pin.planar_chain(3), "tip", home=gb_pin.planar_home(3), axes="xy")
    X = [[0.5, 0.0], [0.6, 0.2], [0.4, -0.2]]
    full = gb_pin.babble(target, movements=20, seed=1, targets=X)
    path = tmp_path / "custom.ckpt"

    def crash(r: int) -> None:
        if r >= 10:
            raise _CrashError

    with pytest.raises(_CrashError):
        gb_pin.babble(
            target, movements=20, seed=1, targets=X, checkpoint=path, checkpoint_every=5, callback=crash
        )
    with pytest.raises(gb_pin.InvalidArgumentError, match="pass it as robot="):
        gb_pin.resume(path)
    other = gb_pin.KinematicTarget(gb_pin.planar_chain(3, total_length=2.0), "tip", axes="xy")
    with pytest.raises(gb_pin.ResultFileError, match="kinematics differ"):
        gb_pin.resume(path, robot=other)
    _same(gb_pin.resume(path, robot=target), full)


def test_checkpoint_write_is_atomic(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A crash while writing a checkpoint leaves the previous checkpoint intact and no temporary file."""
    path = tmp_path / "run.ckpt"
    gb_pin.babble("planar3", movements=10, seed=0, checkpoint=path, checkpoint_every=5)
    before = path.read_bytes()

    def failing_replace(src: str, dst: str) -> None:
        raise OSError("disk died")

    monkeypatch.setattr(os, "replace", failing_replace)
    monkeypatch.chdir(tmp_path)  # where a fallback checkpoint would go (it fails too)
    # Every write fails: the run goes on (its result is not lost), saying so at each checkpoint.
    with pytest.warns(gb_pin.GbPinWarning, match="disk died.*nor anywhere else"):
        gb_pin.babble("planar3", movements=10, seed=1, checkpoint=path, checkpoint_every=5)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.ckpt"]


def test_divergence_keeps_the_last_good_checkpoint(tmp_path: Path) -> None:
    """An exploding run stops with DivergenceError naming the movement; the last checkpoint stays valid."""
    path = tmp_path / "run.ckpt"
    with pytest.raises(gb_pin.DivergenceError, match=r"movement \d+.*learning_rate=1000000\.0"):
        gb_pin.babble(
            "planar5", movements=200, seed=0, learning_rate=1e6, checkpoint=path, checkpoint_every=1
        )
    if path.exists():  # diverged after at least one movement: that checkpoint is finite and loadable
        state, _ = read_checkpoint(path)
        assert np.all(np.isfinite(state.llm.offsets_))


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "gb_pin.cli", "babble", *args, "--quiet"]


RUN = ["--robot", "planar50", "--movements", "600", "--seed", "11", "--learning-rate", "0.2"]


def _interrupted_run(tmp_path: Path, sig: int, delay: float) -> subprocess.CompletedProcess[str] | None:
    """Start a checkpointing CLI run, send ``sig`` once checkpoints exist, resume it.

    Returns None if the run ended before the signal could be sent.
    """
    ckpt = tmp_path / "run.ckpt"
    proc = subprocess.Popen(
        _cli(*RUN, "--checkpoint", str(ckpt), "--checkpoint-every", "1"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not ckpt.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(delay)
    if proc.poll() is not None:
        return None
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=120)
    assert read_checkpoint(ckpt)[0].movements < 600
    resumed = subprocess.run(
        [
            sys.executable,
            "-m",
            "gb_pin.cli",
            "babble",
            "--resume",
            str(ckpt),
            "--out",
            str(tmp_path / "b.npz"),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert resumed.returncode == 0, resumed.stderr
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGINT])
@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_cli_killed_and_resumed_equals_uninterrupted(tmp_path: Path, sig: int) -> None:
    """A CLI run killed with SIGKILL (or stopped with Ctrl-C) mid-run and resumed ends bit-identical."""
    subprocess.run([*_cli(*RUN, "--out", str(tmp_path / "a.npz"))], check=True, timeout=300)
    for delay in (0.3, 0.1, 0.0):
        done = _interrupted_run(tmp_path, sig, delay)
        if done is not None:
            break
    else:
        pytest.fail("the run always finished before it could be interrupted")
    if sig == signal.SIGKILL:
        assert done.returncode == -signal.SIGKILL
    else:
        assert done.returncode == 130
        assert "checkpoint written" in done.stderr
        assert "Traceback" not in done.stderr
    _same(gb_pin.load_result(tmp_path / "b.npz"), gb_pin.load_result(tmp_path / "a.npz"))


def _corrupt(path: Path, how: str) -> None:
    data = bytearray(path.read_bytes())
    if how == "truncate":
        path.write_bytes(bytes(data[: len(data) // 2]))
    elif how == "flip":
        for i in range(len(data) // 3, len(data) // 3 + 64):
            data[i] ^= 0xFF
        path.write_bytes(bytes(data))
    elif how == "empty":
        path.write_bytes(b"")


@pytest.mark.parametrize("how", ["truncate", "flip", "empty"])
def test_broken_checkpoint_is_a_clear_error(tmp_path: Path, how: str) -> None:
    """A truncated, byte-flipped or empty checkpoint raises ResultFileError naming the file."""
    path = tmp_path / "run.ckpt"
    gb_pin.babble("planar3", movements=10, seed=0, checkpoint=path)
    _corrupt(path, how)
    with pytest.raises(gb_pin.ResultFileError, match=r"run\.ckpt"):
        gb_pin.resume(path)


def test_foreign_and_newer_checkpoints_are_refused(tmp_path: Path) -> None:
    """A result file, an npz with wrong keys, or a newer format version is refused with ResultFileError."""
    res = gb_pin.babble("planar3", movements=5, seed=0)
    res.save(tmp_path / "result.npz")
    # A result file for a checkpoint: what it is and what to do (extend it with --continue).
    with pytest.raises(gb_pin.ResultFileError, match=r"a result file, not a checkpoint.*--continue"):
        gb_pin.resume(tmp_path / "result.npz")
    np.savez(tmp_path / "keys.npz", a=np.zeros(3))
    with pytest.raises(gb_pin.ResultFileError, match=r"keys\.npz"):
        gb_pin.resume(tmp_path / "keys.npz")
    path = tmp_path / "run.ckpt"
    gb_pin.babble("planar3", movements=5, seed=0, checkpoint=path)
    with np.load(path) as archive:
        arrays = {k: archive[k] for k in archive.files}
    arrays["meta"] = np.array(str(arrays["meta"]).replace('"format_version": 2', '"format_version": 99'))
    with open(path, "wb") as fh:
        np.savez(fh, **arrays)
    with pytest.raises(gb_pin.ResultFileError, match="newer gb_pin"):
        gb_pin.resume(path)
    with pytest.raises(gb_pin.ResultFileError, match="no such"):
        gb_pin.resume(tmp_path / "missing.ckpt")
