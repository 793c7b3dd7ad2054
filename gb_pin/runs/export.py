"""The learned inverse g as a plain ``.npz`` of arrays, for use without gb_pin, numba or Pinocchio.

``result.export_inverse("inverse.npz")`` writes the local-linear map (Sec. II-C of the paper) and what
a controller needs beside it; ``examples/numpy_inverse.py`` is a reader of about 30 lines of numpy
that predicts what ``result.inverse`` predicts (to about 1e-15 relative: the sums' order and the
exponential's last bit differ; tested to 1e-12). Arrays (no pickle, ``np.load(path)`` reads them):

- ``prototypes`` (K, n): the centres p_k [task units];
- ``matrices`` (K, m, n): W_k, acting on u_k = (x - p_k) / radius;
- ``offsets`` (K, m): o_k;
- ``radius`` (): d; g(x) = sum_k b_k (o_k + W_k u_k) / sum_k b_k, b_k = exp(-||u_k||^2);
- ``cutoff`` (): c^2 of a truncated map (inf: none): b_k = 0 where ||u_k||^2 > min_j ||u_j||^2 + c^2;
- ``home``, ``lower``, ``upper`` (m,): the home posture and joint limits (clip what you execute);
- ``joints`` (m,) and ``axes`` (): names, as text; ``format_version`` ().
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from gb_pin._files import atomic_write, check_writable

FORMAT_VERSION = 1


def export_inverse(result: Any, path: str | os.PathLike[str]) -> str:
    """Write ``result``'s learned inverse to ``path`` (a plain ``.npz``); returns the path written.

    Raises:
        InvalidArgumentError: ``path`` cannot be written (checked before anything is computed).
    """
    if hasattr(result.model, "part_of"):  # a region in parts: one map per part, no single inverse
        from gb_pin.exceptions import InvalidArgumentError

        raise InvalidArgumentError(
            "the inverse of a workspace region learnt in parts has a map per part and a rule choosing one "
            "(gb_pin.learn.parts.PartedMap); the plain export holds one map: learn it with parts=1 to export"
        )
    path = check_writable(path, "inverse file")
    target = result.target
    arrays = result.model.to_arrays()
    joints = getattr(target, "joints", None) or [f"q{i}" for i in range(target.n_joints)]
    axes = (
        getattr(target, "axes", "")
        if getattr(target, "task", None) is None
        else "+".join(target.component_labels)
    )
    with atomic_write(path) as fh:
        np.savez(
            fh,
            prototypes=arrays["prototypes"],
            matrices=arrays["matrices"],
            offsets=arrays["offsets"],
            radius=np.float64(result.model.radius),
            cutoff=np.float64(np.inf if result.model.cutoff is None else float(result.model.cutoff) ** 2),
            home=np.asarray(target.home, dtype=np.float64),
            lower=np.asarray(target.lower, dtype=np.float64),
            upper=np.asarray(target.upper, dtype=np.float64),
            joints=np.array([str(j) for j in joints]),
            axes=np.array(str(axes)),
            format_version=np.int64(FORMAT_VERSION),
        )
    return path
