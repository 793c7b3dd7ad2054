"""The IK solver's Python side: validate, choose the seeds, run the compiled refinement.

``solve(robot, X, model=...)`` takes any robot the learner takes (the
:class:`~gb_pin.learn.body.kinematics.Kinematics` protocol: a chain, a home, limits), so it
works for presets, URDF and planar targets and loaded result files alike.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.ik.jacobian import check_task_map
from gb_pin.ik.solution import IKPath, IKSolution
from gb_pin.ik.solver import IKBuffers, IKRobot, IKSettings, refine_batch
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.kinematics import Kinematics
from gb_pin.learn.llm import LocalLinearMap

__all__ = [
    "DEFAULT_BACKTRACKS",
    "DEFAULT_DAMPING",
    "DEFAULT_MAX_ITERATIONS",
    "DEFAULT_TOL",
    "Seed",
    "solve",
    "solve_path",
]

DEFAULT_TOL = 1e-4  # [m]
DEFAULT_DAMPING = 1e-3  # [m]
DEFAULT_MAX_ITERATIONS = 100
DEFAULT_BACKTRACKS = 10  # halvings of a step that does not reduce the error
SEED_NAMES = ("learned", "home")

Seed = Literal["learned", "home"] | ArrayLike


MAX_COORDINATE = 1e6
"""Targets farther than this [m] are refused: no robot reaches them, and their residual would overflow."""


def _seeds(
    robot: Kinematics, X: NDArray[np.float64], model: LocalLinearMap | None, seed: Seed
) -> tuple[NDArray[np.float64], str]:
    """(N, m) starting postures (a fresh array) and the seed's label."""
    m = _chain(robot).n_joints
    if isinstance(seed, str):
        if seed == "learned":
            if model is None:
                raise InvalidArgumentError("seed='learned' needs a learned model (model=...)")
            if model.n_inputs_ != X.shape[1] or model.n_outputs_ != m:
                raise InvalidArgumentError(
                    f"model maps {model.n_inputs_} -> {model.n_outputs_} dimensions, the robot "
                    f"{X.shape[1]} -> {m}"
                )
            return np.array(model.predict(X, warn=False), order="C"), "learned"  # refined: residuals tell
        if seed == "home":
            return np.tile(np.asarray(robot.home, dtype=np.float64), (X.shape[0], 1)), "home"
        raise InvalidArgumentError(f"seed must be one of {SEED_NAMES} or postures, got {seed!r}")
    Q = check.points("seed", seed, m, allow_single=True)
    if Q.shape[0] == 1:
        Q = np.tile(Q, (X.shape[0], 1))
    if Q.shape[0] != X.shape[0]:
        raise InvalidArgumentError(
            f"seed postures must be one (m,) posture or one per target ({X.shape[0]}), got {Q.shape[0]}"
        )
    return np.array(Q, order="C"), "given"


def _chain(robot: Kinematics) -> KinematicChain:
    """The robot's compiled chain, with a task map the Jacobian handles."""
    chain = getattr(robot, "chain", None)
    if not isinstance(chain, KinematicChain):
        raise InvalidArgumentError(
            f"IK needs the robot's compiled kinematic chain (a KinematicTarget, preset, URDF or changed "
            f"body); {robot!r} has none (a robot given as a Python function): seed its own solver with "
            "result.inverse(X)"
        )
    check_task_map(chain)
    return chain


