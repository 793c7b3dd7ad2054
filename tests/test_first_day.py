"""What a first day with gb_pin tripped on (issue 35): continued runs' E_0, no-clobber outputs, messages."""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main


def test_a_continued_run_measures_e_x_against_the_home_estimates_e0(tmp_path: Path) -> None:
    """babble(init=...) keeps the first run's E_0 (q_home's), through files and further continuations.

    The continued run's own movement 0 is the previous estimate (about 1.5 % of E_0 for planar20),
    which made a healthy run look degenerate ("E^X is 69 % of E_0").
    """
    first = gb_pin.babble("planar5", movements=300, seed=0)
    e0 = first.history.initial_error
    assert first.home_error is None and first.initial_error == e0
    more = gb_pin.babble("planar5", movements=150, init=first)
    assert more.initial_error == e0 and more.history.error[0] < 0.5 * e0
    assert more.diagnose() is None  # learned: E^X far below half of E_0
    assert f"{more.error / e0:.1%} of E_0" in repr(more)
    path = tmp_path / "more.npz"
    more.save(path)
    loaded = gb_pin.load_result(path)
    assert loaded.initial_error == e0
    again = gb_pin.babble("planar5", movements=100, init=loaded)
    assert again.initial_error == e0
    np.testing.assert_array_equal(more.history.error, loaded.history.error)


def test_cli_continue_prints_e0_of_home_and_no_degenerate_warning(tmp_path: Path, capsys: Any) -> None:
    """`gb-pin babble --continue run.npz`: E^X against the first run's E_0, no false warning."""
    first = tmp_path / "run.npz"
    assert main(["babble", "--robot", "planar20", "--movements", "400", "--quiet", "--out", str(first)]) == 0
    head = capsys.readouterr().out
    e0_line = next(line for line in head.splitlines() if line.startswith("E^X"))
    e0 = e0_line.split("E_0 = ")[1].split(" m")[0]
    assert main(["babble", "--continue", str(first), "--movements", "200", "--quiet"]) == 0
    out, err = capsys.readouterr()
    assert f"E_0 = {e0} m" in out and "degenerate" not in err


