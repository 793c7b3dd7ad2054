"""Local-linear map (paper Sec. II-C): the inverse estimate g(x) and its online learning.

    g(x) = sum_k beta_k(x) (W_k u_k + o_k),   u_k = (x - p_k) / d,
    beta_k(x) = b(u_k) / sum_j b(u_j),         b(u) = exp(-||u||^2).

Conventions (the paper is silent; these reproduce its numbers):

* W_k acts on the scaled input u_k, so a new prototype gets W = d * dg/dx.
* The gradient of w ||q - g(x)||^2 is taken with its factor 2 folded into the
  learning rate: o_k += eta w beta_k (q - g(x)) and W_k += eta w beta_k (q - g(x)) u_k^T.
* Responsibilities are computed as exp(-(||u_k||^2 - min_j ||u_j||^2)) before
  normalising, which is the same soft-max but never underflows far from all prototypes.

The compiled kernels work on preallocated arrays (:class:`MapArrays`, :class:`Scratch`): no
allocation per step. With hundreds of prototypes a step is three passes over all of them (g at
the target; g and the update at the reached position). What is computed per prototype
independently (u_k, ||u_k||^2, the exponentials of :func:`~gb_pin.learn.vector_math.vexp`) runs
over rows contiguous in k, which LLVM turns into SIMD code; the sum over k and the update run over
each prototype's numbers o_k, W_k stored together, eight outputs side by side in one SIMD register
(:mod:`~gb_pin.learn.llm_simd`). Sums over j and over k keep their order, and the minimum is exact
in any order: the numbers are those of plain per-prototype loops with that exp
(tests/test_llm_kernels.py checks it bit for bit).

A truncated map (``cutoff`` c, not the paper's: a workspace region's map of hundreds of prototypes)
leaves out of the sums, the Jacobian and the update every prototype whose activation is below
exp(-c^2) of the nearest one's: the distances are computed for all K, the rest only for the
prototypes listed near x (:func:`_truncated_predict`), in increasing k, so that the numbers are those of
the same per-prototype loops skipping the others (tested bit for bit). Without a cutoff (every
preset's run) the code path is the one above: :func:`llm_predict` chooses at its first line, by a constant
of the map's type, and the whole-sum code after it is as it was (measured: the same choice placed after
the minimum, or the block sums' unpacking shared with the truncated path, made a prediction 2-6 % slower).
:class:`~gb_pin.learn.llm.LocalLinearMap` wraps them with a scikit-learn style interface.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numba import types
from numba.extending import overload
from numpy.typing import NDArray

from gb_pin._jit import NO_REFCOUNT, njit
from gb_pin.learn.llm_list import distances_smallest, list_within, smallest
from gb_pin.learn.llm_simd import LANES, block_sum, block_sum_near, block_update, block_update_near
from gb_pin.learn.vector_math import VEXP_LIMIT, vexp


class MapArrays(NamedTuple):
    """A local-linear map's storage, as the compiled kernels take it (what a prediction reads).

    The centres are stored entry-major (contiguous over k, for the SIMD distance pass), each
    prototype's local model o_k, W_k together (for the SIMD sums of :mod:`~gb_pin.learn.llm_simd`);
    :class:`~gb_pin.learn.llm.LocalLinearMap` converts to and from the (K, m, n) layout of its
    attributes and files. ``capacity`` is ``prototypes.shape[1]``.

    Attributes:
        prototypes: (n, capacity) prototype centres, ``prototypes[j, k]`` = (p_k)_j [m]; the
            first K columns are in use.
        models: (capacity, n + 1, m') local models, m' >= m + 1 a multiple of ``LANES``:
            ``models[k, 0, i]`` = (o_k)_i, ``models[k, 1 + j, i]`` = (W_k)_ij (W_k acts on
            (x - p_k) / d); ``models[k, 0, m]`` = 1 (so that the sums over k also give sum_k b_k),
            zeros after it.
        radius: d [m].
        act: (capacity,) scratch: the activations of the last prediction.
        inputs: (n + 1, capacity) scratch: the scaled inputs u_k = (x - p_k) / d of the last
            prediction (rows 0..n-1, column k; a truncated map's in the order of its list, column
            t for k = ``nearby[1 + t]``), then ||u_k||^2 (column k).
        errors: (m',) scratch: the error q - g(x) of a learning step, zeros after entry m - 1.
    """

    prototypes: NDArray[np.float64]
    models: NDArray[np.float64]
    radius: float
    act: NDArray[np.float64]
    inputs: NDArray[np.float64]
    errors: NDArray[np.float64]


class TruncatedMapArrays(NamedTuple):
    """:class:`MapArrays` of a truncated map: the same storage, its cutoff, the list of prototypes near x.

    A type of its own, so that the kernels compile the truncated sums for it only (:func:`truncated`
    is a constant of the type): an untruncated map, every preset's, runs the code it ran before.

    Attributes:
        cutoff: c^2 [radii^2]: prototypes with ||u_k||^2 > min_j ||u_j||^2 + c^2 are left out.
        nearby: (capacity + 1,) scratch of a prediction: ``nearby[0]`` prototypes entered its
            sums, their indices k in ``nearby[1:]`` (increasing); ``act[:nearby[0]]`` their
            activations, in that order.
    """

    prototypes: NDArray[np.float64]
    models: NDArray[np.float64]
    radius: float
    act: NDArray[np.float64]
    inputs: NDArray[np.float64]
    errors: NDArray[np.float64]
    cutoff: float
    nearby: NDArray[np.int64]


def _is_truncated_type(lm: Any) -> bool:
    return isinstance(lm, types.BaseNamedTuple) and getattr(lm, "instance_class", None) is TruncatedMapArrays


def truncated(lm):  # type: ignore[no-untyped-def]
    """Whether ``lm`` is a :class:`TruncatedMapArrays` (in compiled code: a constant of its type)."""
    return isinstance(lm, TruncatedMapArrays)


@overload(truncated, inline="always")
def _truncated_overload(lm):  # type: ignore[no-untyped-def]
    flag = _is_truncated_type(lm)
    return lambda lm: flag


def listed(lm, K):  # type: ignore[no-untyped-def]
    """How many prototypes the last prediction's sums ran over: K, or ``nearby[0]`` if truncated."""
    return int(lm.nearby[0]) if isinstance(lm, TruncatedMapArrays) else K


@overload(listed, inline="always")
def _listed_overload(lm, K):  # type: ignore[no-untyped-def]
    if _is_truncated_type(lm):
        return lambda lm, K: lm.nearby[0]
    return lambda lm, K: K


def prototype(lm, t):  # type: ignore[no-untyped-def]
    """The index k of the t-th prototype of the last prediction's sums: t, or ``nearby[1 + t]``."""
    return int(lm.nearby[1 + t]) if isinstance(lm, TruncatedMapArrays) else t


@overload(prototype, inline="always")
def _prototype_overload(lm, t):  # type: ignore[no-untyped-def]
    if _is_truncated_type(lm):
        return lambda lm, t: lm.nearby[1 + t]
    return lambda lm, t: t


class Scratch(NamedTuple):
    """Buffers of learning steps and Jacobians (kept apart so that predictions pass less).

    Attributes:
        g: (m,) g(x).
        y: (m,) one local model's output.
        J: (m, n) dg/dx.
    """

    g: NDArray[np.float64]
    y: NDArray[np.float64]
    J: NDArray[np.float64]


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def llm_predict(x, lm, K, out):  # type: ignore[no-untyped-def]
    """g(x) into ``out`` (m,); returns (sum of activations, min ||u_k||^2).

    ``lm.inputs`` receives the scaled inputs u_k, ``lm.act`` the shifted activations
    b_k = exp(-(||u_k||^2 - min)). The loops that treat the prototypes independently run on
    contiguous rows (SIMD code); the sums over them, sum_k b_k (o_k + W_k u_k) in order
    k = 0, 1, ..., run eight outputs to a register (:func:`~gb_pin.learn.llm_simd.block_sum`).
    With two or three inputs, u_k and ||u_k||^2 are one expression per prototype: the same sums
    in the same order as the general loop over the inputs.
    """
    if truncated(lm):  # a constant of lm's type: one of the two paths is compiled
        return truncated_predict(x, lm, K, out)
    P, M, U, act = lm.prototypes, lm.models, lm.inputs, lm.act
    inv = 1.0 / lm.radius
    n = x.shape[0]
    m = out.shape[0]
    sq = U[n]  # scratch row: ||u_k||^2
    # u_k and ||u_k||^2 (sum over j in order, from 0.0: 0.0 + u_0^2 is u_0^2).
    if n == 3:
        x0, x1, x2 = x[0], x[1], x[2]
        for k in range(K):
            u0 = (x0 - P[0, k]) * inv
            u1 = (x1 - P[1, k]) * inv
            u2 = (x2 - P[2, k]) * inv
            U[0, k] = u0
            U[1, k] = u1
            U[2, k] = u2
            sq[k] = (u0 * u0 + u1 * u1) + u2 * u2
    elif n == 2:
        x0, x1 = x[0], x[1]
        for k in range(K):
            u0 = (x0 - P[0, k]) * inv
            u1 = (x1 - P[1, k]) * inv
            U[0, k] = u0
            U[1, k] = u1
            sq[k] = u0 * u0 + u1 * u1
    else:
        for k in range(K):
            sq[k] = 0.0
        for j in range(n):
            xj = x[j]
            for k in range(K):
                u = (xj - P[j, k]) * inv
                U[j, k] = u
                sq[k] += u * u
    # min_k ||u_k||^2 in four lanes (exact in any order; NaNs skipped).
    s0 = s1 = s2 = s3 = np.inf
    k = 0
    while k + 4 <= K:
        a, b, c, d = sq[k], sq[k + 1], sq[k + 2], sq[k + 3]
        s0 = a if a < s0 else s0
        s1 = b if b < s1 else s1
        s2 = c if c < s2 else s2
        s3 = d if d < s3 else s3
        k += 4
    while k < K:
        a = sq[k]
        s0 = a if a < s0 else s0
        k += 1
    s0 = s1 if s1 < s0 else s0
    s2 = s3 if s3 < s2 else s2
    nearest = s2 if s2 < s0 else s0
    # The activations b_k = exp(nearest - ||u_k||^2) (arguments <= 0, or NaN): vexp in SIMD
    # code, then math.exp for the rare argument beyond its range (a prototype 26 radii farther
    # than the nearest, or NaN).
    outside = False
    for k in range(K):
        v = nearest - sq[k]
        inside = v >= -VEXP_LIMIT
        outside |= not inside
        act[k] = vexp(v if inside else -VEXP_LIMIT)
    if outside:
        for k in range(K):
            v = nearest - sq[k]
            if not v >= -VEXP_LIMIT:
                act[k] = math.exp(v)
    # sum_k b_k (o_k + W_k u_k) and sum_k b_k (the ones after o_k), a block of eight outputs at a time.
    total = 0.0
    for block in range(M.shape[2] // LANES):
        sums = block_sum(M, U, act, K, block)
        for r in range(LANES):
            i = LANES * block + r
            if i < m:
                out[i] = sums[r]
            elif i == m:
                total = sums[r]
    for i in range(m):
        out[i] /= total
    return total, nearest


def truncated_predict(x, lm, K, out):  # type: ignore[no-untyped-def]
    """:func:`llm_predict` of a truncated map (compiled code; :func:`_truncated_predict`)."""
    raise NotImplementedError("compiled code only")


@overload(truncated_predict)
def _truncated_predict_overload(x, lm, K, out):  # type: ignore[no-untyped-def]
    if _is_truncated_type(lm):
        return lambda x, lm, K, out: _truncated_predict(x, lm, K, out)
    return lambda x, lm, K, out: (0.0, 0.0)  # never called: the untruncated path


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _truncated_predict(x, lm, K, out):  # type: ignore[no-untyped-def]
    """g(x) into ``out`` over the prototypes near x only; returns (sum of their activations, nearest).

    A truncated map leaves out of the sums every prototype whose activation is below exp(-c^2)
    of the nearest one's, ||u_k||^2 > min_j ||u_j||^2 + c^2 (``lm.cutoff`` = c^2): their share
    of g is at most exp(-c^2) each (a region's c = 3: 1.2e-4), while a region's map of 800
    prototypes has about 55 within it (docs/WORKSPACE.md), so the exponentials, the sums and the
    update cost K/14 of the whole map's. The list goes to ``lm.nearby`` in increasing k (the order of the
    untruncated sums), their activations to ``lm.act[:count]`` in the list's order.
    """
    P, U, act, near = lm.prototypes, lm.inputs, lm.act, lm.nearby
    inv = 1.0 / lm.radius
    n = x.shape[0]
    sq = U[n]  # ||u_k||^2 for every k; u_k itself only for the prototypes listed
    # The same expressions as llm_predict's, without storing u_k: (u0^2 + u1^2) + u2^2, ...
    if n == 3:  # and the minimum in the same pass, eight prototypes a step (llm_list)
        nearest = distances_smallest(x, P, inv, sq, K)
    else:
        if n == 2:
            x0, x1 = x[0], x[1]
            for k in range(K):
                u0 = (x0 - P[0, k]) * inv
                u1 = (x1 - P[1, k]) * inv
                sq[k] = u0 * u0 + u1 * u1
        else:
            for k in range(K):
                sq[k] = 0.0
            for j in range(n):
                xj = x[j]
                for k in range(K):
                    u = (xj - P[j, k]) * inv
                    sq[k] += u * u
        nearest = smallest(sq, K)  # eight prototypes a step (llm_list)
    limit = nearest + lm.cutoff
    count = list_within(sq, limit, K, near)
    near[0] = count
    if n == 3:  # u_k of the listed prototypes side by side, in the list's order
        x0, x1, x2 = x[0], x[1], x[2]
        for t in range(count):
            k = near[t + 1]
            U[0, t] = (x0 - P[0, k]) * inv
            U[1, t] = (x1 - P[1, k]) * inv
            U[2, t] = (x2 - P[2, k]) * inv
    else:
        for t in range(count):
            k = near[t + 1]
            for j in range(n):
                U[j, t] = (x[j] - P[j, k]) * inv
    for t in range(count):  # the exponents gathered, then the exponentials in SIMD code
        act[t] = nearest - sq[near[t + 1]]
    for t in range(count):
        act[t] = vexp(act[t])
    m = out.shape[0]
    total = 0.0
    for block in range(lm.models.shape[2] // LANES):
        sums = block_sum_near(lm.models, lm.inputs, act, near, block)
        for r in range(LANES):
            i = LANES * block + r
            if i < m:
                out[i] = sums[r]
            elif i == m:
                total = sums[r]
    for i in range(m):
        out[i] /= total
    return total, nearest


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def llm_jacobian(x, lm, K, scratch):  # type: ignore[no-untyped-def]
    """dg/dx into ``scratch.J`` (m, n) and g(x) into ``scratch.g`` (m,), the responsibilities' derivative in.

    With beta_k' = -(2/d) beta_k (u_k - sum_j beta_j u_j):
    J = (1/d) sum_k beta_k [W_k - 2 (y_k - g) u_k^T],  y_k = W_k u_k + o_k.
    """
    total, _ = llm_predict(x, lm, K, scratch.g)
    _jacobian_of_prediction(lm, K, total, scratch)


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def _jacobian_of_prediction(lm, K, total, scratch):  # type: ignore[no-untyped-def]
    """dg/dx into ``scratch.J`` from the last prediction (u_k, activations, their sum, g in ``scratch.g``)."""
    M, U, act = lm.models, lm.inputs, lm.act
    g, y, J = scratch
    m, n = J.shape
    inv = 1.0 / lm.radius
    for i in range(m):
        for j in range(n):
            J[i, j] = 0.0
    for t in range(listed(lm, K)):  # K, or the prototypes near x of a truncated map
        k = prototype(lm, t)
        beta = act[t] / total  # in the order of the sums (t = k without a cutoff)
        for i in range(m):
            yi = M[k, 0, i]
            for j in range(n):
                yi += M[k, 1 + j, i] * U[j, t]
            y[i] = yi
        for i in range(m):
            r = 2.0 * (y[i] - g[i])
            for j in range(n):
                J[i, j] += beta * (M[k, 1 + j, i] - r * U[j, t])
    for i in range(m):
        for j in range(n):
            J[i, j] *= inv


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def llm_insert(x, lm, K, total, scratch):  # type: ignore[no-untyped-def]
    """Add prototype K at ``x`` with o = g(x) and W = d * dg/dx, so g and dg/dx stay unchanged.

    ``total`` and ``scratch.g``: the sum of activations and g(x) of the last prediction, which was
    at ``x`` with these K prototypes. The caller guarantees capacity (P.shape[1] > K). Returns the
    new count K + 1.
    """
    P, M, radius = lm.prototypes, lm.models, lm.radius
    g, J = scratch.g, scratch.J
    _jacobian_of_prediction(lm, K, total, scratch)
    n = x.shape[0]
    m = g.shape[0]
    for j in range(n):
        P[j, K] = x[j]
    for i in range(m):
        M[K, 0, i] = g[i]
        for j in range(n):
            M[K, 1 + j, i] = radius * J[i, j]
    return K + 1


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def llm_learn(x, q, w, eta, lm, K, scratch):  # type: ignore[no-untyped-def]
    """One online step on the example (x, q) with weight w; returns the new prototype count.

    Inserts a prototype first if ``x`` is at distance >= d from all prototypes,
    then descends the gradient of w ||q - g(x)||^2 (factor 2 folded into eta):
    o_k += eta w beta_k e,  W_k += eta w beta_k e u_k^T,  e = q - g(x).
    """
    g, e = scratch.g, lm.errors
    m = q.shape[0]
    total, nearest = llm_predict(x, lm, K, g)
    if nearest >= 1.0:
        K = llm_insert(x, lm, K, total, scratch)
        total, nearest = llm_predict(x, lm, K, g)
    if w == 0.0:
        return K
    for i in range(m):
        e[i] = q[i] - g[i]  # the error e (its padding stays zero)
    scale = eta * w / total
    # c_k e = (scale b_k) e added to o_k and (c_k e) u_kj to column j of W_k, eight outputs at a time.
    for block in range(lm.models.shape[2] // LANES):
        update_block(lm, K, block, e, scale, m - LANES * block)
    return K


def update_block(lm, K, block, errors, scale, used):  # type: ignore[no-untyped-def]
    """The gradient step's update of one block of outputs (compiled code): all prototypes, or those listed."""
    raise NotImplementedError("compiled code only")


@overload(update_block, inline="always")
def _update_block_overload(lm, K, block, errors, scale, used):  # type: ignore[no-untyped-def]
    if _is_truncated_type(lm):

        def near(lm, K, block, errors, scale, used):  # type: ignore[no-untyped-def]
            block_update_near(lm.models, lm.inputs, lm.act, lm.nearby, block, errors, scale, used)

        return near

    def whole(lm, K, block, errors, scale, used):  # type: ignore[no-untyped-def]
        block_update(lm.models, lm.inputs, lm.act, K, block, errors, scale, used)

    return whole


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)
def llm_predict_many(X, lm, K, out, nearest):  # type: ignore[no-untyped-def]
    """g(x) for every row of X (N, n) into out (N, m); min_k ||u_k||^2 of each row into nearest (N,)."""
    for r in range(X.shape[0]):
        _, nearest[r] = llm_predict(X[r], lm, K, out[r])
