"""The local-linear map's passes over its prototypes, written so that the compiler vectorises them.

A map with hundreds of prototypes spends its time in three loops over all of them per step
(g at the target, g and the update at the reached position). Each prototype's numbers are
therefore stored entry-major (:class:`~gb_pin.learn.llm_kernels.MapArrays`): entry (i, j) of
every matrix W_k is one contiguous row ``W[i, j, :K]``, entry i of every offset one row
``O[i, :K]``, and the scaled inputs u_k of the last point one row per coordinate ``U[j, :K]``.
Every pass that treats the prototypes independently (scaled inputs and their squared norms,
the local outputs W_k u_k + o_k times the activation, the gradient step) is then a loop over k
on contiguous rows, which LLVM turns into SIMD instructions; the task dimensions n = 2 (planar)
and n = 3 (3-D positions) get their own fused loops, other n a loop per coordinate.

Every number is computed by the same floating-point operations in the same order as the plain
per-prototype loops of :mod:`gb_pin.learn.llm_kernels`' docstring formulas: sums over j run
j = 0, 1, ..., sums over the prototypes k = 0, 1, ... (:func:`row_sums` keeps that order and
gains its speed by running four rows side by side), and the minimum is exact in any order. So
the learned maps are bit-identical to those of the earlier per-prototype layout
(tests/test_fingerprint.py).
"""

from __future__ import annotations

import math

import numpy as np

