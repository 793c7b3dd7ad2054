"""Local-linear map (paper Sec. II-C): the inverse estimate g(x) and its online learning.

    g(x) = sum_k beta_k(x) (W_k u_k + o_k),   u_k = (x - p_k) / d,
    beta_k(x) = b(u_k) / sum_j b(u_j),         b(u) = exp(-||u||^2).

Conventions (the paper is silent; these reproduce its numbers):

* W_k acts on the scaled input u_k, so a new prototype gets W = d * dg/dx.
* The gradient of w ||q - g(x)||^2 is taken with its factor 2 folded into the
  learning rate: o_k += eta w beta_k (q - g(x)) and W_k += eta w beta_k (q - g(x)) u_k^T.
* Responsibilities are computed as exp(-(||u_k||^2 - min_j ||u_j||^2)) before
  normalising, which is the same soft-max but never underflows far from all prototypes.

The compiled kernels work on preallocated arrays (:class:`MapArrays`: prototypes P (K, n),
matrices and offsets stored entry-major, contiguous over the prototypes (:mod:`gb_pin.learn.llm_passes`);
:class:`Scratch` buffers): no allocation per step.
:class:`~gb_pin.learn.llm.LocalLinearMap` wraps them with a scikit-learn style interface.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import njit
from gb_pin.learn.llm_passes import activations, descend, row_sums, scaled_inputs, weighted_outputs


class MapArrays(NamedTuple):
    """A local-linear map's storage, as the compiled kernels take it (what a prediction reads).

    Prototype k's numbers are stored entry-major, contiguous over k, so that the passes over
    the prototypes vectorise (:mod:`gb_pin.learn.llm_passes`); :class:`~gb_pin.learn.llm.LocalLinearMap`
    converts to and from the (K, m, n) layout of its attributes and files.

    Attributes:
        prototypes: (capacity, n) prototype centres p_k [m]; the first K are in use.
        matrix_entries: (m, n, capacity) local matrices, ``matrix_entries[i, j, k]`` = (W_k)_ij
            (W_k acts on (x - p_k) / d).
        offset_entries: (m, capacity) local offsets, ``offset_entries[i, k]`` = (o_k)_i.
        radius: d [m].
        act: (capacity,) scratch: the activations of the last prediction.
        inputs: (n, capacity) scratch: the scaled inputs u_k = (x - p_k) / d of the last prediction.
        outputs: (m, capacity) scratch: the weighted local outputs of the last prediction.
    """

    prototypes: NDArray[np.float64]
    matrix_entries: NDArray[np.float64]
    offset_entries: NDArray[np.float64]
    radius: float
    act: NDArray[np.float64]
    inputs: NDArray[np.float64]
    outputs: NDArray[np.float64]


class Scratch(NamedTuple):
    """Buffers of learning steps and Jacobians (kept apart so that predictions pass less).

    Attributes:
        g: (m,) g(x).
        y: (m,) one local model's output, or the error q - g(x).
        J: (m, n) dg/dx.
    """

    g: NDArray[np.float64]
    y: NDArray[np.float64]
    J: NDArray[np.float64]


@njit(cache=True, nogil=True, error_model="numpy")
def llm_predict(x, lm, K, out):  # type: ignore[no-untyped-def]
    """g(x) into ``out`` (m,); returns (sum of activations, min ||u_k||^2).

    ``lm.act`` (>= K,) receives the shifted activations exp(-(||u_k||^2 - min)) and
    ``lm.inputs`` the scaled inputs u_k.
    """
    nearest = scaled_inputs(x, lm.prototypes, 1.0 / lm.radius, K, lm.inputs, lm.act)
    return _finish_prediction(lm, K, nearest, out), nearest


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _finish_prediction(lm, K, nearest, out):  # type: ignore[no-untyped-def]
    """g into ``out`` from the scaled inputs and squared norms in ``lm``; returns the sum of activations."""
    activations(lm.act, K, nearest)
    weighted_outputs(lm.matrix_entries, lm.offset_entries, lm.inputs, lm.act, K, lm.outputs)
    return row_sums(lm.outputs, lm.act, K, out)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def llm_jacobian(x, lm, K, scratch):  # type: ignore[no-untyped-def]
    """dg/dx into ``scratch.J`` (m, n) and g(x) into ``scratch.g`` (m,), the responsibilities' derivative in.

    With beta_k' = -(2/d) beta_k (u_k - sum_j beta_j u_j):
    J = (1/d) sum_k beta_k [W_k - 2 (y_k - g) u_k^T],  y_k = W_k u_k + o_k.
    """
    W, O, U, act = lm.matrix_entries, lm.offset_entries, lm.inputs, lm.act
    g, y, J = scratch
    n = x.shape[0]
    m = g.shape[0]
    inv = 1.0 / lm.radius
    total, _ = llm_predict(x, lm, K, g)
    for i in range(m):
        for j in range(n):
            J[i, j] = 0.0
    for k in range(K):
        beta = act[k] / total
        for i in range(m):
            yi = O[i, k]
            for j in range(n):
                yi += W[i, j, k] * U[j, k]
            y[i] = yi
        for i in range(m):
            r = 2.0 * (y[i] - g[i])
            for j in range(n):
                J[i, j] += beta * (W[i, j, k] - r * U[j, k])
    for i in range(m):
        for j in range(n):
            J[i, j] *= inv


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def llm_insert(x, lm, K, scratch):  # type: ignore[no-untyped-def]
    """Add prototype K at ``x`` with o = g(x) and W = d * dg/dx, so g and dg/dx stay unchanged.

    The caller guarantees capacity (P.shape[0] > K). Returns the new count K + 1.
    """
    P, W, O, radius = lm.prototypes, lm.matrix_entries, lm.offset_entries, lm.radius
    g, J = scratch.g, scratch.J
    llm_jacobian(x, lm, K, scratch)
    n = x.shape[0]
    m = g.shape[0]
    for j in range(n):
        P[K, j] = x[j]
    for i in range(m):
        O[i, K] = g[i]
        for j in range(n):
            W[i, j, K] = radius * J[i, j]
    return K + 1


@njit(cache=True, nogil=True, error_model="numpy")
def llm_learn(x, q, w, eta, lm, K, scratch):  # type: ignore[no-untyped-def]
    """One online step on the example (x, q) with weight w; returns the new prototype count.

    Inserts a prototype first if ``x`` is at distance >= d from all prototypes,
    then descends the gradient of w ||q - g(x)||^2 (factor 2 folded into eta):
    o_k += eta w beta_k e,  W_k += eta w beta_k e u_k^T,  e = q - g(x).
    With w = 0 only the distances are computed (whether to insert).
    """
    g, e = scratch.g, scratch.y
    m = q.shape[0]
    inv = 1.0 / lm.radius
    nearest = scaled_inputs(x, lm.prototypes, inv, K, lm.inputs, lm.act)
    if nearest >= 1.0:
        K = llm_insert(x, lm, K, scratch)
        nearest = scaled_inputs(x, lm.prototypes, inv, K, lm.inputs, lm.act)
    if w == 0.0:
        return K
    total = _finish_prediction(lm, K, nearest, g)
    for i in range(m):
        e[i] = q[i] - g[i]  # the error e, kept in y
    descend(lm.matrix_entries, lm.offset_entries, lm.inputs, lm.act, K, eta * w / total, e)
    return K


@njit(cache=True, nogil=True, error_model="numpy")
def llm_predict_many(X, lm, K, out, nearest):  # type: ignore[no-untyped-def]
    """g(x) for every row of X (N, n) into out (N, m); min_k ||u_k||^2 of each row into nearest (N,)."""
    for r in range(X.shape[0]):
        _, nearest[r] = llm_predict(X[r], lm, K, out[r])
