"""Compile the numba kernels of the common runs into numba's on-disk cache, ahead of the first run.

numba compiles a kernel for the types it is called with and caches the machine code beside the
source (``__pycache__``, or ``NUMBA_CACHE_DIR``). Every position task of any robot with the
paper's goal choice calls the loop with the same types, but for the forward kinematics: chains
about parallel axes (the planar arms) take the closed form, all others the general kernel; so
one small planar run and one two-joint 3-D chain compile what ``gb-pin babble --robot <any
preset>`` needs. :data:`PARTS` are independent (no cached
kernel in common), so that two processes can compile them side by side: ``"babble"`` (the
loop, the inverse estimate, forward kinematics) and ``"ik"`` (the IK solver). It needs only
numpy and numba (no pinocchio): the build backend (``gb_pin/_build_backend.py``) runs it at
``pip install -e .``, so that the first run of a fresh install loads the kernels instead of
compiling them (other goal generators and stacked tasks still compile on their first use).

Run by hand: ``python -m gb_pin.runs.precompile [babble] [ik]`` (prints the seconds each took).
"""

from __future__ import annotations

import sys
import time
import warnings
from collections.abc import Sequence

import numpy as np

from gb_pin.exceptions import InvalidArgumentError

PARTS = ("babble", "ik")


def precompile(parts: Sequence[str] = PARTS) -> dict[str, float]:
    """Compile (or load) the kernels of ``parts`` (of :data:`PARTS`); the seconds each took.

    Raises:
        InvalidArgumentError: an unknown part.
    """
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        raise InvalidArgumentError(f"unknown precompile part(s) {unknown}; valid: {', '.join(PARTS)}")
    from gb_pin.robot.planar import planar_target

    X = np.array([[0.5, 0.5], [0.7, 0.2]])
    target = planar_target(2, targets=X)
    times: dict[str, float] = {}
    for part in parts:
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # two movements learn little: the queries extrapolate
            if part == "babble":
                from gb_pin.runs.api import babble

                result = babble(target, movements=2, seed=0)
                result.inverse(result.targets)
                target.forward(np.zeros((2, 2)))
                _general_chain_run(X)
            else:
                from gb_pin.ik.api import solve

                solve(target, X, seed="home")
        times[part] = time.perf_counter() - start
    return times


def _general_chain_run(X: np.ndarray) -> None:
    """The loop and forward kinematics of a chain not about parallel axes (any 3-D arm), compiled.

    A planar chain runs the closed form (``KinematicChain.forward_kernel``); every other chain the
    general kinematics, which are other kernels: a two-joint chain whose second joint turns about y
    compiles them without pinocchio.
    """
    from dataclasses import replace
    from types import SimpleNamespace

    from gb_pin.learn.learner import GoalBabbling
    from gb_pin.robot.planar import planar_home, planar_kinematics
    from gb_pin.robot.reachability import positions

    chain = replace(planar_kinematics(2), axes=np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]))
    unbounded = np.full(2, np.inf)
    robot = SimpleNamespace(chain=chain, home=planar_home(2), lower=-unbounded, upper=unbounded)
    GoalBabbling().fit(robot, X, 2, seed=0)
    positions(np.zeros((2, 2)), chain.forward_kernel(), np.empty((2, 2)))


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m gb_pin.runs.precompile [part ...]``: compile, print the times; 2 on a bad part."""
    args = list(sys.argv[1:] if argv is None else argv)
    try:
        times = precompile(args or PARTS)
    except InvalidArgumentError as exc:
        print(f"gb_pin: {exc}", file=sys.stderr)
        return 2
    done = ", ".join(f"{k} {v:.1f} s" for k, v in times.items())
    print(f"gb_pin: numba kernels compiled or loaded: {done}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
