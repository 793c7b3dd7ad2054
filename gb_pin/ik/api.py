"""The IK solver's Python side: validate, choose the seeds and the budget, run the compiled search.

``solve(robot, X, model=...)`` takes any robot the learner takes (a preset name, or the
:class:`~gb_pin.learn.body.kinematics.Kinematics` protocol: a chain, a home, limits) and any of
its task maps (positions, poses, pointing, several frames), so it works for presets, URDF and
planar targets and loaded result files alike.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._interrupt import interruptible
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.ik.clock import CLOCKS
from gb_pin.ik.robot import as_components, chain_of, ik_robot, resolve
from gb_pin.ik.search import (
    SEED_GIVEN,
    SEED_LEARNED,
    SEED_NEAREST,
    IKOut,
    IKSeeds,
    search_scratch,
    solve_batch,
)
from gb_pin.ik.solution import IKPath, IKSolution
from gb_pin.ik.solver import IKSettings
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.components import POSITION
from gb_pin.learn.body.kinematics import Kinematics
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.llm_kernels import MapArrays

__all__ = [
    "DEFAULT_ANGLE_TOL",
    "DEFAULT_BACKTRACKS",
    "DEFAULT_DAMPING",
    "DEFAULT_ERROR_DAMPING",
    "DEFAULT_MAX_ITERATIONS",
    "DEFAULT_SEARCH_TIMEOUT",
    "DEFAULT_TOL",
    "MAX_ITERATIONS",
    "MAX_OUTPUT_BYTES",
    "MAX_PATH_STEPS",
    "Seed",
    "solve",
    "solve_path",
]

DEFAULT_TOL = 1e-4  # [m]
DEFAULT_ANGLE_TOL = 1e-4  # [rad]
DEFAULT_DAMPING = 1e-5  # [m], the least damping
DEFAULT_ERROR_DAMPING = 0.1  # lambda^2 = damping^2 + 0.1 ||e||^2 (docs/IK.md: measured best of 0.03-10)
DEFAULT_MAX_ITERATIONS = 100
DEFAULT_BACKTRACKS = 10  # halvings of a step that does not reduce the error
DEFAULT_SEARCH_TIMEOUT = 5e-3  # [s] per target, when several or the closest solutions are asked
DEFAULT_MIN_DISTANCE = 0.1  # [rad]: two solutions differing by less in every joint are one
MAX_ITERATIONS = 10**9  # steps of one attempt (about 1000 s), and restarts
MAX_BACKTRACKS = 100  # a step halved 100 times is 1e-30 of itself
MAX_TIMEOUT = 86_400.0  # [s] per target
MAX_SOLUTIONS = 1000
MAX_PATH_STEPS = 10**6
MAX_OUTPUT_BYTES = 2**31
"""The most memory a call's results may take (2 GiB): checked before anything is allocated."""
MAX_COORDINATE = 1e6
"""Targets farther than this [m] are refused: no robot reaches them, and their residual would overflow."""
SEED_NAMES = ("learned", "nearest", "home", "middle")
SEED_CUT = 16.0
"""The learned seed g(x*) sums the prototypes whose activation is above exp(-16) of the nearest one's."""

Seed = Literal["learned", "nearest", "home", "middle"] | ArrayLike


def _empty_map(n: int, m: int) -> MapArrays:
    """A map of no prototypes, of the learned map's compiled type (for given seeds)."""
    return LocalLinearMap(radius=1.0).initialize(np.zeros(n), np.zeros(m), capacity=1).kernel()


def _model(model: LocalLinearMap | None, seed: str, n: int, m: int) -> tuple[MapArrays, int]:
    if model is None:
        raise InvalidArgumentError(f"seed={seed!r} needs a learned model (model=...)")
    if model.n_inputs_ != n or model.n_outputs_ != m:
        raise InvalidArgumentError(
            f"model maps {model.n_inputs_} -> {model.n_outputs_} dimensions, the robot {n} -> {m}"
        )
    return model.kernel(), model.n_prototypes_


def _postures(name: str, value: Any, m: int, N: int) -> NDArray[np.float64]:
    """(N, m) or (1, m) postures: one (m,) for every target or one per target."""
    Q = check.points(name, value, m, allow_single=True)
    if Q.shape[0] not in (1, N):
        raise InvalidArgumentError(
            f"{name} postures must be one (m,) posture or one per target ({N}), got {Q.shape[0]}"
        )
    return Q


