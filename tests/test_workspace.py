"""Workspace regions, curriculum goals, settings scaled to the goal set, the noise-free reach (issue 30)."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main
from gb_pin.learn.config import default_sigma
from gb_pin.learn.goals import CurriculumGoals, make_goals
from gb_pin.learn.goals.curriculum import stage_of
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.metrics import evaluation_schedule
from gb_pin.learn.parts import PartedMap, Sectors
from gb_pin.learn.reach_errors import ReachErrors
from gb_pin.robot.workspace import WorkspaceRegion, extent, is_workspace_spec, region_postures
from gb_pin.robot.workspace_parts import auto_parts, region_parts, turn_axis
from gb_pin.runs.parted import share
from gb_pin.runs.scaling import (
    RADIUS_SHARE,
    REGION_LEARNING_RATE,
    REGION_RADIUS_SHARE,
    REGION_SIGMA_GAIN,
    noise_walk_share,
    scaled_sigma,
)


def test_region_specs_parse_round_trip_and_refuse_bad_values() -> None:
    region = WorkspaceRegion.parse("workspace:fraction=0.25,points=40,seed=3,test_seed=4,stages=2")
    assert (region.fraction, region.points, region.seed, region.test_seed, region.stages) == (
        0.25,
        40,
        3,
        4,
        2,
    )
    assert (
        WorkspaceRegion.parse(region.spec()) == region
        and WorkspaceRegion.parse("workspace") == WorkspaceRegion()
    )
    assert (
        is_workspace_spec("workspace:fraction=0.5")
        and not is_workspace_spec("workspaces")
        and not is_workspace_spec(1)
    )
    for bad, match in (("workspace:fraction=0", "fraction"), ("workspace:fraction=1.5", "fraction"),
                       ("workspace:points=0", "points"), ("workspace:size=3", "key"),
                       ("workspace:fraction=half", "not a number"),
                       ("workspace:seed=-1", "seed"), ("workspace:parts=9", "auto"),
                       ("workspace:parts=-1", "parts")):  # fmt: skip
        with pytest.raises(gb_pin.InvalidArgumentError, match=match):
            WorkspaceRegion.parse(bad)
    with pytest.raises(gb_pin.InvalidArgumentError, match="fraction"):
        gb_pin.babble("so101", movements=10, targets="workspace:fraction=2")


def test_region_postures_are_uniform_windows_around_home_within_the_limits() -> None:
    """Each joint's window is f of its range, centred on home, shifted inside the limits: nothing piles up."""
    arm = gb_pin.load_robot("panda")
    u = np.random.default_rng(0).random((4000, arm.n_joints))
    for f in (0.25, 0.5, 1.0):
        Q = region_postures(arm, f, u)
        assert np.all(arm.lower <= Q) and np.all(arm.upper >= Q)
        width = Q.max(axis=0) - Q.min(axis=0)
        np.testing.assert_allclose(width, f * (arm.upper - arm.lower), rtol=0.01)
        assert np.all(np.mean(np.isclose(Q, arm.lower) | np.isclose(Q, arm.upper), axis=0) < 0.01)
        inside = (Q.min(axis=0) <= arm.home) & (arm.home <= Q.max(axis=0))
        assert inside.all()
    # a joint with more than a turn of range (the xArm7's +-2 pi) or none counts as one turn
    wide = SimpleNamespace(home=np.zeros(3), lower=np.array([-2 * np.pi, -np.inf, -1.0]),
                           upper=np.array([2 * np.pi, np.inf, 1.0]), forward=lambda q: q)  # fmt: skip
    Q = region_postures(wide, 0.5, u[:, :3])
    np.testing.assert_allclose(Q.max(axis=0) - Q.min(axis=0), [np.pi, np.pi, 1.0], rtol=0.01)


