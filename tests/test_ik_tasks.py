"""Tests of gb_pin.ik on every task map: Jacobians, goals, pose / pointing / two-hand solves, the search.

Tolerances:

- Task Jacobians vs central differences with h = 1e-6: truncation h^2/6 |f'''| (|f'''| of a few
  units for arms of ~1 m and the rotation log away from 180 degrees) ~ 1e-12, rounding eps/h
  ~ 1e-10; 1e-7 is well above both and far below any wrong axis, sign or lever arm (1e-2 and up).
- Goals and log/exp: sums of a few products of unit vectors, exact to ~1e-15; 1e-12 of margin.
- Solves: success means every position within tol and every angle within angle_tol; each is
  checked again with Pinocchio (frame placement, log3), to the tolerance plus 1e-12 of rounding.
- Success rates use a deterministic budget (``max_restarts``, no clock). Measured on the Panda's
  pose over the full limits (200 targets, max_restarts 300): 200/200 (the protocol's 10^4 give
  100.00 %, docs/IK.md); the floor 0.99 allows two failures in 200.
"""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest

import gb_pin
from gb_pin import KinematicTarget
from gb_pin.exceptions import InvalidArgumentError, UnknownRobotError
from gb_pin.ik import frame_jacobian, solve, solve_path
from gb_pin.ik.geometry import exp3, goal_from_task, log3
from gb_pin.ik.robot import ik_robot
from gb_pin.ik.solver import evaluate, work_buffers
from gb_pin.learn.body.components import ORIENTATION, POSITION

H = 1e-6
PANDA = [f"panda_joint{i}" for i in range(1, 8)]
TOL = 1e-5


@pytest.fixture(scope="module")
def pose() -> KinematicTarget:
    return KinematicTarget.from_example_robot_data("panda", "panda_hand", PANDA, "default", task="pose")


@pytest.fixture(scope="module")
def pointing() -> KinematicTarget:
    return KinematicTarget.from_example_robot_data(
        "panda", "panda_hand", PANDA, "default", task="pointing", pointing_axis="x", orientation_scale=0.3
    )


@pytest.fixture(scope="module")
def bimanual() -> KinematicTarget:
    return gb_pin.load_robot("talos_bimanual")


def in_limits(target: KinematicTarget, rng: np.random.Generator, count: int, spread: float | None = None):  # type: ignore[no-untyped-def]
    """Postures uniform within the limits, or home +/- spread clipped to them."""
    if spread is not None:
        return target.clip(target.home + rng.uniform(-spread, spread, (count, target.n_joints)))
    return rng.uniform(target.lower, target.upper, (count, target.n_joints))


def central_differences(target: KinematicTarget, q: np.ndarray) -> np.ndarray:
    cols = [
        (target.chain.forward(q + H * e) - target.chain.forward(q - H * e)) / (2 * H) for e in np.eye(q.size)
    ]
    return np.array(cols).T


def placement(target: KinematicTarget, q: np.ndarray, frame: str) -> pin.SE3:
    """The frame's world placement by Pinocchio (the full model)."""
    model = target.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, target.to_pinocchio(q))
    return data.oMf[model.getFrameId(frame)]


# -- Jacobians ------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["pose", "pointing", "bimanual"])
def test_task_jacobian_of_every_component_matches_central_differences(name: str, request) -> None:  # type: ignore[no-untyped-def]
    """dx/dq of positions, s log(R_ref^T R) and pointing tangent coordinates, as central differences."""
    target = request.getfixturevalue(name)
    kinds = set(target.chain.components.kinds.tolist())
    assert kinds == {POSITION, ORIENTATION} if name == "pose" else True
    for q in in_limits(target, np.random.default_rng(0), 10, spread=1.0):
        J = frame_jacobian(target.chain, q)
        assert J.shape == (target.n_task, target.n_joints)
        np.testing.assert_allclose(J, central_differences(target, q), rtol=0, atol=1e-7)


