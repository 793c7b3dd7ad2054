"""`gb-pin babble --plant/--sensor/--max-joint-step`: robots that are not their model, from the CLI."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main
from gb_pin.robot.plant import Plant


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_a_plant_run_saves_rebuilds_and_resumes_its_robot(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """--plant miscalibrated: missing readings counted; the file and the checkpoint rebuild the plant."""
    out, ckpt = tmp_path / "run.npz", tmp_path / "run.ckpt"
    args = ["babble", "--robot", "so101", "--plant", "miscalibrated:noise=0.0015,loss=0.1,seed=3",
            "--movements", "120", "--quiet", "--out", str(out), "--checkpoint", str(ckpt)]  # fmt: skip
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "missing readings" in text and "reach (observed)" in text
    result = gb_pin.load_result(out)
    assert isinstance(result.target, Plant) and result.missing > 0
    plant = Plant("so101", offset_std=np.radians(3), length_std=0.03, noise=0.0015, loss=0.1, seed=3)
    np.testing.assert_array_equal(result.target.chain.rotations, plant.chain.rotations)
    ref = gb_pin.babble(plant, movements=120, seed=0)
    np.testing.assert_array_equal(result.history.error, ref.history.error)  # the preset's learner defaults
    np.testing.assert_array_equal(result.history.reach, ref.history.reach)
    assert gb_pin.resume(ckpt).movements == 120  # the checkpoint rebuilds the plant alone


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_sensor_and_step_limit_options_reach_the_run(capsys) -> None:  # type: ignore[no-untyped-def]
    """--sensor noise=,loss=,seed= and --max-joint-step give the run babble() gives."""
    assert main(["babble", "--robot", "planar5", "--movements", "60", "--quiet", "--sensor",
                 "noise=0.001,loss=0.2,seed=4", "--max-joint-step", "0.03"]) == 0  # fmt: skip
    text = capsys.readouterr().out
    ref = gb_pin.babble("planar5", movements=60, sensor=gb_pin.Sensor(0.001, 0.2, 4), max_joint_step=0.03)
    assert f"{ref.error:.5f}" in text and f"missing readings {ref.missing} " in text


@pytest.mark.parametrize(
    ("option", "value", "message"),
    [
        ("--plant", "mujocoo", "unknown kind 'mujocoo'"),
        ("--plant", "miscalibrated:ofsets=3", "unknown key 'ofsets'"),
        ("--plant", "miscalibrated:loss=1.5", "loss"),
        ("--sensor", "noise=x", "noise must be a finite number"),
        ("--sensor", "noise=-1", "noise"),
        ("--max-joint-step", "-0.1", "max_joint_step"),
    ],
)
def test_bad_body_options_are_one_line_errors(capsys, option: str, value: str, message: str) -> None:  # type: ignore[no-untyped-def]
    """Unknown kinds and keys, bad values: exit 2, one line naming them."""
    assert main(["babble", "--robot", "so101", "--movements", "5", "--quiet", option, value]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_young_maps_observed_reach_is_not_printed_as_a_figure(capsys) -> None:  # type: ignore[no-untyped-def]
    """history.reach estimates the noise's share with the learned Jacobian: a young map's is not a figure.

    After 3 movements the estimate is 8.2 m for goals 0.21 m across (measured); after 300 it is a figure.
    """
    args = [
        "babble",
        "--robot",
        "so101",
        "--plant",
        "miscalibrated:noise=0.0015,loss=0.1,seed=3",
        "--movements",
    ]
    assert main([*args, "3"]) == 0
    line = next(r for r in capsys.readouterr().out.splitlines() if r.startswith("reach (observed)"))
    assert "not yet meaningful" in line and "3 movements" in line
    assert main([*args, "300", "--quiet"]) == 0
    line = next(r for r in capsys.readouterr().out.splitlines() if r.startswith("reach (observed)"))
    assert "median miss" in line and float(line.split()[2]) < 0.02
