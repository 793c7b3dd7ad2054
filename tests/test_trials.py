"""Independent trials: seeds, parallel equality, S(Q, e), quantiles, JSON round trip."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main


def test_trial_i_uses_seed_plus_i() -> None:
    """Trial i of run_trials equals babble with seed + i."""
    ts = gb_pin.run_trials("planar3", trials=3, movements=20, seed=5, workers=1)
    for i in range(3):
        single = gb_pin.babble("planar3", movements=20, seed=5 + i)
        np.testing.assert_array_equal(ts.error[i], single.history.error)
        np.testing.assert_array_equal(ts.home_distance[i], single.history.home_distance)
    assert ts.initial_error == ts.error[0, 0]
    assert np.all(ts.error[:, 0] == ts.initial_error)


def test_parallel_equals_serial() -> None:
    """Two worker processes give bit-identical results to one process."""
    serial = gb_pin.run_trials("planar5", trials=4, movements=15, seed=0, workers=1, learning_rate=0.3)
    parallel = gb_pin.run_trials("planar5", trials=4, movements=15, seed=0, workers=2, learning_rate=0.3)
    np.testing.assert_array_equal(serial.error, parallel.error)
    np.testing.assert_array_equal(serial.home_distance, parallel.home_distance)
    np.testing.assert_array_equal(serial.prototypes, parallel.prototypes)


def test_speed_and_quantiles_follow_their_definitions() -> None:
    """speed() is Eq. 11 over the trials; quantiles() are numpy quantiles over trials."""
    ts = gb_pin.run_trials("planar5", trials=6, movements=60, seed=1, workers=1)
    level = 0.1 * ts.initial_error
    s = ts.speed(0.5, level)
    frac = np.mean(ts.error <= level, axis=0)
    if s is None:
        assert np.all(frac < 0.5)
    else:
        idx = int(np.flatnonzero(ts.movements == s)[0])
        assert frac[idx] >= 0.5
        assert np.all(frac[:idx] < 0.5)
    q = ts.quantiles((0.25, 0.5))
    np.testing.assert_array_equal(q[1], np.median(ts.error, axis=0))
    assert q.shape == (2, ts.movements.shape[0])
    assert ts.speed(1.0, -1.0) is None


def test_save_load_round_trip(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A saved TrialSet loads back identical (JSON, no pickle)."""
    ts = gb_pin.run_trials("planar3", trials=2, movements=10, seed=0, workers=1, radius=0.15)
    path = tmp_path / "t.json"
    ts.save(path)
    back = gb_pin.TrialSet.load(path)
    np.testing.assert_array_equal(back.error, ts.error)
    np.testing.assert_array_equal(back.movements, ts.movements)
    assert back.parameters == {"radius": 0.15}
    (tmp_path / "bad.json").write_text("{not json")
    with pytest.raises(gb_pin.ResultFileError, match=r"bad\.json"):
        gb_pin.TrialSet.load(tmp_path / "bad.json")
    (tmp_path / "foreign.json").write_text(json.dumps({"a": 1}))
    with pytest.raises(gb_pin.ResultFileError, match="not a gb_pin trials file"):
        gb_pin.TrialSet.load(tmp_path / "foreign.json")


