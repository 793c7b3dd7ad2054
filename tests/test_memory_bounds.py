"""Sizes that used to be allocated before any check: joint paths of a tiny max_joint_step.

Before (main 995bb8d) ``result.reach``, ``FeedbackReach`` and ``session.reacher`` built the whole
joint path of a tiny ``max_joint_step`` as a list (2.7 GB and growing); now the path is computed
one posture at a time (:class:`gb_pin.learn.probe.JointPath`) and one of more than 10^9 asks is
refused.
"""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import gb_pin
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.feedback import FeedbackReach
from gb_pin.learn.probe import JointPath


def test_a_joint_path_is_the_list_it_replaces_posture_for_posture() -> None:
    rng = np.random.default_rng(0)
    start, end = rng.uniform(-1, 1, 4), rng.uniform(-1, 1, 4)
    span = float(np.max(np.abs(end - start)))
    k = int(np.ceil(span / 0.1))
    listed = [start + (end - start) * (i / k) for i in range(1, k)] + [end.copy()]
    path = JointPath(start, end, 0.1)
    assert len(path) == k and all(np.array_equal(a, b) for a, b in zip(path, listed, strict=True))
    walked = [path.pop(0) for _ in range(k)]
    assert not path and all(np.array_equal(a, b) for a, b in zip(walked, listed, strict=True))


def test_a_tiny_max_joint_step_costs_asks_not_memory() -> None:
    result = gb_pin.babble("planar5", movements=50, seed=0)
    arm = result.target
    start = arm.home - 0.5
    tracemalloc.start()
    reach = FeedbackReach(result.model, [0.4, 0.3], arm.lower, arm.upper, start=start, max_joint_step=1e-8)
    for _ in range(1000):
        reach.tell(arm.forward(reach.ask()))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 5 * 2**20, f"{peak / 2**20:.1f} MB for 1000 asks of a 10^8-ask path"
    with pytest.raises(InvalidArgumentError, match="raise max_joint_step"):
        FeedbackReach(result.model, [0.4, 0.3], arm.lower, arm.upper, start=start, max_joint_step=1e-300)


def test_a_map_larger_than_half_the_memory_is_refused_before_allocation(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """10^4 joints x 1000 task axes asked for 19.7 GiB before any check; now a one-line error."""
    from gb_pin.learn import llm

    monkeypatch.setattr(llm, "memory_bytes", lambda: 8 * 2**30)
    arm = gb_pin.FunctionTarget(lambda q: np.resize(q, 1000), np.zeros(10**4), lower=-1, upper=1,
                                targets=np.zeros((2, 1000)))  # fmt: skip
    tracemalloc.start()
    with pytest.raises(InvalidArgumentError, match=r"needs 19.7 GiB, more than half of the 8.0 GiB"):
        gb_pin.babble(arm, movements=2, seed=0)
    assert tracemalloc.get_traced_memory()[1] < 200 * 2**20
    tracemalloc.stop()