def _seeds(
    robot: Kinematics, chain: KinematicChain, N: int, model: LocalLinearMap | None, seed: Seed
) -> tuple[int, NDArray[np.float64], MapArrays, int, str]:
    """(mode, given postures, map, prototypes, label)."""
    n, m = chain.n_task, chain.n_joints
    if isinstance(seed, str):
        if seed in ("learned", "nearest"):
            arrays, count = _model(model, seed, n, m)
            mode = SEED_LEARNED if seed == "learned" else SEED_NEAREST
            return mode, np.zeros((1, m)), arrays, count, seed
        if seed == "home":
            return (
                SEED_GIVEN,
                np.asarray(robot.home, dtype=np.float64).reshape(1, m),
                _empty_map(n, m),
                0,
                seed,
            )
        if seed == "middle":
            lower, upper = np.asarray(robot.lower, float), np.asarray(robot.upper, float)
            mid = np.where(np.isfinite(lower) & np.isfinite(upper), 0.5 * (lower + upper), robot.home)
            return SEED_GIVEN, mid.reshape(1, m), _empty_map(n, m), 0, seed
        raise InvalidArgumentError(f"seed must be one of {SEED_NAMES} or postures, got {seed!r}")
    return SEED_GIVEN, _postures("seed", seed, m, N), _empty_map(n, m), 0, "given"


def _targets(chain: KinematicChain, X: ArrayLike) -> NDArray[np.float64]:
    pts = check.points("X", X, chain.n_task, allow_single=True)
    if np.max(np.abs(pts)) > MAX_COORDINATE:
        raise InvalidArgumentError(
            f"X must lie within {MAX_COORDINATE:g} of the origin (no robot reaches farther; the squared "
            f"residual would overflow), got a coordinate of {float(np.max(np.abs(pts))):.3g}"
        )
    return pts


def _budget(
    timeout: float | None, max_restarts: int | None, search: bool, clock: str
) -> tuple[float, int, int]:
    """(timeout [s] or inf, max_restarts or -1 for unbounded, clock id) from the arguments."""
    if clock not in CLOCKS:
        raise InvalidArgumentError(f"clock must be one of {', '.join(CLOCKS)}, got {clock!r}")
    if timeout is None and max_restarts is None and search:
        timeout = DEFAULT_SEARCH_TIMEOUT
    if timeout is not None:
        timeout = check.positive_float("timeout", timeout)
        if timeout > MAX_TIMEOUT:
            raise InvalidArgumentError(
                f"timeout must be at most {MAX_TIMEOUT:g} s per target, got {timeout!r}"
            )
        if CLOCKS[clock] < 0:
            raise InvalidArgumentError(
                f"timeout needs the {clock} clock, which this platform lacks: give max_restarts"
            )
    if max_restarts is not None:
        restarts = check.positive_int("max_restarts", max_restarts, minimum=0, maximum=MAX_ITERATIONS)
    else:
        restarts = -1 if timeout is not None else 0
    return (np.inf if timeout is None else timeout), restarts, CLOCKS[clock]


def _kinds_sizes(chain: KinematicChain) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    comps = as_components(chain)
    return comps.kinds, comps.sizes


def _check_memory(N: int, k: int, chain: KinematicChain, what: str) -> None:
    m, n, C = chain.n_joints, chain.n_task, max(chain.n_components, 1)
    size = 8 * N * (k * (m + n + 1 + C) + 2 * m + 4)
    if size > MAX_OUTPUT_BYTES:
        raise InvalidArgumentError(
            f"{what} would need {size / 2**30:.1f} GiB of results (limit {MAX_OUTPUT_BYTES / 2**30:g} GiB, "
            "MAX_OUTPUT_BYTES): solve fewer targets or solutions per call"
        )


