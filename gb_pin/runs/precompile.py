"""Compile the numba kernels of the common runs into numba's on-disk cache, ahead of the first run.

numba compiles a kernel for the types it is called with and caches the machine code beside the
source (``__pycache__``, or ``NUMBA_CACHE_DIR``). Every position task of any robot with the
paper's goal choice calls the loop with the same types, so that one small planar run compiles
what ``gb-pin babble --robot <any preset>`` needs; :func:`precompile` runs it together with the
inverse estimate, the forward kinematics and the IK solver. It needs only numpy and numba (no
pinocchio): the build backend (``scripts/build_backend.py``) runs it at ``pip install -e .``, so
that the first run of a fresh install loads the kernels instead of compiling them (other goal
generators and stacked tasks still compile on their first use).

Run by hand: ``python -m gb_pin.runs.precompile`` (prints the seconds each part took).
"""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Callable

import numpy as np


def precompile() -> dict[str, float]:
    """Compile (or load) the kernels of the common runs; the seconds of each part, ``"total"`` last."""
    from gb_pin.robot.planar import planar_target
    from gb_pin.runs.api import babble

    start = time.perf_counter()
    target = planar_target(2, targets=np.array([[0.5, 0.5], [0.7, 0.2]]))
    result = babble(target, movements=2, seed=0)
    times = {"babble": time.perf_counter() - start}
    X = result.targets
    parts: dict[str, Callable[[], object]] = {
        "inverse": lambda: result.inverse(X),
        "forward": lambda: target.forward(np.zeros((2, 2))),
        "solve": lambda: result.solve(X),
    }
    for name, call in parts.items():
        t = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # two movements learn little: the queries extrapolate
            call()
        times[name] = time.perf_counter() - t
    times["total"] = time.perf_counter() - start
    return times


def main() -> int:
    """``python -m gb_pin.runs.precompile``: compile, print the times, exit 0."""
    times = precompile()
    print(
        "gb_pin: numba kernels compiled or loaded in " + ", ".join(f"{k} {v:.1f} s" for k, v in times.items())
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