def test_task_jacobian_near_the_reference_and_at_it(pose, pointing) -> None:  # type: ignore[no-untyped-def]
    """At home the rotational rows are 0 (theta = 0): the series branches still give the derivative."""
    for target in (pose, pointing):
        for q in (target.home, target.home + 1e-7):
            np.testing.assert_allclose(
                frame_jacobian(target.chain, q), central_differences(target, q), rtol=0, atol=1e-7
            )


@pytest.mark.parametrize("name", ["pose", "pointing", "bimanual"])
@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_solver_jacobian_is_the_derivative_of_the_geometric_errors_at_the_goal(name: str, request) -> None:  # type: ignore[no-untyped-def]
    """With the goal at f(q): de/dq = -J (positions anywhere; rotations at the goal, where e = 0)."""
    target = request.getfixturevalue(name)
    robot = ik_robot(target, target.chain)
    comps = robot.comps
    n_e = int(
        sum(
            s if k == POSITION else 3
            for k, s in zip(comps.component_kinds, comps.component_sizes, strict=True)
        )
    )
    w = work_buffers(n_e, target.n_joints, len(comps.component_kinds))
    for q in in_limits(target, np.random.default_rng(1), 5, spread=1.0):
        goal_from_task(comps, target.chain.forward(q), w.goal[0], w.goal[1])
        evaluate(q, robot, w)
        J = w.J.copy()
        np.testing.assert_allclose(w.e, 0.0, atol=1e-12)  # the goal of f(q) is reached at q
        for i, step in enumerate(np.eye(q.size)):
            evaluate(q + H * step, robot, w)
            plus = w.e.copy()
            evaluate(q - H * step, robot, w)
            np.testing.assert_allclose((plus - w.e) / (2 * H), -J[:, i], rtol=0, atol=1e-7)


def test_goals_invert_the_task_map_as_pinocchio_places_the_frame(pose, pointing) -> None:  # type: ignore[no-untyped-def]
    """R* = R_ref exp(x / s) is the frame's rotation; d* = R a its pointing axis (1e-12)."""
    for target in (pose, pointing):
        robot = ik_robot(target, target.chain)
        goal_pos, goal_rot = np.zeros((2, 3)), np.zeros((2, 3, 3))
        for q in in_limits(target, np.random.default_rng(2), 10):
            goal_from_task(robot.comps, target.chain.forward(q), goal_pos, goal_rot)
            M = placement(target, q, "panda_hand")
            np.testing.assert_allclose(goal_pos[0], M.translation, atol=1e-12)
            if target is pose:
                np.testing.assert_allclose(goal_rot[1], M.rotation, atol=1e-12)
            else:
                np.testing.assert_allclose(goal_rot[1, 0], M.rotation[:, 0], atol=1e-12)  # axis "x"


@pytest.mark.parametrize("angle", [0.0, 1e-9, 0.3, 2.0, np.pi - 1e-3, np.pi - 1e-6, np.pi - 1e-9])
def test_log3_inverts_exp3_up_to_180_degrees(angle: float) -> None:
    """log(exp(phi)) = phi for angles from 0 to pi - 1e-9 (the near-pi branch reads the symmetric part)."""
    axis = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    R = np.array(exp3(*(angle * axis))).reshape(3, 3)
    np.testing.assert_allclose(R, pin.exp3(angle * axis), atol=1e-12)
    x, y, z, theta = log3(R)
    assert theta == pytest.approx(angle, abs=1e-12)
    np.testing.assert_allclose([x, y, z], angle * axis, atol=1e-7 if angle > 3 else 1e-12)


