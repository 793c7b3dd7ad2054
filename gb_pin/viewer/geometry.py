"""Plain geometry of the scene: homogeneous transforms, quaternions, target grids, spread-out picks.

numpy only; nothing here knows meshcat or pinocchio.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

Transforms = list[tuple[str, NDArray[np.float64]]]
"""(meshcat path, 4x4 world transform) of the moving nodes of a figure."""


def translation(p: ArrayLike) -> NDArray[np.float64]:
    """Homogeneous transform of a pure translation."""
    T = np.eye(4)
    T[:3, 3] = np.asarray(p, dtype=float)
    return T


def align_y(direction: ArrayLike) -> NDArray[np.float64]:
    """Rotation taking the y-axis (meshcat's cylinder axis) onto ``direction``."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    y = np.array([0.0, 1.0, 0.0])
    v = np.cross(y, d)
    c = float(np.dot(y, d))
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])
    vx = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def quaternions(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """Unit quaternions (x, y, z, w) (three.js order) of rotation matrices (..., 3, 3), sign-continuous."""
    m = np.asarray(R, dtype=float)
    tr = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    q = np.empty((*m.shape[:-2], 4))
    # Shepperd's method: take the largest of w, x, y, z as pivot for accuracy.
    cand = np.stack([tr, m[..., 0, 0], m[..., 1, 1], m[..., 2, 2]], axis=-1)
    pivot = np.argmax(cand, axis=-1)
    for k in range(4):
        sel = pivot == k
        if not np.any(sel):
            continue
        a = m[sel]
        if k == 0:
            s = np.sqrt(1.0 + a[:, 0, 0] + a[:, 1, 1] + a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 2, 1] - a[:, 1, 2]) / s,
                    (a[:, 0, 2] - a[:, 2, 0]) / s,
                    (a[:, 1, 0] - a[:, 0, 1]) / s,
                    s / 4,
                ],
                axis=-1,
            )
        elif k == 1:
            s = np.sqrt(1.0 + a[:, 0, 0] - a[:, 1, 1] - a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    s / 4,
                    (a[:, 0, 1] + a[:, 1, 0]) / s,
                    (a[:, 0, 2] + a[:, 2, 0]) / s,
                    (a[:, 2, 1] - a[:, 1, 2]) / s,
                ],
                axis=-1,
            )
        elif k == 2:
            s = np.sqrt(1.0 + a[:, 1, 1] - a[:, 0, 0] - a[:, 2, 2]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 0, 1] + a[:, 1, 0]) / s,
                    s / 4,
                    (a[:, 1, 2] + a[:, 2, 1]) / s,
                    (a[:, 0, 2] - a[:, 2, 0]) / s,
                ],
                axis=-1,
            )
        else:
            s = np.sqrt(1.0 + a[:, 2, 2] - a[:, 0, 0] - a[:, 1, 1]) * 2.0
            q[sel] = np.stack(
                [
                    (a[:, 0, 2] + a[:, 2, 0]) / s,
                    (a[:, 1, 2] + a[:, 2, 1]) / s,
                    s / 4,
                    (a[:, 1, 0] - a[:, 0, 1]) / s,
                ],
                axis=-1,
            )
    if q.ndim == 2 and q.shape[0] > 1:
        # q and -q are the same rotation; keep neighbours in one hemisphere so keyframes interpolate short.
        flips = np.cumsum(np.einsum("ij,ij->i", q[1:], q[:-1]) < 0.0) % 2
        q[1:][flips == 1] *= -1.0
    return q


def grid_shape(X: NDArray[np.float64]) -> tuple[int, ...] | None:
    """The shape of ``X`` if it is a regular grid listed first axis slowest (as in presets), else None."""
    N, n = X.shape
    axes = [np.unique(np.round(X[:, a], 9)) for a in range(n)]
    shape = tuple(len(u) for u in axes)
    if math.prod(shape) != N or N < 2:
        return None
    mesh = np.meshgrid(*axes, indexing="ij")
    grid = np.stack([g.ravel() for g in mesh], axis=1)
    return shape if np.allclose(grid, X, atol=1e-8) else None


def grid_step(X: NDArray[np.float64]) -> float:
    """The smallest step of ``X`` (N, d) along an axis if it is a regular grid [m]; inf otherwise."""
    X = np.atleast_2d(np.asarray(X, dtype=float))
    shape = grid_shape(X)
    if shape is None:
        return math.inf
    steps = [np.ptp(X[:, a]) / (k - 1) for a, k in enumerate(shape) if k > 1 and np.ptp(X[:, a]) > 0]
    return float(min(steps)) if steps else math.inf


def grid_edges(shape: tuple[int, ...]) -> NDArray[np.int64]:
    """(E, 2) index pairs of neighbouring grid points."""
    idx = np.arange(math.prod(shape)).reshape(shape)
    pairs = []
    for a in range(len(shape)):
        if shape[a] < 2:
            continue
        lo = np.take(idx, np.arange(shape[a] - 1), axis=a).ravel()
        hi = np.take(idx, np.arange(1, shape[a]), axis=a).ravel()
        pairs.append(np.stack([lo, hi], axis=1))
    return np.concatenate(pairs) if pairs else np.zeros((0, 2), dtype=np.int64)


def spread_indices(X: NDArray[np.float64], k: int) -> list[int]:
    """``k`` indices of points spread over ``X``: the one nearest the centroid, then farthest-point picks."""
    k = min(k, X.shape[0])
    chosen = [int(np.argmin(np.linalg.norm(X - X.mean(axis=0), axis=1)))]
    dist = np.linalg.norm(X - X[chosen[0]], axis=1)
    while len(chosen) < k:
        nxt = int(np.argmax(dist))
        chosen.append(nxt)
        dist = np.minimum(dist, np.linalg.norm(X - X[nxt], axis=1))
    return chosen
