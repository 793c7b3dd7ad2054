"""Tests of gb_pin.robot.reachability and targets_auto: reachability, the beyond-reach bound, "auto", specs.

Reachability is checked by seeded sampling and a projected descent.

Reachability claims are checked independently with Pinocchio's forward kinematics on the returned
postures; the 1e-4 m tolerance is the module's TOLERANCE (a reached point is closer than that).
"""

from __future__ import annotations

import ast
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from gb_pin import InvalidArgumentError, KinematicTarget, load_robot, planar_chain
from gb_pin.exceptions import UnreachableTargetWarning
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.robot.grids import grid_targets, regular_grid
from gb_pin.robot.reachability import (
    TOLERANCE,
    _solve_small,
    beyond_reach,
    check_reachable,
    sample_positions,
    sampling_bounds,
)
from gb_pin.robot.targets_auto import auto_grid, resolve_targets

DATA = Path(__file__).parent / "data"


def small_arm() -> KinematicTarget:
    """tests/data/small_arm.urdf: revolute, continuous, prismatic and unaligned joints; home 'ready'."""
    return KinematicTarget.from_urdf(
        DATA / "small_arm.urdf", "tool", srdf=DATA / "small_arm.srdf", onboard=False
    )


def limited_planar(m: int = 3) -> KinematicTarget:
    """A planar chain of total length 1 m with every joint limited to [-1, 1] rad."""
    model = planar_chain(m)
    model.lowerPositionLimit = -np.ones(m)
    model.upperPositionLimit = np.ones(m)
    home = np.full(m, 0.5)
    return KinematicTarget(model, "tip", home=home, axes="xy")


def test_solve_small_matches_numpy() -> None:
    """The compiled n <= 3 solver equals numpy.linalg.solve on SPD systems (pivoting included)."""
    rng = np.random.default_rng(0)
    for n in (1, 2, 3):
        for _ in range(20):
            B = rng.normal(size=(n, n))
            A = B @ B.T + 1e-3 * np.eye(n)
            b = rng.normal(size=n)
            x = np.empty(n)
            _solve_small(A, b, x)
            np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-9, atol=1e-12)


def test_sampling_bounds_use_limits_or_a_full_turn() -> None:
    """Bounded joints sample within their limits; unbounded revolute [-pi, pi], prismatic [-1, 1] m."""
    target = small_arm()  # j1 [-2, 2], j2 continuous, j3 [0, 0.1] m, j4 [-1.5, 1.5]
    lo, hi = sampling_bounds(target)
    np.testing.assert_array_equal(lo, [-2.0, -math.pi, 0.0, -1.5])
    np.testing.assert_array_equal(hi, [2.0, math.pi, 0.1, 1.5])
    Q, X = sample_positions(target, 500, seed=3)
    np.testing.assert_array_equal(np.clip(Q, lo, hi), Q)
    np.testing.assert_allclose(X, target.forward(Q), rtol=0, atol=1e-12)
    Q2, _ = sample_positions(target, 500, seed=3)
    np.testing.assert_array_equal(Q, Q2)


def test_positions_of_postures_within_limits_are_reachable() -> None:
    """f(q) for random q within the limits is reachable.

    The returned posture is within the limits and Pinocchio puts the frame within TOLERANCE of the point.
    """
    target = load_robot("talos_left_arm")
    rng = np.random.default_rng(11)
    Q = target.lower + (target.upper - target.lower) * rng.random((30, target.n_joints))
    points = target.forward(Q)
    result = check_reachable(target, points, seed=5)
    assert result.reachable.all()
    assert np.all((result.postures >= target.lower) & (result.postures <= target.upper))
    reached = target.forward(result.postures)
    assert np.all(np.linalg.norm(reached - points, axis=1) < TOLERANCE)
    np.testing.assert_allclose(result.residual, np.linalg.norm(reached - points, axis=1), atol=1e-12)


def test_points_out_of_reach_or_limits_are_not_reachable() -> None:
    """Points beyond reach or the joint limits are not reachable.

    A planar arm (3 links of 1/3 m) with joints in [-1, 1] rad cannot reach beyond 1 m, behind itself,
    nor its own base (folding back needs 2 pi / 3 turns at two joints).
    """
    target = limited_planar(3)
    far = [[1.2, 0.0], [-0.5, 0.0], [0.02, 0.0]]
    result = check_reachable(target, far)
    assert not result.reachable.any()
    assert np.all(result.residual > 0.05)


def test_check_reachable_is_deterministic() -> None:
    """Same seed, same postures."""
    target = small_arm()
    points = target.forward(target.home)[None, :] + np.array([[0.01, 0.0, 0.0], [0.0, 0.02, -0.01]])
    a = check_reachable(target, points, seed=2)
    b = check_reachable(target, points, seed=2)
    np.testing.assert_array_equal(a.postures, b.postures)


