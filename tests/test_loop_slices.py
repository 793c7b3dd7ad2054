"""The babbling loop returns to Python every SLICE_SECONDS, so Ctrl-C lands within a second.

Python handles Ctrl-C only between bytecodes. The compiled loop ran a chunk of up to 1000 movements,
and with E^X recorded after every one of the first 1000 movements over a large test set that was
minutes (planar20, 10^5 test targets: 163 s from SIGINT to the exit; 10^6: still running after
600 s). The loop now reads the monotonic clock between movements and every 256 evaluation targets
(gb_pin/learn/clock.py) and returns SLICE; an evaluation cut there goes on where it stopped, so a
run sliced anywhere is bit-identical to one that is not.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.learn import state as state_module
from gb_pin.learn.learner import GoalBabbling


def _near(count: int, seed: int) -> np.ndarray:
    """``count`` test targets near planar5's goals (where the map learns)."""
    goals = gb_pin.load_robot("planar5").targets
    rng = np.random.default_rng(seed)
    return goals[rng.integers(0, len(goals), count)] + rng.normal(0.0, 0.01, (count, 2))


def test_a_run_sliced_at_every_chance_is_bit_identical(monkeypatch: pytest.MonkeyPatch) -> None:
    """Slices of 0 s: the loop returns after every movement and every 256 targets of each E^X."""
    targets = _near(1000, 0)  # 4 blocks of 256 per evaluation
    whole = gb_pin.babble("planar5", movements=120, seed=4, eval_targets=targets)
    calls = []
    real = state_module.babble_loop

    def counted(*args: object) -> int:
        status = real(*args)
        calls.append(status)
        return status

    monkeypatch.setattr(state_module, "SLICE_SECONDS", 0.0)
    monkeypatch.setattr(state_module, "babble_loop", counted)
    sliced = gb_pin.babble("planar5", movements=120, seed=4, eval_targets=targets)
    np.testing.assert_array_equal(sliced.history.error, whole.history.error)
    np.testing.assert_array_equal(sliced.history.home_distance, whole.history.home_distance)
    np.testing.assert_array_equal(sliced.model.predict(targets), whole.model.predict(targets))
    assert calls.count(8) >= 121 * 3  # SLICE inside each evaluation (3 times) and between movements


def test_an_interrupt_inside_an_evaluation_is_redone_on_resume(monkeypatch: pytest.MonkeyPatch) -> None:
    """should_stop at the first slice: the run stops mid-evaluation; resumed, it is the whole run."""
    target = gb_pin.load_robot("planar5")
    targets = _near(2000, 1)
    whole = GoalBabbling().fit(target, target.targets, 60, seed=2, eval_targets=targets)
    monkeypatch.setattr(state_module, "SLICE_SECONDS", 0.0)
    learner = GoalBabbling()
    asked = []

    def stop() -> bool:
        asked.append(learner.state_.movements if hasattr(learner, "state_") else -1)
        return len(asked) >= 3  # from the third slice on: inside the evaluation at movement 1

    learner.fit(target, target.targets, 60, seed=2, eval_targets=targets, should_stop=stop)
    assert learner.movements_ < 60 and np.asarray(learner.state_._progress)[0] > 0  # cut mid-evaluation
    saved = learner.state_.to_arrays()  # what a checkpoint holds: no partial evaluation
    monkeypatch.setattr(state_module, "SLICE_SECONDS", 0.1)
    again = state_module.BabbleState.from_arrays(
        saved, learner.state_.config, learner.state_.rng_state(), goals=learner.state_.goals
    )
    rest = GoalBabbling()
    rest.state_ = again
    rest.resume(60)
    np.testing.assert_array_equal(rest.history_.error, whole.history_.error)


def test_ctrl_c_in_a_long_babble_lands_within_two_seconds(tmp_path: Path) -> None:
    """`gb-pin babble` with 5*10^4 test targets (E^X after every movement): exit 130, checkpoint named."""
    points = tmp_path / "test.csv"
    np.savetxt(points, np.random.default_rng(0).uniform(-0.6, 0.6, (50_000, 2)), delimiter=",")
    ckpt = tmp_path / "run.ckpt"
    cmd = [sys.executable, "-m", "gb_pin.cli", "babble", "--robot", "planar5", "--movements", "1000000",
           "--eval-targets", str(points), "--checkpoint", str(ckpt), "--checkpoint-every", "3",
           "--quiet"]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not ckpt.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert ckpt.exists() and proc.poll() is None, "the run did not start"
        time.sleep(0.5)
        start = time.monotonic()
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
        took = time.monotonic() - start
    finally:
        proc.kill()
        proc.wait()
    assert proc.returncode == 130, err[-500:]
    assert f"checkpoint written to {ckpt}" in err and "interrupted at movement" in err, err[-500:]
    assert took < 2.0, f"exit {took:.2f} s after SIGINT"
    from gb_pin.runs.checkpoint import read_checkpoint

    state, info = read_checkpoint(ckpt)  # written at the interrupt, and whole
    assert 0 < state.movements < info.movements