def solve(
    robot: Kinematics,
    X: ArrayLike,
    *,
    model: LocalLinearMap | None = None,
    seed: Seed = "learned",
    tol: float = DEFAULT_TOL,
    max_iterations: int = DEFAULT_MAX_ITERATIONS,
    damping: float = DEFAULT_DAMPING,
    backtracks: int = DEFAULT_BACKTRACKS,
) -> IKSolution:
    """Postures reaching the targets ``X``: seeds refined by damped least squares within the limits.

    Args:
        robot: the robot (a :class:`~gb_pin.robot.target.KinematicTarget` or any
            :class:`~gb_pin.learn.body.kinematics.Kinematics`).
        X: (N, n) targets, or one (n,) target, on the robot's task axes [m].
        model: the learned inverse estimate g (needed for ``seed="learned"``).
        seed: ``"learned"`` (g(x*), the learned redundancy resolution), ``"home"`` (q_home)
            or postures: one (m,) for every target or (N, m), one per target.
        tol: success when ||x* - f(q)|| <= tol [m].
        max_iterations: the most damped least-squares steps per target (0: evaluate the seeds).
        damping: lambda [m]: the step is J^T (J J^T + lambda^2 I)^-1 e.
        backtracks: the most halvings of a step that does not reduce the error; when none
            does, the iteration stops at that local minimum (0: full steps, always taken).
            Learned and home seeds rarely need one, random seeds do.

    Returns:
        The :class:`~gb_pin.ik.solution.IKSolution` (always batch-shaped, N >= 1).

    Raises:
        InvalidArgumentError: targets, seeds or settings of the wrong shape or value; a robot
            without a compiled kinematic chain.
    """
    chain = _chain(robot)
    pts = check.points("X", X, chain.n_task, allow_single=True)
    if np.max(np.abs(pts)) > MAX_COORDINATE:
        raise InvalidArgumentError(
            f"X must lie within {MAX_COORDINATE:g} m of the origin (no robot reaches farther; the squared "
            f"residual would overflow), got a coordinate of {float(np.max(np.abs(pts))):.3g}"
        )
    settings = IKSettings(
        check.positive_float("tol", tol),
        check.positive_float("damping", damping),
        check.positive_int("max_iterations", max_iterations, minimum=0),
        check.positive_int("backtracks", backtracks, minimum=0),
    )
    Q, label = _seeds(robot, pts, model, seed)
    lower = np.ascontiguousarray(robot.lower, dtype=np.float64)
    upper = np.ascontiguousarray(robot.upper, dtype=np.float64)
    seeds = np.clip(Q, lower, upper)
    N = pts.shape[0]
    out = IKBuffers(seeds.copy(), np.empty((N, chain.n_task)), np.empty(N), np.zeros(N, dtype=np.int64))
    refine_batch(pts, IKRobot(chain.kernel(), lower, upper), settings, out)
    return IKSolution(
        targets=pts,
        postures=out.q,
        positions=out.x,
        residuals=out.residual,
        iterations=out.iterations,
        success=out.residual <= settings.tol,
        seeds=seeds,
        tol=settings.tol,
        seed=label,
    )


def solve_path(
    robot: Kinematics,
    start: ArrayLike,
    end: ArrayLike,
    steps: int = 50,
    *,
    model: LocalLinearMap | None = None,
    seed: Seed = "learned",
    tol: float = DEFAULT_TOL,
    max_iterations: int = DEFAULT_MAX_ITERATIONS,
    damping: float = DEFAULT_DAMPING,
) -> IKPath:
    """A joint path along the straight line from ``start`` to ``end``, each point solved by :func:`solve`.

    With ``seed="learned"`` each point starts from the learned estimate g(x*), so the path's
    redundancy resolution is the learned one (no drift along the self-motion).

    Args:
        robot: the robot.
        start: (n,) first point of the line [m].
        end: (n,) last point [m].
        steps: points on the line, ends included (>= 2).
        model: the learned inverse estimate g (needed for ``seed="learned"``).
        seed: as for :func:`solve`; postures: one (m,) or ``steps`` rows.
        tol: success when ||x* - f(q)|| <= tol [m].
        max_iterations: the most damped least-squares steps per point.
        damping: lambda of the damped least squares [m].

    Returns:
        The :class:`~gb_pin.ik.solution.IKPath`, with its joint length and largest joint step.

    Raises:
        InvalidArgumentError: points, steps or settings of the wrong shape or value.
    """
    n = _chain(robot).n_task
    a = check.vector("start", start, n)
    b = check.vector("end", end, n)
    count = check.positive_int("steps", steps, minimum=2)
    line = a + np.linspace(0.0, 1.0, count)[:, None] * (b - a)
    sol = solve(robot, line, model=model, seed=seed, tol=tol, max_iterations=max_iterations, damping=damping)
    return IKPath.of(sol)
