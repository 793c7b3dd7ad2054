"""Every file reader over mutated real files (tests/fuzz_files.py, CI-sized): success or gb_pin's error."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

HARNESS = Path(__file__).with_name("fuzz_files.py")


def test_every_file_reader_answers_mutated_files_with_success_or_its_own_error(tmp_path: Path) -> None:
    """25 probes per reader (results, checkpoints, journals, trial sets, presets), each under an alarm."""
    proc = subprocess.run(
        [sys.executable, str(HARNESS), "--probes", "25", "--seed", "0"],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
    )
    counts = json.loads(proc.stdout.strip().splitlines()[-1])
    failures = {kind: c["failures"] for kind, c in counts.items() if c["failed"]}
    assert not failures, failures
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert all(c["tried"] >= 20 for c in counts.values()), counts
