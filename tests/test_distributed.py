"""Trials and sweeps on a Dask cluster (a LocalCluster on 127.0.0.1) equal the local run."""

from __future__ import annotations

import numpy as np
import pytest

import gb_pin
import gb_pin.experiments.distributed

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def cluster():  # type: ignore[no-untyped-def]
    """Two worker processes on the loopback interface, no dashboard."""
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as c:
        yield c


def test_sweep_on_a_cluster_equals_the_local_sweep(cluster) -> None:  # type: ignore[no-untyped-def]
    """A sweep sent to a tcp:// scheduler address gives bit-identical E^X, D^home and prototypes."""
    assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
    kwargs = {
        "robot": ["planar3", "planar5"],
        "learning_rate": [0.1, 0.5],
        "trials": 3,
        "movements": 40,
        "seed": 7,
    }
    remote = gb_pin.run_sweep(scheduler=cluster.scheduler_address, **kwargs)
    local = gb_pin.run_sweep(workers=1, **kwargs)
    assert remote.conditions == local.conditions
    for r, lo in zip(remote.results, local.results, strict=True):
        np.testing.assert_array_equal(r.error, lo.error)
        np.testing.assert_array_equal(r.home_distance, lo.home_distance)
        np.testing.assert_array_equal(r.prototypes, lo.prototypes)
        np.testing.assert_array_equal(r.movements, lo.movements)


def test_run_trials_accepts_a_client(cluster) -> None:  # type: ignore[no-untyped-def]
    """run_trials(scheduler=Client) runs there, leaves the client open and equals the local run."""
    with distributed.Client(cluster, set_as_default=False) as client:
        remote = gb_pin.run_trials("planar20", trials=2, movements=30, seed=1, scheduler=client)
        assert client.status == "running"
    local = gb_pin.run_trials("planar20", trials=2, movements=30, seed=1, workers=1)
    np.testing.assert_array_equal(remote.error, local.error)


def test_worker_errors_reach_the_caller(cluster) -> None:  # type: ignore[no-untyped-def]
    """An exception raised in a task on a worker is raised by run_sweep with its type and message."""

    def boom(*args):  # type: ignore[no-untyped-def]
        raise gb_pin.DivergenceError("diverged on a worker")

    with pytest.raises(gb_pin.DivergenceError, match="diverged on a worker"):
        gb_pin.experiments.distributed.map_tasks(
            boom, [(1,), (2,)], cluster.scheduler_address, lambda i, out: None
        )


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_unreachable_scheduler_is_a_clear_error(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A scheduler nobody listens on gives GbPinError naming the address, not a Dask traceback."""
    monkeypatch.setattr(gb_pin.experiments.distributed, "CONNECT_TIMEOUT", 1.0)
    with pytest.raises(gb_pin.GbPinError, match=r"127\.0\.0\.1:9"):
        gb_pin.run_trials("planar3", trials=2, movements=3, scheduler="tcp://127.0.0.1:9")
    with pytest.raises(gb_pin.InvalidArgumentError, match="scheduler must be"):
        gb_pin.run_trials("planar3", trials=2, movements=3, scheduler=42)


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_cli_trials_scheduler_option(cluster, tmp_path) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin trials --scheduler ADDRESS` runs on the cluster and writes the same JSON numbers as locally."""
    from gb_pin.cli import main

    common = ["trials", "--robot", "planar3", "--trials", "2", "--movements", "10", "--quiet", "--json"]
    assert main([*common, str(tmp_path / "d.json"), "--scheduler", cluster.scheduler_address]) == 0
    assert main([*common, str(tmp_path / "l.json"), "--workers", "1"]) == 0
    remote = gb_pin.TrialSet.load(tmp_path / "d.json")
    local = gb_pin.TrialSet.load(tmp_path / "l.json")
    np.testing.assert_array_equal(remote.error, local.error)
