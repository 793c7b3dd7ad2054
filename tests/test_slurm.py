"""SLURM specs (no SLURM needed: a LocalCluster stands in) and batched trials equal unbatched and local."""

from __future__ import annotations

import sys
import types

import numpy as np
import pytest

import gb_pin
import gb_pin.experiments.execute as execute
import gb_pin.experiments.slurm as slurm
from gb_pin.experiments.slurm import parse_slurm_spec


def test_spec_parsing() -> None:
    """slurm:KEY=VALUE,... gives typed options; counts are integers, the rest strings."""
    assert parse_slurm_spec("slurm:cores=4,memory=8GB,jobs=10") == {"cores": 4, "memory": "8GB", "jobs": 10}
    assert parse_slurm_spec("slurm:cores=2, memory=1GB ,queue=short,walltime=01:00:00,processes=2") == {
        "cores": 2, "memory": "1GB", "queue": "short", "walltime": "01:00:00", "processes": 2,
    }  # fmt: skip


@pytest.mark.parametrize(
    ("spec", "match"),
    [
        ("slurm:", "needs cores and memory"),
        ("slurm:cores=4", "needs memory"),
        ("slurm:cores=4,memory=8GB,gpus=1", "bad item 'gpus=1'"),
        ("slurm:cores=4,memory=8GB,jobs", "bad item 'jobs'"),
        ("slurm:cores=4,memory=8GB,jobs=", "bad item"),
        ("slurm:cores=four,memory=8GB", "cores must be an integer"),
        ("slurm:cores=0,memory=8GB", "cores must be an integer"),
        ("slurm:cores=4,memory=8GB,jobs=-1", "jobs must be an integer"),
        ("slurm:cores=4,cores=5,memory=8GB", "given twice"),
        ("tcp://head:8786", "starts with 'slurm:'"),
    ],
)
def test_bad_specs_are_refused(spec: str, match: str) -> None:
    """A malformed spec is gb_pin's InvalidArgumentError naming the problem."""
    with pytest.raises(gb_pin.InvalidArgumentError, match=match):
        parse_slurm_spec(spec)


def test_bad_spec_is_refused_before_any_work(monkeypatch: pytest.MonkeyPatch) -> None:
    """run_trials checks the spec before planning or importing dask_jobqueue."""
    monkeypatch.setitem(sys.modules, "dask_jobqueue", None)
    with pytest.raises(gb_pin.InvalidArgumentError, match="needs memory"):
        gb_pin.run_trials("planar3", trials=2, movements=3, scheduler="slurm:cores=4")


def test_missing_dask_jobqueue_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    """Without dask-jobqueue a slurm: scheduler is GbPinError naming gb_pin[slurm]."""
    monkeypatch.setitem(sys.modules, "dask_jobqueue", None)  # import fails
    with pytest.raises(gb_pin.GbPinError, match=r'pip install "gb_pin\[slurm\]"'):
        gb_pin.run_trials("planar3", trials=2, movements=3, scheduler="slurm:cores=1,memory=1GB")


def test_slurm_is_not_imported_for_other_schedulers() -> None:
    """Importing gb_pin's cluster code does not import dask_jobqueue."""
    import subprocess

    code = "import gb_pin.experiments.distributed, sys; assert 'dask_jobqueue' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_batches() -> None:
    """Consecutive trials are gathered until their cost reaches the minimum; min_cost 0 is one per task."""
    costs = [5.0, 1.0, 1.0, 1.0, 3.0, 1.0]
    order = [0, 4, 1, 2, 3, 5]
    assert execute.batch_trials(order, costs, 3.0) == [[0], [4], [1, 2, 3], [5]]
    assert execute.batch_trials(order, costs, 0.0) == [[i] for i in order]
    assert execute.batch_trials(order, costs, 100.0) == [order]
    assert execute.batch_trials([], costs, 3.0) == []
    # planar5, 300 movements (gb-pin trials' default): about 20-30 ms a trial, 3 or 4 to a task.
    assert 2 < execute.BATCH_COST / (300 * (5 + 5)) < 5


distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def cluster():  # type: ignore[no-untyped-def]
    """Two worker processes on the loopback interface, no dashboard."""
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as c:
        yield c


def test_batched_equals_unbatched_and_local(cluster, monkeypatch: pytest.MonkeyPatch) -> None:  # type: ignore[no-untyped-def]
    """Trials batched several to a task, one to a task, and locally give the same numbers bit for bit."""
    submitted: list[int] = []
    kwargs = {"robot": ["planar3", "planar5"], "trials": 5, "movements": 30, "seed": 3}
    real_map = gb_pin.experiments.distributed.map_tasks

    def spy(fn, tasks, *args, **kw):  # type: ignore[no-untyped-def]
        submitted.append(len(tasks))
        return real_map(fn, tasks, *args, **kw)

    monkeypatch.setattr(gb_pin.experiments.distributed, "map_tasks", spy)
    batched = gb_pin.run_sweep(scheduler=cluster.scheduler_address, **kwargs)
    monkeypatch.setattr(execute, "BATCH_COST", 0.0)
    unbatched = gb_pin.run_sweep(scheduler=cluster.scheduler_address, **kwargs)
    local = gb_pin.run_sweep(workers=1, **kwargs)
    assert submitted == [1, 10]  # ten short trials: one task, then ten
    for sweep in (batched, unbatched):
        assert sweep.conditions == local.conditions
        for r, lo in zip(sweep.results, local.results, strict=True):
            np.testing.assert_array_equal(r.error, lo.error)
            np.testing.assert_array_equal(r.home_distance, lo.home_distance)
            np.testing.assert_array_equal(r.prototypes, lo.prototypes)
            np.testing.assert_array_equal(r.movements, lo.movements)


def test_slurm_spec_builds_the_cluster(cluster, monkeypatch: pytest.MonkeyPatch) -> None:  # type: ignore[no-untyped-def]
    """A slurm: spec builds SLURMCluster(**options), scales it to jobs, runs there and closes it.

    A stand-in dask_jobqueue whose SLURMCluster points at the LocalCluster: the same path as on SLURM.
    """
    made: list[object] = []

    class FakeSLURMCluster:
        def __init__(self, **options):  # type: ignore[no-untyped-def]
            self.options = options
            self.scheduler_address = cluster.scheduler_address
            self.jobs = None
            self.closed = False
            made.append(self)

        def scale(self, jobs):  # type: ignore[no-untyped-def]
            self.jobs = jobs

        def close(self):  # type: ignore[no-untyped-def]
            self.closed = True

    monkeypatch.setattr(
        slurm, "_import_jobqueue", lambda: types.SimpleNamespace(SLURMCluster=FakeSLURMCluster)
    )
    spec = "slurm:cores=4,memory=8GB,jobs=3,queue=short"
    remote = gb_pin.run_trials("planar5", trials=3, movements=20, seed=2, scheduler=spec)
    local = gb_pin.run_trials("planar5", trials=3, movements=20, seed=2, workers=1)
    np.testing.assert_array_equal(remote.error, local.error)
    np.testing.assert_array_equal(remote.prototypes, local.prototypes)
    (fake,) = made
    assert fake.options == {"cores": 4, "memory": "8GB", "queue": "short"}  # type: ignore[attr-defined]
    assert fake.jobs == 3 and fake.closed  # type: ignore[attr-defined]


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_cli_refuses_a_bad_slurm_spec(capsys: pytest.CaptureFixture[str]) -> None:
    """`gb-pin trials --scheduler slurm:...` with a bad spec fails with the message, not a traceback."""
    from gb_pin.cli import main

    code = main(["trials", "--robot", "planar3", "--trials", "2", "--movements", "3", "--quiet",
                 "--scheduler", "slurm:cores=4"])  # fmt: skip
    assert code != 0
    assert "needs memory" in capsys.readouterr().err
