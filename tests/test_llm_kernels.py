"""Tests of gb_pin.learn.llm_kernels and llm_simd: the vectorised kernels compute what per-prototype loops do.

The kernels store the centres entry-major and each prototype's local model together, run the
sums and the update eight outputs to a SIMD register, and treat the task dimensions 2 and 3 with
code written out, other n with a loop per coordinate; each must give, bit for bit, the numbers of
the plain per-prototype loops of Sec. II-C written below in pure Python (IEEE doubles, the map's
exp, sums over j and over k in order): the layout changes no number. Here it is checked for every
branch (n = 1..6), for prototype counts around the four-lane boundaries of the minimum, and for m
below, at and above the eight lanes of a block (the sum of the activations rides in lane m).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gb_pin import LocalLinearMap
from gb_pin.learn.vector_math import VEXP_LIMIT, vexp


def exp(x: float) -> float:
    """The map's exponential: vexp within its range, the C library's outside (llm_kernels.llm_predict)."""
    return float(vexp(x)) if -VEXP_LIMIT <= x <= VEXP_LIMIT else math.exp(x)


class LoopMap:
    """g, insertion and the gradient step of Sec. II-C as per-prototype Python loops, documented order."""

    def __init__(self, x0: list[float], q0: list[float], d: float, cutoff: float | None = None) -> None:
        self.d, self.inv = d, 1.0 / d
        self.c2 = math.inf if cutoff is None else cutoff * cutoff  # prototypes farther are left out
        self.P, self.O = [list(x0)], [list(q0)]
        self.W = [[[0.0] * len(x0) for _ in q0]]

    def predict(self, x: list[float]) -> tuple[list[float], list[float], float, float]:
        """(g(x), activations, their sum, min_k ||u_k||^2)."""
        n, m, K = len(x), len(self.O[0]), len(self.P)
        sq = []
        for k in range(K):
            s = 0.0
            for j in range(n):
                u = (x[j] - self.P[k][j]) * self.inv
                s += u * u
            sq.append(s)
        smallest = min(sq)
        act, total, out = [], 0.0, [0.0] * m
        for k in range(K):
            if not sq[k] <= smallest + self.c2:
                act.append(0.0)  # left out of every sum
                continue
            a = exp(smallest - sq[k])
            act.append(a)
            total += a
            for i in range(m):
                y = self.O[k][i]
                for j in range(n):
                    y += self.W[k][i][j] * ((x[j] - self.P[k][j]) * self.inv)
                out[i] += a * y
        return [v / total for v in out], act, total, smallest

    def learn(self, x: list[float], q: list[float], w: float, eta: float) -> None:
        """Insert a prototype at x if none is within d, then one gradient step."""
        n, m = len(x), len(q)
        g, act, total, smallest = self.predict(x)
        if smallest >= 1.0:
            J = [[0.0] * n for _ in range(m)]
            for k in range(len(self.P)):
                if act[k] == 0.0:
                    continue
                beta = act[k] / total
                y = []
                for i in range(m):
                    yi = self.O[k][i]
                    for j in range(n):
                        yi += self.W[k][i][j] * ((x[j] - self.P[k][j]) * self.inv)
                    y.append(yi)
                for i in range(m):
                    r = 2.0 * (y[i] - g[i])
                    for j in range(n):
                        J[i][j] += beta * (self.W[k][i][j] - r * ((x[j] - self.P[k][j]) * self.inv))
            self.P.append(list(x))
            self.O.append(list(g))
            self.W.append([[self.d * (J[i][j] * self.inv) for j in range(n)] for i in range(m)])
            g, act, total, smallest = self.predict(x)
        if w == 0.0:
            return
        e = [q[i] - g[i] for i in range(m)]
        scale = eta * w / total
        for k in range(len(self.P)):
            if act[k] == 0.0:
                continue
            c = scale * act[k]
            for i in range(m):
                ce = c * e[i]
                self.O[k][i] += ce
                for j in range(n):
                    self.W[k][i][j] += ce * ((x[j] - self.P[k][j]) * self.inv)


@pytest.mark.parametrize("cutoff", [None, 1.5])
@pytest.mark.parametrize("n", [1, 2, 3, 4, 6])
@pytest.mark.parametrize("m", [1, 3, 4, 7, 8, 9, 20])
def test_passes_equal_per_prototype_loops_bit_for_bit(n: int, m: int, cutoff: float | None) -> None:
    """partial_fit (insertions, zero weights included) and predict give the loops' numbers exactly.

    With a cutoff the loops leave out the prototypes beyond it; the kernels' list of the others
    (branch-free, in increasing k) gives the same sums in the same order.
    """
    rng = np.random.default_rng(10 * n + m)
    d, eta = 0.1, 0.4
    x0, q0 = rng.uniform(-1, 1, n), rng.normal(size=m)
    fast = LocalLinearMap(radius=d, learning_rate=eta, cutoff=cutoff).initialize(x0, q0, capacity=2)
    slow = LoopMap(x0.tolist(), q0.tolist(), d, cutoff)
    X = rng.uniform(-1, 1, (30, n))
    Q = rng.normal(size=(30, m))
    w = rng.uniform(0, 1, 30)
    w[::7] = 0.0
    for r in range(30):
        fast.partial_fit(X[r : r + 1], Q[r : r + 1], w[r : r + 1])
        slow.learn(X[r].tolist(), Q[r].tolist(), float(w[r]), eta)
        probes = np.vstack([X[r], rng.uniform(-1, 1, (3, n))])
        got = fast.predict(probes, warn=False)
        for p, row in zip(probes, got, strict=True):
            assert row.tolist() == slow.predict(p.tolist())[0]
    assert fast.n_prototypes_ == len(slow.P)
    assert fast.n_prototypes_ >= 9  # one insertion at a time: K went through the four-lane boundaries
    np.testing.assert_array_equal(fast.prototypes_, np.array(slow.P))
    np.testing.assert_array_equal(fast.matrices_, np.array(slow.W))
    np.testing.assert_array_equal(fast.offsets_, np.array(slow.O))
    # The padding of every stored model is untouched by the updates: a one after o_k, zeros else.
    padding = fast._M[:, :, m:]
    np.testing.assert_array_equal(padding[:, 0, 0], 1.0)
    assert not padding[:, 1:].any() and not padding[:, 0, 1:].any()


def test_storage_round_trips_in_the_file_layout() -> None:
    """to_arrays: (K, n), (K, m, n), (K, m) contiguous copies; from_arrays and reserve keep every number."""
    rng = np.random.default_rng(3)
    fast = LocalLinearMap(radius=0.2, learning_rate=0.5).initialize(rng.uniform(-1, 1, 3), rng.normal(size=5))
    fast.partial_fit(rng.uniform(-1, 1, (40, 3)), rng.normal(size=(40, 5)))
    K = fast.n_prototypes_
    arrays = fast.to_arrays()
    assert [arrays[k].shape for k in ("prototypes", "matrices", "offsets")] == [(K, 3), (K, 5, 3), (K, 5)]
    assert all(a.flags.c_contiguous for a in arrays.values())
    X = rng.uniform(-1, 1, (10, 3))
    before = fast.predict(X, warn=False)
    again = LocalLinearMap.from_arrays(arrays, radius=0.2, learning_rate=0.5, capacity=3 * K)
    np.testing.assert_array_equal(again.predict(X, warn=False), before)
    for name in ("prototypes_", "matrices_", "offsets_"):
        np.testing.assert_array_equal(getattr(again, name), getattr(fast, name))
    fast.reserve(4 * fast.capacity)
    np.testing.assert_array_equal(fast.predict(X, warn=False), before)
    np.testing.assert_array_equal(fast.matrices_, arrays["matrices"])
    arrays["matrices"][0, 0, 0] += 1.0  # copies: the map is untouched
    np.testing.assert_array_equal(fast.predict(X, warn=False), before)


@pytest.mark.parametrize(("n", "m"), [(1, 1), (1, 4), (3, 1)])
def test_stored_arrays_are_copies_whatever_their_shape(n: int, m: int) -> None:
    """to_arrays copies even where a view of the storage would count as contiguous (a dimension of 1)."""
    rng = np.random.default_rng(n + m)
    fast = LocalLinearMap(radius=0.2).initialize(rng.uniform(-1, 1, n), rng.normal(size=m))
    for arrays in (fast.to_arrays(), LocalLinearMap.from_arrays(fast.to_arrays(), radius=0.2).to_arrays()):
        for name, a in arrays.items():
            assert a.flags.c_contiguous and a.flags.owndata, name
    X = rng.uniform(-1, 1, (3, n))
    before = fast.predict(X, warn=False)
    arrays = fast.to_arrays()
    for a in arrays.values():
        a[...] = 7.0
    np.testing.assert_array_equal(fast.predict(X, warn=False), before)


def test_cutoff_beyond_every_prototype_changes_no_number() -> None:
    """A cutoff no prototype lies beyond gives the untruncated map's numbers bit for bit (the same sums)."""
    rng = np.random.default_rng(5)
    X, Q = rng.uniform(-0.3, 0.3, (400, 3)), rng.normal(size=(400, 6))
    maps = [LocalLinearMap(0.05, 0.3, cutoff=c).initialize(X[0], Q[0]) for c in (None, 26.0)]
    for lm in maps:
        lm.partial_fit(X, Q)
    probes = rng.uniform(-0.3, 0.3, (50, 3))
    np.testing.assert_array_equal(maps[0].predict(probes, warn=False), maps[1].predict(probes, warn=False))
    np.testing.assert_array_equal(maps[0].jacobian(probes[0]), maps[1].jacobian(probes[0]))


