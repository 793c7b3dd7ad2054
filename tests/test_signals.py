"""Ctrl-C during a compiled call that takes a Generator (gb_pin._signals): deferred to the call's end.

numba's unboxing of a Generator runs Python code (``ctypes.cast``) without checking it for an
error; a KeyboardInterrupt raised there crashed the process (signal 11) in about 1 of 10-40
Ctrl-Cs of the hardware CLI. Here a call that receives SIGINT while it runs must finish, and the
KeyboardInterrupt must come right after it; handlers other than Python's are left alone.
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Iterator

import numpy as np
import pytest

from gb_pin import _signals
from gb_pin._signals import deferring
from gb_pin.learn.exploration import noise_walk


@pytest.fixture(autouse=True)
def _restore_sigint() -> Iterator[None]:
    before = signal.getsignal(signal.SIGINT)
    yield
    signal.signal(signal.SIGINT, before)


def _interrupted_call(log: list[str]) -> str:
    os.kill(os.getpid(), signal.SIGINT)  # Python runs the handler at the next bytecode: in this call
    log.append("after the signal, inside the call")
    return "result"


def test_ctrl_c_inside_a_call_lands_when_it_returns() -> None:
    log: list[str] = []
    with pytest.raises(KeyboardInterrupt):
        deferring(_interrupted_call, log)
    assert log == ["after the signal, inside the call"]  # the call was not cut
    assert getattr(signal.getsignal(signal.SIGINT), "gb_pin_defers", False)
    assert _signals._State.depth == 0 and _signals._State.pending is None
    assert deferring(lambda: 7) == 7  # and the next call goes on as usual


def test_the_previous_handler_is_the_one_that_answers() -> None:
    seen: list[int] = []
    signal.signal(signal.SIGINT, lambda signum, frame: seen.append(signum))
    assert deferring(_interrupted_call, []) == "result"  # the user's handler does not raise
    assert seen == [signal.SIGINT]
    os.kill(os.getpid(), signal.SIGINT)  # outside a call: handed on at once
    assert seen == [signal.SIGINT, signal.SIGINT]


def test_a_restored_handler_keeps_its_own_chain() -> None:
    """A program that saves gb_pin's handler, sets its own, calls, and restores: Ctrl-C still raises."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    deferring(lambda: None)
    saved = signal.getsignal(signal.SIGINT)  # gb_pin's, over Python's
    signal.signal(signal.SIGINT, lambda signum, frame: None)  # e.g. a server's own
    deferring(lambda: None)  # wrapped in turn
    signal.signal(signal.SIGINT, saved)
    with pytest.raises(KeyboardInterrupt):
        deferring(_interrupted_call, [])


def test_an_ignored_sigint_is_left_alone() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    assert deferring(_interrupted_call, []) == "result"
    assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN


def test_another_thread_calls_directly() -> None:
    signal.signal(signal.SIGINT, signal.default_int_handler)
    out: list[float] = []
    worker = threading.Thread(target=lambda: out.append(deferring(lambda: 1.5)))
    worker.start()
    worker.join()
    assert out == [1.5]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # nothing installed from there


def test_a_compiled_call_with_a_generator_gives_the_same_draws() -> None:
    A, b = np.zeros((3, 2)), np.zeros(3)
    A2, b2 = np.zeros((3, 2)), np.zeros(3)
    noise_walk(np.random.default_rng(5), 0.1, 0.01, A, b)
    deferring(noise_walk, np.random.default_rng(5), 0.1, 0.01, A2, b2)
    assert np.array_equal(A, A2) and np.array_equal(b, b2)
