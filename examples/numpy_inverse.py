"""The learned inverse without gb_pin: read ``result.export_inverse("inverse.npz")`` with numpy alone.

    python examples/numpy_inverse.py inverse.npz 0.5 0.1      # g(x) for one target on the task axes

Copy :func:`load_inverse` into a controller that has numpy and nothing else (no numba, no Pinocchio).
It predicts what ``result.inverse`` does (the local-linear map of the paper's Sec. II-C), to about
1e-15 relative (the order of the sums and the exponential's last bit differ; tested to 1e-12).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np


def load_inverse(path):  # type: ignore[no-untyped-def]
    """g(X) of an exported inverse: a function from (N, n) or (n,) targets to (N, m) or (m,) postures."""
    with np.load(path, allow_pickle=False) as f:
        P, W, o, d = f["prototypes"], f["matrices"], f["offsets"], float(f["radius"])
        c2 = float(f["cutoff"]) if "cutoff" in f else np.inf  # a truncated map's c^2 (older files: none)

    def inverse(X):  # type: ignore[no-untyped-def]
        X = np.asarray(X, dtype=float)
        single = X.ndim == 1
        X = np.atleast_2d(X)
        U = (X[:, None, :] - P[None, :, :]) / d  # (N, K, n): u_k = (x - p_k) / d
        sq = np.einsum("nkj,nkj->nk", U, U)  # ||u_k||^2
        near = sq.min(axis=1, keepdims=True)
        b = np.where(sq <= near + c2, np.exp(near - sq), 0.0)  # b_k, shifted by the nearest (no underflow)
        Y = o[None] + np.einsum("kij,nkj->nki", W, U)  # o_k + W_k u_k
        g = np.einsum("nk,nki->ni", b, Y) / b.sum(axis=1, keepdims=True)
        return g[0] if single else g

    return inverse


def main(argv: list[str] | None = None) -> int:
    """Print g(x) for the target given on the command line."""
    parser = argparse.ArgumentParser(description="g(x) of an inverse exported by result.export_inverse")
    parser.add_argument("file", help="the .npz written by result.export_inverse(path)")
    parser.add_argument("x", nargs="+", type=float, help="one target's coordinates")
    args = parser.parse_args(argv)
    q = load_inverse(args.file)(np.array(args.x))
    print(" ".join(f"{v:.6f}" for v in q))
    return 0


if __name__ == "__main__":
    sys.exit(main())