def test_region_points_goals_tests_and_curriculum_blocks() -> None:
    """FK of the postures; test points from another seed; blocks grow from home outwards."""
    arm = gb_pin.load_robot("so101")
    region = WorkspaceRegion(fraction=0.5, points=200, test_points=150)
    goals, tests = region.goal_points(arm), region.test_set(arm)
    assert goals.shape == (600, 3) and tests.shape == (150, 3)
    np.testing.assert_array_equal(goals[400:], region.final_goals(arm))
    assert not np.isin(tests, goals).all(axis=1).any()
    spread = [
        np.median(np.linalg.norm(goals[i * 200 : (i + 1) * 200] - arm.home_position, axis=1))
        for i in range(3)
    ]
    assert spread[0] < spread[1] < spread[2]
    u = np.random.default_rng(0).random((200, arm.n_joints))
    np.testing.assert_allclose(region.final_goals(arm), arm.forward(region_postures(arm, 0.5, u)))


def test_extent_is_the_diagonal_of_the_5_95_percent_box() -> None:
    X = np.random.default_rng(1).uniform([0, 0, 0], [0.3, 0.4, 1.2], size=(20000, 3))
    assert extent(X) == pytest.approx(0.9 * np.sqrt(0.3**2 + 0.4**2 + 1.2**2), rel=0.01)
    with pytest.raises(gb_pin.InvalidArgumentError):
        extent(np.zeros(3))


def test_curriculum_stages_follow_the_goal_count() -> None:
    assert [stage_of(k, 3, 900, 3.0) for k in (0, 899, 900, 2699, 2700, 10**6)] == [0, 0, 1, 1, 2, 2]
    assert [stage_of(k, 1, 900, 3.0) for k in (0, 10**6)] == [0, 0]
    goals = make_goals("curriculum:stages=2,first=10,growth=2")
    assert isinstance(goals, CurriculumGoals) and goals.get_params()["first"] == 10
    with pytest.raises(gb_pin.InvalidArgumentError, match="multiple"):
        goals.start(np.zeros((5, 2)))
    with pytest.raises(gb_pin.InvalidArgumentError, match="growth"):
        CurriculumGoals(growth=0.5)


def test_the_compiled_curriculum_draws_each_goal_from_its_stage_block() -> None:
    """The k-th goal-directed movement's goal lies in block stage_of(k) (planar5, three distinct blocks)."""
    blocks = [np.column_stack([np.full(4, x), np.linspace(-0.2, 0.2, 4)]) for x in (0.4, 0.5, 0.6)]
    X = np.vstack(blocks)
    curriculum = "curriculum:stages=3,first=8,growth=3"
    run = gb_pin.babble("planar5", movements=80, seed=2, targets=X, goals=curriculum,
                        radius=0.1, record=gb_pin.Recording(every=1, first=0, last=80))  # fmt: skip
    rec = run.recording
    assert rec is not None
    L = 25
    ends = rec.target[L - 1 :: L]  # each movement's last target: its goal (NaN for home returns)
    goals = ends[~np.isnan(ends[:, 0])]
    assert len(goals) > 60
    for k, goal in enumerate(goals):
        assert goal[0] == pytest.approx([0.4, 0.5, 0.6][stage_of(k, 3, 8, 3.0)]), k


