"""``njit`` for gb_pin's kernels, with an on-disk cache that notices changes in any kernel file.

numba caches a compiled function beside its source and reuses it while *that file* is
unchanged; but a kernel's machine code also holds the kernels it calls from other files
(``inline="always"`` helpers, the goal dispatch, the task maps). Edit one of those and numba
would go on loading the old code. Here the freshness stamp of every gb_pin kernel is the hash
of all the files in :data:`KERNEL_FILES` together, so that any change there recompiles all of
them (tests/test_jit.py keeps the list complete). Every gb_pin module with compiled code
imports ``njit`` from here, which installs the stamp before the first kernel is declared.
Functions outside gb_pin keep numba's own rule.
"""

from __future__ import annotations

import functools
import hashlib
import os
from typing import Any

from numba import njit as _numba_njit

# The package's files that hold compiled code, relative to the package directory.
KERNEL_FILES: tuple[str, ...] = (
    "ik/clock.py",
    "ik/geometry.py",
    "ik/jacobian.py",
    "ik/search.py",
    "ik/solver.py",
    "learn/body/chain.py",
    "learn/body/components.py",
    "learn/body/joints.py",
    "learn/body/planar.py",
    "learn/body/task.py",
    "learn/clock.py",
    "learn/component_metrics.py",
    "learn/exploration.py",
    "learn/goals/draw.py",
    "learn/goals/kernel.py",
    "learn/llm_kernels.py",
    "learn/llm_list.py",
    "learn/llm_simd.py",
    "learn/loop.py",
    "learn/metrics.py",
    "learn/sensor.py",
    "learn/session_kernels.py",
    "learn/vector_math.py",
    "learn/weighting.py",
    "robot/reachability.py",
    "safety/broadphase.py",
)
PACKAGE = os.path.dirname(os.path.abspath(__file__))


@functools.lru_cache(maxsize=1)
def kernel_stamp() -> bytes:
    """The hash of every file of :data:`KERNEL_FILES` (in order; a missing file counts as empty)."""
    digest = hashlib.sha256()
    for name in KERNEL_FILES:
        digest.update(name.encode())
        try:
            with open(os.path.join(PACKAGE, name), "rb") as f:
                digest.update(hashlib.sha256(f.read()).digest())
        except OSError:
            digest.update(b"missing")
    return digest.digest()


def _ours(py_file: str) -> bool:
    return os.path.abspath(py_file).startswith(PACKAGE + os.sep)


def _install() -> bool:
    """Put gb_pin's locators first in numba's list; False if this numba lacks the hooks."""
    try:
        from numba.core import caching

        impl = caching.CacheImpl
        bases = [caching.UserProvidedCacheLocator, caching.InTreeCacheLocator, caching.UserWideCacheLocator]
    except (ImportError, AttributeError):  # pragma: no cover - a numba that moved them: its own rule
        return False
    if any(getattr(cls, "gb_pin", False) for cls in impl._locator_classes):
        return True

    def subclass(base: type) -> type:
        def from_function(cls: type, py_func: Any, py_file: str) -> Any:
            if not _ours(py_file):
                return None
            return base.from_function.__func__(cls, py_func, py_file)  # type: ignore[attr-defined]

        def get_source_stamp(self: Any) -> bytes:
            return kernel_stamp()

        return type(
            f"GbPin{base.__name__}",
            (base,),
            {
                "gb_pin": True,
                "from_function": classmethod(from_function),
                "get_source_stamp": get_source_stamp,
            },
        )

    ours: list[Any] = [subclass(b) for b in bases]
    impl._locator_classes = [*ours, *impl._locator_classes]
    return True


INSTALLED = _install()


def _refcount_option(on: bool) -> dict[str, Any]:
    """``{"_nrt": on}`` where this numba has the option (a private one), else nothing."""
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:  # pragma: no cover - a numba that moved it
        return {}
    return {"_nrt": on} if hasattr(CPUTargetOptions, "_nrt") else {}


NO_REFCOUNT: dict[str, Any] = _refcount_option(False)
"""``njit(**NO_REFCOUNT)``: no reference counting of arrays (and no allocation), where numba offers it.

A kernel compiled so cannot allocate (numba refuses to compile one that does) and must not be given
an array a callee allocated (it would never be freed); it reads and writes the arrays it is passed.
With counting every array read from the kernels' structures was counted in and out at each use: one
evaluation of the Panda's IK pose errors and Jacobian took 1.5 us with it and 0.3 us without (min of
15 runs of 2 x 10^4 evaluations); the babbling loop compiled 0.7 s faster and ran 8-49 % faster.
"""
REFCOUNTED: dict[str, Any] = _refcount_option(True)
"""Reference counting stated (see :func:`njit`)."""
OVERLOAD_OPTIONS: Any = {"nogil": True, "error_model": "numpy", **REFCOUNTED}
"""``jit_options`` of gb_pin's ``@overload`` implementations: the kernels' options, counting stated."""


def njit(*args: Any, **options: Any) -> Any:
    """numba's ``njit``, with reference counting stated for every gb_pin kernel (on unless given).

    numba compiles a kernel met during another kernel's compilation with the caller's ``nrt`` flag
    unless the kernel states its own. Kernels without counting (:data:`NO_REFCOUNT`: the IK's, the
    babbling loop :func:`~gb_pin.learn.loop.babble_loop`) call kernels that allocate (e.g.
    :func:`~gb_pin.learn.metrics.reach_median`); stating it for every kernel compiles each the same
    way whichever caller or process (the cold start's helper) compiles it first.
    """
    for key, value in REFCOUNTED.items():
        options.setdefault(key, value)
    return _numba_njit(*args, **options)


__all__ = [
    "INSTALLED",
    "KERNEL_FILES",
    "NO_REFCOUNT",
    "OVERLOAD_OPTIONS",
    "REFCOUNTED",
    "kernel_stamp",
    "njit",
]
