"""Ctrl-C during a compiled call that takes a ``numpy.random.Generator``: deferred, never a crash.

numba unboxes a Generator argument by calling ``ctypes.cast`` (Python code) three times, and does
not check that call for an error (numba 0.68, ``unbox_numpy_random_generator``). Python runs a
pending signal's handler in any Python code, so a Ctrl-C that lands there raises
KeyboardInterrupt inside the unboxing, ``ctypes.cast`` returns NULL, and numba reads an attribute
of NULL: a segmentation fault. Measured on the hardware CLI's Ctrl-C test (SIGINT sent right
after the first checkpoint, a second process keeping the other core busy): 1 run in 10-40 ended
with signal 11 (in ``ask_step`` or ``tell_step``, core dump: ``PyObject_GetAttrString(NULL,
"value")`` in the call's wrapper); the ask/tell calls, one per step, are where it lands most.

:func:`deferring` makes such a call with gb_pin's SIGINT handler in place: inside the call the
signal is only noted, and the handler that was there before (Python's, which raises
KeyboardInterrupt, or the user's) runs as soon as the call returns, so Ctrl-C still lands within
the call's duration. The handler is installed once (per process, in the main thread, over a
Python handler only: an ignored or default SIGINT runs no Python code) and again if someone
replaced it; a call costs about 0.25 us more (a signal handler swap would cost 5 us, blocking the
signal 1.8 us, against the 36 us of a session's step).
"""

from __future__ import annotations

# _signal.getsignal is signal.getsignal's C function (signal's own adds an enum lookup: 1.5 us a call)
import _signal  # type: ignore[import-not-found]
import signal
import threading
from collections.abc import Callable
from types import FrameType
from typing import Any, TypeVar

T = TypeVar("T")

_MAIN = threading.main_thread().ident
_SIGINT = int(signal.SIGINT)


Handler = Callable[[int, FrameType | None], Any]


class _State:
    """Calls under way, and the signal noted meanwhile with the handler to hand it to."""

    depth = 0
    pending: tuple[Handler, int, FrameType | None] | None = None


def _deferring_handler(previous: Handler) -> Handler:
    """A SIGINT handler that notes the signal inside a deferring call, else hands it to ``previous``.

    Each wraps the handler it replaced (a closure, not a global), so a test or a program that saves
    one of ours and restores it later restores its own chain too.
    """

    def handler(signum: int, frame: FrameType | None) -> None:
        if _State.depth:
            _State.pending = (previous, signum, frame)
            return
        previous(signum, frame)

    handler.gb_pin_defers = True  # type: ignore[attr-defined]
    return handler


def deferring(call: Callable[..., T], *args: Any) -> T:
    """``call(*args)`` with a Ctrl-C during it handled when it returns (see the module's docstring)."""
    if threading.get_ident() != _MAIN:  # signal handlers run in the main thread only
        return call(*args)
    current = _signal.getsignal(_SIGINT)
    if not getattr(current, "gb_pin_defers", False):
        if not callable(current):  # SIG_IGN, SIG_DFL, None: no Python code runs on the signal
            return call(*args)
        signal.signal(signal.SIGINT, _deferring_handler(current))
    _State.depth += 1
    try:
        return call(*args)
    finally:
        _State.depth -= 1
        if _State.pending is not None and not _State.depth:
            previous, signum, frame = _State.pending
            _State.pending = None
            previous(signum, frame)


__all__ = ["deferring"]