# -- solving every task ----------------------------------------------------------------------------------
def check_pose(target: KinematicTarget, sol, X: np.ndarray, frame: str) -> None:  # type: ignore[no-untyped-def]
    """Every solved posture places ``frame`` within TOL of the target pose (Pinocchio)."""
    robot = ik_robot(target, target.chain)
    goal_pos, goal_rot = np.zeros((2, 3)), np.zeros((2, 3, 3))
    for r in np.flatnonzero(sol.success):
        goal_from_task(robot.comps, X[r], goal_pos, goal_rot)
        M = placement(target, sol.postures[r], frame)
        assert np.linalg.norm(M.translation - goal_pos[0]) <= TOL + 1e-12
        if target.chain.components.kinds[1] == ORIENTATION:
            angle = np.linalg.norm(pin.log3(goal_rot[1].T @ M.rotation))
        else:
            d, goal = M.rotation[:, 0], goal_rot[1, 0]
            angle = np.arctan2(np.linalg.norm(np.cross(d, goal)), d @ goal)
        assert angle <= TOL + 1e-9
        np.testing.assert_allclose(
            sol.errors[r], [np.linalg.norm(M.translation - goal_pos[0]), angle], atol=1e-8
        )


@pytest.mark.parametrize("name", ["pose", "pointing"])
def test_fk_sampled_targets_over_the_full_limits_are_solved_to_both_tolerances(name: str, request) -> None:  # type: ignore[no-untyped-def]
    """200 postures uniform within the limits, their FK as targets: >= 99 % within 1e-5 m and 1e-5 rad."""
    target = request.getfixturevalue(name)
    X = target.forward(in_limits(target, np.random.default_rng(3), 200))
    sol = solve(
        target, X, seed="middle", tol=TOL, angle_tol=TOL, max_restarts=300, max_iterations=15, backtracks=3
    )
    assert sol.postures.shape == (200, 7) and sol.errors.shape == (200, 2)
    assert sol.success_rate >= 0.99, sol.summary()
    assert np.all(sol.postures >= target.lower) and np.all(sol.postures <= target.upper)
    check_pose(target, sol, X, "panda_hand")
    assert ("1e-05 m / 1e-05 rad" in sol.summary() and "orientation" in sol.summary()) or name == "pointing"
    json.dumps(sol.records())


def test_both_hands_are_solved_together(bimanual) -> None:  # type: ignore[no-untyped-def]
    """TALOS' two hands (14 joints, two position components): each hand within 1e-5 m."""
    X = bimanual.forward(in_limits(bimanual, np.random.default_rng(4), 50, spread=0.4))
    sol = solve(bimanual, X, seed="home", tol=TOL, max_restarts=50)
    assert sol.success_rate >= 0.98, sol.summary()
    assert np.all(sol.errors[sol.success] <= TOL)
    reached = bimanual.forward(sol.postures[sol.success])
    assert np.all(np.linalg.norm((reached - X[sol.success]).reshape(-1, 2, 3), axis=2) <= TOL + 1e-12)


def test_several_solutions_are_distinct_and_each_reaches_the_pose(pose) -> None:  # type: ignore[no-untyped-def]
    """solutions=4: >= 90 % of the targets get 4 postures, pairwise >= 0.1 rad apart in some joint."""
    X = pose.forward(in_limits(pose, np.random.default_rng(5), 40))
    sol = solve(
        pose, X, seed="middle", tol=TOL, angle_tol=TOL, solutions=4, max_restarts=200, max_iterations=15
    )
    assert sol.postures.shape == (40, 4, 7) and sol.errors.shape == (40, 4, 2)
    assert np.mean(sol.found == 4) >= 0.9
    for r in range(40):
        k = int(sol.found[r])
        assert np.all(np.isnan(sol.postures[r, k:])) and np.all(np.isfinite(sol.postures[r, :k]))
        for a in range(k):
            assert np.all(sol.errors[r, a] <= TOL)
            np.testing.assert_allclose(pose.forward(sol.postures[r, a]), sol.positions[r, a], atol=1e-12)
            for b in range(a):
                assert np.max(np.abs(sol.postures[r, a] - sol.postures[r, b])) >= 0.1