def solve(
    robot: Kinematics | str,
    X: ArrayLike,
    *,
    model: LocalLinearMap | None = None,
    seed: Seed = "learned",
    tol: float = DEFAULT_TOL,
    angle_tol: float = DEFAULT_ANGLE_TOL,
    max_iterations: int = DEFAULT_MAX_ITERATIONS,
    damping: float = DEFAULT_DAMPING,
    error_damping: float = DEFAULT_ERROR_DAMPING,
    backtracks: int = DEFAULT_BACKTRACKS,
    timeout: float | None = None,
    max_restarts: int | None = None,
    solutions: int = 1,
    closest_to: ArrayLike | None = None,
    min_distance: float = DEFAULT_MIN_DISTANCE,
    rng: int | np.random.Generator = 0,
    follow: bool = False,
    clock: str = "wall",
) -> IKSolution:
    """Postures reaching the targets ``X``: seeds refined by damped least squares within the limits.

    Args:
        robot: a preset name, a :class:`~gb_pin.robot.target.KinematicTarget` or any
            :class:`~gb_pin.learn.body.kinematics.Kinematics` with a compiled chain.
        X: (N, n) targets, or one (n,) target, in the learner's task vector (``target.forward(q)``
            gives one): positions [m], orientations s log(R_ref^T R), pointing directions.
        model: the learned inverse estimate g (needed for ``seed="learned"`` and ``"nearest"``).
        seed: ``"learned"`` (g(x*), the learned redundancy resolution), ``"nearest"`` (the local
            model of the prototype nearest x*: about K n operations instead of g's K n m),
            ``"home"`` (q_home), ``"middle"`` (the middle of the limits), or postures: one (m,)
            for every target or (N, m), one per target.
        tol: success when every position component is within ``tol`` [m] ...
        angle_tol: ... and every orientation and pointing component within ``angle_tol`` [rad]
            (the angle between the reached and the target rotation or direction).
        max_iterations: the most damped least-squares steps from one seed (0: evaluate the seeds).
        damping: the least lambda [m]: the step is J^T (J J^T + lambda^2 I)^-1 e, ...
        error_damping: ... with lambda^2 = damping^2 + error_damping ||e||^2 (Levenberg-Marquardt
            damping that vanishes at the goal; 0: a fixed lambda).
        backtracks: the most halvings of a step that does not reduce the error; when none
            does, the attempt stops at that local minimum (0: full steps, always taken).
        timeout: seconds per target: until then, restart from random postures within the limits
            while a target is unsolved (or fewer than ``solutions`` are found). None: no time limit.
        max_restarts: the most restarts per target (None: until ``timeout``; 0 without one).
            Without ``timeout`` the answers are deterministic (the same ``rng``, the same postures).
        solutions: k, the distinct solutions wanted per target (>= 1); with k > 1 the postures
            are (N, k, m), NaN rows where fewer were found.
        closest_to: postures (m,) or (N, m): search the whole budget and return the solutions
            nearest these first.
        min_distance: solutions are distinct when some joint differs by at least this [rad] or [m].
        rng: seed (int >= 0) or ``numpy.random.Generator`` of the restarts.
        follow: targets are consecutive points of a path: each starts from the previous one's
            solution, and restarts prefer the solution nearest it (used by :func:`solve_path`).
        clock: ``"wall"`` (monotonic time, the field's budget) or ``"cpu"`` (the thread's CPU time:
            the time the query ran on its core, which a busy machine's preemptions do not eat into;
            0.7 us a read). ``seconds`` is measured on the same clock.
        search budget: with ``solutions > 1`` or ``closest_to`` and neither ``timeout`` nor
            ``max_restarts``, ``timeout`` is :data:`DEFAULT_SEARCH_TIMEOUT` (5 ms).

    Returns:
        The :class:`~gb_pin.ik.solution.IKSolution` (always batch-shaped, N >= 1).

    Raises:
        InvalidArgumentError: targets, seeds or settings of the wrong shape or value; a robot
            without a compiled kinematic chain.
        UnknownRobotError: an unknown preset name.
    """
    robot = resolve(robot)
    chain = chain_of(robot)
    pts = _targets(chain, X)
    N, m = pts.shape[0], chain.n_joints
    k = check.positive_int("solutions", solutions, minimum=1, maximum=MAX_SOLUTIONS)
    _check_memory(N, k, chain, f"{N} targets x {k} solutions")
    time_limit, restarts, clock_id = _budget(timeout, max_restarts, k > 1 or closest_to is not None, clock)
    settings = IKSettings(
        tol=check.positive_float("tol", tol),
        angle_tol=check.positive_float("angle_tol", angle_tol),
        damping=check.positive_float("damping", damping),
        max_iterations=check.positive_int(
            "max_iterations", max_iterations, minimum=0, maximum=MAX_ITERATIONS
        ),
        backtracks=check.positive_int("backtracks", backtracks, minimum=0, maximum=MAX_BACKTRACKS),
        error_damping=check.nonnegative_float("error_damping", error_damping),
        timeout=time_limit,
        max_restarts=restarts,
        solutions=k,
        min_distance=check.positive_float("min_distance", min_distance),
        closest=closest_to is not None,
        follow=bool(follow),
        clock=clock_id,
    )
    mode, given, arrays, count, label = _seeds(robot, chain, N, model, seed)
    reference = np.zeros((1, m)) if closest_to is None else _postures("closest_to", closest_to, m, N)
    base = np.uint64(check.generator(rng).integers(0, 2**63, dtype=np.uint64))
    seeds = IKSeeds(mode, given, arrays, count, SEED_CUT, reference, closest_to is not None, base)
    n, C = chain.n_task, max(chain.n_components, 1)
    out = IKOut(
        np.full((N, k, m), np.nan), np.full((N, k, n), np.nan), np.full((N, k), np.nan),
        np.full((N, k, C), np.nan), np.zeros(N, np.int64), np.zeros(N, np.int64), np.zeros(N, np.int64),
        np.zeros(N), np.empty((N, m)),
    )  # fmt: skip
    rows = sum(int(size) if kind == POSITION else 3 for kind, size in zip(*_kinds_sizes(chain), strict=True))
    scratch = search_scratch(rows, m, C, k)
    ik = ik_robot(robot, chain)
    interruptible(
        lambda: solve_batch(pts, ik, settings, seeds, out, scratch),
        scratch.work.stop,
        _longest(N, settings),
    )
    return IKSolution.of(pts, out, settings, label, chain)


