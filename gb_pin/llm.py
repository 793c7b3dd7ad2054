"""Local-linear map (paper Sec. II-C): the inverse estimate g(x) and its online learning.

    g(x) = sum_k beta_k(x) (W_k u_k + o_k),   u_k = (x - p_k) / d,
    beta_k(x) = b(u_k) / sum_j b(u_j),         b(u) = exp(-||u||^2).

Conventions (the paper is silent; these reproduce its numbers):

* W_k acts on the scaled input u_k, so a new prototype gets W = d * dg/dx.
* The gradient of w ||q - g(x)||^2 is taken with its factor 2 folded into the
  learning rate: o_k += eta w beta_k (q - g(x)) and W_k += eta w beta_k (q - g(x)) u_k^T.
* Responsibilities are computed as exp(-(||u_k||^2 - min_j ||u_j||^2)) before
  normalising, which is the same soft-max but never underflows far from all prototypes.

The compiled kernels work on preallocated arrays (prototypes P (K, n), matrices
W (K, m, n), offsets O (K, m)) and scratch buffers: no allocation per step.
:class:`LocalLinearMap` wraps them with a scikit-learn style interface.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, NotFittedError


@njit(cache=True, nogil=True, error_model="numpy")
def llm_predict(x, P, W, O, K, radius, act, out):  # type: ignore[no-untyped-def]
    """g(x) into ``out`` (m,); returns (sum of activations, min ||u_k||^2).

    ``act`` (>= K,) receives the shifted activations exp(-(||u_k||^2 - min)).
    """
    n = x.shape[0]
    m = out.shape[0]
    inv = 1.0 / radius
    smallest = np.inf
    for k in range(K):
        s = 0.0
        for j in range(n):
            u = (x[j] - P[k, j]) * inv
            s += u * u
        act[k] = s
        if s < smallest:
            smallest = s
    total = 0.0
    for i in range(m):
        out[i] = 0.0
    for k in range(K):
        a = math.exp(smallest - act[k])
        act[k] = a
        total += a
        for i in range(m):
            y = O[k, i]
            for j in range(n):
                y += W[k, i, j] * ((x[j] - P[k, j]) * inv)
            out[i] += a * y
    for i in range(m):
        out[i] /= total
    return total, smallest


@njit(cache=True, nogil=True, error_model="numpy")
def llm_jacobian(x, P, W, O, K, radius, act, g, y, J):  # type: ignore[no-untyped-def]
    """dg/dx into ``J`` (m, n) and g(x) into ``g`` (m,), responsibilities' derivative included.

    With beta_k' = -(2/d) beta_k (u_k - sum_j beta_j u_j):
    J = (1/d) sum_k beta_k [W_k - 2 (y_k - g) u_k^T],  y_k = W_k u_k + o_k.
    """
    n = x.shape[0]
    m = g.shape[0]
    inv = 1.0 / radius
    total, _ = llm_predict(x, P, W, O, K, radius, act, g)
    for i in range(m):
        for j in range(n):
            J[i, j] = 0.0
    for k in range(K):
        beta = act[k] / total
        for i in range(m):
            yi = O[k, i]
            for j in range(n):
                yi += W[k, i, j] * ((x[j] - P[k, j]) * inv)
            y[i] = yi
        for i in range(m):
            r = 2.0 * (y[i] - g[i])
            for j in range(n):
                J[i, j] += beta * (W[k, i, j] - r * ((x[j] - P[k, j]) * inv))
    for i in range(m):
        for j in range(n):
            J[i, j] *= inv


@njit(cache=True, nogil=True, error_model="numpy")
def llm_insert(x, P, W, O, K, radius, act, g, y, J):  # type: ignore[no-untyped-def]
    """Add prototype K at ``x`` with o = g(x) and W = d * dg/dx, so g and dg/dx stay unchanged.

    The caller guarantees capacity (P.shape[0] > K). Returns the new count K + 1.
    """
    llm_jacobian(x, P, W, O, K, radius, act, g, y, J)
    n = x.shape[0]
    m = g.shape[0]
    for j in range(n):
        P[K, j] = x[j]
    for i in range(m):
        O[K, i] = g[i]
        for j in range(n):
            W[K, i, j] = radius * J[i, j]
    return K + 1


@njit(cache=True, nogil=True, error_model="numpy")
def llm_learn(x, q, w, eta, P, W, O, K, radius, act, g, y, J):  # type: ignore[no-untyped-def]
    """One online step on the example (x, q) with weight w; returns the new prototype count.

    Inserts a prototype first if ``x`` is at distance >= d from all prototypes,
    then descends the gradient of w ||q - g(x)||^2 (factor 2 folded into eta):
    o_k += eta w beta_k e,  W_k += eta w beta_k e u_k^T,  e = q - g(x).
    """
    n = x.shape[0]
    m = q.shape[0]
    inv = 1.0 / radius
    total, smallest = llm_predict(x, P, W, O, K, radius, act, g)
    if smallest >= 1.0:
        K = llm_insert(x, P, W, O, K, radius, act, g, y, J)
        total, smallest = llm_predict(x, P, W, O, K, radius, act, g)
    if w == 0.0:
        return K
    for i in range(m):
        y[i] = q[i] - g[i]  # the error e, kept in y
    scale = eta * w / total
    for k in range(K):
        c = scale * act[k]
        for i in range(m):
            ce = c * y[i]
            O[k, i] += ce
            for j in range(n):
                W[k, i, j] += ce * ((x[j] - P[k, j]) * inv)
    return K


@njit(cache=True, nogil=True, error_model="numpy")
def llm_predict_many(X, P, W, O, K, radius, act, out):  # type: ignore[no-untyped-def]
    """g(x) for every row of X (N, n) into out (N, m)."""
    for r in range(X.shape[0]):
        llm_predict(X[r], P, W, O, K, radius, act, out[r])


class LocalLinearMap:
    """Local-linear map regressor (paper Sec. II-C) with scikit-learn conventions.

    Args:
        radius: radius d of the prototypes' Gaussian responsibilities [m].
        learning_rate: eta of the online gradient descent.

    Attributes:
        prototypes_: (K, n) prototype centres p_k [m].
        matrices_: (K, m, n) local matrices W_k (acting on the scaled input).
        offsets_: (K, m) local offsets o_k.
        n_prototypes_: K.
    """

    def __init__(self, radius: float = 0.1, learning_rate: float = 0.1) -> None:
        self.radius = radius
        self.learning_rate = learning_rate

    # -- initialisation and storage -------------------------------------------
    def initialize(self, x0: ArrayLike, q0: ArrayLike, capacity: int = 256) -> LocalLinearMap:
        """Start with one prototype at ``x0`` whose output is the constant ``q0`` (W = 0).

        This is the paper's initial estimate g(x, theta_0) = q_home with p_1 = f(q_home).
        """
        radius = check.positive_float("radius", self.radius)
        check.positive_float("learning_rate", self.learning_rate)
        x0 = check.vector("x0", x0, np.size(x0))
        q0 = check.vector("q0", q0, np.size(q0))
        if x0.size == 0 or q0.size == 0:
            raise InvalidArgumentError(
                f"x0 and q0 must be non-empty vectors, got shapes {x0.shape}, {q0.shape}"
            )
        n, m = x0.shape[0], q0.shape[0]
        capacity = max(int(capacity), 1)
        self._P = np.zeros((capacity, n))
        self._W = np.zeros((capacity, m, n))
        self._O = np.zeros((capacity, m))
        self._P[0] = x0
        self._O[0] = q0
        self._K = 1
        self._radius = radius
        self._allocate_scratch()
        return self

    def _allocate_scratch(self) -> None:
        m, n = self._O.shape[1], self._P.shape[1]
        self._act = np.empty(self._P.shape[0])
        self._g = np.empty(m)
        self._y = np.empty(m)
        self._J = np.empty((m, n))

    def reserve(self, capacity: int) -> None:
        """Grow the preallocated storage to hold at least ``capacity`` prototypes."""
        if capacity <= self._P.shape[0]:
            return
        new = max(capacity, 2 * self._P.shape[0])
        for name in ("_P", "_W", "_O"):
            old = getattr(self, name)
            grown = np.zeros((new, *old.shape[1:]))
            grown[: self._K] = old[: self._K]
            setattr(self, name, grown)
        self._allocate_scratch()

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
        """(K, n) prototype centres [m]."""
        self._check_fitted()
        return self._P[: self._K]

    @property
    def matrices_(self) -> NDArray[np.float64]:
        """(K, m, n) local matrices W_k, acting on (x - p_k) / d."""
        self._check_fitted()
        return self._W[: self._K]

    @property
    def offsets_(self) -> NDArray[np.float64]:
        """(K, m) local offsets o_k."""
        self._check_fitted()
        return self._O[: self._K]

    @property
    def n_inputs_(self) -> int:
        """Input (task) dimension n."""
        self._check_fitted()
        return int(self._P.shape[1])

    @property
    def n_outputs_(self) -> int:
        """Output (posture) dimension m."""
        self._check_fitted()
        return int(self._O.shape[1])

    # -- scikit-learn style interface -------------------------------------------
    def predict(self, X: ArrayLike) -> NDArray[np.float64]:
        """g(x) for (N, n) inputs -> (N, m); a single (n,) input gives (m,)."""
        self._check_fitted()
        pts = check.points("X", X, self.n_inputs_, allow_single=True)
        single = np.ndim(X) == 1
        out = np.empty((pts.shape[0], self.n_outputs_))
        llm_predict_many(pts, self._P, self._W, self._O, self._K, self._radius, self._act, out)
        bad = np.flatnonzero(~np.all(np.isfinite(out), axis=1))
        if bad.size:
            raise InvalidArgumentError(
                f"X rows {bad[:5].tolist()} (e.g. {pts[bad[0]].tolist()}) lie so far from the learned "
                "region that the linear extrapolation overflows; give inputs near the targets"
            )
        return out[0] if single else out

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """dg/dx at one input (n,) -> (m, n), derivative of the responsibilities included."""
        self._check_fitted()
        xv = check.vector("x", x, self.n_inputs_)
        J = np.empty((self.n_outputs_, self.n_inputs_))
        g = np.empty(self.n_outputs_)
        llm_jacobian(xv, self._P, self._W, self._O, self._K, self._radius, self._act, g, self._y, J)
        return J

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
            self._K = llm_learn(
                pts[r], Q[r], float(w[r]), eta, self._P, self._W, self._O, self._K,
                self._radius, self._act, self._g, self._y, self._J,
            )  # fmt: skip
        return self
