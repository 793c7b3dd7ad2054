"""Kernels compiled ahead of the first run (gb_pin.runs.precompile, gb_pin/_build_backend.py).

The build backend runs the precompile step at ``pip install -e .``; a fresh process must then
find every kernel a default run, the inverse estimate, the forward kinematics and the IK solver
need in numba's cache: no gb_pin kernel may be compiled again (numba's own per-dispatcher
statistics count the misses). Each test uses its own empty cache directory.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.runs.precompile import PARTS, main, precompile

ROOT = Path(__file__).resolve().parent.parent

_CHECK = """
import gc, json, sys, warnings
warnings.simplefilter("ignore")
import gb_pin
from numba.core.registry import CPUDispatcher
robot = sys.argv[1]
result = gb_pin.babble(robot, movements=20, seed=0)
result.inverse(result.targets)
result.target.forward(result.target.home)
result.solve(result.targets[:2])
hits, misses = {}, {}
for obj in gc.get_objects():
    if isinstance(obj, CPUDispatcher) and obj.py_func.__module__.startswith("gb_pin"):
        name = obj.py_func.__module__ + "." + obj.py_func.__qualname__
        hits[name] = sum(obj.stats.cache_hits.values())
        misses[name] = sum(obj.stats.cache_misses.values())
print(json.dumps({"hits": hits, "misses": misses, "pinocchio": "pinocchio" in sys.modules}))
"""


def _env(cache: Path) -> dict[str, str]:
    return {**os.environ, "NUMBA_CACHE_DIR": str(cache)}


def _backend() -> ModuleType:
    return importlib.import_module("gb_pin._build_backend")


@pytest.mark.slow
def test_the_build_step_leaves_nothing_to_compile(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The backend's step (a subprocess, as pip runs it), then planar20 and a TALOS arm load every kernel."""
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    _backend()._precompile()
    assert any(tmp_path.rglob("*.nbi")), "the precompile step wrote no cache index"
    for robot in ("planar20", "talos_left_arm"):
        out = subprocess.run(
            [sys.executable, "-c", _CHECK, robot], env=_env(tmp_path), capture_output=True, text=True,
            timeout=600, check=False,
        )  # fmt: skip
        assert out.returncode == 0, out.stderr[-2000:]
        stats = json.loads(out.stdout.strip().splitlines()[-1])
        compiled = {k: v for k, v in stats["misses"].items() if v}
        assert not compiled, f"{robot}: compiled again: {compiled}"
        assert stats["hits"]["gb_pin.learn.loop.babble_loop"] >= 1
        assert stats["pinocchio"] == (robot != "planar20")  # a planar run never imports it


def test_backend_runs_every_part() -> None:
    assert _backend().PARTS == PARTS


def test_backend_asks_for_numpy_and_numba_with_the_project_bounds(monkeypatch: pytest.MonkeyPatch) -> None:
    backend = _backend()
    # setuptools' own part needs a recent setuptools (the build environment has one), not ours.
    monkeypatch.setattr(backend._setuptools, "get_requires_for_build_editable", lambda settings=None: [])
    monkeypatch.delenv("GB_PIN_PRECOMPILE", raising=False)
    wanted = backend._kernel_requirements()
    assert sorted(r.split(">")[0] for r in wanted) == ["numba", "numpy"]
    assert all(r in backend.get_requires_for_build_editable() for r in wanted)
    monkeypatch.setenv("GB_PIN_PRECOMPILE", "0")
    assert not any(r in backend.get_requires_for_build_editable() for r in wanted)


def test_a_failing_step_never_fails_the_install(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    backend = _backend()
    monkeypatch.setattr(backend.sys, "executable", str(ROOT / "no-such-python"))
    backend._precompile()  # an OSError inside: reported, not raised
    assert "not precompiled" in capsys.readouterr().err


def test_unknown_part_is_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="unknown precompile part"):
        precompile(["everything"])
    assert main(["everything"]) == 2