def test_cutoff_four_stays_within_its_bound_and_leaves_g_unchanged_on_insertion() -> None:
    """c = 4: g within exp(-16) K of the whole map's (the left-out share); insertion keeps g and dg/dx."""
    rng = np.random.default_rng(6)
    X, Q = rng.uniform(-0.4, 0.4, (3000, 3)), rng.normal(size=(3000, 5))
    whole = LocalLinearMap(0.04, 0.3).initialize(X[0], Q[0])
    whole.partial_fit(X, Q)
    cut = LocalLinearMap.from_arrays(whole.to_arrays(), 0.04, 0.3, cutoff=4.0)
    assert whole.n_prototypes_ > 500
    probes = rng.uniform(-0.4, 0.4, (200, 3))
    scale = np.abs(whole.offsets_).max() + 0.8 * np.abs(whole.matrices_).sum(axis=2).max()
    bound = math.exp(-16.0) * whole.n_prototypes_ * 2 * scale
    diff = np.abs(cut.predict(probes, warn=False) - whole.predict(probes, warn=False)).max()
    assert diff <= bound, (diff, bound)
    x = np.array([0.55, 0.0, 0.0])  # beyond every prototype: inserted
    before, J = cut.predict(x, warn=False), cut.jacobian(x)
    cut.partial_fit(x[None], before[None], np.zeros(1))
    np.testing.assert_allclose(cut.predict(x, warn=False), before, rtol=0, atol=1e-12)
    np.testing.assert_allclose(cut.jacobian(x), J, rtol=0, atol=1e-9)