def test_closest_to_keeps_the_solution_nearest_the_reference(pose) -> None:  # type: ignore[no-untyped-def]
    """The same attempts, the nearest solution kept: never farther than the first one found."""
    Q = in_limits(pose, np.random.default_rng(6), 30)
    X = pose.forward(Q)
    kw = {"seed": "middle", "tol": TOL, "angle_tol": TOL, "max_restarts": 40, "max_iterations": 15, "rng": 1}
    first = solve(pose, X, **kw)  # type: ignore[arg-type]
    near = solve(pose, X, closest_to=Q, **kw)  # type: ignore[arg-type]
    both = first.success & near.success
    assert both.mean() >= 0.9
    d_first = np.linalg.norm(first.postures - Q, axis=1)[both]
    d_near = np.linalg.norm(near.postures - Q, axis=1)[both]
    assert np.all(d_near <= d_first + 1e-12) and np.median(d_near) < np.median(d_first)


def test_the_same_seed_gives_the_same_postures_and_another_seed_other_restarts(pose) -> None:  # type: ignore[no-untyped-def]
    """Without a clock the search is deterministic; the restarts come from the rng."""
    X = pose.forward(in_limits(pose, np.random.default_rng(7), 30))
    kw = {"seed": "home", "tol": TOL, "angle_tol": TOL, "max_restarts": 30, "max_iterations": 15}
    a, b = solve(pose, X, rng=0, **kw), solve(pose, X, rng=np.random.default_rng(0), **kw)  # type: ignore[arg-type]
    np.testing.assert_array_equal(a.postures, b.postures)
    np.testing.assert_array_equal(a.restarts, b.restarts)
    c = solve(pose, X, rng=1, **kw)  # type: ignore[arg-type]
    restarted = a.restarts > 0
    assert restarted.any() and not np.array_equal(a.postures[restarted], c.postures[restarted])
    np.testing.assert_array_equal(a.postures[~restarted], c.postures[~restarted])


def test_an_unreachable_pose_searches_until_the_timeout(pose) -> None:  # type: ignore[no-untyped-def]
    """A hand 5 m away: restarts until the deadline, then the closest posture found, unsuccessful."""
    x = pose.forward(pose.home)
    x[:3] = [5.0, 0.0, 0.0]
    sol = solve(pose, x, seed="home", tol=TOL, angle_tol=TOL, timeout=2e-3, max_iterations=15)
    assert not sol.success[0] and sol.restarts[0] > 0 and sol.seconds[0] >= 2e-3
    assert np.isfinite(sol.postures).all() and sol.found[0] == 0


def test_a_pose_path_follows_without_joint_jumps(pose) -> None:  # type: ignore[no-untyped-def]
    """Each point from the previous solution: every point reached, no joint moves more than 0.1 rad."""
    q0 = pose.home
    start, end = pose.forward(q0), pose.forward(pose.clip(q0 + 0.3))
    path = solve_path(pose, start, end, 40, seed=q0, tol=TOL, angle_tol=TOL)
    assert path.all_solved and path.postures.shape == (40, 7)
    assert path.max_joint_step < 0.1
    np.testing.assert_array_equal(path.solution.seeds[1:], path.postures[:-1])


# -- seeds and names --------------------------------------------------------------------------------
def test_learned_and_nearest_seeds_are_the_maps_estimates() -> None:
    """Seed "learned" is g(x*) within 1e-6 (prototypes below e^-16 left out); "nearest" is o_k + W_k u_k."""
    result = gb_pin.babble("planar5", movements=300, seed=0)
    X = result.targets
    model = result.model
    target = result.target
    learned = solve(target, X, model=model, seed="learned", max_iterations=0)
    np.testing.assert_allclose(learned.seeds, target.clip(model.predict(X)), atol=1e-6)
    nearest = solve(target, X, model=model, seed="nearest", max_iterations=0)
    P, W, O = model.prototypes_, model.matrices_, model.offsets_
    k = np.argmin(((X[:, None, :] - P[None]) ** 2).sum(axis=2), axis=1)
    u = (X - P[k]) / model.radius
    expected = O[k] + np.einsum("kij,kj->ki", W[k], u)
    np.testing.assert_allclose(nearest.seeds, target.clip(expected), atol=1e-12)
    assert solve(target, X, model=model, seed="nearest").success_rate == 1.0


