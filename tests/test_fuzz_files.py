"""Every file reader fuzzed and every class of issue 24 probed (tests/fuzz_files.py, CI-sized).

Each probe runs in a process of its own under a time and memory limit, and must end as it
should: success where success is right, else gb_pin's own error, within the probe's time and peak
memory (measured per probe with os.wait4); the slow probes (large files, full benchmark runs)
are left to the large run, ``python tests/fuzz_files.py --probes 2000 --seed 1 --large --table``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

HARNESS = Path(__file__).with_name("fuzz_files.py")
READERS = {"result", "result_urdf", "checkpoint", "session", "journal", "trials", "sweep", "points_csv",
           "points_npy", "ik_targets", "preset", "urdf", "plot_result", "plot_trials", "srdf",
           "doc", "meshes"}  # fmt: skip
CLASSES = {"0 mutations", "1 bounds", "2 integers", "3 wrong files", "4 failed writes", "5 processes",
           "6 MODULE:NAME", "7 viewer server", "8 robot descriptions", "9 messages", "10 viewer backpressure",
           "11 plant", "12 interrupts", "13 memory", "14 onboarding", "15 kernel files", "16 silent values",
           "17 disk"}  # fmt: skip


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_every_reader_and_every_class_answers_with_success_or_gb_pins_error(tmp_path: Path) -> None:
    """12 mutated files per reader and every quick targeted probe: no other outcome, none too slow or big."""
    proc = subprocess.run(
        [sys.executable, str(HARNESS), "--probes", "12", "--seed", "0", "--quick"],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=tmp_path,
    )
    counts = json.loads(proc.stdout.strip().splitlines()[-1])
    owned = {k: c for k, c in counts["readers"].items() if "(" not in k}  # "(ik)", "(lead)": fixed elsewhere
    failures = {k: c["failures"] for k, c in owned.items() if c["other"]}
    assert not failures, failures
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert set(owned) >= READERS, sorted(owned)
    assert {k for k in counts["classes"] if "(" not in k} >= CLASSES, sorted(counts["classes"])
    assert all(c["tried"] >= 2 for k, c in owned.items() if k in READERS), owned
