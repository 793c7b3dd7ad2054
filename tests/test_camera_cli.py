"""`gb-pin babble --sensor aruco:...`: learning in the camera's frame from the command line; errors."""

from __future__ import annotations

import pytest

pytest.importorskip("mujoco")
pytest.importorskip("cv2")

from gb_pin.cli import main


def _error(capsys, args: list[str]) -> str:  # type: ignore[no-untyped-def]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0, err  # one line, before anything moved
    return err


def test_camera_errors_are_one_line_before_anything_moves(capsys) -> None:  # type: ignore[no-untyped-def]
    base = ["babble", "--robot", "so101", "--movements", "5", "--quiet"]
    assert "cannot open camera 57" in _error(capsys, [*base, "--sensor", "aruco:size=0.025,camera=57"])
    assert "closest: size" in _error(capsys, [*base, "--sensor", "aruco:siz=0.025"])
    assert "plant that renders" in _error(capsys, [*base, "--sensor", "aruco:size=0.025"])
    assert "not seen at home" in _error(
        capsys, [*base, "--plant", "mujoco:camera=side,meshes=0", "--sensor", "aruco:size=0.025,id=3"]
    )


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
@pytest.mark.parametrize("mode", ["uv"])  # (xyz: tests/test_camera_plant.py)
def test_a_camera_run_from_the_cli(capsys, mode: str) -> None:  # type: ignore[no-untyped-def]
    """A few movements in the camera's frame (goals taught at the corners); pixels scaled by depth / f."""
    assert main(["babble", "--robot", "so101", "--plant", "mujoco:kp=10,camera=side,meshes=0",
                 "--sensor", f"aruco:size=0.025,id=7,mode={mode},readings=2", "--movements", "3",
                 "--quiet"]) == 0  # fmt: skip
    text = capsys.readouterr().out
    assert "camera           ArucoTracker" in text and " 0 without the marker" in text
    assert ("pixels x" in text and " px" in text) == (mode == "uv")