def _longest(N: int, settings: IKSettings) -> float:
    """A bound on the seconds a batch of ``N`` targets may take (inf: unbounded or unknown)."""
    if settings.timeout < np.inf:
        return N * settings.timeout * 1.01
    if settings.max_restarts < 0:
        return np.inf
    steps = N * (settings.max_restarts + 1) * (settings.max_iterations + 1) * (settings.backtracks + 1)
    return steps * 1e-6  # about 1 us a step of a small arm: long calls go to a worker thread


def solve_path(
    robot: Kinematics | str,
    start: ArrayLike,
    end: ArrayLike,
    steps: int = 50,
    *,
    model: LocalLinearMap | None = None,
    seed: Seed = "learned",
    follow: bool = True,
    **options: Any,
) -> IKPath:
    """A joint path along the straight task-space line from ``start`` to ``end``.

    With ``follow`` (the default) the first point starts from ``seed`` and every later point
    from the previous point's posture (restarts, if a budget is given, prefer the solution
    nearest it): no joint jumps while the line stays reachable. ``follow=False`` seeds every
    point on its own (``seed="learned"``: the learned redundancy resolution of each point).

    Args:
        robot: the robot (as for :func:`solve`).
        start: (n,) first point of the line (task vector).
        end: (n,) last point.
        steps: points on the line, ends included (2 to :data:`MAX_PATH_STEPS`).
        model: the learned inverse estimate g (needed for ``seed="learned"``).
        seed: as for :func:`solve`; postures: one (m,) or ``steps`` rows.
        follow: start each point from the previous point's solution.
        **options: :func:`solve`'s settings (``tol``, ``angle_tol``, ``timeout``, ...).

    Returns:
        The :class:`~gb_pin.ik.solution.IKPath`, with its joint length and largest joint step.

    Raises:
        InvalidArgumentError: points, steps or settings of the wrong shape or value.
    """
    robot = resolve(robot)
    chain = chain_of(robot)
    n = chain.n_task
    a = check.vector("start", start, n)
    b = check.vector("end", end, n)
    count = check.positive_int("steps", steps, minimum=2, maximum=MAX_PATH_STEPS)
    _check_memory(count, 1, chain, f"a path of {count} steps")
    for bad in ("solutions", "closest_to"):
        if bad in options:
            raise InvalidArgumentError(f"solve_path takes no {bad}= (one posture per point)")
    line = a + np.linspace(0.0, 1.0, count)[:, None] * (b - a)
    sol = solve(robot, line, model=model, seed=seed, follow=follow, **options)
    return IKPath.of(sol)
