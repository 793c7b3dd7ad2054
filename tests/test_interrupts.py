"""Waits that Ctrl-C ends: long compiled IK solves run in a worker thread that a stop flag ends.

Before (main 995bb8d) ``gb-pin ik`` and ``result.solve`` with a long ``timeout`` kept running for
minutes after Ctrl-C: the compiled batch returned only at its budget (:mod:`gb_pin._interrupt`).
"""

from __future__ import annotations

import _thread
import threading
import time

import numpy as np
import pytest

import gb_pin
import gb_pin.ik
from gb_pin import _interrupt


def _interrupt_after(seconds: float) -> threading.Timer:
    timer = threading.Timer(seconds, _thread.interrupt_main)
    timer.start()
    return timer


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_ctrl_c_ends_a_long_ik_solve_within_a_second() -> None:
    """An unreachable target with a 60 s budget: Ctrl-C after 0.3 s ends the call within 2 s."""
    arm = gb_pin.load_robot("planar5")
    gb_pin.ik.solve(arm, [[5.0, 5.0]], seed="home", timeout=1e-3)  # compiled before the clock starts
    timer = _interrupt_after(0.3)
    start = time.perf_counter()
    try:
        with pytest.raises(KeyboardInterrupt):
            gb_pin.ik.solve(arm, [[5.0, 5.0]], seed="home", timeout=60.0)
    finally:
        timer.cancel()
    elapsed = time.perf_counter() - start
    assert elapsed < 2.0, f"Ctrl-C took {elapsed:.1f} s to land"


def test_answers_do_not_depend_on_the_thread_they_are_computed_in(monkeypatch: pytest.MonkeyPatch) -> None:
    """A deterministic batch (restarts, no timeout) gives the same postures, bit for bit, either way."""
    arm = gb_pin.load_robot("planar5")
    X = np.random.default_rng(0).uniform(-0.6, 0.6, (50, 2))
    direct = gb_pin.ik.solve(arm, X, seed="home", max_restarts=5, rng=1)
    monkeypatch.setattr(_interrupt, "DIRECT_SECONDS", -1.0)
    threaded = gb_pin.ik.solve(arm, X, seed="home", max_restarts=5, rng=1)
    assert np.array_equal(direct.postures, threaded.postures, equal_nan=True)
    assert np.array_equal(direct.iterations, threaded.iterations)