@pytest.mark.parametrize("bad", [0.0, -1.0, 27.0, float("nan"), float("inf"), "4"])
def test_bad_cutoff_is_one_clear_error(bad: object) -> None:
    """The cutoff is in radii, in (0, 26], or None."""
    from gb_pin.exceptions import InvalidArgumentError

    with pytest.raises(InvalidArgumentError, match="cutoff"):
        LocalLinearMap(0.1, cutoff=bad).initialize(np.zeros(2), np.zeros(2))  # type: ignore[arg-type]


def test_the_simd_minimum_and_list_of_prototypes_within_a_limit_are_the_plain_loops() -> None:
    """smallest and list_within (eight at a time) give the scalar loops' minimum and list, in order."""
    from numba import njit

    from gb_pin.learn.llm_list import distances_smallest, list_within, smallest

    @njit(cache=False)
    def simd(sq, limit, K, near):  # type: ignore[no-untyped-def]
        return list_within(sq, limit, K, near)

    @njit(cache=False)
    def least(sq, K):  # type: ignore[no-untyped-def]
        return smallest(sq, K)

    @njit(cache=False)
    def fused(x, P, inv, sq, K):  # type: ignore[no-untyped-def]
        return distances_smallest(x, P, inv, sq, K)

    rng = np.random.default_rng(3)
    for K in [*range(0, 40), 255, 256, 257, 1001]:
        sq = rng.uniform(0.0, 30.0, K + 5)  # entries beyond K must be ignored
        if K > 3:
            sq[rng.integers(0, K, 3)] = [np.nan, np.inf, 0.0]
        plain = math.inf
        for k in range(K):  # llm_predict's rule: a NaN never enters
            plain = sq[k] if sq[k] < plain else plain
        assert least(sq, K) == plain
        assert least(np.full(K + 1, np.nan), K) == math.inf
        x, P, inv = rng.normal(size=3), rng.normal(size=(3, K + 5)), 1.0 / 0.37
        loop = []
        for k in range(K):  # (u0^2 + u1^2) + u2^2, each u_j^2 a product
            u0, u1, u2 = (float((x[j] - P[j, k]) * inv) for j in range(3))
            loop.append((u0 * u0 + u1 * u1) + u2 * u2)
        out = np.full(K + 5, -1.0)
        assert fused(x, P, inv, out, K) == min(loop, default=math.inf)
        assert out[:K].tolist() == loop and (out[K:] == -1.0).all()
        for limit in (-1.0, 0.0, 9.0, 16.5, 31.0, np.inf, np.nan):
            near = np.full(K + 6, -7, dtype=np.int64)
            count = simd(sq, limit, K, near)
            expected = [k for k in range(K) if sq[k] <= limit]
            assert count == len(expected), (K, limit)
            assert near[1 : 1 + count].tolist() == expected and near[0] == -7, (K, limit)


def test_the_list_falls_back_to_the_scalar_loop_where_llvm_lacks_the_compress(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """An LLVM before 19 has no vector compress: list_within then compiles the scalar loop, same list."""
    from numba import njit

    from gb_pin.learn import llm_list

    monkeypatch.setattr(llm_list, "COMPRESS", False)

    @njit(cache=False)
    def scalar(sq, limit, K, near):  # type: ignore[no-untyped-def]
        return llm_list.list_within(sq, limit, K, near)

    rng = np.random.default_rng(4)
    for K in (0, 7, 8, 9, 100):
        sq = rng.uniform(0.0, 30.0, K)
        near = np.zeros(K + 1, dtype=np.int64)
        count = scalar(sq, 9.0, K, near)
        assert near[1 : 1 + count].tolist() == [k for k in range(K) if sq[k] <= 9.0]
    assert "vector.compress" not in "".join(scalar.inspect_llvm().values())
