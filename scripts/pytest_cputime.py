"""A pytest plugin: each test's CPU time (its process and the subprocesses it waited for) and wall time.

    CPUTIME_OUT=cpu.tsv PYTHONPATH=scripts python -m pytest -p pytest_cputime tests/...

One line a test in $CPUTIME_OUT: node id, own CPU [s], children's CPU [s], wall [s]. CPU time, not wall
time, is what tells slow tests apart on a machine shared with other jobs (README, "Two commands").
"""

import os
import resource
import time
from typing import Any

import pytest

OUT = os.environ.get("CPUTIME_OUT", "cputimes.tsv")


def _cpu() -> tuple[float, float]:
    s = resource.getrusage(resource.RUSAGE_SELF)
    c = resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime, c.ru_utime + c.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: Any, nextitem: Any) -> Any:
    """Around each test (setup, call, teardown): one line of its CPU and wall time."""
    s0, c0 = _cpu()
    w0 = time.perf_counter()
    yield
    s1, c1 = _cpu()
    with open(OUT, "a") as fh:
        fh.write(f"{item.nodeid}\t{s1 - s0:.3f}\t{c1 - c0:.3f}\t{time.perf_counter() - w0:.3f}\n")
