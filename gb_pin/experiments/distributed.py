"""Run trials and sweeps on a Dask cluster (``pip install "gb_pin[cluster]"``).

:func:`gb_pin.run_trials` and :func:`gb_pin.run_sweep` take ``scheduler=``: a
scheduler address such as ``"tcp://host:8786"``, a ``dask.distributed.Client``, or
a cluster object (e.g. ``LocalCluster``). Each trial is one Dask task whose
arguments are the robot's preset name, the movement count, the seed, the movement
counts to record and the babble parameters: a few hundred bytes. Workers build the
robot from its name (``gb_pin`` must be installed on them), so no Pinocchio model,
let alone a visual geometry model, ever travels. Trial i uses seed ``seed + i``
wherever it runs, so a cluster gives the same numbers as a local run, bit for bit,
when the workers run the same gb_pin, numpy and numba on the same CPU architecture.

A cluster, for example::

    dask scheduler                                   # on the head node, port 8786
    dask worker tcp://head:8786 --nworkers 16 --nthreads 1   # on each worker node
    gb-pin trials --robot planar50 --movements 1000000 --scheduler tcp://head:8786

On SLURM: ``--scheduler slurm:cores=4,memory=8GB,jobs=10`` (``pip install "gb_pin[slurm]"``),
see :mod:`gb_pin.experiments.slurm` and docs/CLUSTERS.md. Short trials are sent several to a
task (``gb_pin.experiments.execute``), so that Dask's per-task overhead stays small.

Dask is imported only here, and only when a scheduler is given: local runs need no Dask.
"""

from __future__ import annotations

import re
import socket
import uuid
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from typing import Any

from gb_pin.exceptions import GbPinError, InvalidArgumentError
from gb_pin.experiments.slurm import is_slurm_spec, slurm_cluster

CONNECT_TIMEOUT = 20.0  # [s] to reach a scheduler before giving up
PROBE_TIMEOUT = 5.0  # [s] to open a TCP connection to a tcp:// scheduler, before Dask is asked

_ADDRESS = re.compile(
    r"(?:(?P<scheme>tcp|tls|ws|wss|ucx|inproc)://)?(?P<host>\[[0-9a-fA-F:.]+\]|[\w.-]+)(?::(?P<port>\d{1,5}))?"
)


def check_address(address: str) -> tuple[str, str, int | None]:
    """(scheme, host, port) of a scheduler address like ``tcp://host:8786``, checked before Dask sees it.

    Raises:
        InvalidArgumentError: not of the form ``[SCHEME://]HOST:PORT`` (port 1-65535; tcp needs a port).
    """
    match = _ADDRESS.fullmatch(address)
    port = None if match is None or match["port"] is None else int(match["port"])
    scheme = "tcp" if match is None or match["scheme"] is None else match["scheme"]
    if match is None or (port is not None and not 1 <= port <= 65535) or (scheme == "tcp" and port is None):
        raise InvalidArgumentError(
            f"scheduler address {address[:100]!r} is not of the form [tcp://]HOST:PORT, e.g. tcp://head:8786"
        )
    return scheme, match["host"].strip("[]"), port


def _probe(address: str, host: str, port: int) -> None:
    """Open (and close) a TCP connection to the scheduler: a quick, clean failure for a wrong address."""
    try:
        socket.create_connection((host, port), timeout=PROBE_TIMEOUT).close()
    except OSError as exc:
        raise GbPinError(f"cannot connect to the Dask scheduler {address!r}: {exc}") from exc


def _import_distributed() -> Any:
    try:
        import distributed
    except ImportError as exc:
        raise GbPinError(
            'running on a Dask cluster needs dask.distributed: pip install "gb_pin[cluster]" '
            f"(import failed: {exc})"
        ) from exc
    return distributed


@contextmanager
def client_for(scheduler: Any, timeout: float | None = None) -> Any:
    """A ``dask.distributed.Client`` for ``scheduler``; one this function opened is closed on exit.

    Args:
        scheduler: an address (``"tcp://host:8786"``), a ``Client`` (used as is, left
            open), a cluster object with a ``scheduler_address`` (e.g. ``LocalCluster``,
            ``dask_jobqueue.SLURMCluster``), or a SLURM spec ``"slurm:cores=4,memory=8GB,jobs=10"``
            (:mod:`gb_pin.experiments.slurm`: a SLURMCluster started here and closed on exit).
        timeout: seconds to wait for the scheduler [s]; default :data:`CONNECT_TIMEOUT`.

    Raises:
        GbPinError: Dask is not installed, or the scheduler cannot be reached.
        InvalidArgumentError: ``scheduler`` is none of the above.
    """
    if is_slurm_spec(scheduler):  # a SLURMCluster built for this run, closed with it
        cluster = slurm_cluster(scheduler)
        try:
            with client_for(cluster, timeout) as client:
                yield client
        finally:
            cluster.close()
        return
    if isinstance(scheduler, str):  # checked (and, for tcp, reached) before Dask is imported
        scheme, host, port = check_address(scheduler)
        if scheme == "tcp" and port is not None:
            _probe(scheduler, host, port)
    distributed = _import_distributed()
    if isinstance(scheduler, distributed.Client):
        yield scheduler
        return
    address = getattr(scheduler, "scheduler_address", scheduler)
    if not isinstance(address, str) or not address:
        raise InvalidArgumentError(
            f"scheduler must be a Dask scheduler address like 'tcp://host:8786', a dask.distributed.Client "
            f"or a cluster object, got {scheduler!r}"
        )
    try:
        wait = CONNECT_TIMEOUT if timeout is None else timeout
        client = distributed.Client(address, timeout=wait, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise GbPinError(f"cannot connect to the Dask scheduler {address!r}: {exc}") from exc
    try:
        yield client
    finally:
        client.close()


def map_tasks(
    fn: Callable[..., Any],
    tasks: Sequence[tuple[Any, ...]],
    scheduler: Any,
    on_result: Callable[[int, Any], None],
    *,
    priorities: Sequence[float] | None = None,
) -> None:
    """Run ``fn(*task)`` for every task on a Dask cluster; call ``on_result(index, output)`` as each ends.

    Args:
        fn: a module-level function (workers import it by name).
        tasks: plain-value argument tuples.
        scheduler: see :func:`client_for`.
        on_result: receives the task's index and its output, in completion order.
        priorities: per task; the cluster starts higher values first (e.g. the longest trials).

    Raises:
        Whatever a task raised (e.g. :class:`~gb_pin.exceptions.DivergenceError`); the
        remaining tasks are cancelled.
    """
    distributed = _import_distributed()
    run = uuid.uuid4().hex[:12]
    with client_for(scheduler) as client:
        futures = {}
        for i, task in enumerate(tasks):
            priority = 0 if priorities is None else int(priorities[i])
            fut = client.submit(fn, *task, key=f"gb_pin-trial-{run}-{i}", pure=False, priority=priority)
            futures[fut] = i
        try:
            for fut in distributed.as_completed(list(futures), loop=client.loop):
                on_result(futures[fut], fut.result())
        finally:
            client.cancel(list(futures))