def test_a_workspace_run_scales_its_settings_and_measures_separate_test_points() -> None:
    run = gb_pin.babble("so101", movements=60, seed=0, targets="workspace:fraction=0.5")
    region = WorkspaceRegion()
    goals = region.goal_points(run.target)
    assert run.goal_targets is not None
    np.testing.assert_array_equal(run.goal_targets, goals)
    np.testing.assert_array_equal(run.targets, region.test_set(run.target))
    L = extent(goals[-region.points :])
    assert 0.5 < L < 0.7  # the SO-101's region f = 0.5 (docs/WORKSPACE.md: 0.60 m)
    assert run.config.radius == pytest.approx(REGION_RADIUS_SHARE * L)
    assert run.config.learning_rate == REGION_LEARNING_RATE
    np.testing.assert_array_equal(run.history.movements, evaluation_schedule(60, 100, 20))
    assert run.config.sigma == pytest.approx(scaled_sigma(run.target, L, REGION_SIGMA_GAIN))
    assert run.config.sigma <= REGION_SIGMA_GAIN * default_sigma(run.target.n_joints) + 1e-12
    assert run.goals is not None and "CurriculumGoals" in run.goals
    errors = run.workspace_errors()
    assert isinstance(errors, ReachErrors) and errors.errors.shape == (300,)
    assert errors.mean == pytest.approx(run.error) and errors.median <= errors.p90
    explicit = gb_pin.babble(
        "so101", movements=5, radius=0.07, sigma=0.03, targets="workspace", goals="uniform"
    )
    assert (explicit.config.radius, explicit.config.sigma) == (
        0.07,
        0.03,
    ) and explicit.goal_targets.shape == (1000, 3)
    assert explicit.config.sigma_delta == 0.1 * 0.03  # the SO-101: one redundant joint, the paper's walk


def test_a_regions_noise_walk_follows_the_redundant_joints_and_yields_to_given_values() -> None:
    """sigma_delta = 0.1 sigma per redundant joint, at most 0.3 sigma; given values win; presets keep 0.1."""

    class Arm:
        def __init__(self, joints: int, task: int) -> None:
            self.n_joints, self.n_task = joints, task

    shares = [noise_walk_share(Arm(j, t)) for j, t in ((4, 3), (5, 3), (6, 3), (7, 3), (20, 2), (2, 2))]
    assert shares == pytest.approx([0.1, 0.2, 0.3, 0.3, 0.3, 0.1])
    region = gb_pin.babble("panda", movements=2, seed=0, targets="workspace:fraction=0.5")
    assert region.config.sigma_delta == pytest.approx(0.3 * region.config.sigma)
    given = gb_pin.babble("panda", movements=2, seed=0, targets="workspace:fraction=0.5", sigma=0.05)
    assert given.config.sigma_delta == pytest.approx(0.015)
    fixed = gb_pin.babble("panda", movements=2, seed=0, targets="workspace:fraction=0.5", sigma_delta=0.002)
    assert fixed.config.sigma_delta == 0.002
    own = gb_pin.babble("panda", movements=2, seed=0)  # the preset's own targets: the paper's 0.1 sigma
    assert own.config.sigma_delta == pytest.approx(0.1 * own.config.sigma)


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_own_targets_keep_the_presets_settings_and_given_sets_only_scale_up() -> None:
    own = gb_pin.babble("so101", movements=5)
    same = gb_pin.babble("so101", movements=5, targets=own.target.targets)
    assert own.config == same.config and own.config.radius == 0.04
    small = gb_pin.babble("so101", movements=5, targets=own.target.targets[:3] * 0.999)
    assert small.config.radius == 0.04  # the preset's radius is the floor
    arm = gb_pin.load_robot("so101")
    wide = WorkspaceRegion(fraction=0.5, points=60).final_goals(arm)
    big = gb_pin.babble("so101", movements=5, targets=wide)
    assert big.config.radius == pytest.approx(RADIUS_SHARE * extent(wide)) and big.config.radius > 0.04
    walk = gb_pin.babble("so101", movements=5, targets=wide, goals="directions")
    assert (
        walk.goals == "DirectionGoals(distance=0.2, snap=0.05)"
    )  # 0.1 L = 0.06 m: the default's 0.2 m stays
    region = gb_pin.babble(
        "so101", movements=5, targets="workspace:fraction=0.5", goals="directions:snap=0.05"
    )
    L = extent(WorkspaceRegion().final_goals(arm))
    assert region.goals == f"DirectionGoals(distance={0.1 * L!r}, snap=0.05)"


