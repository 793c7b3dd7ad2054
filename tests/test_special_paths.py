"""Paths read back from files that name kernel files: refused, never read (a read could block forever).

Before (main 995bb8d) a result whose recorded robot path was ``/proc/kmsg`` (or a symlink to it)
blocked ``load_result``, ``show``, ``ik`` and ``replay`` forever: /proc and /sys files look
regular (size 0) to ``stat``, so the regular-file check let them through.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin._reading import read_bytes
from gb_pin.exceptions import InvalidArgumentError, ResultFileError

URDF = Path(__file__).resolve().parent / "data" / "small_arm.urdf"


@pytest.mark.parametrize(
    "path", ["/proc/self/status", "/proc/kmsg", "/sys/kernel/mm/transparent_hugepage/enabled"]
)
def test_kernel_files_and_links_to_them_are_refused(path: str, tmp_path: Path) -> None:
    if not os.path.exists(path):
        pytest.skip(f"{path} does not exist here")
    link = tmp_path / "link.urdf"
    link.symlink_to(path)
    for given in (path, link):
        with pytest.raises(InvalidArgumentError, match="a file of the kernel"):
            read_bytes(given, str(given), "URDF file", 2**20, InvalidArgumentError)


def test_a_result_recording_a_kernel_file_as_its_robot_fails_at_once(tmp_path: Path) -> None:
    arm = gb_pin.KinematicTarget.from_urdf(URDF, "tool")
    result = gb_pin.babble(arm, movements=20, seed=0)
    result.save(tmp_path / "run.npz")
    with np.load(tmp_path / "run.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    meta = json.loads(str(arrays["meta"]))
    (tmp_path / "robot.urdf").symlink_to("/proc/self/status")
    meta["robot_source"]["path"] = str(tmp_path / "robot.urdf")
    arrays["meta"] = np.array(json.dumps(meta))
    np.savez(tmp_path / "bent.npz", **arrays)
    start = time.perf_counter()
    with pytest.raises(ResultFileError, match="a file of the kernel"):
        gb_pin.BabbleResult.load(tmp_path / "bent.npz")
    assert time.perf_counter() - start < 5.0
