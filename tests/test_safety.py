"""Safe babbling (gb_pin.safety): obstacles, the collision matrix, asks cut short, bad setups refused."""

from __future__ import annotations

import itertools
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.exceptions import InvalidArgumentError, UnsafeSetupError
from gb_pin.robot.presets import load_robot
from gb_pin.safety import Box, Sphere, Table, parse_obstacle
from gb_pin.safety.checker import CollisionChecker
from gb_pin.safety.geometry import robot_geometry
from gb_pin.safety.matrix import ENABLED, generate_matrix, pair_contacts, sample_postures

# the SO-101 scenario: goals 1-8 cm above the table it stands on, a 4 x 4 x 9 cm post in their middle
POST = Box((0.26, 0.0, 0.045), (0.02, 0.02, 0.045))


def so101_goals() -> np.ndarray:
    g = np.mgrid[0.19:0.33:5j, -0.07:0.07:5j, 0.01:0.08:3j].reshape(3, -1).T
    return g[~POST.contains(g, margin=0.03)]


@pytest.fixture(autouse=True, scope="module")
def _cache(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    old = os.environ.get("GB_PIN_CACHE")
    os.environ["GB_PIN_CACHE"] = str(tmp_path_factory.mktemp("cache"))
    yield
    if old is None:
        del os.environ["GB_PIN_CACHE"]
    else:
        os.environ["GB_PIN_CACHE"] = old


def test_obstacles_are_checked_and_parsed() -> None:
    assert parse_obstacle("table:0.0") == Table(0.0)
    box = parse_obstacle("box:center=0.21,0,0.045,half=0.02,0.02,0.045")
    assert box == Box((0.21, 0, 0.045), (0.02, 0.02, 0.045))
    assert parse_obstacle("sphere:center=0.3,0,0.2,radius=0.05") == Sphere((0.3, 0, 0.2), 0.05)
    for bad in ("cube:1", "box:center=1,2,half=1,1,1", "sphere:center=0,0,0,radius=-1", "table:x"):
        with pytest.raises(InvalidArgumentError) as info:
            parse_obstacle(bad)
        assert "\n" not in str(info.value)
    with pytest.raises(InvalidArgumentError):
        Box((0, 0, np.nan), (1, 1, 1))
    pts = np.array([[0.26, 0.0, 0.0], [0.26, 0.0, 0.1], [0.5, 0.5, 0.5]])
    assert POST.contains(pts).tolist() == [True, False, False]
    assert POST.contains(pts, margin=0.011).tolist() == [True, True, False]


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_a_far_obstacle_changes_nothing_bit_for_bit() -> None:
    """A checked run whose asks are all safe is babble()'s run, bit for bit (the check draws nothing)."""
    plain = gb_pin.babble("so101", movements=20, seed=3)
    checked = gb_pin.babble("so101", movements=20, seed=3, obstacles=[Sphere((5.0, 5.0, 5.0), 0.1)])
    assert np.array_equal(plain.history.error, checked.history.error)
    assert np.array_equal(plain.model.predict(plain.targets), checked.model.predict(plain.targets))
    assert checked.checked_asks == 20 * 25 and checked.cut_asks == 0


def _fine_contacts(checker: CollisionChecker, postures: list[np.ndarray]) -> int:
    """Contacts (no margin) along the straight segments between consecutive postures, 2 mm apart."""
    import pinocchio as pin

    gd = checker.collision_model.createData()
    model, data = checker._model, checker._model.createData()
    hits = 0
    for a, b in itertools.pairwise(postures):
        n = max(1, int(np.ceil(2.0 * np.dot(checker._lever, np.abs(b - a)) / 0.002)))
        for s in np.linspace(0.0, 1.0, n + 1):
            q = checker.target.to_pinocchio(a + s * (b - a))
            hits += bool(pin.computeCollisions(model, data, checker.collision_model, gd, q, True))
    return hits


def test_unsafe_asks_are_cut_short_and_nothing_touches() -> None:
    """SO-101 by its table around a post: asks are cut, and no executed move touches (2 mm sampling)."""
    session = gb_pin.babble_session(
        "so101",
        movements=20,
        seed=0,
        obstacles=[Table(0.0), POST],
        self_collision=True,
        targets=so101_goals(),
    )
    checker = session.guard
    assert isinstance(checker, CollisionChecker)
    postures = [checker.target.home.copy()]
    while not session.done:
        q = session.ask()
        postures.append(q)
        session.tell(checker.target.forward(q))
    assert session.cuts > 0  # the goals by the post and the table make some asks unsafe
    assert _fine_contacts(checker, postures) == 0
    assert all(checker.is_safe(q) for q in postures)


def test_bad_setups_get_one_line_errors_before_anything_moves(tmp_path: Path) -> None:
    cases = [
        dict(obstacles=[Sphere((0.29, 0.0, 0.134), 0.03)]),  # contains the gripper at home
        dict(obstacles=[Table(0.1)]),  # above the lowest goals (z 0.074 m)
        dict(obstacles=[Box((0.29, 0.0, 0.13), (0.1, 0.1, 0.001))], targets=[[0.29, 0.0, 0.13]]),
    ]
    for options in cases:
        with pytest.raises(UnsafeSetupError) as info:
            gb_pin.babble_session("so101", movements=5, seed=0, **options)  # type: ignore[arg-type]
        assert "\n" not in str(info.value), str(info.value)
    urdf = tmp_path / "bare.urdf"
    urdf.write_text(
        '<robot name="bare"><link name="base"/><link name="l1"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        '<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>'
        '<origin xyz="0 0 0.1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>'
        '<link name="tip"/><joint name="f" type="fixed"><parent link="l1"/><child link="tip"/>'
        '<origin xyz="0.3 0 0"/></joint></robot>'
    )
    goal = [[0.3 * np.cos(0.2), 0.3 * np.sin(0.2)]]
    robot = gb_pin.KinematicTarget.from_urdf(urdf, frame="tip", axes="xy", home=[0.3], targets=goal)
    with pytest.raises(UnsafeSetupError, match="no <collision> geometry") as info:
        gb_pin.babble(robot, movements=5, obstacles=[Table(-1.0)])
    assert "\n" not in str(info.value)
    result = gb_pin.babble(robot, movements=5, obstacles=[Table(-1.0)], collision_geometry="capsules")
    assert result.checked_asks == 5 * 25


@pytest.mark.parametrize("robot", ["so101", "so100", "panda", "ur5"])
def test_collision_matrix_keeps_every_pair_that_collides(robot: str) -> None:
    """The matrix from 300 samples keeps every pair that touches in 300 other postures.

    And no pair in contact at home. CI-sized: scripts/check_collision_matrix.py samples 10^4.
    """
    target = load_robot(robot)
    geometry = robot_geometry(target)
    matrix = generate_matrix(target, geometry, clearance=0.01, samples=300, seed=0)
    k = len(geometry.body)
    enabled = [(i, j) for i in range(k) for j in range(i + 1, k) if matrix.reason[i, j] == ENABLED]
    assert pair_contacts(target, geometry, enabled, target.home[None, :]).sum() == 0
    candidates = [(i, j) for i in range(k) for j in range(i + 1, k) if matrix.reason[i, j] != 1]
    hits = pair_contacts(target, geometry, candidates, sample_postures(target.lower, target.upper, 300, 1))
    missed = [candidates[p] for p in np.nonzero(hits)[0] if matrix.reason[candidates[p]] != ENABLED]
    assert missed == []


def test_mujoco_plant_with_contacts_agrees_with_the_checker_and_counts_no_contact() -> None:
    """MuJoCo's contacts (the same shapes and pairs, no margin) agree with coal's.

    A checked run of the SO-101 around the post never touches in physics; an unchecked ask into the
    table does.
    """
    pytest.importorskip("mujoco")
    import pinocchio as pin

    from gb_pin.sim import MujocoPlant

    obstacles = [Table(0.0), POST]
    plant = MujocoPlant("so101", kp=100.0, obstacles=obstacles, self_collision=True)
    checker = plant.collision
    mj, model, data = plant._mj, plant.mj_model, plant._scratch
    postures = sample_postures(checker.target.lower, checker.target.upper, 60, 5)
    disagree = 0
    for q in postures:
        data.qpos[plant._dofs] = q
        mj.mj_forward(model, data)
        gd = checker.collision_model.createData()
        touch = pin.computeCollisions(checker._model, checker._data, checker.collision_model, gd,
                                      checker.target.to_pinocchio(q), True)  # fmt: skip
        disagree += bool(touch) != (data.ncon > 0)
    assert disagree <= 2  # (contacts within rounding of touching may differ)
    result = gb_pin.babble(plant, movements=5, seed=1, obstacles=obstacles, self_collision=True,
                           targets=so101_goals())  # fmt: skip
    assert result.checked_asks == 5 * 25
    assert plant.collision.asks == 5 * 25  # the plant's own checker served the run
    assert plant.contacts == 0 and plant.contact_pairs == {}
    into_table = next(
        q for q in postures if not checker.is_safe(q) and checker.contacts(q)[0][1] == "obstacle_0"
    )
    plant.forward(into_table)  # unchecked: the arm hits the table
    assert plant.contacts > 0
    pairs = plant.contact_pairs  # which geoms touched, in how many steps, how deep
    assert sum(steps for steps, _ in pairs.values()) == plant.contacts
    assert any("obstacle_0" in a + b for a, b in pairs) and all(depth >= 0.0 for _, depth in pairs.values())


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_preset_safety_table_and_cli_options(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A preset's [safety] table applies to its runs; the CLI's --table/--obstacle make the same run."""
    import dataclasses

    from gb_pin.robot import presets

    text = (presets._preset_bytes(presets.resources.files("gb_pin.presets") / "so101.toml")).decode()
    text = text.replace("[learner]", '[safety]\nobstacles = [{kind = "table", height = 0.0}]\n\n[learner]')
    preset = presets._read_preset(text.encode(), "so101.toml")
    assert preset.safety == {"obstacles": [{"kind": "table", "height": 0.0}]}
    with pytest.raises(InvalidArgumentError, match=r"\[safety\]"):
        presets._read_preset(text.replace("obstacles =", "obstacle =").encode(), "so101.toml")
    table = dict(presets._presets())
    table["so101safe"] = dataclasses.replace(preset, name="so101safe")
    monkeypatch.setattr(presets, "_PRESETS", table)
    session = gb_pin.babble_session("so101safe", movements=2, seed=0)
    assert isinstance(session.guard, CollisionChecker) and session.guard.obstacles == (Table(0.0),)
    assert gb_pin.babble_session("so101", movements=2, seed=0).guard is None
    from gb_pin.cli import main

    argv = ["babble", "--robot", "so101", "--movements", "3", "--quiet", "--table", "0.0"]
    assert main([*argv, "--obstacle", "box:center=0.35,0.1,0.1,half=0.02,0.02,0.1"]) == 0
    assert "safety           75 asks checked" in capsys.readouterr().out
    assert main([*argv[:-1], "0.2"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "the table (z <= 0.2 m)" in err, err


def test_trials_carry_obstacles_as_plain_tables() -> None:
    """run_trials(obstacles=...) checks each trial's asks; the parameters stay plain (journals)."""
    trials = gb_pin.run_trials("so101", trials=1, movements=2, workers=1, obstacles=[Table(0.0)])
    assert trials.parameters["obstacles"] == [{"kind": "table", "height": 0.0}]
    spec = gb_pin.RunSpec("so101", movements=2, obstacles=[Table(0.0)], clearance=0.02)
    assert spec.trial_arguments()[3]["clearance"] == 0.02
    with pytest.raises(InvalidArgumentError, match="obstacle kind"):
        gb_pin.run_trials("so101", trials=1, movements=2, workers=1, obstacles=[{"kind": "cube"}])


def test_srdf_disables_pairs_and_a_resumed_session_keeps_its_guard(tmp_path: Path) -> None:
    from gb_pin.safety.matrix import SRDF, apply_srdf

    target = load_robot("panda")
    geometry = robot_geometry(target)
    matrix = generate_matrix(target, geometry, clearance=0.01, samples=50)
    links = geometry.links
    i, j = matrix.pairs[0]
    srdf = tmp_path / "arm.srdf"
    srdf.write_text(f'<robot name="panda"><disable_collisions link1="{links[i]}" link2="{links[j]}" '
                    'reason="Never"/></robot>')  # fmt: skip
    assert apply_srdf(matrix, geometry, srdf).reason[i, j] == SRDF
    checker = CollisionChecker(target, [Table(0.0)], self_collision=True, matrix=matrix, srdf=srdf)
    assert (i, j) not in checker.matrix.pairs  # type: ignore[union-attr]
    session = gb_pin.babble_session(target, movements=3, seed=0, checkpoint=tmp_path / "s.npz",
                                    obstacles=[Table(0.0)])  # fmt: skip
    while not session.done:
        session.tell(target.forward(session.ask()))
    session.close()
    resumed = gb_pin.resume_session(tmp_path / "s.npz", guard=session.guard)
    assert resumed.guard is session.guard


def _exact_safe(checker: CollisionChecker, q: np.ndarray) -> bool:
    """Reference: coal on every checked pair (no prefilter), as the checker's pairs and clearance."""
    import pinocchio as pin

    gm, gd = checker.collision_model, checker.collision_model.createData()
    for request in gd.collisionRequests:
        request.security_margin = checker.clearance
    data = checker.target.model.createData()
    pin.computeCollisions(checker.target.model, data, gm, gd, checker.target.to_pinocchio(q), False)
    return not any(r.isCollision() for r in gd.collisionResults)


def _exact_cut(checker: CollisionChecker, a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, bool, int]:
    """Reference: the segment's samples one by one (the first version of ``cut``), each by coal alone.

    Returns (last safe posture, whether the segment is safe, postures checked).
    """
    n = checker.samples(a, b)
    last = a
    for k in range(1, n + 1):
        q = b if k == n else a + (k / n) * (b - a)
        if not _exact_safe(checker, q):
            return last, False, k
        last = q
    return b, True, n


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
@pytest.mark.parametrize("scene", ["so101", "panda"])
def test_prefiltered_checks_give_coals_exact_verdicts_and_cuts(scene: str) -> None:
    """The compiled bounding-sphere prefilter drops no pair coal finds within the clearance.

    120 random postures (about a third unsafe) and 60 segments from near-home postures (some cut),
    against coal on every checked pair: the same verdicts, the same cut postures bit for bit, the
    same count of postures checked.
    """
    from gb_pin.safety.scenarios import SCENES

    setup = SCENES[scene]()
    target = load_robot(setup.robot)
    checker = CollisionChecker(target, setup.obstacles, self_collision=True)
    Q = sample_postures(target.lower, target.upper, 180, seed=3)
    assert checker._base is not None  # the fast configuration, the same as to_pinocchio's
    assert all(np.array_equal(checker._configuration(q), target.to_pinocchio(q)) for q in Q[:20])
    verdicts = [checker.is_safe(q) for q in Q[:120]]
    assert verdicts == [_exact_safe(checker, q) for q in Q[:120]]
    assert 0 < sum(verdicts) < 120
    home = np.asarray(target.home, dtype=float)
    cuts = 0
    for q0, q1 in itertools.pairwise(home + 0.3 * (Q[120:] - home)):
        if not _exact_safe(checker, q0):
            continue
        before = checker.checks
        got = checker.cut(q0, q1)
        want = _exact_cut(checker, q0, q1)
        assert got[1] == want[1] and np.array_equal(got[0], want[0])
        assert checker.checks - before == want[2]
        cuts += not want[1]
    assert cuts > 0


class _StopError(Exception):
    pass


def test_checkpoints_and_results_record_the_obstacles_and_resume_checked(tmp_path: Path) -> None:
    """A safe run's checkpoint and result file record its obstacles and settings; resumes check them.

    Stopped at movement 3 of 6 and resumed from the file alone (no guard given), a session and a
    babble() run end bit-identical to the uninterrupted run, with the same asks checked and cut.
    """
    from gb_pin.exceptions import ResultFileError
    from gb_pin.runs.checkpoint import read_checkpoint

    options = dict(obstacles=[Table(0.0), POST], self_collision=True, targets=so101_goals())
    full = gb_pin.babble("so101", movements=6, seed=5, **options)  # type: ignore[arg-type]
    assert full.cut_asks > 0 and full.safety is not None
    assert full.safety["obstacles"] == [{"kind": "table", "height": 0.0}, plain_box(POST)]
    path = tmp_path / "s.npz"
    session = gb_pin.babble_session("so101", movements=6, seed=5, checkpoint=path, checkpoint_every=3,
                                    **options)  # type: ignore[arg-type]  # fmt: skip
    target = session.target
    while session.movements < 3:
        session.tell(target.forward(session.ask()))
    session.close()
    info = read_checkpoint(path)[1]
    assert info.safety is not None and info.safety["self_collision"] is True
    assert info.safety["clearance"] == 0.01 and info.safety["cut_asks"] == session.cuts
    resumed = gb_pin.resume_session(path)
    guard = resumed.guard
    assert isinstance(guard, CollisionChecker) and guard.obstacles == (Table(0.0), POST)
    while not resumed.done:
        resumed.tell(target.forward(resumed.ask()))
    result = resumed.result()
    assert np.array_equal(result.history.error, full.history.error)
    assert (result.checked_asks, result.cut_asks) == (full.checked_asks, full.cut_asks)
    assert result.safety == full.safety
    resumed.close()

    def stop(movements: int) -> None:
        if movements == 3:
            raise _StopError

    path2 = tmp_path / "b.npz"
    with pytest.raises(_StopError):
        gb_pin.babble("so101", movements=6, seed=5, checkpoint=path2, checkpoint_every=3, callback=stop,
                      **options)  # type: ignore[arg-type]  # fmt: skip
    again = gb_pin.resume(path2)
    assert np.array_equal(again.history.error, full.history.error)
    assert (again.checked_asks, again.cut_asks, again.safety) == (full.checked_asks, full.cut_asks,
                                                                  full.safety)  # fmt: skip
    full.save(tmp_path / "r.npz")
    loaded = gb_pin.load_result(tmp_path / "r.npz")
    assert (loaded.safety, loaded.cut_asks, loaded.checked_asks) == (full.safety, full.cut_asks,
                                                                     full.checked_asks)  # fmt: skip
    assert gb_pin.babble("so101", movements=2).safety is None
    from gb_pin.runs.archive import atomic_savez, read_archive
    from gb_pin.runs.checkpoint import FORMAT_VERSION

    arrays, meta = read_archive(str(path), "checkpoint", "gb_pin.checkpoint", FORMAT_VERSION)
    for bad in ({"obstacles": [{"kind": "cube"}]}, {"clearance": -1.0}, {"self_collision": "yes"}, []):
        meta2 = dict(meta)
        meta2["safety"] = {**meta["safety"], **bad} if isinstance(bad, dict) else bad
        atomic_savez(str(tmp_path / "bad.npz"), arrays, meta2, digest=True)  # a well-formed file
        with pytest.raises(ResultFileError) as error:
            gb_pin.resume_session(tmp_path / "bad.npz")
        assert "\n" not in str(error.value) and "digest" not in str(error.value)


def test_slide_false_stops_at_the_cut_and_is_recorded_resumed_and_refused_when_malformed(
    tmp_path: Path,
) -> None:
    """``slide=False``: every cut ask stops on its straight move; files record it; resumes keep it.

    The sliding run (default) writes no ``slide`` key, so its files are as before; a stopping run's
    checkpoint says ``"slide": False`` and a resume from the file alone stops too, ending bit-identical
    to the uninterrupted run. A malformed entry, a non-bool option, a preset key and the CLI flag.
    """
    from gb_pin.cli.body_options import add_safety_options, safety
    from gb_pin.exceptions import ResultFileError
    from gb_pin.runs.spec import RunSpec

    options = dict(obstacles=[Table(0.0), POST], self_collision=True, targets=so101_goals())
    sliding = gb_pin.babble("so101", movements=6, seed=5, **options)  # type: ignore[arg-type]
    full = gb_pin.babble("so101", movements=6, seed=5, slide=False, **options)  # type: ignore[arg-type]
    assert sliding.safety is not None and "slide" not in sliding.safety
    assert full.safety is not None and full.safety["slide"] is False and full.cut_asks > 0
    assert not np.array_equal(full.history.error, sliding.history.error)
    path = tmp_path / "stop.npz"
    session = gb_pin.babble_session("so101", movements=6, seed=5, slide=False, checkpoint=path,
                                    checkpoint_every=3, **options)  # type: ignore[arg-type]  # fmt: skip
    guard, target = session.guard, session.target
    assert isinstance(guard, CollisionChecker) and guard.slide is False
    sliding_guard = CollisionChecker(target, [Table(0.0), POST], self_collision=True)
    stopping = CollisionChecker(target, [Table(0.0), POST], self_collision=True, slide=False)
    rng = np.random.default_rng(0)
    home, on_move, off_move = target.home, 0, 0
    for q_to in rng.uniform(target.lower, target.upper, size=(60, target.n_joints)):
        stop, slid = stopping(home, q_to), sliding_guard(home, q_to)
        assert (stop is None) == (slid is None)
        if stop is not None:  # the stop lies on the straight move, before its end
            t = float(np.dot(stop - home, q_to - home) / np.dot(q_to - home, q_to - home))
            assert 0.0 <= t < 1.0 and np.allclose(stop, home + t * (q_to - home), atol=1e-12)
            on_move += 1
            off_move += not np.allclose(slid, stop)
    assert on_move > 0 and off_move > 0  # cuts happened, and sliding went elsewhere
    while session.movements < 3:
        session.tell(target.forward(session.ask()))
    session.close()
    resumed = gb_pin.resume_session(path)
    assert isinstance(resumed.guard, CollisionChecker) and resumed.guard.slide is False
    while not resumed.done:
        resumed.tell(target.forward(resumed.ask()))
    result = resumed.result()
    assert np.array_equal(result.history.error, full.history.error)
    assert (result.cut_asks, result.safety) == (full.cut_asks, full.safety)
    resumed.close()
    from gb_pin.runs.archive import atomic_savez, read_archive
    from gb_pin.runs.checkpoint import FORMAT_VERSION

    arrays, meta = read_archive(str(path), "checkpoint", "gb_pin.checkpoint", FORMAT_VERSION)
    meta["safety"] = {**meta["safety"], "slide": "no"}
    atomic_savez(str(tmp_path / "bad.npz"), arrays, meta, digest=True)
    with pytest.raises(ResultFileError, match="slide"):
        gb_pin.resume_session(tmp_path / "bad.npz")
    with pytest.raises(InvalidArgumentError, match="slide"):
        RunSpec("so101", 1, 0, slide="no")  # type: ignore[arg-type]
    assert RunSpec("so101", 1, 0, slide=False, **options).trial_arguments()[3]["slide"] is False
    assert "slide" not in RunSpec("so101", 1, 0, **options).trial_arguments()[3]
    import argparse

    parser = argparse.ArgumentParser()
    add_safety_options(parser)
    assert safety(parser.parse_args(["--table", "0", "--no-slide"]))["slide"] is False
    assert "slide" not in safety(parser.parse_args(["--table", "0"]))


def plain_box(box: Box) -> dict:
    from gb_pin.safety.obstacles import plain

    return plain(box)


@pytest.mark.parametrize("scene", ["so101", "so101-issue", "panda"])
def test_segments_called_safe_never_touch_by_a_dense_check(scene: str) -> None:
    """60 random segments near the obstacles: none the checker passes touches at 2 mm sampling.

    The reference is coal on every checked pair with no margin and no prefilter, every 2 mm of the
    fastest point's travel; segments it finds touching must all be cut (and some are).
    """
    from gb_pin.safety.scenarios import SCENES

    setup = SCENES[scene]()
    target = load_robot(setup.robot)
    checker = CollisionChecker(target, setup.obstacles, self_collision=True)
    home = np.asarray(target.home, dtype=float)
    Q = home + 0.4 * (sample_postures(target.lower, target.upper, 300, seed=11) - home)
    passed = touching = 0
    for q0, q1 in itertools.pairwise(Q):
        if passed >= 60 or not checker.is_safe(q0):
            continue
        ok = checker.cut(q0, q1)[1]
        dense = _fine_contacts(checker, [q0, q1])
        touching += dense > 0
        assert not (ok and dense), (q0.tolist(), q1.tolist())
        passed += 1
    assert passed == 60 and touching > 5


def test_the_issue_scene_is_the_issues_post_with_goals_around_it() -> None:
    """The issue's own post (its CLI example), 72 goals 1-8 cm above the table around it, home safe.

    Every goal keeps 3 cm from the post; the setup passes the checks before anything moves (home
    safe, no obstacle holding a goal), and home is not within the clearance of the post or table.
    """
    from gb_pin.safety.scenarios import ISSUE_POST, so101_issue_scene

    scene = so101_issue_scene()
    assert parse_obstacle("box:center=0.21,0,0.045,half=0.02,0.02,0.045") == ISSUE_POST
    assert scene.obstacles == (Table(0.0), ISSUE_POST) and scene.goals.shape == (72, 3)
    assert np.allclose(np.unique(scene.goals[:, 2]), [0.01, 0.045, 0.08])
    assert np.allclose(scene.goals[:, :2].min(axis=0), [0.06, -0.15])
    assert np.allclose(scene.goals[:, :2].max(axis=0), [0.36, 0.15])
    assert not ISSUE_POST.contains(scene.goals, margin=0.03).any()
    target = load_robot(scene.robot)
    checker = CollisionChecker(target, scene.obstacles, self_collision=True)
    checker.check_setup(scene.goals)
    assert checker.is_safe(np.asarray(target.home, dtype=float))
    assert so101_issue_scene(0.07).goals.shape == (48, 3)
    with pytest.raises(InvalidArgumentError, match="half_width"):
        so101_issue_scene(-0.1)