def test_reach_falls_with_the_true_error_on_the_so101_plant() -> None:
    """The free measure less the noise's share: no longer the exploration's 15-35 mm (docs/WORKSPACE.md)."""
    for seed in (0, 1):
        arm = gb_pin.Plant("so101", offset_std=0.05, length_std=0.03, noise=0.0015, loss=0.1, seed=3)
        run = gb_pin.babble(arm, movements=2000, seed=seed, schedule=[300, 2000])
        reach, error = run.history.reach, run.history.error
        assert reach is not None and error[1] < error[0]
        assert reach[1] < reach[0] and reach[1] < 0.008  # measured 4.6-5.0 mm (observed end: 15-29 mm)


def test_trials_and_the_cli_take_a_workspace_region(capsys) -> None:  # type: ignore[no-untyped-def]
    trials = gb_pin.run_trials("so101", trials=2, movements=30, targets="workspace:fraction=0.25", workers=1)
    assert trials.error.shape[0] == 2 and trials.parameters["targets"] == "workspace:fraction=0.25"
    assert (
        main(["babble", "--robot", "so101", "--movements", "40", "--targets", "workspace:fraction=0.5"]) == 0
    )
    assert "test points      median" in capsys.readouterr().out
    assert main(["babble", "--robot", "so101", "--movements", "5", "--targets", "workspace:fraction=7"]) == 2
    assert "fraction" in capsys.readouterr().err


