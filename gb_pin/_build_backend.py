"""gb_pin's build backend: setuptools', plus the numba kernels compiled at an editable install.

``pip install -e .`` builds the editable wheel with this backend (``[build-system]`` of
pyproject.toml). After setuptools has built it, :func:`build_editable` runs
``python -m gb_pin.runs.precompile`` on the source tree in the build environment (numpy and
numba are added to its requirements, with the project's own version bounds; its two
independent parts in two processes). That writes the machine code of the common kernels into
numba's cache beside the sources (``gb_pin/**/__pycache__``), where the installed package
finds them: the first ``gb-pin babble`` then loads the kernels instead of compiling them. A
failure there never fails the install (the first run compiles, as without it).
``GB_PIN_PRECOMPILE=0`` skips it; wheels (``pip install .``) are left alone: their files move,
and numba's cache is keyed by the source path. The backend lives in the package (``backend-path``
is the project's root) so that an sdist carries it; importing ``gb_pin`` itself imports nothing
(its names are lazy), so that the build environment needs no more than setuptools.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
import tomllib
from pathlib import Path
from typing import Any

from setuptools import build_meta as _setuptools
from setuptools.build_meta import (  # noqa: F401  (the rest of the PEP 517/660 interface, unchanged)
    build_sdist,
    build_wheel,
    get_requires_for_build_sdist,
    get_requires_for_build_wheel,
    prepare_metadata_for_build_editable,
    prepare_metadata_for_build_wheel,
)

ROOT = Path(__file__).resolve().parent.parent  # the project: this file is gb_pin/_build_backend.py
TIMEOUT_S = 900  # a slow machine compiles in ~30 s; past this something is wrong
PARTS = ("babble", "ik")  # gb_pin.runs.precompile.PARTS: independent, compiled side by side


def _enabled() -> bool:
    return os.environ.get("GB_PIN_PRECOMPILE", "1").strip().lower() not in ("0", "false", "no", "off")


def _kernel_requirements() -> list[str]:
    """numpy and numba as the project depends on them (pyproject.toml's own bounds)."""
    with open(ROOT / "pyproject.toml", "rb") as f:
        dependencies = tomllib.load(f)["project"]["dependencies"]
    wanted = {"numpy", "numba"}
    return [d for d in dependencies if re.split(r"[<>=!~ \[;]", d, maxsplit=1)[0].lower() in wanted]


def get_requires_for_build_editable(config_settings: dict[str, Any] | None = None) -> list[str]:
    """setuptools' requirements, plus numpy and numba to compile the kernels."""
    extra = _kernel_requirements() if _enabled() else []
    return [*_setuptools.get_requires_for_build_editable(config_settings), *extra]


def build_editable(
    wheel_directory: str,
    config_settings: dict[str, Any] | None = None,
    metadata_directory: str | None = None,
) -> str:
    """setuptools' editable wheel, then the kernels compiled into the source tree's numba cache."""
    name = _setuptools.build_editable(wheel_directory, config_settings, metadata_directory)
    if _enabled():
        _precompile()
    return name


def _precompile() -> None:
    """Run ``gb_pin.runs.precompile``'s independent parts in parallel processes; report, never raise."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p)
    start = time.perf_counter()
    jobs: list[subprocess.Popen[str]] = []
    try:
        for part in PARTS:
            jobs.append(
                subprocess.Popen(
                    [sys.executable, "-m", "gb_pin.runs.precompile", part],
                    cwd=ROOT,
                    env=env,
                    stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE,
                    text=True,
                )
            )
        outputs = [job.communicate(timeout=TIMEOUT_S) for job in jobs]
    except (OSError, subprocess.SubprocessError) as exc:
        for job in jobs:
            job.kill()
        print(f"gb_pin: kernels not precompiled ({exc}); the first run compiles them", file=sys.stderr)
        return
    for job, (out, err) in zip(jobs, outputs, strict=True):
        if job.returncode != 0:
            tail = (err or out).strip().splitlines()[-3:]
            why = " / ".join(tail)
            print(f"gb_pin: kernels not precompiled ({why}); the first run compiles them", file=sys.stderr)
        else:
            print(out.strip(), file=sys.stderr)
    print(f"gb_pin: precompile step {time.perf_counter() - start:.1f} s", file=sys.stderr)
