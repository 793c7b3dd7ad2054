"""Every ```python block of README.md runs as written, in a fresh interpreter in an empty folder.

A block that needs what a test machine lacks starts with a comment the test recognises:
``# needs: browser`` (a person looking at a page), ``# needs: my_arm.urdf`` (a file of the reader's).
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCK = re.compile(r"^```python\n(.*?)^```", re.M | re.S)


def python_blocks() -> list[str]:
    """The ```python blocks of README.md, in order."""
    return BLOCK.findall(README.read_text())


def _needs(block: str) -> str | None:
    first = block.lstrip().splitlines()[0] if block.strip() else ""
    match = re.match(r"#\s*needs:\s*(.+)", first)
    return match.group(1).strip() if match else None


def test_readme_has_python_blocks() -> None:
    """The README shows the API in several blocks, and most of them run here."""
    blocks = python_blocks()
    assert len(blocks) >= 6
    assert sum(_needs(b) is None for b in blocks) >= 5


@pytest.mark.parametrize("index", range(len(python_blocks())))
def test_readme_block_runs(index: int, tmp_path: Path) -> None:
    """Block ``index`` runs without error (imports included), in an empty folder."""
    block = python_blocks()[index]
    needs = _needs(block)
    if needs is not None:
        pytest.skip(f"README block {index} needs {needs}")
    done = subprocess.run(
        [sys.executable, "-c", block], cwd=tmp_path, capture_output=True, text=True, timeout=300, check=False
    )
    assert done.returncode == 0, f"README block {index}:\n{block}\n{done.stderr[-3000:]}"
