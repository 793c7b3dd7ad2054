"""Local-linear map (paper Sec. II-C) with scikit-learn conventions: the inverse estimate g.

    g(x) = sum_k beta_k(x) (W_k u_k + o_k),   u_k = (x - p_k) / d,
    beta_k(x) = b(u_k) / sum_j b(u_j),         b(u) = exp(-||u||^2).

With a ``cutoff`` c (not the paper's; None by default) the sums run over the prototypes with
||u_k||^2 <= min_j ||u_j||^2 + c^2 only: each one left out weighs less than exp(-c^2) of the nearest.
The compiled kernels and the conventions where the paper is silent are in
:mod:`gb_pin.learn.llm_kernels`; this class owns the preallocated storage.
"""

from __future__ import annotations

import os
import warnings
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import ExtrapolationWarning, InvalidArgumentError, NotFittedError
from gb_pin.learn.llm_kernels import (
    MapArrays,
    Scratch,
    TruncatedMapArrays,
    llm_jacobian,
    llm_learn,
    llm_predict_many,
)
from gb_pin.learn.llm_simd import LANES


def _row(capacity: int) -> int:
    """Length of the entry-major rows for ``capacity`` prototypes: whole cache lines, and one more.

    Capacities double, so rows of exactly ``capacity`` doubles could lie a power of two apart,
    where the rows one loop streams (centres, scaled inputs) compete for the same cache sets
    (measured when the matrices were stored in such rows too: a third slower at 1024 than at
    1032). Whole cache lines (eight doubles) keep every row aligned as its array is
    (:func:`_zeros`).
    """
    return 8 * -(-capacity // 8) + 8


MAX_CUTOFF = 26.0
"""The largest cutoff c [radii]: exp(-c^2) is then below what the map's exponential resolves."""


def cutoff_squared(cutoff: float | None) -> float:
    """c^2 for the kernels (:class:`~gb_pin.learn.llm_kernels.MapArrays`): inf for None (no truncation).

    Raises:
        InvalidArgumentError: not a number in (0, :data:`MAX_CUTOFF`].
    """
    if cutoff is None:
        return float("inf")
    c = check.positive_float("cutoff", cutoff)
    if c > MAX_CUTOFF:
        raise InvalidArgumentError(
            f"cutoff is in radii, at most {MAX_CUTOFF:g} (or None: no cutoff), got {cutoff!r}"
        )
    return c * c


def memory_bytes() -> int:
    """The memory this process may use [bytes]: the machine's, or its address-space limit if lower.

    0 where the platform says neither.
    """
    try:
        memory = int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        memory = 0
    try:
        import resource

        limit = resource.getrlimit(resource.RLIMIT_AS)[0]
        if limit != resource.RLIM_INFINITY and limit > 0:
            memory = min(memory, int(limit)) if memory else int(limit)
    except (ImportError, OSError, ValueError):
        pass
    return memory


def _models(capacity: int, n: int, m: int) -> NDArray[np.float64]:
    """Zeroed storage of ``capacity`` local models (MapArrays.models), the ones after o_k set.

    Raises:
        InvalidArgumentError: the storage would exceed half the machine's memory (checked before
            it is allocated: a robot of 10^6 joints asked for 5.9 GiB, 10^4 joints x 1000 axes 19.7).
    """
    shape = (capacity, n + 1, LANES * (m // LANES + 1))
    size = 8 * capacity * (n + 1) * shape[2]
    memory = memory_bytes()
    if memory and size > memory // 2:
        raise InvalidArgumentError(
            f"the map of {capacity} prototypes for {n} task axes and {m} joints needs "
            f"{size / 2**30:.1f} GiB, more than half of the {memory / 2**30:.1f} GiB this process may use: "
            "learn fewer joints or task axes"
        )
    models = _zeros(shape)
    models[:, 0, m] = 1.0
    return models


def _zeros(shape: tuple[int, ...]) -> NDArray[np.float64]:
    """A C-contiguous array of zeros starting on a 64-byte boundary (a cache line, a SIMD register).

    numpy aligns to 16 bytes; the map's passes load and store whole registers of eight doubles,
    and rows that start mid-line split every one of them across two lines (measured: a step
    10-20 % slower).
    """
    size = int(np.prod(shape))
    buffer = np.zeros(size + 8)
    start = (-buffer.ctypes.data // 8) % 8
    return buffer[start : start + size].reshape(shape)


class LocalLinearMap:
    """Local-linear map regressor (paper Sec. II-C) with scikit-learn conventions.

    Args:
        radius: radius d of the prototypes' Gaussian responsibilities [m].
        learning_rate: eta of the online gradient descent.
        cutoff: c [radii]: prototypes whose activation is below exp(-c^2) of the nearest one's
            are left out of g(x), its Jacobian and the update (``||u_k||^2 > min_j ||u_j||^2 +
            c^2``); None: every prototype (the paper's sums).

    Attributes:
        prototypes_: (K, n) prototype centres p_k [m].
        matrices_: (K, m, n) local matrices W_k (acting on the scaled input).
        offsets_: (K, m) local offsets o_k.
        n_prototypes_: K.
    """

    ARRAY_NAMES = ("prototypes", "matrices", "offsets")
    #: :meth:`predict` warns of queries farther than this many radii d from every prototype.
    FAR_RADII = 3.0

    def __init__(self, radius: float = 0.1, learning_rate: float = 0.1, cutoff: float | None = None) -> None:
        self.radius = radius
        self.learning_rate = learning_rate
        self.cutoff = cutoff

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """The hyperparameters (scikit-learn convention)."""
        return {"radius": self.radius, "learning_rate": self.learning_rate, "cutoff": self.cutoff}

    # -- initialisation and storage -------------------------------------------
    def initialize(self, x0: ArrayLike, q0: ArrayLike, capacity: int = 256) -> LocalLinearMap:
        """Start with one prototype at ``x0`` whose output is the constant ``q0`` (W = 0).

        This is the paper's initial estimate g(x, theta_0) = q_home with p_1 = f(q_home).
        """
        radius = check.positive_float("radius", self.radius)
        check.positive_float("learning_rate", self.learning_rate)
        self._cutoff_sq = cutoff_squared(self.cutoff)
        x0 = check.vector("x0", x0, np.size(x0))
        q0 = check.vector("q0", q0, np.size(q0))
        if x0.size == 0 or q0.size == 0:
            raise InvalidArgumentError(
                f"x0 and q0 must be non-empty vectors, got shapes {x0.shape}, {q0.shape}"
            )
        n, m = x0.shape[0], q0.shape[0]
        capacity = max(int(capacity), 1)
        # Storage as the kernels take it (MapArrays): P[j, k] = (p_k)_j, contiguous over the
        # prototypes; M[k, 0, i] = (o_k)_i, M[k, 1 + j, i] = (W_k)_ij, M[k, 0, m] = 1.
        self._m = m
        self._P = _zeros((n, _row(capacity)))
        self._M = _models(_row(capacity), n, m)
        self._P[:, 0] = x0
        self._M[0, 0, :m] = q0
        self._K = 1
        self._radius = radius
        self._allocate_scratch()
        return self

    def _allocate_scratch(self) -> None:
        n, row = self._P.shape
        m = self._m
        self._U = _zeros((n + 1, row))
        self._act = _zeros((row,))
        self._near = np.zeros(row + 1, dtype=np.int64)
        self._e = _zeros((self._M.shape[2],))
        self._g = np.empty(m)
        self._y = np.empty(m)
        self._J = np.empty((m, n))

    def reserve(self, capacity: int) -> None:
        """Grow the preallocated storage to hold at least ``capacity`` prototypes."""
        if capacity <= self._P.shape[1]:
            return
        new = max(capacity, 2 * self._P.shape[1])
        K = self._K
        P = _zeros((self._P.shape[0], _row(new)))
        P[:, :K] = self._P[:, :K]
        M = _models(_row(new), P.shape[0], self._m)
        M[:K] = self._M[:K]
        self._P, self._M = P, M
        self._allocate_scratch()

    def kernel(self) -> MapArrays:
        """The storage and scratch buffers as the compiled kernels take them."""
        self._check_fitted()
        if self._cutoff_sq == float("inf"):
            return MapArrays(self._P, self._M, self._radius, self._act, self._U, self._e)
        return TruncatedMapArrays(  # type: ignore[return-value]  # the same storage and its list
            self._P, self._M, self._radius, self._act, self._U, self._e, self._cutoff_sq, self._near
        )

    def scratch(self) -> Scratch:
        """The buffers of learning steps and Jacobians."""
        self._check_fitted()
        return Scratch(self._g, self._y, self._J)

    @property
    def capacity(self) -> int:
        """Prototypes the storage holds before it must grow."""
        self._check_fitted()
        return int(self._P.shape[1])

    def set_count(self, K: int) -> None:
        """Record that the compiled kernels now use ``K`` prototypes of the storage."""
        if not 1 <= K <= self._P.shape[1]:
            raise InvalidArgumentError(f"prototype count {K} outside 1..{self._P.shape[1]}")
        self._K = int(K)

    def to_arrays(self) -> dict[str, NDArray[np.float64]]:
        """The learned map as ``prototypes`` (K, n), ``matrices`` (K, m, n), ``offsets`` (K, m) (copies)."""
        return {
            "prototypes": np.array(self.prototypes_, order="C"),
            "matrices": np.array(self.matrices_, order="C"),
            "offsets": np.array(self.offsets_, order="C"),
        }

    @classmethod
    def from_arrays(
        cls,
        arrays: dict[str, Any],
        radius: float,
        learning_rate: float = 0.1,
        capacity: int | None = None,
        cutoff: float | None = None,
    ) -> LocalLinearMap:
        """The map stored by :meth:`to_arrays`, exactly (same numbers, same predictions).

        Args:
            arrays: ``prototypes``, ``matrices`` and ``offsets``.
            radius: d [m].
            learning_rate: eta for further :meth:`partial_fit` calls.
            capacity: storage to preallocate (default: the prototypes' count).
            cutoff: c [radii] of the truncated sums (None: every prototype).

        Raises:
            InvalidArgumentError: missing, non-finite or inconsistent arrays.
        """
        try:
            P, W, O = (np.asarray(arrays[k]) for k in cls.ARRAY_NAMES)
        except KeyError as exc:
            raise InvalidArgumentError(f"local-linear map incomplete (missing {exc})") from exc
        if not all(a.dtype.kind in "fiu" for a in (P, W, O)):
            raise InvalidArgumentError(f"model arrays of dtypes {P.dtype}, {W.dtype}, {O.dtype}, not real")
        K = P.shape[0] if P.ndim == 2 else 0
        n = P.shape[1] if P.ndim == 2 else 0
        m = O.shape[1] if O.ndim == 2 else 0
        if K < 1 or n < 1 or m < 1 or W.shape != (K, m, n) or O.shape != (K, m):
            raise InvalidArgumentError(f"model arrays of inconsistent shapes {P.shape}, {W.shape}, {O.shape}")
        if not all(np.all(np.isfinite(a)) for a in (P, W, O)):
            raise InvalidArgumentError("model arrays are not finite")
        lm = cls(radius=radius, learning_rate=learning_rate, cutoff=cutoff)
        lm.initialize(P[0], O[0], capacity=max(K, capacity or K))
        lm._P[:, :K] = P.T
        lm._M[:K, 1:, :m] = np.transpose(W, (0, 2, 1))
        lm._M[:K, 0, :m] = O
        lm._K = K
        return lm

    def _check_fitted(self) -> None:
        if not hasattr(self, "_K"):
            raise NotFittedError("this LocalLinearMap is not initialised: call initialize(x0, q0) first")

    @property
    def n_prototypes_(self) -> int:
        """Number of prototypes K."""
        self._check_fitted()
        return int(self._K)

    @property
    def prototypes_(self) -> NDArray[np.float64]:
        """(K, n) prototype centres [m] (a view of the storage)."""
        self._check_fitted()
        return self._P[:, : self._K].T

    @property
    def matrices_(self) -> NDArray[np.float64]:
        """(K, m, n) local matrices W_k, acting on (x - p_k) / d (a view of the storage)."""
        self._check_fitted()
        return np.transpose(self._M[: self._K, 1:, : self._m], (0, 2, 1))

    @property
    def offsets_(self) -> NDArray[np.float64]:
        """(K, m) local offsets o_k (a view of the storage)."""
        self._check_fitted()
        return self._M[: self._K, 0, : self._m]

    @property
    def n_inputs_(self) -> int:
        """Input (task) dimension n."""
        self._check_fitted()
        return int(self._P.shape[0])

    @property
    def n_outputs_(self) -> int:
        """Output (posture) dimension m."""
        self._check_fitted()
        return int(self._m)

    # -- scikit-learn style interface -------------------------------------------
    def predict(self, X: ArrayLike, *, warn: bool = True) -> NDArray[np.float64]:
        """g(x) for (N, n) inputs -> (N, m); a single (n,) input gives (m,).

        Args:
            X: inputs (effector positions) [m], (N, n) or (n,).
            warn: warn (:class:`~gb_pin.exceptions.ExtrapolationWarning`) of inputs farther than
                ``FAR_RADII`` radii d from every prototype, where the map only extrapolates; the
                learner's own evaluations pass False.
        """
        self._check_fitted()
        pts = check.points("X", X, self.n_inputs_, allow_single=True)
        single = np.ndim(X) == 1
        out = np.empty((pts.shape[0], self.n_outputs_))
        nearest = np.empty(pts.shape[0])  # min_k ||x - p_k||^2 / d^2, from the prediction itself
        llm_predict_many(pts, self.kernel(), self._K, out, nearest)
        if warn:
            self._warn_far(pts, nearest)
        bad = np.flatnonzero(~np.all(np.isfinite(out), axis=1))
        if bad.size:
            raise InvalidArgumentError(
                f"X rows {bad[:5].tolist()} (e.g. {pts[bad[0]].tolist()}) lie so far from the learned "
                "region that the linear extrapolation overflows; give inputs near the targets"
            )
        return out[0] if single else out

    def _warn_far(self, pts: NDArray[np.float64], nearest_sq: NDArray[np.float64]) -> None:
        """An ExtrapolationWarning naming the farthest of ``pts`` outside the learned region, if any.

        ``nearest_sq``: (N,) min_k ||x - p_k||^2 / d^2 of each input (computed by the prediction).
        """
        far = np.flatnonzero(nearest_sq > self.FAR_RADII**2)
        if far.size:
            nearest = np.sqrt(nearest_sq) * self._radius
            worst = far[np.argmax(nearest[far])]
            warnings.warn(
                f"{far.size} of {pts.shape[0]} inputs lie more than {self.FAR_RADII:g} radii "
                f"(d = {self._radius:g} m) from every prototype, e.g. X row {int(worst)} = "
                f"{pts[worst].tolist()} is {nearest[worst]:.3g} m from the nearest: the map only "
                "extrapolates there and may be far off (query inside the learned region, near the targets)",
                ExtrapolationWarning,
                stacklevel=3,
            )

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """dg/dx at one input (n,) -> (m, n), derivative of the responsibilities included."""
        self._check_fitted()
        xv = check.vector("x", x, self.n_inputs_)
        llm_jacobian(xv, self.kernel(), self._K, self.scratch())
        return self._J.copy()

    def partial_fit(
        self, X: ArrayLike, y: ArrayLike, sample_weight: ArrayLike | None = None
    ) -> LocalLinearMap:
        """One online gradient step per example, in order (prototypes inserted as needed).

        Args:
            X: (N, n) inputs (effector positions) [m].
            y: (N, m) targets (postures).
            sample_weight: (N,) weights w >= 0; default 1.
        """
        self._check_fitted()
        eta = check.positive_float("learning_rate", self.learning_rate)
        pts = check.points("X", X, self.n_inputs_)
        Q = check.points("y", y, self.n_outputs_)
        if Q.shape[0] != pts.shape[0]:
            raise InvalidArgumentError(f"X and y must have as many rows, got {pts.shape[0]} and {Q.shape[0]}")
        w = np.ones(pts.shape[0]) if sample_weight is None else np.asarray(sample_weight, dtype=float)
        if w.shape != (pts.shape[0],) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InvalidArgumentError(
                f"sample_weight must be {pts.shape[0]} finite numbers >= 0, got {sample_weight!r}"
            )
        for r in range(pts.shape[0]):
            self.reserve(self._K + 1)
            self._K = llm_learn(pts[r], Q[r], float(w[r]), eta, self.kernel(), self._K, self.scratch())
        return self
