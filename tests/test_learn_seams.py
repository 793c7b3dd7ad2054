"""The learner's seams: goal generators, the task map, bodies that change, and plain-array round trips.

A second goal generator (targets in a fixed cyclic order) proves that the loop takes any
goal generator; the same generator written in Python proves the Python path gives the
same numbers; a body change at a movement equals swapping the chain by hand.
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin import _files, _names
from gb_pin.learn import BabbleState, CyclicGoals, GoalBabbling, PythonGoals, UniformGoals, layout
from gb_pin.learn.goals import GoalArrays, make_goals
from gb_pin.learn.history import RecordedSteps


def _start(robot: str = "planar5", movements: int = 120, seed: int = 0, **kw: Any) -> BabbleState:
    target = gb_pin.load_robot(robot)
    config = GoalBabbling()._resolve(target.n_joints)
    return BabbleState.start(target, target.targets, movements, config, seed=seed, **kw)


def _same(a: BabbleState, b: BabbleState) -> None:
    """Every array of the two states is equal, bit for bit (the body-change schedule aside)."""
    theirs = b.to_arrays()
    for key, value in a.to_arrays().items():
        if not key.startswith("change"):
            np.testing.assert_array_equal(theirs[key], value, err_msg=key)


class PythonCycle(PythonGoals):
    """The cyclic order, written in Python (the loop hands control back at every goal)."""

    name = "python-cycle"

    def next_goal(self, state: GoalArrays, rng: np.random.Generator) -> np.ndarray:
        """The next target in order."""
        k = int(state.istate[0])
        state.istate[0] = (k + 1) % state.targets.shape[0]
        return state.targets[k]


def test_cyclic_goals_visit_the_targets_in_order() -> None:
    """With CyclicGoals every goal-directed movement ends at the next target, home returns in between."""
    st = _start(movements=60, goals=CyclicGoals(start=3), record=gb_pin.Recording(every=1))
    st.run(60)
    rec = st.recorded()
    assert rec is not None
    ends = []
    for r in range(60):
        rows = np.flatnonzero(rec.movement == r)
        last = rec.target[rows[-1]]
        if not np.isnan(last[0]):  # goal-directed: its last target is the goal
            ends.append(last)
    N = st.targets.shape[0]
    expected = st.targets[(3 + np.arange(len(ends))) % N]
    np.testing.assert_allclose(ends, expected, rtol=0, atol=1e-15)
    assert 40 < len(ends) < 60  # about p_home = 0.1 of the movements go home


def test_default_goals_are_the_papers_uniform_choice() -> None:
    """goals=None, "uniform" and UniformGoals() run the same numbers; cyclic goals run others."""
    runs = []
    for goals in (None, "uniform", UniformGoals()):
        st = _start(goals=goals)
        st.run(120)
        runs.append(st)
    _same(runs[0], runs[1])
    _same(runs[0], runs[2])
    cyc = _start(goals="cyclic")
    cyc.run(120)
    assert not np.array_equal(cyc.errors, runs[0].errors)


def test_python_goal_generator_equals_the_compiled_one() -> None:
    """A generator written in Python gives bit for bit what the compiled CyclicGoals gives."""
    a = _start(goals=CyclicGoals(), seed=5)
    b = _start(goals=PythonCycle(), seed=5)
    a.run(120)
    b.run(120)
    _same(a, b)


def test_make_goals_errors_name_the_value() -> None:
    """Unknown names and bad parameters are the package's error, with close names."""
    with pytest.raises(gb_pin.InvalidArgumentError, match="closest: cyclic"):
        make_goals("cyclc")
    with pytest.raises(
        gb_pin.InvalidArgumentError, match=r"unknown parameter 'stride'.*cyclic takes start, snap"
    ):
        make_goals("cyclic", {"stride": 2})
    with pytest.raises(gb_pin.InvalidArgumentError, match="'snp'; did you mean 'snap'"):
        make_goals("uniform:snp=0.1")  # the user's misspelling, never Python's TypeError text
    with pytest.raises(gb_pin.InvalidArgumentError, match="goals must be"):
        make_goals(5)  # type: ignore[arg-type]
    with pytest.raises(gb_pin.InvalidArgumentError, match="start"):
        CyclicGoals(start=-1)