def test_cli_trials_json_has_the_documented_keys(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin trials --json` writes movements, error, home_distance and initial_error."""
    out = tmp_path / "out.json"
    argv = ["trials", "--robot", "planar3", "--trials", "2", "--movements", "10", "--workers", "1"]
    code = main([*argv, "--learning-rate", "0.5", "--json", str(out), "--quiet"])
    assert code == 0
    raw = json.loads(out.read_text())
    for key in ("movements", "error", "home_distance", "initial_error"):
        assert key in raw
    assert len(raw["error"]) == 2
    assert "S(0.5, 0.1 E_0)" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"trials": 0}, "trials"),
        ({"movements": -1}, "movements"),
        ({"seed": -2}, "seed"),
        ({"workers": 0}, "workers"),
        ({"learning_rate": -0.1}, "learning_rate"),
        ({"bogus": 1}, "bogus"),
        ({"robot": "planar1"}, "planar1"),
    ],
)
def test_bad_arguments_name_the_parameter(kwargs, name) -> None:  # type: ignore[no-untyped-def]
    """Bad run_trials arguments raise the package's ValueError naming the parameter."""
    args = {"robot": "planar3", "trials": 2, "movements": 5, "workers": 1, **kwargs}
    with pytest.raises(gb_pin.InvalidArgumentError, match=name):
        gb_pin.run_trials(**args)


def test_sweep_grid_equals_separate_trials() -> None:
    """run_sweep over a grid gives, per condition, exactly run_trials of that condition."""
    sweep = gb_pin.run_sweep(
        robot="planar3", learning_rate=[0.05, 0.5], trials=3, movements=15, seed=2, workers=2
    )
    assert [c.label for c in sweep.conditions] == ["planar3 learning_rate=0.05", "planar3 learning_rate=0.5"]
    for condition, ts in sweep:
        alone = gb_pin.run_trials(
            "planar3",
            trials=3,
            movements=15,
            seed=2,
            workers=1,
            learning_rate=condition.parameters["learning_rate"],
        )
        np.testing.assert_array_equal(ts.error, alone.error)
        np.testing.assert_array_equal(ts.home_distance, alone.home_distance)
        assert ts.parameters == condition.parameters


def test_sweep_conditions_keep_their_own_length_and_schedule(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A Condition's movements and schedule override the sweep's; the sweep saves and loads as JSON."""
    conditions = [
        gb_pin.Condition("planar2", {"learning_rate": 0.2}, movements=12, schedule=(5, 12)),
        gb_pin.Condition("planar4"),
    ]
    sweep = gb_pin.run_sweep(conditions, trials=2, movements=8, seed=0, workers=1)
    assert sweep[0].movements.tolist() == [0, 5, 12]
    assert sweep[1].movements[-1] == 8
    single = gb_pin.babble("planar2", movements=12, seed=1, learning_rate=0.2, schedule=[0, 5, 12])
    np.testing.assert_array_equal(sweep[0].error[1], single.history.error)
    sweep.save(tmp_path / "s.json")
    back = gb_pin.Sweep.load(tmp_path / "s.json")
    assert back.conditions == sweep.conditions
    for a, b in zip(back.results, sweep.results, strict=True):
        np.testing.assert_array_equal(a.error, b.error)
    with pytest.raises(gb_pin.ResultFileError, match="not a gb_pin sweep file"):
        gb_pin.Sweep.load(_trials_file(tmp_path))


def _trials_file(tmp_path) -> str:  # type: ignore[no-untyped-def]
    path = tmp_path / "t.json"
    gb_pin.run_trials("planar2", trials=1, movements=2, workers=1).save(path)
    return str(path)


def test_conditions_grid_is_the_cartesian_product() -> None:
    """conditions_grid lists robots slowest, then the arguments in the order given."""
    grid = gb_pin.conditions_grid(["planar2", "planar3"], learning_rate=[0.1, 0.2], radius=0.05)
    assert [(c.robot, c.parameters["learning_rate"]) for c in grid] == [
        ("planar2", 0.1),
        ("planar2", 0.2),
        ("planar3", 0.1),
        ("planar3", 0.2),
    ]
    assert all(c.parameters["radius"] == 0.05 for c in grid)
    assert len(set(grid)) == 4  # conditions are hashable (used as keys by the reproduction)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: gb_pin.run_sweep(robot="planar3", bogus=[1, 2]), "bogus"),
        (lambda: gb_pin.run_sweep([gb_pin.Condition("planar3")], robot="planar3"), "either conditions"),
        (lambda: gb_pin.run_sweep([]), "at least one condition"),
        (lambda: gb_pin.run_sweep(robot="planar3", learning_rate=[]), "learning_rate"),
        (lambda: gb_pin.run_sweep([gb_pin.Condition("planar3", {"sigma": -1.0})], trials=1), "sigma"),
        (lambda: gb_pin.run_sweep([gb_pin.Condition("planar3", movements=0)], trials=1), "movements"),
        (lambda: gb_pin.run_trials("planar3", trials=1, movements=5, schedule=[3, 9]), "schedule"),
        (
            lambda: gb_pin.run_trials("planar3", trials=1, movements=5, workers=2, scheduler="tcp://x:1"),
            "workers",
        ),
    ],
)
def test_bad_sweep_arguments_are_reported_before_running(call, name) -> None:  # type: ignore[no-untyped-def]
    """Bad sweep conditions raise the package's ValueError naming the culprit, before any trial runs."""
    with pytest.raises(gb_pin.InvalidArgumentError, match=name):
        call()


def test_tasks_carry_only_plain_values(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A cluster worker receives a preset name, numbers and a small array, no model (pickled < 2 kB)."""
    import pickle

    import gb_pin.experiments.distributed

    seen = []

    def fake_map_tasks(fn, tasks, scheduler, on_result, *, priorities=None):  # type: ignore[no-untyped-def]
        for i, task in enumerate(tasks):
            seen.append(task)
            on_result(i, fn(*task))

    monkeypatch.setattr(gb_pin.experiments.distributed, "map_tasks", fake_map_tasks)
    ts = gb_pin.run_trials("planar20", trials=2, movements=5, seed=4, scheduler="tcp://unused:8786")
    local = gb_pin.run_trials("planar20", trials=2, movements=5, seed=4, workers=1)
    np.testing.assert_array_equal(ts.error, local.error)
    assert len(seen) == 1  # two short trials: one task (batched, docs/CLUSTERS.md)
    ((batch,),) = seen
    assert len(batch) == 2 and len(pickle.dumps(seen[0])) < 2 * 2000
    for robot, movements, seed, schedule, kwargs in batch:
        assert isinstance(robot, str) and isinstance(movements, int) and isinstance(seed, int)
        assert isinstance(schedule, np.ndarray) and schedule.dtype == np.int64
        assert isinstance(kwargs, dict)
        assert len(pickle.dumps((robot, movements, seed, schedule, kwargs))) < 2000


def test_local_runs_import_neither_dask_nor_matplotlib() -> None:
    """Importing gb_pin and gb_pin.reproduce and running trials locally loads neither Dask nor matplotlib."""
    import subprocess
    import sys

    code = (
        "import sys, gb_pin, gb_pin.reproduce, gb_pin.experiments.distributed\n"
        "gb_pin.run_trials('planar2', trials=2, movements=2, workers=1)\n"
        "print(sorted(m for m in ('distributed', 'dask', 'matplotlib') if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_journal_skips_finished_trials_and_gives_the_same_result(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """With checkpoint=, an interrupted run_trials resumes: finished trials are read, not recomputed."""
    import gb_pin.experiments.execute as execute_module

    path = tmp_path / "trials.jsonl"
    full = gb_pin.run_trials("planar3", trials=5, movements=12, seed=2, workers=1, learning_rate=0.3)
    calls: list[int] = []
    real = execute_module.run_one_trial

    def crashing(robot, movements, seed, schedule, kwargs):  # type: ignore[no-untyped-def]
        if len(calls) == 3:
            raise KeyboardInterrupt
        calls.append(seed)
        return real(robot, movements, seed, schedule, kwargs)

    monkeypatch.setattr(execute_module, "run_one_trial", crashing)
    with pytest.raises(KeyboardInterrupt):
        gb_pin.run_trials(
            "planar3", trials=5, movements=12, seed=2, workers=1, learning_rate=0.3, checkpoint=path
        )
    assert len(path.read_text().splitlines()) == 1 + 3
    # A torn last line (killed mid-write) is ignored.
    with open(path, "a") as fh:
        fh.write('{"key": "half a line')
    calls.clear()
    monkeypatch.setattr(execute_module, "run_one_trial", lambda *a: (calls.append(a[2]), real(*a))[1])
    resumed = gb_pin.run_trials(
        "planar3", trials=5, movements=12, seed=2, workers=1, learning_rate=0.3, checkpoint=path
    )
    assert len(calls) == 2  # only the two unfinished trials ran
    np.testing.assert_array_equal(resumed.error, full.error)
    np.testing.assert_array_equal(resumed.home_distance, full.home_distance)
    np.testing.assert_array_equal(resumed.prototypes, full.prototypes)
    # Another condition in the same journal is not confused with this one.
    other = gb_pin.run_trials("planar3", trials=2, movements=12, seed=2, workers=1, checkpoint=path)
    assert not np.array_equal(other.error, full.error[:2])


def test_journal_refuses_a_foreign_file(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A checkpoint file that is not a trial journal raises ResultFileError naming it."""
    path = tmp_path / "notes.txt"
    path.write_text("hello\n")
    with pytest.raises(gb_pin.ResultFileError, match=r"notes\.txt"):
        gb_pin.run_trials("planar3", trials=2, movements=5, workers=1, checkpoint=path)


def test_babble_args_are_the_hyperparameter_table() -> None:
    """Trials take exactly the learner's hyperparameters; the old import paths still work."""
    from gb_pin.experiments import trials
    from gb_pin.learn.config import NAMES

    assert trials.BABBLE_ARGS == NAMES
    assert set(NAMES) == {
        "learning_rate",
        "sigma",
        "sigma_delta",
        "radius",
        "path_length",
        "p_home",
        "cutoff",
    }
    for name in (
        "run_trials",
        "run_sweep",
        "TrialSet",
        "Condition",
        "Sweep",
        "conditions_grid",
        "TrialJournal",
    ):
        assert getattr(trials, name) is getattr(gb_pin.experiments, name)
    assert trials.run_trials is gb_pin.run_trials and trials.TrialSet is gb_pin.TrialSet


def test_files_are_written_whole(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Saving a trial set or sweep, and dropping a journal's torn line, leave no temporary file."""
    path = tmp_path / "journal.jsonl"
    ts = gb_pin.run_trials("planar2", trials=2, movements=3, workers=1, checkpoint=path)
    lines = path.read_text().splitlines()
    assert json.loads(lines[0]) == {"format": "gb_pin.trial-journal", "format_version": 1}
    assert len(lines) == 3
    with open(path, "a") as fh:
        fh.write('{"key": "torn')
    again = gb_pin.run_trials("planar2", trials=2, movements=3, workers=1, checkpoint=path)
    np.testing.assert_array_equal(again.error, ts.error)
    assert path.read_text().splitlines() == lines
    ts.save(tmp_path / "t.json")
    gb_pin.Sweep(conditions=(gb_pin.Condition("planar2"),), results=(ts,)).save(tmp_path / "s.json")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["journal.jsonl", "s.json", "t.json"]
    assert json.loads((tmp_path / "t.json").read_text())["format"] == "gb_pin.trials"