from gb_pin._jit import njit


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def scaled_inputs(x, P, inv, K, U, sq):  # type: ignore[no-untyped-def]
    """u_k = (x - p_k) / d into ``U`` (n, >= K), ||u_k||^2 into ``sq`` (>= K,); returns min_k ||u_k||^2.

    Args:
        x: (n,) the point [m].
        P: (capacity, n) prototype centres [m].
        inv: 1 / d [1/m].
        K: prototypes in use.
        U: (n, capacity) output.
        sq: (capacity,) output.
    """
    n = x.shape[0]
    if n == 2:
        x0, x1 = x[0], x[1]
        for k in range(K):
            u0 = (x0 - P[k, 0]) * inv
            u1 = (x1 - P[k, 1]) * inv
            U[0, k] = u0
            U[1, k] = u1
            sq[k] = u0 * u0 + u1 * u1
    elif n == 3:
        x0, x1, x2 = x[0], x[1], x[2]
        for k in range(K):
            u0 = (x0 - P[k, 0]) * inv
            u1 = (x1 - P[k, 1]) * inv
            u2 = (x2 - P[k, 2]) * inv
            U[0, k] = u0
            U[1, k] = u1
            U[2, k] = u2
            sq[k] = u0 * u0 + u1 * u1 + u2 * u2
    else:
        for k in range(K):
            sq[k] = 0.0
        for j in range(n):
            xj = x[j]
            for k in range(K):
                u = (xj - P[k, j]) * inv
                U[j, k] = u
                sq[k] += u * u
    return smallest(sq, K)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def smallest(v, K):  # type: ignore[no-untyped-def]
    """min(v[:K]) (inf if K = 0; NaNs skipped), in four independent lanes: exact in any order."""
    s0 = s1 = s2 = s3 = np.inf
    k = 0
    while k + 4 <= K:
        a, b, c, d = v[k], v[k + 1], v[k + 2], v[k + 3]
        s0 = a if a < s0 else s0
        s1 = b if b < s1 else s1
        s2 = c if c < s2 else s2
        s3 = d if d < s3 else s3
        k += 4
    while k < K:
        a = v[k]
        s0 = a if a < s0 else s0
        k += 1
    s0 = s1 if s1 < s0 else s0
    s2 = s3 if s3 < s2 else s2
    return s2 if s2 < s0 else s0


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def activations(sq, K, shift):  # type: ignore[no-untyped-def]
    """b_k = exp(-(||u_k||^2 - shift)) in place of ``sq`` (their sum: :func:`row_sums`)."""
    for k in range(K):
        sq[k] = math.exp(shift - sq[k])


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def weighted_outputs(W, O, U, act, K, Y):  # type: ignore[no-untyped-def]
    """Y[i, k] = b_k (W_k u_k + o_k)_i for the first K prototypes (sum over j in order).

    Args:
        W: (m, n, capacity) matrix entries.
        O: (m, capacity) offset entries.
        U: (n, capacity) scaled inputs.
        act: (capacity,) activations b_k.
        K: prototypes in use.
        Y: (m, capacity) output.
    """
    m, n = W.shape[0], W.shape[1]
    if n == 2:
        for i in range(m):
            for k in range(K):
                y = O[i, k] + W[i, 0, k] * U[0, k] + W[i, 1, k] * U[1, k]
                Y[i, k] = act[k] * y
    elif n == 3:
        for i in range(m):
            for k in range(K):
                y = O[i, k] + W[i, 0, k] * U[0, k] + W[i, 1, k] * U[1, k] + W[i, 2, k] * U[2, k]
                Y[i, k] = act[k] * y
    else:
        for i in range(m):
            for k in range(K):
                Y[i, k] = O[i, k]
            for j in range(n):
                for k in range(K):
                    Y[i, k] += W[i, j, k] * U[j, k]
            for k in range(K):
                Y[i, k] *= act[k]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def row_sums(Y, act, K, out):  # type: ignore[no-untyped-def]
    """total = sum_k act[k] and out[i] = (sum_k Y[i, k]) / total; returns total.

    Every sum runs k = 0, 1, ... in order, a chain of dependent additions; the chains run side by
    side, four at a time (rows in fours, the last one to three rows with the activations' sum).
    """
    m = out.shape[0]
    i = 0
    while i + 4 <= m:
        s0 = s1 = s2 = s3 = 0.0
        for k in range(K):
            s0 += Y[i, k]
            s1 += Y[i + 1, k]
            s2 += Y[i + 2, k]
            s3 += Y[i + 3, k]
        out[i], out[i + 1], out[i + 2], out[i + 3] = s0, s1, s2, s3
        i += 4
    total = s0 = s1 = s2 = 0.0
    left = m - i
    if left == 3:
        for k in range(K):
            total += act[k]
            s0 += Y[i, k]
            s1 += Y[i + 1, k]
            s2 += Y[i + 2, k]
        out[i], out[i + 1], out[i + 2] = s0, s1, s2
    elif left == 2:
        for k in range(K):
            total += act[k]
            s0 += Y[i, k]
            s1 += Y[i + 1, k]
        out[i], out[i + 1] = s0, s1
    elif left == 1:
        for k in range(K):
            total += act[k]
            s0 += Y[i, k]
        out[i] = s0
    else:
        for k in range(K):
            total += act[k]
    for i in range(m):
        out[i] /= total
    return total


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def descend(W, O, U, act, K, scale, e):  # type: ignore[no-untyped-def]
    """The gradient step o_k += c_k e, W_k += c_k e u_k^T with c_k = scale b_k (``act`` becomes c).

    Args:
        W: (m, n, capacity) matrix entries, updated.
        O: (m, capacity) offset entries, updated.
        U: (n, capacity) scaled inputs of the example.
        act: (capacity,) activations b_k of the example; overwritten with c_k.
        K: prototypes in use.
        scale: eta w / sum_k b_k.
        e: (m,) the error q - g(x).
    """
    m, n = W.shape[0], W.shape[1]
    for k in range(K):
        act[k] = scale * act[k]
    # One row at a time, each loop over k writing one row: a loop that wrote all of W_i's rows
    # at once would need more run-time overlap checks than LLVM vectorises with. c_k e_i is
    # recomputed per row (one product) rather than stored and read back.
    for i in range(m):
        ei = e[i]
        for k in range(K):
            O[i, k] += act[k] * ei
        for j in range(n):
            for k in range(K):
                W[i, j, k] += (act[k] * ei) * U[j, k]