def test_auto_grid_is_reachable_centred_and_maximal() -> None:
    """The auto grid is centred on home, reachable, and maximal at its resolution.

    3 points per axis, a half-width multiple of the resolution; the next larger half-width has an
    unreachable point (the bisection's upper bracket).
    """
    target = limited_planar(3)
    grid = auto_grid(target, resolution=0.01)
    assert grid.targets.shape == (9, 2)
    np.testing.assert_allclose(grid.center, target.home_position, atol=1e-15)
    np.testing.assert_allclose(grid.targets.mean(axis=0), grid.center, atol=1e-12)
    assert grid.half_width > 0
    assert math.isclose(grid.half_width / 0.01, round(grid.half_width / 0.01), abs_tol=1e-9)
    assert check_reachable(target, grid.targets).reachable.all()
    bigger = regular_grid(grid.center, grid.half_width + 0.01, (3, 3))
    assert not check_reachable(target, bigger).reachable.all()
    again = auto_grid(target, resolution=0.01)
    np.testing.assert_array_equal(grid.targets, again.targets)
    np.testing.assert_allclose(grid.lower, grid.center - grid.half_width)
    np.testing.assert_allclose(grid.upper, grid.center + grid.half_width)


def test_auto_grid_shape_and_scale() -> None:
    """shape sets the points per axis; scale < 1 shrinks the grid; bad values raise."""
    target = small_arm()
    full = auto_grid(target, resolution=0.005)
    half = auto_grid(target, (2, 3, 4), scale=0.5, resolution=0.005)
    assert half.targets.shape == (24, 3)
    assert half.half_width <= 0.5 * full.half_width + 1e-12
    for shape in [(3, 3), (0, 3, 3), (3, 3, 2.5)]:
        with pytest.raises(InvalidArgumentError, match="shape"):
            auto_grid(target, shape)
    for scale in (0.0, 1.5, -1.0):
        with pytest.raises(InvalidArgumentError, match="scale"):
            auto_grid(target, scale=scale)


def test_auto_grid_at_the_border_of_the_workspace_is_an_error() -> None:
    """A stretched planar arm (home at full reach) has no reachable grid around its home."""
    model = planar_chain(2)
    model.lowerPositionLimit = -np.ones(2)
    model.upperPositionLimit = np.ones(2)
    target = KinematicTarget(model, "tip", home=[0.0, 0.0], axes="xy")
    with pytest.raises(InvalidArgumentError, match="border of the workspace"):
        auto_grid(target)


def test_beyond_reach_bound() -> None:
    """A planar arm of length 1 m: points beyond 1 m from the first joint are flagged, closer ones not."""
    target = KinematicTarget(planar_chain(4), "tip", axes="xy")
    flags = beyond_reach(target.chain, target.lower, target.upper, [[1.01, 0.0], [0.0, -0.99], [0.7, 0.7]])
    np.testing.assert_array_equal(flags, [True, False, False])


def test_beyond_reach_counts_prismatic_strokes_and_root_offset() -> None:
    """The small arm's bound: link lengths after j1 plus j3's stroke 0.1 m, from j1's position."""
    target = small_arm()
    chain = target.chain
    root = chain.translations[0]  # j1 at (0, 0, 0.1)
    np.testing.assert_allclose(root, [0.0, 0.0, 0.1])
    lengths = sum(np.linalg.norm(chain.translations[i]) for i in (1, 2, 3)) + np.linalg.norm(
        chain.frame_translation
    )
    bound = lengths + 0.1
    direction = np.array([0.6, 0.0, 0.8])
    inside = root + (bound - 1e-6) * direction
    outside = root + (bound + 1e-6) * direction
    np.testing.assert_array_equal(
        beyond_reach(chain, target.lower, target.upper, [inside, outside]), [False, True]
    )
    # Every sampled position lies within the bound (it is a bound).
    _, X = sample_positions(target, 2000, seed=0)
    assert not beyond_reach(chain, target.lower, target.upper, X).any()


def test_beyond_reach_unbounded_prismatic_flags_nothing() -> None:
    """An unbounded prismatic joint on the path: no finite bound, nothing flagged."""
    model = pin.Model()
    j = model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "slide")
    model.addJointFrame(j)
    model.addFrame(
        pin.Frame("tip", j, 0, pin.SE3(np.eye(3), np.array([0.0, 0.3, 0.0])), pin.FrameType.OP_FRAME)
    )
    target = KinematicTarget(model, "tip", home=[0.0])
    assert not beyond_reach(target.chain, target.lower, target.upper, [[100.0, 0.3, 0.0]]).any()


