"""Target sets of stacked tasks: grids of positions with turned orientations, checked reachable.

:func:`task_grid` builds a pose (or pointing, or several-frame) target set the way the
``"auto"`` grids are built: a regular grid for the first position component; every other
position component at its home position, or the grid mirrored across a world plane
(``mirror="y"``: both hands of a humanoid, left and right); every rotational component at
its home orientation (or pointing direction) turned by an angle drawn uniformly in
``[0, turn]`` degrees about a random axis (seeded). Every point is then checked with the
reachability solver (:func:`~gb_pin.robot.reachability.check_reachable`, on the whole
task vector); the turn of an unreachable point is drawn again (up to ``REDRAWS`` times).

Like :mod:`gb_pin.robot.targets_auto`, this module imports neither pinocchio nor the robot class.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.body.components import ORIENTATION, POSITION, TaskComponents
from gb_pin.robot.grids import grid_targets
from gb_pin.robot.reachability import Robot, check_reachable

REDRAWS = 20
"""How many times the turn of an unreachable target is drawn again."""
_MIRROR = {"x": 0, "y": 1, "z": 2}


def exp3(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation matrix of rotation vector v [rad] (Rodrigues)."""
    theta = float(np.linalg.norm(v))
    k = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    if theta < 1e-12:
        return np.eye(3) + k
    return np.eye(3) + math.sin(theta) / theta * k + (1.0 - math.cos(theta)) / theta**2 * (k @ k)


def log3(r: NDArray[np.float64]) -> NDArray[np.float64]:
    """The rotation vector [rad] of a rotation matrix (angles below about 179 deg)."""
    w = 0.5 * np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    s = float(np.linalg.norm(w))
    theta = math.atan2(s, 0.5 * (np.trace(r) - 1.0))
    return w * (theta / s if s > 0.0 else 1.0)


def _random_turn(rng: np.random.Generator, turn: float) -> NDArray[np.float64]:
    """A rotation vector of angle uniform in [0, turn] rad about a uniformly random axis."""
    axis = rng.normal(size=3)
    return axis / np.linalg.norm(axis) * rng.uniform(0.0, turn)


def _turned(
    comps: TaskComponents, c: int, x_home: NDArray[np.float64], turn: NDArray[np.float64]
) -> list[float]:
    """Component c's rows for the home orientation (or direction) turned by rotation vector ``turn``."""
    rows = x_home[comps.rows(c)]
    s = float(comps.scales[c])
    if comps.kinds[c] == ORIENTATION:
        reached = exp3(rows / s) @ exp3(turn)  # R_ref^T R_home, turned in the frame
        return list(s * log3(reached))
    d0, u, v = comps.references[c]
    home = exp3((rows[0] * u + rows[1] * v) / s) @ d0  # the chart's inverse: the home direction
    # Turn the direction by the full angle, about the part of the axis normal to it.
    normal = turn - float(turn @ home) * home
    norm = float(np.linalg.norm(normal))
    d = exp3(normal / norm * float(np.linalg.norm(turn))) @ home if norm > 0 else home
    axis = np.cross(d0, d)
    sn, cs = float(np.linalg.norm(axis)), float(d0 @ d)
    r = axis * (math.atan2(sn, cs) / sn if sn > 0 else 0.0)
    return [s * float(r @ u), s * float(r @ v)]


def _points(chain: KinematicChain, x_home: NDArray[np.float64], grid: NDArray[np.float64],
            turns: NDArray[np.float64], mirror: int | None) -> NDArray[np.float64]:  # fmt: skip
    comps = chain.components
    assert comps is not None
    out = np.empty((grid.shape[0], comps.n_task))
    first = next(c for c in range(comps.count) if comps.kinds[c] == POSITION)
    for i, p in enumerate(grid):
        row: list[float] = []
        for c in range(comps.count):
            if comps.kinds[c] == POSITION:
                if c == first:
                    row.extend(p)
                elif mirror is not None:
                    q = p.copy()
                    q[mirror] = -q[mirror]
                    row.extend(q)
                else:
                    row.extend(x_home[comps.rows(c)])
            else:
                row.extend(_turned(comps, c, x_home, turns[i, c]))
        out[i] = row
    return out


def task_grid(
    robot: Robot,
    lower: ArrayLike,
    upper: ArrayLike,
    shape: Sequence[int],
    *,
    turn: float = 0.0,
    seed: int = 0,
    mirror: str | None = None,
) -> NDArray[np.float64]:
    """A reachable target set of a stacked task (see the module docstring).

    Args:
        robot: a robot whose chain has a stacked task with a position component first among
            its positions (e.g. a :class:`~gb_pin.robot.target.KinematicTarget` with ``task=``).
        lower: lower corner of the grid of the first position component [m].
        upper: upper corner [m].
        shape: points per axis of that component.
        turn: largest turn of the rotational components from their home values [deg], in [0, 180).
        seed: seed of the turns and of the reachability sampling.
        mirror: ``"x"``, ``"y"`` or ``"z"``: the other position components take the grid point
            with that coordinate negated; None: they stay at home.

    Returns:
        (N, n) targets, every one reached by a posture within the limits.

    Raises:
        InvalidArgumentError: bad arguments, or a target unreachable after ``REDRAWS`` draws.
    """
    chain = robot.chain
    comps = chain.components
    if comps is None or not np.any(comps.kinds == POSITION):
        raise InvalidArgumentError("task_grid needs a stacked task with a position component")
    if isinstance(turn, bool) or not isinstance(turn, (int, float)) or not 0.0 <= turn < 180.0:
        raise InvalidArgumentError(f"turn must be an angle in [0, 180) degrees, got {turn!r}")
    if mirror is not None and mirror not in _MIRROR:
        raise InvalidArgumentError(f"mirror must be 'x', 'y', 'z' or None, got {mirror!r}")
    seed = check.positive_int("seed", seed, minimum=0)
    grid = grid_targets(lower, upper, shape)
    first = next(c for c in range(comps.count) if comps.kinds[c] == POSITION)
    if grid.shape[1] != int(comps.sizes[first]):
        raise InvalidArgumentError(
            f"the grid has {grid.shape[1]} coordinates, the first position component "
            f"{int(comps.sizes[first])}"
        )
    others = [c for c in range(comps.count) if comps.kinds[c] == POSITION and c != first]
    if mirror is not None and any(comps.sizes[c] != comps.sizes[first] for c in others):
        raise InvalidArgumentError("mirror needs every position component on as many axes as the first")
    rng = np.random.default_rng(seed)
    x_home = chain.forward(np.ascontiguousarray(robot.home, dtype=float))
    turns = np.zeros((grid.shape[0], comps.count, 3))
    rotational = [c for c in range(comps.count) if comps.kinds[c] != POSITION]
    redo = np.ones(grid.shape[0], dtype=bool)
    points = np.empty((grid.shape[0], comps.n_task))
    for _ in range(REDRAWS + 1):
        for i in np.flatnonzero(redo):
            for c in rotational:
                turns[i, c] = _random_turn(rng, math.radians(turn))
        points = _points(chain, x_home, grid, turns, None if mirror is None else _MIRROR[mirror])
        redo = ~check_reachable(robot, points, seed=seed).reachable
        if not redo.any():
            return points
        if not rotational or turn == 0.0:  # nothing to draw again
            break
    bad = "; ".join(str(np.round(p, 3).tolist()) for p in points[redo][:3])
    raise InvalidArgumentError(
        f"{int(redo.sum())} of {len(points)} task targets are not reachable within the joint limits "
        f"(e.g. {bad}): choose a smaller grid or turn"
    )