def test_a_preset_name_is_a_robot() -> None:
    """gb_pin.ik.solve("planar5", ...) loads the preset; an unknown name gets UnknownRobotError."""
    target = gb_pin.load_robot("planar5")
    x = target.forward(target.home + 0.1)
    sol = solve("planar5", x, seed="home")
    assert sol.success[0]
    with pytest.raises(UnknownRobotError):
        solve("planar5x", x, seed="home")


def test_result_solve_takes_every_option() -> None:
    """BabbleResult.solve forwards angle_tol, budgets and solutions to gb_pin.ik.solve."""
    result = gb_pin.babble("planar5", movements=200, seed=0)
    sol = result.solve(result.targets[:3], solutions=2, max_restarts=30, min_distance=0.2)
    assert sol.postures.shape == (3, 2, 5) and np.all(sol.found >= 1)


# -- bad input ------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"X": np.zeros((2, 5))}, r"X must have shape \(N, 6\)"),
        ({"tol": 0.0}, "tol must be a positive"),
        ({"angle_tol": -1e-5}, "angle_tol must be a positive"),
        ({"timeout": -1.0}, "timeout must be a positive"),
        ({"timeout": 0.0}, "timeout must be a positive"),
        ({"timeout": 1e9}, "timeout must be at most"),
        ({"solutions": 0}, r"solutions must be an integer in \[1, "),
        ({"max_restarts": -1}, r"max_restarts must be an integer in \[0, "),
        ({"max_restarts": 2**70}, r"max_restarts must be an integer in \[0, "),
        ({"max_iterations": 2**70}, r"max_iterations must be an integer in \[0, "),
        ({"min_distance": 0.0}, "min_distance must be a positive"),
        ({"closest_to": np.zeros(3)}, "closest_to must have shape"),
        ({"seed": "random"}, "seed must be one of"),
        ({"seed": "nearest"}, "needs a learned model"),
        ({"rng": -1}, "seed must be a non-negative integer"),
    ],
)
def test_bad_arguments_get_gb_pins_error_naming_them(pose, kwargs, needle) -> None:  # type: ignore[no-untyped-def]
    args = {"X": pose.forward(pose.home), "seed": "home", **kwargs}
    with pytest.raises(InvalidArgumentError, match=needle):
        solve(pose, **args)


def test_results_too_large_for_memory_are_refused_before_allocating() -> None:
    """300 000 targets x 1000 solutions would need 16 GiB: refused, naming the limit."""
    X = np.zeros((300_000, 2))
    with pytest.raises(InvalidArgumentError, match="MAX_OUTPUT_BYTES"):
        solve("planar5", X, seed="home", solutions=1000, max_restarts=1)
    with pytest.raises(InvalidArgumentError, match=r"steps must be an integer in \[2, 1000000\]"):
        solve_path("planar5", [0.5, 0.0], [0.6, 0.1], steps=10**9, seed="home")
    with pytest.raises(InvalidArgumentError, match="solve_path takes no solutions"):
        solve_path("planar5", [0.5, 0.0], [0.6, 0.1], seed="home", solutions=2)


