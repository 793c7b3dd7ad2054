"""SLURM clusters for trials and sweeps: ``scheduler="slurm:cores=4,memory=8GB,jobs=10"``.

The spec names a ``dask_jobqueue.SLURMCluster`` (``pip install "gb_pin[slurm]"``): each SLURM
job is one Dask worker job with ``cores`` cores and ``memory`` memory, and ``jobs`` of them are
requested. ``dask_jobqueue`` is imported only when such a spec is used. A cluster object built
by hand (``SLURMCluster(...)``, with any option of dask-jobqueue) can be passed as ``scheduler=``
instead. See docs/CLUSTERS.md.
"""

from __future__ import annotations

from typing import Any

from gb_pin.exceptions import GbPinError, InvalidArgumentError

PREFIX = "slurm:"
# key -> type of the value; everything but ``jobs`` is passed to SLURMCluster(...).
SPEC_KEYS: dict[str, type] = {
    "cores": int,
    "processes": int,
    "memory": str,
    "jobs": int,
    "queue": str,
    "account": str,
    "walltime": str,
    "interface": str,
}
MAX_JOBS = 10_000


def is_slurm_spec(scheduler: Any) -> bool:
    """Whether ``scheduler`` is a string of the form ``slurm:KEY=VALUE,...``."""
    return isinstance(scheduler, str) and scheduler.startswith(PREFIX)


def parse_slurm_spec(spec: str) -> dict[str, Any]:
    """The options of ``slurm:cores=4,memory=8GB,jobs=10`` as a dict (``cores`` and ``memory`` required).

    Raises:
        InvalidArgumentError: not ``slurm:`` followed by ``KEY=VALUE`` pairs of :data:`SPEC_KEYS`,
            a repeated key, a non-positive count, or ``cores`` / ``memory`` missing.
    """
    if not is_slurm_spec(spec):
        raise InvalidArgumentError(f"a SLURM scheduler spec starts with 'slurm:', got {spec[:100]!r}")
    options: dict[str, Any] = {}
    body = spec[len(PREFIX) :]
    for item in body.split(",") if body else []:
        key, sep, value = item.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or key not in SPEC_KEYS or not value:
            raise InvalidArgumentError(
                f"bad item {item[:60]!r} in the SLURM spec {spec[:100]!r}: expected KEY=VALUE with KEY "
                f"one of {', '.join(SPEC_KEYS)} (e.g. slurm:cores=4,memory=8GB,jobs=10)"
            )
        if key in options:
            raise InvalidArgumentError(f"{key!r} given twice in the SLURM spec {spec[:100]!r}")
        if SPEC_KEYS[key] is int:
            if not value.isdigit() or not 1 <= int(value) <= MAX_JOBS:
                raise InvalidArgumentError(
                    f"{key} must be an integer in [1, {MAX_JOBS}] in the SLURM spec, got {value[:20]!r}"
                )
            options[key] = int(value)
        else:
            options[key] = value
    missing = [k for k in ("cores", "memory") if k not in options]
    if missing:
        raise InvalidArgumentError(
            f"the SLURM spec {spec[:100]!r} needs {' and '.join(missing)} "
            "(e.g. slurm:cores=4,memory=8GB,jobs=10)"
        )
    return options


def _import_jobqueue() -> Any:
    try:
        import dask_jobqueue
    except ImportError as exc:
        raise GbPinError(
            f'a slurm: scheduler needs dask-jobqueue: pip install "gb_pin[slurm]" (import failed: {exc})'
        ) from exc
    return dask_jobqueue


def slurm_cluster(spec: str) -> Any:
    """A started ``dask_jobqueue.SLURMCluster`` for ``spec``, scaled to its ``jobs`` (default 1).

    Raises:
        InvalidArgumentError: a malformed spec (checked before dask_jobqueue is imported).
        GbPinError: dask-jobqueue is not installed.
    """
    options = parse_slurm_spec(spec)
    jobs = options.pop("jobs", 1)
    cluster = _import_jobqueue().SLURMCluster(**options)
    cluster.scale(jobs=jobs)
    return cluster
