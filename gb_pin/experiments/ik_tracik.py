"""TRAC-IK (the ``pytracik`` wheel: KDL + NLopt) on the same chain, for the protocol's side-by-side table.

Optional: ``pip install 'gb_pin[bench]'``. KDL reads example-robot-data's Panda joint limits as
zero, so the limits are always passed explicitly (continuous joints: home +/- pi, gb_pin's
restart range). Its targets come from its own forward kinematics of the same postures, so
that both solvers are asked the same poses in their own frames (the two agree to ~1e-15 m,
checked by :func:`check_same_chain`). TRAC-IK solves 6-D poses only here: the binding does not
expose its per-axis tolerances (free orientation), so position-only and pointing rows have none.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import GbPinError

__all__ = ["TracIK", "available", "check_same_chain"]


def available() -> bool:
    """Whether ``pytracik`` can be imported."""
    try:
        import pytracik  # type: ignore[import-not-found, import-untyped, unused-ignore]  # noqa: F401
    except ImportError:
        return False
    return True


def _quaternion(R: NDArray[np.float64]) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation matrix (Shepperd's method)."""
    t = R[0, 0] + R[1, 1] + R[2, 2]
    if t > 0.0:
        s = 2.0 * np.sqrt(t + 1.0)
        return (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, 0.25 * s
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
    q = np.empty(4)
    q[i] = 0.25 * s
    q[j] = (R[j, i] + R[i, j]) / s
    q[k] = (R[k, i] + R[i, k]) / s
    q[3] = (R[k, j] - R[j, k]) / s
    return float(q[0]), float(q[1]), float(q[2]), float(q[3])


class TracIK:
    """One TRAC-IK solver (Speed mode) on ``base`` -> ``tip`` of a URDF, limits given explicitly.

    Args:
        urdf: path of the URDF file.
        base: the chain's base link.
        tip: the chain's tip link.
        lower: (m,) lower limits [rad] (finite).
        upper: (m,) upper limits [rad] (finite).
        timeout: seconds per solve (TRAC-IK's own budget: wall-clock time).
        eps: tolerance of the Cartesian error (m and rad).
        cpu: time each solve by the CPU time it used (both of its threads; gb_pin's ``clock="cpu"``
            is one thread's), not wall time.

    Raises:
        GbPinError: pytracik missing, or a chain of another length than the limits.
    """

    def __init__(
        self,
        urdf: str,
        base: str,
        tip: str,
        lower: NDArray[np.float64],
        upper: NDArray[np.float64],
        timeout: float,
        eps: float,
        cpu: bool = False,
    ) -> None:
        try:
            import pytracik  # type: ignore[import-not-found, import-untyped, unused-ignore]
        except ImportError as exc:
            raise GbPinError("TRAC-IK needs pytracik: pip install 'gb_pin[bench]'") from exc
        with open(urdf, encoding="utf-8") as f:
            text = f.read()
        self._lib: Any = pytracik
        # TRAC-IK solves in two threads (KDL and NLopt, in parallel): its CPU time is the process's
        self._clock = time.process_time if cpu else time.perf_counter
        self._solver = pytracik.TRAC_IK(base, tip, text, float(timeout), float(eps), pytracik.SolveType.Speed)
        if pytracik.get_num_joints(self._solver) != len(lower):
            raise GbPinError(
                f"TRAC-IK's chain {base} -> {tip} has {pytracik.get_num_joints(self._solver)} joints, "
                f"gb_pin's {len(lower)}"
            )
        pytracik.set_joint_limits(self._solver, [float(v) for v in lower], [float(v) for v in upper])

    def forward(self, q: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(position (3,) [m], rotation (3, 3)) of the tip at ``q``."""
        T = np.asarray(self._lib.fk(self._solver, np.ascontiguousarray(q, dtype=np.float64)))
        return T[:3, 3].copy(), T[:3, :3].copy()

    def solve(
        self, Q: NDArray[np.float64], seed: NDArray[np.float64]
    ) -> tuple[NDArray[np.bool_], NDArray[np.float64], NDArray[np.float64]]:
        """Solve the poses of postures ``Q`` (N, m) from ``seed`` (m,): (success, seconds, postures)."""
        N, m = Q.shape
        ok, seconds, out = np.zeros(N, bool), np.zeros(N), np.full((N, m), np.nan)
        seed = np.ascontiguousarray(seed, dtype=np.float64)
        for r in range(N):
            p, R = self.forward(Q[r])
            qx, qy, qz, qw = _quaternion(R)
            start = self._clock()
            answer = self._lib.ik(self._solver, seed, p[0], p[1], p[2], qx, qy, qz, qw)
            seconds[r] = self._clock() - start
            ok[r] = answer[0] >= 0
            if ok[r]:
                out[r] = answer[1:]
        return ok, seconds, out

    def follow(
        self, poses: list[tuple[NDArray[np.float64], NDArray[np.float64]]], seed: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """A path through ``poses`` (position, rotation), each from the previous solution (NaN: none)."""
        out = np.full((len(poses), seed.shape[0]), np.nan)
        q = np.ascontiguousarray(seed, dtype=np.float64)
        for r, (p, R) in enumerate(poses):
            qx, qy, qz, qw = _quaternion(R)
            answer = self._lib.ik(self._solver, q, p[0], p[1], p[2], qx, qy, qz, qw)
            if answer[0] >= 0:
                q = np.ascontiguousarray(answer[1:], dtype=np.float64)
                out[r] = q
        return out


def check_same_chain(tracik: TracIK, forward: Any, Q: NDArray[np.float64]) -> float:
    """The largest distance [m] between TRAC-IK's and gb_pin's tip positions at postures ``Q``."""
    gap = 0.0
    for q in Q:
        gap = max(gap, float(np.linalg.norm(tracik.forward(q)[0] - forward(q))))
    return gap
