"""A cold start compiled in two processes (gb_pin.runs.coldstart): when, what, and that it changes nothing.

The end-to-end test runs a warm-up in a fresh process with an empty NUMBA_CACHE_DIR: the helper
must start, the loop must have called every planned kernel with exactly the planned argument types
(one specialisation each: the helper's cache entries are the loop's), the helper must be gone
afterwards, and a run must give the same numbers as in this process. The others check the
fall-backs: no helper without a writable cold cache, on one core, on a busy machine, when switched
off, or when it cannot start; and a helper whose parent is gone ends at once.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.runs import coldstart

ROOT = Path(__file__).resolve().parent.parent

_COLD = """
import json, sys, warnings
warnings.simplefilter("ignore")
from gb_pin.runs import api, coldstart
helpers = []
real = coldstart.start_helper
coldstart.start_helper = lambda: helpers.append(real()) or helpers[-1]
api.warmup()
state = coldstart.warmup_state()
plan = coldstart.callee_signatures(state.rng, state.kernel_args())
signatures = {
    name: [list(map(str, s)) == list(map(str, sig)) for s in d.overloads] for name, (d, sig) in plan.items()
}
result = api.babble("planar5", movements=60, seed=3)
print(json.dumps({
    "helper": helpers[0] is not None if helpers else None,
    "returncode": helpers[0].poll() if helpers and helpers[0] is not None else None,
    "signatures": signatures,
    "history": [result.history.error.tolist(), result.history.home_distance.tolist(),
                result.history.reach.tolist()],
}))
"""


def test_a_cold_start_compiles_in_two_processes_and_the_same_numbers_come_out(tmp_path: Path) -> None:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    env[coldstart.ENV] = "1"  # even on a busy machine
    out = subprocess.run(
        [sys.executable, "-c", _COLD], env=env, capture_output=True, text=True, timeout=900, check=False
    )
    assert out.returncode == 0, out.stderr[-3000:]
    report = json.loads(out.stdout.strip().splitlines()[-1])
    if len(os.sched_getaffinity(0)) < 2:  # pragma: no cover - one core: no helper, by design
        assert report["helper"] is None
    else:
        assert report["helper"] is True
        assert report["returncode"] is not None  # stopped and reaped, not left running
    # Every kernel of the plan was compiled (here or by the helper) for exactly the loop's types.
    assert report["signatures"] == {name: [True] for name in report["signatures"]}
    assert set(report["signatures"]) == set(coldstart.OWN) | set(coldstart.HELPER)
    here = gb_pin.babble("planar5", movements=60, seed=3)
    h = here.history
    for got, want in zip(report["history"], (h.error, h.home_distance, h.reach), strict=True):
        assert np.array_equal(np.array(got), want, equal_nan=True)  # bit for bit


def test_no_helper_without_a_writable_cache(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(coldstart.ENV, raising=False)
    monkeypatch.setattr(coldstart, "_cores", lambda: 2)
    monkeypatch.setattr(coldstart, "_writable", lambda path: False)
    assert not coldstart.cache_is_cold_and_writable()
    assert not coldstart.wanted()


def test_a_read_only_directory_is_not_writable(tmp_path: Path) -> None:
    assert coldstart._writable(str(tmp_path))
    assert not coldstart._writable(str(tmp_path / "missing"))


@pytest.mark.parametrize("setting", ["0", "off", "false"])
def test_switched_off(monkeypatch: pytest.MonkeyPatch, setting: str) -> None:
    monkeypatch.setenv(coldstart.ENV, setting)
    monkeypatch.setattr(coldstart, "cache_is_cold_and_writable", lambda: True)
    assert not coldstart.wanted()


def test_a_busy_machine_starts_no_helper_unless_asked(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(coldstart.ENV, raising=False)
    monkeypatch.setattr(coldstart, "cache_is_cold_and_writable", lambda: True)
    monkeypatch.setattr(coldstart, "_cores", lambda: 2)
    monkeypatch.setattr(coldstart.os, "getloadavg", lambda: (1.7, 1.0, 1.0))
    assert not coldstart.wanted()
    monkeypatch.setenv(coldstart.ENV, "1")
    assert coldstart.wanted()
    monkeypatch.setattr(coldstart.os, "getloadavg", lambda: (1.2, 1.0, 1.0))
    monkeypatch.delenv(coldstart.ENV)
    assert coldstart.wanted()


def test_one_core_starts_no_helper(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv(coldstart.ENV, raising=False)
    monkeypatch.setattr(coldstart, "cache_is_cold_and_writable", lambda: True)
    monkeypatch.setattr(coldstart, "_cores", lambda: 1)
    assert not coldstart.wanted()


def test_a_helper_that_cannot_start_leaves_the_compile_here(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuse(*args: object, **kwargs: object) -> None:
        raise OSError("no processes left")

    monkeypatch.setattr(coldstart, "wanted", lambda: True)
    monkeypatch.setattr(coldstart.subprocess, "Popen", refuse)
    shares: list[tuple[str, ...]] = []
    monkeypatch.setattr(coldstart, "compile_share", lambda names, state=None: shares.append(names))
    with coldstart.parallel_compile() as helper:
        assert helper is None
    assert shares == []  # nothing done ahead: the loop compiles everything, as without a helper


def test_the_helper_is_stopped_when_the_block_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    sleeper = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    monkeypatch.setattr(coldstart, "wanted", lambda: True)
    monkeypatch.setattr(coldstart, "start_helper", lambda: sleeper)
    monkeypatch.setattr(coldstart, "compile_share", lambda names, state=None: None)
    with pytest.raises(KeyboardInterrupt), coldstart.parallel_compile():
        raise KeyboardInterrupt
    assert sleeper.poll() is not None


def test_a_helper_without_its_parent_ends_at_once(tmp_path: Path) -> None:
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path), "PYTHONPATH": str(ROOT)}
    start = time.monotonic()
    # A parent id that is not its parent: the watch ends it before it compiles its share.
    out = subprocess.run(
        [sys.executable, "-m", "gb_pin.runs.coldstart", "1"], env=env, timeout=120, check=False,
        capture_output=True,
    )  # fmt: skip
    assert out.returncode == 0
    assert not list(tmp_path.rglob("loop.noise_free_reach*")), "it went on compiling"
    assert time.monotonic() - start < 60