def test_grid_targets_rejects_bad_boxes() -> None:
    """grid_targets needs finite lower <= upper and counts >= 1 of one length."""
    np.testing.assert_array_equal(grid_targets([0.0], [1.0], [3]), [[0.0], [0.5], [1.0]])
    for lower, upper, shape in [
        ([1.0], [0.0], [2]),
        ([0.0], [np.inf], [2]),
        ([0.0], [1.0], ["a"]),
        ([], [], []),
    ]:
        with pytest.raises(InvalidArgumentError):
            grid_targets(lower, upper, shape)


def test_resolve_targets_specs() -> None:
    """Arrays, 'auto', grid, points and auto specs resolve; bad specs raise naming what is valid."""
    target = small_arm()
    x = target.home_position
    np.testing.assert_array_equal(resolve_targets([x], target), [x])
    np.testing.assert_array_equal(resolve_targets("auto", target), target.auto_targets())
    grid = resolve_targets({"lower": x - 0.01, "upper": x + 0.01, "shape": [2, 2, 2]}, target)
    assert grid.shape == (8, 3)
    pts = resolve_targets({"points": [x, x + 0.01]}, target)
    assert pts.shape == (2, 3)
    auto = resolve_targets({"auto": True, "shape": [2, 2, 2], "scale": 0.5}, target)
    assert auto.shape == (8, 3)
    bad = [
        "grid",
        {"lower": x, "upper": x},
        {"points": [x], "shape": [1, 1, 1]},
        {"auto": True, "lower": x},
        {"auto": True, "seed": 1.5},
        {"spacing": 0.1},
        {"lower": x, "upper": x, "shape": [2, 2]},
        [[0.1, 0.2]],
        [[0.1, np.nan, 0.2]],
    ]
    for spec in bad:
        with pytest.raises(InvalidArgumentError):
            resolve_targets(spec, target)


def test_resolve_targets_warns_about_points_beyond_reach() -> None:
    """Explicit targets beyond the arm's reach warn (UnreachableTargetWarning), naming the point."""
    target = small_arm()
    with pytest.warns(UnreachableTargetWarning, match=r"1 of 2 targets.*\[5\.0, 0\.0, 0\.0\]"):
        resolve_targets([target.home_position, [5.0, 0.0, 0.0]], target)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        resolve_targets([target.home_position], target)


@dataclass(frozen=True)
class BareRobot:
    """Just what the reachability checks need: no KinematicTarget, no Pinocchio model."""

    chain: KinematicChain
    home: np.ndarray
    lower: np.ndarray
    upper: np.ndarray


def test_reachability_and_auto_grid_work_on_any_robot() -> None:
    """check_reachable, sample_positions and auto_grid take anything with chain, home, lower, upper."""
    target = limited_planar(3)
    bare = BareRobot(target.chain, target.home, target.lower, target.upper)
    np.testing.assert_array_equal(
        auto_grid(bare, resolution=0.01).targets, auto_grid(target, resolution=0.01).targets
    )
    points = target.forward(target.home)[None, :] + np.array([[0.01, 0.0], [2.0, 0.0]])
    np.testing.assert_array_equal(check_reachable(bare, points).reachable, [True, False])
    np.testing.assert_array_equal(sample_positions(bare, 50)[1], sample_positions(target, 50)[1])


def _robot_imports() -> dict[str, set[str]]:
    """Modules of gb_pin.robot each module imports, anywhere in the file (inside functions too)."""
    root = Path(__file__).parent.parent / "gb_pin" / "robot"
    graph: dict[str, set[str]] = {}
    for path in sorted(root.glob("*.py")):
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module:
                found |= {node.module, *(f"{node.module}.{a.name}" for a in node.names)}
            elif isinstance(node, ast.Import):
                found |= {a.name for a in node.names}
        graph[path.stem] = found
    return graph


def test_robot_imports_are_one_way() -> None:
    """No import cycle in gb_pin.robot; reachability and targets_auto never import target (nor pinocchio)."""
    graph = _robot_imports()
    inner = {
        m: {d.split(".")[2] for d in deps if d.startswith("gb_pin.robot.")} & set(graph)
        for m, deps in graph.items()
    }
    for module in ("reachability", "targets_auto"):
        assert "target" not in inner[module]
        assert "pinocchio" not in graph[module]
    done: set[str] = set()

    def visit(module: str, path: tuple[str, ...]) -> None:
        assert module not in path, f"import cycle {' -> '.join((*path, module))}"
        if module not in done:
            for dep in inner[module]:
                visit(dep, (*path, module))
            done.add(module)

    for module in inner:
        visit(module, ())
    upper = ("gb_pin.runs", "gb_pin.experiments", "gb_pin.viewer", "gb_pin.cli", "gb_pin.reproduce")
    assert not {(m, d) for m, deps in graph.items() for d in deps if d.startswith(upper)}