def test_reproduce_workspace_writes_table_and_figure(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    from gb_pin.reproduce.workspace import Condition, run_workspace

    files = run_workspace(
        str(tmp_path), robots=("so101",), fractions=(0.5,), seeds=1, movements=3000, workers=1
    )
    assert {Path(f).name for f in files} == {"workspace.json", "workspace.md", "workspace_so101.png"}
    run = json.loads((tmp_path / "workspace.json").read_text())["runs"][0]
    assert set(run["snapshots"]) == {"3000"} and run["snapshots"]["3000"]["median"] < 0.05
    assert "| so101 | 0.5 | 1 |" in (tmp_path / "workspace.md").read_text()
    assert Condition("panda", 0.5, 3).key.startswith("panda_f0.5_s3_")
    with pytest.raises(gb_pin.InvalidArgumentError):
        run_workspace(str(tmp_path), robots=("so102",), seeds=1)


def test_a_robot_given_as_a_function_learns_a_region_and_reports_its_errors() -> None:
    """FunctionTarget: the region drawn one posture at a time, the errors by its own forward model."""

    def forward(q: np.ndarray) -> np.ndarray:
        return np.array([np.cos(q[0]) + np.cos(q[0] + q[1]), np.sin(q[0]) + np.sin(q[0] + q[1])])

    arm = gb_pin.FunctionTarget(forward, home=[0.3, 0.8], lower=[-2, -2], upper=[2, 2])
    run = gb_pin.babble(arm, movements=30, seed=0, targets="workspace:fraction=0.5")
    assert run.targets.shape == (300, 2) and run.config.learning_rate == REGION_LEARNING_RATE
    assert run.workspace_errors().mean == pytest.approx(run.error)
    session = gb_pin.babble_session("so101", movements=5, seed=0, targets="workspace:fraction=0.5")
    assert session.state.eval_targets.shape == (300, 3) and session.state.config.learning_rate == 0.5
    with pytest.raises(gb_pin.InvalidArgumentError, match="no forward model"):
        gb_pin.babble_session(gb_pin.ExternalRobot.from_preset("so101"), movements=5, targets="workspace")


def test_sectors_route_each_query_to_the_map_of_its_part_and_survive_a_file() -> None:
    rng = np.random.default_rng(0)
    maps = []
    for q0 in (-1.0, 1.0):  # two maps that answer constants -1 and +1
        lm = LocalLinearMap(radius=0.1).initialize(np.zeros(2), np.full(3, q0))
        maps.append(lm)
    sectors = Sectors.checked([0, 0], [1, 0], [0, 1], [0.0], 2)  # part 0: below the x axis, 1: above
    parted = PartedMap(maps, sectors)
    X = rng.uniform(-1, 1, (50, 2))
    expected = np.where(X[:, 1:] > 0, 1.0, -1.0) * np.ones(3)
    np.testing.assert_array_equal(parted.predict(X, warn=False), expected)
    np.testing.assert_array_equal(parted.part_of(X), (X[:, 1] > 0).astype(int))
    assert parted.predict([0.2, 0.3], warn=False).shape == (3,) and parted.n_prototypes_ == 2
    again = PartedMap.from_arrays(parted.to_arrays(), 0.1)
    np.testing.assert_array_equal(again.predict(X, warn=False), expected)
    np.testing.assert_array_equal(parted.jacobian([0.1, 0.5]), maps[1].jacobian([0.1, 0.5]))
    bad = {**parted.to_arrays(), "part_sizes": np.array([1, 2])}
    with pytest.raises(gb_pin.InvalidArgumentError, match="add up"):
        PartedMap.from_arrays(bad, 0.1)
    for edges, match in (([0.5, 0.1], "increasing"), ([4.0], "increasing")):
        with pytest.raises(gb_pin.InvalidArgumentError, match=match):
            Sectors.checked([0, 0], [1, 0], [0, 1], edges, 2)
    with pytest.raises(gb_pin.InvalidArgumentError, match="orthonormal"):
        Sectors.checked([0, 0], [1, 0], [1, 1], [0.0], 2)


def test_region_parts_split_around_the_first_joints_axis_with_a_home_each() -> None:
    panda = gb_pin.load_robot("panda")
    origin, u, v = turn_axis(panda, 0.5)  # joint 1 turns about the vertical through the base
    np.testing.assert_allclose(origin[:2], 0.0, atol=1e-9)
    home = panda.forward(panda.home)
    np.testing.assert_allclose(u, np.r_[home[:2] / np.linalg.norm(home[:2]), 0.0], atol=1e-9)
    assert abs(v[2]) < 1e-9 and abs(u @ v) < 1e-12
    region = WorkspaceRegion(0.5, points=200, parts=2)
    parts = region_parts(panda, region)
    assert parts.sectors.parts == 2 and parts.homes.shape == (2, 7)
    assert np.all(parts.homes >= panda.lower) and np.all(parts.homes <= panda.upper)
    sizes = [g.shape[0] for g in parts.goals]
    assert sum(sizes) == 3 * 200 and all(s % 3 == 0 for s in sizes)  # the curriculum's blocks
    for p, goals in enumerate(parts.goals):  # the last block lies in its part
        assert np.all(parts.sectors.part_of(goals[-sizes[p] // 3 :]) == p)
    # parts=auto: two where the region wraps around the axis (Panda, UR5 at 0.5), else one
    assert auto_parts(panda, WorkspaceRegion(0.5)) == 2 and auto_parts(panda, WorkspaceRegion(0.25)) == 1
    assert auto_parts(gb_pin.load_robot("so101"), WorkspaceRegion(0.5)) == 1
    assert auto_parts(panda, WorkspaceRegion(0.25, parts=3)) == 3
    from gb_pin.learn import parts as learn_parts
    from gb_pin.robot import workspace as robot_workspace

    assert robot_workspace.MAX_PARTS == learn_parts.MAX_PARTS
    assert [share(7, 2, p) for p in (0, 1)] == [4, 3] and WorkspaceRegion.parse(
        "workspace:parts=auto"
    ).parts == 0


def test_a_region_in_parts_learns_saves_and_answers_through_the_normal_api(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    spec = "workspace:fraction=0.5,points=60,parts=2"
    run = gb_pin.babble("panda", movements=400, seed=0, targets=spec)
    assert isinstance(run.model, PartedMap) and run.model.n_parts == 2 and run.movements == 400
    assert run.steps == 400 * run.config.path_length and run.goals is not None and "2 parts" in run.goals
    assert run.config.radius == pytest.approx(
        REGION_RADIUS_SHARE * extent(WorkspaceRegion(0.5, 60).final_goals(run.target))
    )
    errors = run.workspace_errors()
    assert errors.errors.shape == (300,) and errors.mean == pytest.approx(run.error)
    assert run.error < 0.5 * run.initial_error  # it learns
    home = run.target.forward(run.target.home)  # E_0: the robot's constant home, as one learner's
    assert run.initial_error == pytest.approx(np.mean(np.linalg.norm(run.targets - home, axis=1)))
    again = gb_pin.babble("panda", movements=400, seed=0, targets=spec)
    np.testing.assert_array_equal(again.history.error, run.history.error)  # same seed, same numbers
    run.save(tmp_path / "run.npz")
    loaded = gb_pin.load_result(tmp_path / "run.npz")
    assert isinstance(loaded.model, PartedMap)
    np.testing.assert_array_equal(
        loaded.model.predict(run.targets, warn=False), run.model.predict(run.targets, warn=False)
    )
    assert loaded.workspace_errors().median == errors.median
    solved = run.solve(run.targets[:2])  # the IK solver seeded by each target's part
    assert solved.postures.shape == (2, 7) and np.all(solved.residuals < 1e-3)
    assert run.solve_path(run.targets[0], run.targets[1], steps=5).postures.shape == (5, 7)
    with pytest.raises(gb_pin.InvalidArgumentError, match="steps must be"):
        run.solve_path(run.targets[0], run.targets[1], steps=10**9)  # refused before anything is allocated
    with pytest.raises(gb_pin.InvalidArgumentError, match="parts=1 to export"):
        run.export_inverse(tmp_path / "inverse.npz")
    with pytest.raises(gb_pin.InvalidArgumentError, match="checkpoint"):
        gb_pin.babble("panda", movements=10, targets=spec, checkpoint=str(tmp_path / "c.npz"))
    with pytest.raises(gb_pin.InvalidArgumentError, match="parts"):
        gb_pin.babble_session("panda", movements=5, targets=spec)
    assert main(["babble", "--robot", "panda", "--movements", "40", "--targets", spec]) == 0
    assert "test points      median" in capsys.readouterr().out


def test_a_regions_truncated_map_survives_files_checkpoints_and_resume(tmp_path: Path) -> None:
    """A region's map is truncated (cutoff 3); a result file and a checkpoint keep it, bit for bit."""
    from gb_pin.runs.scaling import REGION_CUTOFF

    class CrashError(Exception):
        pass

    def crash(r: int) -> None:
        if r >= 25:
            raise CrashError

    full = gb_pin.babble("so101", movements=40, seed=2, targets="workspace")
    assert full.config.cutoff == REGION_CUTOFF and full.model.cutoff == REGION_CUTOFF
    full.save(tmp_path / "run.npz")
    loaded = gb_pin.load_result(tmp_path / "run.npz")
    assert loaded.config.cutoff == REGION_CUTOFF
    probes = full.targets[:50]
    np.testing.assert_array_equal(loaded.inverse(probes), full.inverse(probes))
    with pytest.raises(CrashError):
        gb_pin.babble(
            "so101", movements=40, seed=2, targets="workspace",
            checkpoint=str(tmp_path / "c.ckpt"), checkpoint_every=10, callback=crash,
        )  # fmt: skip
    resumed = gb_pin.resume(tmp_path / "c.ckpt")
    assert resumed.config.cutoff == REGION_CUTOFF
    np.testing.assert_array_equal(resumed.history.error, full.history.error)
    np.testing.assert_array_equal(resumed.inverse(probes), full.inverse(probes))
    uncut = gb_pin.babble("so101", movements=40, seed=2, targets="workspace", cutoff=26.0)
    assert uncut.n_prototypes == full.n_prototypes  # the same run but for the shares left out
    # c = 3 leaves out activations below exp(-9) = 1.2e-4 of the nearest: measured 2.4e-4 rad at most here
    # (c = 4: 5e-7), 0.05 mm at the hand; the errors over 10 seeds are those of the whole sums (WORKSPACE.md)
    np.testing.assert_allclose(uncut.inverse(probes), full.inverse(probes), rtol=0, atol=1e-3)
