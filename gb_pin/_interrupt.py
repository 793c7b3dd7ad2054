"""Long compiled calls that Ctrl-C can stop: :func:`interruptible`.

Python handles a signal only between bytecodes: while a compiled (numba) function runs, Ctrl-C
waits until it returns, which for an IK batch with a long ``timeout`` was minutes. A call that may
run long is made in a worker thread instead (the compiled functions release the GIL: ``nogil``),
while the calling thread waits in short joins, where Ctrl-C lands at once; it then sets the
call's stop flag (an int64 array the compiled loop reads every few steps), waits for the worker
to return (milliseconds) and raises KeyboardInterrupt. Calls expected to be short run directly:
a thread costs about 0.1 ms, more than a single IK query.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

T = TypeVar("T")

DIRECT_SECONDS = 0.25
"""Calls whose budget is at most this long run in the calling thread [s]."""
POLL_SECONDS = 0.1
"""How long the calling thread waits between checks for Ctrl-C [s]."""


def interruptible(call: Callable[[], T], stop: NDArray[np.int64], budget: float) -> T:
    """``call()``, in a worker thread when ``budget`` [s] exceeds :data:`DIRECT_SECONDS`.

    Args:
        call: the compiled call (it must return soon after ``stop[0]`` is set).
        stop: the flag it reads: 0 while it should go on.
        budget: the longest it may run [s] (inf: unknown).

    Raises:
        KeyboardInterrupt: Ctrl-C while it ran (after it stopped).
    """
    if budget <= DIRECT_SECONDS:
        return call()
    box: dict[str, Any] = {}

    def work() -> None:
        try:
            box["value"] = call()
        except BaseException as exc:  # handed to the calling thread
            box["error"] = exc

    worker = threading.Thread(target=work, name="gb_pin-compiled", daemon=True)
    worker.start()
    try:
        while worker.is_alive():
            worker.join(POLL_SECONDS)
    except KeyboardInterrupt:
        stop[0] = 1
        worker.join()
        raise
    if "error" in box:
        raise box["error"]
    return box["value"]
