"""Cartesian paths for the IK protocol: straight lines with slerped orientations, solved point after point.

A path starts at the pose of a posture drawn within the limits and ends at the pose of a posture
up to 0.5 rad away in every joint; its 50 points interpolate the position linearly and the
orientation along the geodesic. gb_pin solves them with ``follow`` (each point from the previous
point's solution, restarts preferring the nearest), TRAC-IK with each solve seeded by the previous
solution. Measured: whether every point was solved and the largest joint step between points.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.experiments import ik_tracik
from gb_pin.ik.api import solve
from gb_pin.ik.geometry import exp3, log3
from gb_pin.learn.body.components import ORIENTATION
from gb_pin.robot.target import KinematicTarget

__all__ = ["cartesian_paths", "sample_postures"]


def sample_postures(target: KinematicTarget, count: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Postures uniform within the limits (home +/- pi for a continuous joint)."""
    lo = np.where(np.isfinite(target.lower), target.lower, target.home - np.pi)
    hi = np.where(np.isfinite(target.upper), target.upper, target.home + np.pi)
    return rng.uniform(lo, hi, (count, target.n_joints))


def cartesian_paths(
    target: KinematicTarget,
    tracik: ik_tracik.TracIK | None,
    settings: dict[str, Any],
    count: int,
    rng: np.random.Generator,
) -> dict[str, tuple[float, float, float]]:
    """``count`` Cartesian paths of 50 points; per solver (all points solved, median and max largest step)."""
    comps = target.chain.components
    rot = (
        None
        if comps is None
        else next((c for c in range(comps.count) if comps.kinds[c] == ORIENTATION), None)
    )
    out: dict[str, list[tuple[bool, float]]] = {"gb_pin": [], "TRAC-IK": []}
    for _ in range(count):
        qa = sample_postures(target, 1, rng)[0]
        qb = np.clip(qa + rng.uniform(-0.5, 0.5, qa.shape), target.lower, target.upper)
        X = _line(target, target.forward(qa), target.forward(qb), rot, 50)
        sol = solve(target, X, seed=qa, follow=True, **settings)
        solved = np.where(sol.success[:, None], sol.postures, np.nan)  # as TRAC-IK's: failed points left out
        out["gb_pin"].append((bool(sol.success.all()), _largest_step(solved)))
        if tracik is not None and rot is not None:
            poses = [_pose(target, x, rot) for x in X]
            Q = tracik.follow(poses, qa)
            out["TRAC-IK"].append((bool(np.all(np.isfinite(Q))), _largest_step(Q)))
    return {
        k: (float(np.mean([a for a, _ in v])), float(np.median([b for _, b in v])),
            float(np.max([b for _, b in v])))
        for k, v in out.items() if v
    }  # fmt: skip


def _largest_step(Q: NDArray[np.float64]) -> float:
    """The largest joint change between consecutive solved points (NaN rows: unsolved)."""
    steps = np.abs(np.diff(Q, axis=0))
    steps = steps[np.all(np.isfinite(steps), axis=1)]
    return float(steps.max()) if steps.size else 0.0


def _rotation(target: KinematicTarget, x: NDArray[np.float64], c: int) -> NDArray[np.float64]:
    comps = target.chain.components
    assert comps is not None
    phi = x[comps.rows(c)] / comps.scales[c]
    return comps.references[c] @ np.array(exp3(*phi)).reshape(3, 3)


def _pose(
    target: KinematicTarget, x: NDArray[np.float64], c: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(position, rotation) of a pose task vector (position rows first)."""
    return x[:3].copy(), _rotation(target, x, c)


def _line(target: KinematicTarget, a: NDArray[np.float64], b: NDArray[np.float64], c: int | None,
          steps: int) -> NDArray[np.float64]:  # fmt: skip
    """Task vectors from ``a`` to ``b``: positions linear, the orientation along the geodesic (slerp)."""
    t = np.linspace(0.0, 1.0, steps)[:, None]
    X = a + t * (b - a)
    if c is not None:
        comps = target.chain.components
        assert comps is not None
        Ra, Rb = _rotation(target, a, c), _rotation(target, b, c)
        M = Ra.T @ Rb
        w = np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]]) / 2
        angle = np.arctan2(np.linalg.norm(w), (np.trace(M) - 1) / 2)
        axis = w / max(float(np.linalg.norm(w)), 1e-300)
        for r in range(steps):
            R = Ra @ np.array(exp3(*(axis * angle * t[r, 0]))).reshape(3, 3)
            E = comps.references[c].T @ R
            X[r, comps.rows(c)] = comps.scales[c] * _log(E)
    return X


def _log(E: NDArray[np.float64]) -> NDArray[np.float64]:
    x, y, z, _ = log3(np.ascontiguousarray(E))
    return np.array([x, y, z])