def test_a_cpu_clock_budget_and_a_bad_clock(pose) -> None:  # type: ignore[no-untyped-def]
    """clock="cpu" keeps the budget on the thread's CPU time; an unknown clock is refused by name."""
    x = pose.forward(pose.home)
    x[:3] = [5.0, 0.0, 0.0]
    sol = solve(pose, x, seed="home", timeout=2e-3, clock="cpu")
    assert not sol.success[0] and sol.restarts[0] > 0 and sol.seconds[0] >= 2e-3
    with pytest.raises(InvalidArgumentError, match="clock must be one of wall, cpu"):
        solve(pose, x, seed="home", timeout=2e-3, clock="tsc")


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_the_protocol_command_prints_its_table(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin bench --ik --protocol trac-ik`: every gb_pin row (TRAC-IK's too when pytracik is there)."""
    from gb_pin.cli import main
    from gb_pin.experiments import ik_tracik
    from gb_pin.experiments.ik_protocol import BEGIN, END

    doc = tmp_path / "IK.md"
    doc.write_text(f"{BEGIN.format('ur5', 'pose')}\nold\n{END.format('ur5', 'pose')}\n")
    argv = ["bench", "--ik", "--protocol", "trac-ik", "--robot", "ur5", "--samples", "60", "--paths", "2"]
    assert main([*argv, "--movements", "20", "--doc", str(doc)]) == 0
    out = capsys.readouterr().out
    assert out.count("| gb_pin |") == 6 and ("| TRAC-IK |" in out) == ik_tracik.available()
    assert "solutions=4" in out and "Paths (2 Cartesian" in out and "old" not in doc.read_text()
    assert main(["bench", "--ik", "--protocol", "trac-ik", "--robot", "ur6"]) == 2
    assert "panda, ur5, kinova" in capsys.readouterr().err


def test_tracik_quaternions_are_pinocchios() -> None:
    """The (x, y, z, w) handed to TRAC-IK is the rotation's quaternion, every branch of Shepperd's method."""
    from gb_pin.experiments.ik_tracik import _quaternion

    rng = np.random.default_rng(8)
    for R in [pin.exp3(v) for v in rng.normal(size=(20, 3)) * 1.5] + [
        np.diag([1.0, -1, -1]),
        np.diag([-1.0, 1, -1]),
    ]:
        q = pin.Quaternion(np.array(_quaternion(R)))  # pinocchio takes (x, y, z, w) from a vector
        np.testing.assert_allclose(q.toRotationMatrix(), R, atol=1e-12)


def test_periodic_joints_turn_by_whole_turns_towards_the_reference() -> None:
    """UR5 (joints +/- 2 pi): the solution nearest a reference is the same pose turned by 2 pi."""
    ur5 = gb_pin.load_robot("ur5")
    q0 = ur5.home.copy()
    q0[0] = -2.5
    ref = q0.copy()
    ref[0] += 2 * np.pi
    sol = solve(ur5, ur5.forward(q0), seed=q0, closest_to=ref, max_restarts=1, tol=TOL)
    assert sol.success[0] and sol.postures[0, 0] == pytest.approx(ref[0], abs=1e-9)
    np.testing.assert_allclose(ur5.forward(sol.postures[0]), ur5.forward(q0), atol=1e-12)
    periodic = ik_robot(ur5, ur5.chain).periodic  # every joint but the elbow (+/- pi) spans +/- 2 pi
    np.testing.assert_array_equal(periodic[[0, 1, 3, 4, 5]], 1.0)
    assert ik_robot(gb_pin.load_robot("panda"), gb_pin.load_robot("panda").chain).periodic.sum() == 0


def test_gb_pin_ik_solves_pose_targets_of_a_saved_run(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin ik run.npz --targets poses.csv --angle-tol ... --timeout ...` on a 6-D task vector."""
    from gb_pin.cli import main

    result = gb_pin.babble("talos_left_arm_pose", movements=10, seed=0)
    X = result.target.forward(in_limits(result.target, np.random.default_rng(9), 3, spread=0.3))
    run = str(tmp_path / "run.npz")
    result.save(run)
    csv = tmp_path / "poses.csv"
    csv.write_text("\n".join(",".join(repr(float(v)) for v in x) for x in X) + "\n")
    argv = ["ik", run, "--targets", str(csv), "--tol", "1e-5", "--angle-tol", "1e-5", "--timeout", "0.005"]
    assert main([*argv, "--seed", "home", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert len(data["solutions"]) == 3 and all(s["success"] for s in data["solutions"])
    assert all(s["errors"][0] <= 1e-5 and s["errors"][1] <= 1e-5 for s in data["solutions"])
    assert main(["ik", run, "0.3", "0.1"]) == 2
    assert "expected 6 coordinates (task vector of" in capsys.readouterr().err