def test_babble_takes_a_goal_generator_and_checkpoints_resume_bit_identical(tmp_path: Path) -> None:
    """babble(goals=...) runs it; a checkpoint mid-run holds its state, and resume ends as the full run."""
    full = gb_pin.babble("planar5", movements=150, seed=2, goals=CyclicGoals(start=1))
    path = tmp_path / "run.ckpt"
    st = _start(movements=150, seed=2, goals=CyclicGoals(start=1))
    st.run(70)
    from gb_pin.runs.checkpoint import CheckpointInfo, write_checkpoint

    write_checkpoint(path, st, CheckpointInfo("planar5", "planar5", 150, 2, st.config, 0.0))
    resumed = gb_pin.resume(path)
    np.testing.assert_array_equal(resumed.history.error, full.history.error)
    np.testing.assert_array_equal(resumed.model.offsets_, full.model.offsets_)


def test_state_round_trip_through_arrays_continues_bit_identical() -> None:
    """to_arrays / from_arrays mid-run, with cyclic goals and a body change due, then run on: same numbers."""
    grown = gb_pin.KinematicTarget(gb_pin.planar_chain(5, total_length=1.15), "tip",
                                   home=gb_pin.planar_home(5), axes="xy")  # fmt: skip
    a = _start(goals=CyclicGoals(), changes={80: grown})
    a.run(50)
    b = BabbleState.from_arrays(a.to_arrays(), a.config, a.rng_state(), goals=CyclicGoals())
    assert [at for at, _ in b.changes] == [80]
    a.run(120)
    b.run(120)
    _same(a, b)


def test_a_body_change_equals_swapping_the_chain_by_hand() -> None:
    """changes={r: robot} switches the forward kinematics at movement r, one history throughout."""
    grown = gb_pin.KinematicTarget(gb_pin.planar_chain(5, total_length=1.15), "tip",
                                   home=gb_pin.planar_home(5), axes="xy")  # fmt: skip
    auto = _start(changes={60: grown})
    auto.run(120)
    hand = _start()
    hand.run(60)
    hand.chain = grown.chain
    hand.run(120)
    _same(auto, hand)
    same_body = _start()
    same_body.run(120)
    assert not np.array_equal(auto.errors[61:], same_body.errors[61:])
    np.testing.assert_array_equal(auto.errors[:61], same_body.errors[:61])


def test_body_changes_must_keep_the_joints_and_task() -> None:
    """A change to a chain of other dimensions, or at movement 0, is refused."""
    with pytest.raises(gb_pin.InvalidArgumentError, match="6 joints"):
        _start(changes={10: gb_pin.load_robot("planar6")})
    with pytest.raises(gb_pin.InvalidArgumentError, match="changes movement"):
        _start(changes={0: gb_pin.load_robot("planar5")})


def test_task_map_is_the_frame_position_on_the_task_axes() -> None:
    """The chain's task map gives the frame's position on its axes (the paper's x)."""
    chain = gb_pin.load_robot("talos_left_arm").chain
    task = chain.task
    assert task.n_task == 3 and task.arrays().kind == 0
    q = gb_pin.load_robot("talos_left_arm").home
    np.testing.assert_allclose(chain.forward(q), gb_pin.load_robot("talos_left_arm").forward(q), atol=1e-12)


@pytest.mark.parametrize(
    ("key", "value", "match"),
    [
        ("istate", lambda a: _with(a, layout.EVAL_CURSOR, -(10**9)), "counters"),
        ("istate", lambda a: _with(a, layout.KIND, 7), "counters"),
        ("istate", lambda a: _with(a, layout.RECORDED, 10**6), "counters"),
        ("rec_posture", lambda a: a[:, :-1], "recording"),
        ("lower", lambda a: a[:1], "lower"),
        ("chain_parents", lambda a: a + 3, "chain"),
        ("prototypes", lambda a: a.astype(complex), "dtype"),
        ("noise_A", lambda a: a * np.inf, "finite"),
    ],
)
def test_tampered_state_arrays_are_refused(key: str, value: Any, match: str) -> None:
    """Arrays read back are validated before compiled code sees them (no out-of-bounds access)."""
    st = _start(movements=40, record=gb_pin.Recording(every=2))
    st.run(20)
    arrays = dict(st.to_arrays())
    arrays[key] = value(np.array(arrays[key]))
    with pytest.raises(gb_pin.InvalidArgumentError, match=match):
        BabbleState.from_arrays(arrays, st.config, st.rng_state())


def _with(a: np.ndarray, index: int, value: int) -> np.ndarray:
    a = a.copy()
    a[index] = value
    return a


