"""gb_pin._jit: every kernel's cache is stamped with all kernel files, so no stale code is ever loaded."""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import pytest

import gb_pin
from gb_pin import _jit

PACKAGE = Path(gb_pin.__file__).parent


def _imports_njit(path: Path) -> bool:
    """Whether the module compiles code: njit, or numba intrinsics (LLVM IR inlined into kernels)."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and {"njit", "intrinsic"} & {a.name for a in node.names}:
            return True
        if isinstance(node, ast.Attribute) and node.attr == "njit":  # numba.njit
            return True
    return False


def _compiled_files() -> set[str]:
    return {
        p.relative_to(PACKAGE).as_posix()
        for p in PACKAGE.rglob("*.py")
        if p.name != "_jit.py"
        and ("njit" in p.read_text() or "intrinsic" in p.read_text())
        and _imports_njit(p)
    }


def test_the_kernel_files_list_is_complete() -> None:
    assert set(_jit.KERNEL_FILES) == _compiled_files()


def test_every_kernel_module_takes_njit_from_gb_pin_jit() -> None:
    for name in _compiled_files():
        tree = ast.parse((PACKAGE / name).read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == "numba":
                assert "njit" not in {a.name for a in node.names}, f"{name} imports njit from numba"


def test_gb_pin_kernels_use_the_stamp_of_all_kernel_files() -> None:
    from gb_pin.learn.loop import babble_loop

    assert _jit.INSTALLED
    locator = babble_loop._cache._impl._locator  # numba's cache of the loop
    assert getattr(type(locator), "gb_pin", False)
    assert locator.get_source_stamp() == _jit.kernel_stamp()


def test_the_stamp_changes_when_any_kernel_file_changes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    for name in _jit.KERNEL_FILES:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(PACKAGE / name, tmp_path / name)
    monkeypatch.setattr(_jit, "PACKAGE", str(tmp_path))
    _jit.kernel_stamp.cache_clear()
    try:
        before = _jit.kernel_stamp()
        with open(tmp_path / "learn/goals/kernel.py", "a") as f:  # a helper the loop inlines
            f.write("\n# edited\n")
        _jit.kernel_stamp.cache_clear()
        assert _jit.kernel_stamp() != before
    finally:
        monkeypatch.undo()
        _jit.kernel_stamp.cache_clear()