def test_out_is_never_clobbered_without_overwrite(tmp_path: Path, capsys: Any) -> None:
    """A second run with the same --out refuses before babbling, in one line naming the file; --overwrite."""
    out = tmp_path / "run.npz"
    args = ["babble", "--robot", "planar5", "--movements", "30", "--quiet", "--out", str(out)]
    assert main(args) == 0
    before = out.read_bytes()
    capsys.readouterr()
    assert main([*args[:4], "50", *args[5:]]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(out) in err and "--overwrite" in err
    assert out.read_bytes() == before
    assert main([*args[:4], "50", *args[5:], "--overwrite"]) == 0
    assert gb_pin.load_result(out).movements == 50
    assert main([*args[:4], "40", *args[5:], "--force"]) == 0
    assert gb_pin.load_result(out).movements == 40


def test_point_files_name_themselves_when_empty_or_of_the_wrong_width(tmp_path: Path, capsys: Any) -> None:
    """An empty CSV says so (not "got float64 (0, 0)"); a wrong column count names the file and option."""
    empty = tmp_path / "empty.csv"
    empty.write_text("# nothing\n\n")
    assert main(["babble", "--robot", "planar5", "--movements", "10", "--targets", str(empty)]) == 2
    err = capsys.readouterr().err
    assert "--targets" in err and "empty.csv" in err and "no points" in err and "(0, 0)" not in err
    wide = tmp_path / "wide.csv"
    wide.write_text("0.1,0.2,0.3\n0.2,0.1,0.3\n")
    assert main(["babble", "--robot", "planar5", "--movements", "10", "--targets", str(wide)]) == 2
    err = capsys.readouterr().err
    assert "--targets" in err and "wide.csv" in err and "3" in err and len(err.strip().splitlines()) == 1


def test_robots_frames_lists_joints_and_frames_of_any_robot(tmp_path: Path, capsys: Any) -> None:
    """`gb-pin robots --frames ROBOT` for a preset, an erd:NAME model and a URDF file."""
    assert main(["robots", "--frames", "planar5"]) == 0
    out = capsys.readouterr().out
    assert "joint5" in out and re.search(r"\*\s+tip", out)
    assert main(["robots", "--frames", "erd:z1"]) == 0
    out = capsys.readouterr().out
    assert "link06" in out and "revolute" in out
    urdf = Path(__file__).parent / "data" / "small_arm.urdf"
    if urdf.exists():
        assert main(["robots", "--frames", str(urdf)]) == 0
        assert "tool" in capsys.readouterr().out
    assert main(["robots", "--frames", "erd:no_such_robot"]) == 2


def test_onboarding_prints_the_chosen_joints_and_home() -> None:
    """print(arm.onboarding) shows the joints and home, not a dataclass's fields."""
    arm = gb_pin.KinematicTarget.from_example_robot_data("z1", "link06")
    text = str(arm.onboarding)
    assert ",".join(arm.joints) in text
    assert f"{arm.home[0]:.3f}" in text and "radius" in text and not math.isnan(arm.onboarding.margin)


def test_malformed_urdf_prints_one_line_without_urdfdoms_stderr(tmp_path: Path, capfd: Any) -> None:
    """urdfdom's C++ errors are captured into gb-pin's one line, not printed before it."""
    bad = tmp_path / "bad.urdf"
    bad.write_text(
        '<robot name="x"><link name="a"/><joint name="j" type="revolute"><parent link="a"/></joint></robot>'
    )
    assert main(["babble", "--robot", str(bad), "--frame", "a", "--movements", "5"]) == 2
    err = capfd.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("gb-pin: error:")


@pytest.mark.parametrize("task", ["pose", "pointing"])
@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_cli_task_for_a_model_robot(task: str, capsys: Any) -> None:
    """`--task pose|pointing` for one's own robot: the task vector's components are printed."""
    args = ["babble", "--robot", "erd:panda", "--frame", "panda_hand", "--task", task, "--movements", "20"]
    assert main([*args, "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "orientation" in out or "pointing" in out


def test_exported_inverse_read_with_numpy_alone_predicts_as_result_inverse(tmp_path: Path) -> None:
    """examples/numpy_inverse.py's reader (numpy only) gives result.inverse's postures to 1e-12."""
    import importlib.util
    import subprocess
    import sys

    example = Path(__file__).resolve().parents[1] / "examples" / "numpy_inverse.py"
    spec = importlib.util.spec_from_file_location("numpy_inverse", example)
    assert spec is not None and spec.loader is not None
    reader = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(reader)
    source = example.read_text()
    assert "import gb_pin" not in source and "numba" not in source.split('"""')[2]
    for robot, targets in (("planar5", None), ("talos_left_arm_pose", None), ("so101", "workspace")):
        result = gb_pin.babble(robot, movements=200, seed=1, targets=targets)  # so101: a truncated map
        path = result.export_inverse(tmp_path / f"{robot}.npz")
        inverse = reader.load_inverse(path)
        X = np.vstack([result.targets, result.targets[:3] + 0.01])
        np.testing.assert_allclose(inverse(X), result.inverse(X), rtol=0, atol=1e-12)
        np.testing.assert_allclose(inverse(X[0]), result.inverse(X[0]), rtol=0, atol=1e-12)
        with np.load(path, allow_pickle=False) as f:  # plain arrays, no pickle
            assert list(f["joints"]) == list(result.target.joints)
    args = [sys.executable, str(example), str(tmp_path / "planar5.npz"), "0.5", "0.1"]
    done = subprocess.run(args, capture_output=True, text=True, timeout=120, check=False)
    assert done.returncode == 0 and len(done.stdout.split()) == 5


def test_pose_target_turns_position_and_quaternion_into_the_task_vector() -> None:
    """pose_target(robot, p, quat) equals the task map at a posture whose frame has that pose."""
    import pinocchio as pin

    from gb_pin.ik import pose_target
    from gb_pin.ik.pose import log3, quaternion_matrix

    rng = np.random.default_rng(3)
    joints = [f"panda_joint{i}" for i in range(1, 8)]
    for task, extra in (("pose", {}), ("pointing", {"pointing_axis": "-z"}), (None, {})):
        arm = gb_pin.KinematicTarget.from_example_robot_data(
            "panda", "panda_hand", joints, "default", task=task, onboard=False, **extra
        )
        for _ in range(10):
            q = rng.uniform(arm.lower, arm.upper)
            pin.framesForwardKinematics(arm.model, arm.data, arm.to_pinocchio(q))
            M = arm.data.oMf[arm.frame_id]
            xyzw = pin.Quaternion(M.rotation).coeffs()
            np.testing.assert_allclose(pose_target(arm, M.translation, xyzw), arm.forward(q), atol=1e-9)
            wxyz = np.roll(xyzw, 1)
            np.testing.assert_allclose(
                pose_target(arm, M.translation, wxyz, order="wxyz"), arm.forward(q), atol=1e-9
            )
    for _ in range(50):
        R = pin.exp3(rng.normal(size=3) * 1.5)
        np.testing.assert_allclose(log3(R), pin.log3(R), atol=1e-9)
        np.testing.assert_allclose(quaternion_matrix(pin.Quaternion(R).coeffs()), R, atol=1e-12)
    pose = gb_pin.KinematicTarget.from_example_robot_data(
        "panda", "panda_hand", joints, "default", task="pose"
    )
    with pytest.raises(gb_pin.InvalidArgumentError, match="quaternion"):
        pose_target(pose, [0.1, 0.2, 0.3], [0, 0, 0, 0])
    with pytest.raises(gb_pin.InvalidArgumentError, match="give a quaternion"):
        pose_target(pose, [0.1, 0.2, 0.3])


def test_cli_ik_takes_a_pose(tmp_path: Path, capsys: Any) -> None:
    """`gb-pin ik run.npz --pose X Y Z QX QY QZ QW` solves the pose task's target of that hand pose."""
    run = tmp_path / "pose.npz"
    args = ["babble", "--robot", "talos_left_arm_pose", "--movements", "100", "--quiet", "--out", str(run)]
    assert main(args) == 0
    result = gb_pin.load_result(run)
    import pinocchio as pin

    arm = result.target
    q = arm.home + 0.05
    pin.framesForwardKinematics(arm.model, arm.data, arm.to_pinocchio(q))
    M = arm.data.oMf[arm.frame_id]
    pose = [*M.translation, *pin.Quaternion(M.rotation).coeffs()]
    capsys.readouterr()
    assert main(["ik", str(run), "--pose", *(f"{v:.12f}" for v in pose), "--timeout", "0.05"]) == 0
    assert "1/1 solved" in capsys.readouterr().out


def test_robots_md_lists_every_preset() -> None:
    """docs/ROBOTS.md's `gb-pin robots` listing shows every preset, as the command prints it."""
    from gb_pin.robot.presets import format_presets

    text = (Path(__file__).resolve().parents[1] / "docs" / "ROBOTS.md").read_text()
    listing = text.split("`gb-pin robots` prints:\n\n```\n", 1)[1].split("```", 1)[0]
    for line in format_presets().splitlines():
        assert line in listing.splitlines(), f"docs/ROBOTS.md's listing lacks: {line}"


def test_robots_md_results_table_has_every_preset() -> None:
    """docs/ROBOTS.md's results table (`gb-pin robots --benchmark`) has a row for every preset.

    Its axes as `gb-pin robots` labels them (xyz+R, xyz+d, xyz+xyz for the task presets).
    """
    from gb_pin.robot.presets import format_presets

    text = (Path(__file__).resolve().parents[1] / "docs" / "ROBOTS.md").read_text()
    table = text.split("<!-- robots-benchmark:begin", 1)[1].split("<!-- robots-benchmark:end", 1)[0]
    rows = {line.split("|")[1].strip(): line.split("|")[4].strip() for line in table.splitlines()[4:]}
    for line in format_presets().splitlines()[1:]:
        name, axes = line.split()[0], line.split()[2]
        names = ["planar5", "planar20"] if name == "planarN" else [name]
        for n in names:
            assert rows.get(n) == axes, f"docs/ROBOTS.md's results table: {n} {rows.get(n)!r}, not {axes}"


def test_checkpoint_of_another_run_is_never_clobbered(tmp_path: Path, capsys: Any) -> None:
    """A new run given an existing --checkpoint refuses before any work (--resume continues it)."""
    ckpt = tmp_path / "run.ckpt"
    args = ["babble", "--robot", "planar5", "--movements", "20", "--quiet", "--checkpoint", str(ckpt)]
    assert main(args) == 0
    before = ckpt.read_bytes()
    capsys.readouterr()
    assert main([*args[:4], "10", *args[5:]]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(ckpt) in err and "--resume" in err and "--overwrite" in err
    assert ckpt.read_bytes() == before
    assert main(["babble", "--resume", str(ckpt), "--quiet"]) == 0  # what the line offers works
    assert main([*args[:4], "10", *args[5:], "--overwrite"]) == 0
    from gb_pin.runs.checkpoint import read_checkpoint

    assert read_checkpoint(ckpt)[1].movements == 10


def _refuses(argv: list[str], existing: Path, capsys: Any) -> None:
    """The command exits 2 with one line naming ``existing`` and --overwrite; the file is untouched."""
    existing.write_bytes(b"keep me")
    capsys.readouterr()
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert str(existing) in err and "--overwrite (or --force)" in err and "exists" in err
    assert existing.read_bytes() == b"keep me"


LONG = ["--trials", "100000", "--movements", "1000000"]  # hours of work, if the check came after it


@pytest.mark.parametrize(
    "command",
    [
        "trials --robot planar5 {LONG} --json {F}",
        "robots --benchmark --robots planar5 {LONG} --json {F}",
        "robots --benchmark --robots planar5 {LONG} --figure {F}",
        "replay {D}/missing.npz --html {F}",
        "show {D}/missing.npz --html {F}",
        "plot {D}/missing.npz -o {F}",
        "plot {D}/curve.npz",  # the default figure, FILE.png
        "reproduce fig3 fig5 {LONG} --out {D}",
        "reproduce hardware {LONG} --out {D}",
        "reproduce workspace {LONG} --out {D}",
        "reproduce goals {LONG} --out {D}",
        "babble --robot so101 --arm feetech:port={D}/tty,calibration={D}/cal.json --tracker {D}/trk.py:hand "
        "--movements 1000000 --out {F}",
    ],
)
def test_every_output_file_is_refused_before_work_unless_overwrite(
    command: str, tmp_path: Path, capsys: Any
) -> None:
    """Every command that writes a file refuses an existing one before any work, as `babble --out` does.

    The runs asked for here would take hours: the check comes first. Same option, same message.
    """
    (tmp_path / "trk.py").write_text("def hand():\n    return None\n")
    existing = tmp_path / "out.file"
    defaults = {
        "plot {D}/curve.npz": "curve.png",
        "reproduce fig3": "fig5.png",
        "reproduce hardware": "hardware.md",
        "reproduce workspace": "workspace.md",
        "reproduce goals": "goals.md",
    }
    for start, name in defaults.items():
        if command.startswith(start):
            existing = tmp_path / name
    argv = (
        command.replace("{LONG}", " ".join(LONG)).replace("{F}", str(existing)).replace("{D}", str(tmp_path))
    )
    _refuses(argv.split(), existing, capsys)


def test_overwrite_replaces_the_files_of_plot_and_trials(tmp_path: Path, capsys: Any) -> None:
    """--overwrite (or --force) lets the output replace the file, as for babble --out."""
    trials, figure = tmp_path / "trials.json", tmp_path / "trials.png"
    args = ["trials", "--robot", "planar5", "--trials", "2", "--movements", "20", "--quiet", "--workers", "1"]
    assert main([*args, "--json", str(trials)]) == 0
    _refuses([*args, "--json", str(trials)], trials, capsys)
    assert main([*args, "--json", str(trials), "--force"]) == 0
    assert gb_pin.TrialSet.load(trials).movements[-1] == 20
    assert main(["plot", str(trials)]) == 0 and figure.stat().st_size > 0
    _refuses(["plot", str(trials)], figure, capsys)
    assert main(["plot", str(trials), "--overwrite"]) == 0 and figure.read_bytes()[:4] == b"\x89PNG"


def test_tune_presets_refuses_an_existing_out(tmp_path: Path, capsys: Any, monkeypatch: Any) -> None:
    """scripts/tune_presets.py --out: the same rule (it rewrites its tables there after each preset)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(
        "tune_presets", Path(__file__).parents[1] / "scripts/tune_presets.py"
    )
    assert spec is not None and spec.loader is not None
    tune = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "tune_presets", tune)  # its dataclasses look their module up
    spec.loader.exec_module(tune)
    out = tmp_path / "tune.md"
    out.write_text("keep me")
    with pytest.raises(SystemExit) as exc:
        tune.main(["--robots", "so101", "--seeds", "1000", "--out", str(out)])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert str(out) in err and "--overwrite (or --force)" in err and out.read_text() == "keep me"