def test_the_rng_state_must_name_an_allowed_bit_generator() -> None:
    """A checkpoint naming np.random.seed (or anything but a bit generator) is refused."""
    st = _start(movements=10)
    bad = {**st.rng_state(), "bit_generator": "seed"}
    with pytest.raises(gb_pin.InvalidArgumentError, match="bit generators"):
        BabbleState.from_arrays(st.to_arrays(), st.config, bad)


def test_learner_params_follow_scikit_learn() -> None:
    """get_params returns the hyperparameters as given; set_params sets them and refuses unknown names."""
    learner = GoalBabbling(learning_rate=0.3)
    assert learner.get_params()["learning_rate"] == 0.3
    assert learner.set_params(radius=0.2) is learner and learner.radius == 0.2
    with pytest.raises(gb_pin.InvalidArgumentError, match="unknown hyperparameters"):
        learner.set_params(eta=1.0)


def test_local_linear_map_round_trips_through_arrays() -> None:
    """LocalLinearMap.to_arrays / from_arrays rebuild the same predictions; bad arrays are refused."""
    res = gb_pin.babble("planar5", movements=80, seed=1)
    again = gb_pin.LocalLinearMap.from_arrays(res.model.to_arrays(), radius=res.config.radius)
    np.testing.assert_array_equal(again.predict(res.targets), res.inverse(res.targets))
    arrays = res.model.to_arrays()
    with pytest.raises(gb_pin.InvalidArgumentError, match="inconsistent shapes"):
        gb_pin.LocalLinearMap.from_arrays({**arrays, "offsets": arrays["offsets"][:-1]}, radius=0.1)
    with pytest.raises(gb_pin.InvalidArgumentError, match="not finite"):
        gb_pin.LocalLinearMap.from_arrays({**arrays, "matrices": arrays["matrices"] * np.nan}, radius=0.1)


def test_recorded_steps_round_trip_through_arrays() -> None:
    """RecordedSteps.to_arrays / from_arrays is the one conversion (results and checkpoints use it)."""
    res = gb_pin.babble("planar5", movements=10, seed=1, record=gb_pin.Recording(every=3))
    rec = res.recording
    assert rec is not None
    again = RecordedSteps.from_arrays(rec.to_arrays(), 5, 2)
    assert again is not None
    for name in RecordedSteps.FIELDS:
        np.testing.assert_array_equal(getattr(again, name), getattr(rec, name))
    assert RecordedSteps.from_arrays({}, 5, 2) is None
    with pytest.raises(gb_pin.InvalidArgumentError, match="incomplete"):
        RecordedSteps.from_arrays({"rec_step": rec.step}, 5, 2)


def test_atomic_write_replaces_or_leaves_the_old_file(tmp_path: Path) -> None:
    """A failed write leaves the previous file and no temporary; a planted symlink is never followed."""
    path = tmp_path / "out.json"
    _files.write_json(path, {"a": 1})
    with pytest.raises(RuntimeError), _files.atomic_write(path, text=True) as fh:
        fh.write("half")
        raise RuntimeError("crash")
    assert path.read_text() == '{"a": 1}'
    assert sorted(os.listdir(tmp_path)) == ["out.json"]
    victim = tmp_path / "victim"
    victim.write_text("keep")
    os.symlink(victim, tmp_path / "out.json.tmp")
    _files.write_text(path, "new")
    assert path.read_text() == "new" and victim.read_text() == "keep"
    with pytest.raises(OSError):
        _files.write_text(tmp_path / "missing" / "x.json", "x")


def test_closest_names_helper() -> None:
    """One "did you mean" helper: close names first, else the valid ones."""
    assert _names.closest("plnar", ["planar", "panda", "ur5"]) == ["planar"]
    assert _names.suggest("zzz", ["a", "b"]) == "valid: a, b"
    assert _names.suggest("pand", ["panda", "ur5"]) == "closest: panda"


def test_config_resolve_and_validation() -> None:
    """BabbleConfig.resolve fills sigma (Eq. 12) and sigma_delta (0.1 sigma); bad values name themselves."""
    cfg = gb_pin.BabbleConfig.resolve(20, learning_rate=0.5)
    assert cfg.learning_rate == 0.5 and cfg.sigma == gb_pin.default_sigma(20)
    assert cfg.sigma_delta == 0.1 * cfg.sigma
    with pytest.raises(gb_pin.InvalidArgumentError, match="p_home"):
        replace(cfg, p_home=1.0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="unknown hyperparameters"):
        gb_pin.BabbleConfig.resolve(5, eta=0.1)
