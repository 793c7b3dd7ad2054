"""The local process pool of trials: workers that leave Ctrl-C to their parent, die with it, stop at once.

:func:`run_pool` runs trials in a ``ProcessPoolExecutor`` whose workers ignore SIGINT (the parent
handles Ctrl-C: no traceback from every worker) and exit when the parent is gone
(:func:`watch_parent`). On Ctrl-C the trials finished meanwhile are still passed on (journaled),
the pending ones are cancelled and the workers killed: the command ends within seconds instead of
after every queued trial (issue 24 measured about 68 s).
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

WORKERS_PER_CORE = 4
PARENT_POLL = 0.5  # [s] between a worker's checks that the process that started it is alive


def run_pool(run: Callable[..., Any], tasks: list[Any], order: list[int], workers: int, done: Any) -> None:
    """Run the tasks in a local process pool, passing each output to ``done`` as it comes.

    On Ctrl-C the trials finished meanwhile are passed to ``done`` too, the pending ones cancelled
    and the workers stopped at once; then KeyboardInterrupt goes on.
    """
    pool = ProcessPoolExecutor(max_workers=workers, initializer=start_worker, initargs=(os.getpid(),))
    futures = {pool.submit(run, *tasks[i]): i for i in order}
    passed: set[int] = set()
    try:
        for fut in as_completed(futures):
            passed.add(futures[fut])
            done(futures[fut], fut.result())
    except KeyboardInterrupt:
        for fut, i in futures.items():
            if i not in passed and fut.done() and not fut.cancelled() and fut.exception() is None:
                done(i, fut.result())  # finished while we were interrupted: journal it too
        stop(pool)
        raise
    except BaseException:
        stop(pool)
        raise
    pool.shutdown()


def stop(pool: ProcessPoolExecutor) -> None:
    """Cancel the pool's pending tasks and end its workers now, not after their running trials."""
    processes = list(getattr(pool, "_processes", None) or {})  # pid -> Process (shutdown clears it)
    pool.shutdown(wait=False, cancel_futures=True)
    for pid in processes:
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)  # a worker keeps no state: its trial is recomputed next time


def start_worker(parent: int) -> None:
    """Start a pool worker: Ctrl-C is its parent's to handle, and it exits when its parent is gone.

    (Without this every worker would print a KeyboardInterrupt traceback; :func:`watch_parent`.)
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    watch_parent(parent)


def watch_parent(parent: int) -> None:
    """In a worker process: exit as soon as ``parent`` (the process running the trials) is gone.

    A daemon thread polls the parent every :data:`PARENT_POLL` seconds, so killing ``gb-pin trials``
    (even with SIGKILL) does not leave its workers computing for minutes.
    """
    started_by = os.getppid()

    def poll() -> None:
        while True:
            time.sleep(PARENT_POLL)
            try:
                os.kill(parent, 0)
                alive = os.getppid() == started_by
            except ProcessLookupError:
                alive = False
            except PermissionError:  # the pid was reused by another user's process
                alive = False
            if not alive:
                os._exit(1)

    threading.Thread(target=poll, name="gb_pin-watch-parent", daemon=True).start()


def max_workers() -> int:
    """The most local worker processes a run may start: :data:`WORKERS_PER_CORE` per core, at least 16.

    Each worker loads numpy, numba and the kernels (about 0.1-0.2 GB): many more than the cores
    only exhaust the memory.
    """
    return max(16, WORKERS_PER_CORE * (os.cpu_count() or 1))
