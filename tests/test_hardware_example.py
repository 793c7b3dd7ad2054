"""examples/so101_hardware_session.py: the hardware loop with a stand-in arm crashes and resumes."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "so101_hardware_session.py"


def test_the_hardware_example_crashes_resumes_and_reaches(tmp_path: Path) -> None:
    """--crash-at exits mid-run; --resume finishes and reports the three ways to reach."""
    ckpt = str(tmp_path / "so101.ckpt")
    run = [sys.executable, str(EXAMPLE), "--movements", "80", "--checkpoint", ckpt]
    crashed = subprocess.run(
        [*run, "--crash-at", "30"], capture_output=True, text=True, timeout=300, check=False
    )
    assert crashed.returncode == 3, crashed.stderr
    assert "crashed at movement 30" in crashed.stdout
    done = subprocess.run([*run, "--resume"], capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    assert "resumed at movement" in done.stdout
    for line in ("exact IK on the URDF", "learned, open loop", "learned + feedback", "readings missing"):
        assert line in done.stdout
