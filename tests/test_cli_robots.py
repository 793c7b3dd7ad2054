"""Every command takes every robot, and what a newcomer tripped on (issue 25).

babble, trials, bench, reproduce goals, show, replay, plot and ik accept a preset, a URDF file,
``erd:NAME`` or ``MODULE:NAME`` with the same options; results rebuild their robot or say in one
line what to pass; a finished run can be extended; a degenerate run ends with a warning that
names its cause.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import build_parser, main

SMALL_URDF = Path(__file__).parent / "data" / "small_arm.urdf"
README_COMMAND = ["--robot", str(SMALL_URDF), "--frame", "tool", "--joints", "j1,j2,j3"]


def test_the_readmes_urdf_command_works_verbatim_and_prints_what_was_chosen(
    tmp_path: Path, capsys: Any
) -> None:
    """`gb-pin babble --robot my_arm.urdf --frame tool --joints j1,j2,j3` on the test arm learns.

    It failed with "the home is at the border of the workspace" (the reference posture, the arm
    stretched out). Now home, grid, radius and sigma are chosen and printed with the options that
    set them; 1000 movements end below 0.15 E_0 (measured: 0.5 % of E_0).
    """
    out = tmp_path / "arm.npz"
    assert main(["babble", *README_COMMAND, "--quiet", "--out", str(out)]) == 0
    text = capsys.readouterr()
    assert "chosen           by measurement (give --home, --targets, --radius, --sigma" in text.out
    assert "home      " in text.out and "radius    " in text.out and "warning" not in text.err
    result = gb_pin.load_result(out)
    assert result.error <= 0.15 * result.history.error[0]
    assert result.target.onboarding is not None and result.target.onboarding.sigma is not None


def test_babble_help_has_a_description_and_examples() -> None:
    """`gb-pin babble --help` says what it does and shows commands for every kind of robot."""
    text = build_parser()._subparsers._group_actions[0].choices["babble"].format_help()  # type: ignore[union-attr]
    assert "Learn a robot's inverse kinematics" in text and "examples:" in text
    for example in (
        "--robot planar20",
        "erd:z1 --frame link06",
        "my_arm.urdf",
        "continuum_arm.py:robot",
        "--continue",
    ):
        assert example in text


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_trials_take_a_model_robot_and_each_worker_rebuilds_it(tmp_path: Path, capsys: Any) -> None:
    """`gb-pin trials --robot FILE.urdf --frame ...`: "unknown robot" before; trial i = babble with seed i.

    Each task carries the onboarded robot's source, which the worker rebuilds (no measuring; here
    in this process: a pool only adds the processes), and trial 0 is the babble run of seed 0.
    """
    args = ["trials", *README_COMMAND, "--trials", "2", "--movements", "40", "--quiet", "--workers", "1"]
    assert main([*args, "--json", str(tmp_path / "t.json")]) == 0
    assert "chosen" in capsys.readouterr().out
    trials = gb_pin.TrialSet.load(tmp_path / "t.json")
    arm = gb_pin.KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j2", "j3"])
    run = gb_pin.babble(arm, movements=40, seed=0, schedule=trials.movements)
    np.testing.assert_array_equal(trials.error[0], run.history.error)


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_show_replay_plot_ik_bench_take_every_robot(tmp_path: Path, capsys: Any) -> None:
    """A robot loaded from code: plot needs no robot; show, replay, ik take --robot; bench takes a URDF."""
    module = tmp_path / "arm.py"
    module.write_text(
        "import gb_pin\n"
        f"robot = gb_pin.KinematicTarget.from_urdf({str(SMALL_URDF)!r}, 'tool', ['j1', 'j2', 'j3'])\n"
    )
    spec = f"{module}:robot"
    out = tmp_path / "m.npz"
    assert (
        main(
            [
                "babble",
                "--robot",
                spec,
                "--movements",
                "20",
                "--quiet",
                "--record-every",
                "5",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    assert main(["plot", str(out), "-o", str(tmp_path / "m.png")]) == 0
    for command in (
        ["show", str(out), "--html", str(tmp_path / "s.html")],
        ["replay", str(out), "--html", str(tmp_path / "r.html")],
    ):
        assert main(command) == 2 and "--robot" in capsys.readouterr().err
        assert main([*command, "--robot", spec]) == 0
    x = gb_pin.load_result(out, target=gb_pin.robot.spec.load_robot_spec(spec)).targets[0]
    assert main(["ik", str(out), *map(str, x), "--robot", spec]) == 0
    assert (
        main(
            [
                "bench",
                "--robots",
                f"planar3,{SMALL_URDF}",
                "--frame",
                "tool",
                "--joints",
                "j1,j2,j3",
                "--movements",
                "20",
                "--repeat",
                "1",
            ]
        )
        == 0
    )
    assert "| small_arm | 20 |" in capsys.readouterr().out


def test_a_finished_run_is_extended_from_the_command_line(tmp_path: Path, capsys: Any) -> None:
    """`gb-pin babble --continue run.npz --movements N` continues as babble(init=result) does, bit for bit."""
    first = tmp_path / "run.npz"
    assert (
        main(
            [
                "babble",
                "--robot",
                "planar5",
                "--movements",
                "200",
                "--learning-rate",
                "0.3",
                "--quiet",
                "--out",
                str(first),
            ]
        )
        == 0
    )
    more = tmp_path / "more.npz"
    assert (
        main(["babble", "--continue", str(first), "--movements", "100", "--quiet", "--out", str(more)]) == 0
    )
    assert "seed continued" in capsys.readouterr().out
    start = gb_pin.babble("planar5", movements=200, learning_rate=0.3, seed=0)
    expected = gb_pin.babble("planar5", movements=100, learning_rate=0.3, init=start)
    continued = gb_pin.load_result(more)
    np.testing.assert_array_equal(continued.history.error, expected.history.error)
    assert continued.config.learning_rate == 0.3  # the run's own hyperparameters
    assert main(["babble", "--continue", str(first), "--seed", "3"]) == 2
    assert "drop --seed" in capsys.readouterr().err


def test_a_degenerate_run_ends_with_a_warning_naming_the_cause(capsys: Any) -> None:
    """A home on a joint limit (the small arm's j1 at 2 rad): the warning names the joint and what to try."""
    assert (
        main(
            [
                "babble",
                "--robot",
                str(SMALL_URDF),
                "--frame",
                "tool",
                "--joints",
                "j1,j2,j3",
                "--home",
                "2.0,0.0,0.0",
                "--targets",
                str(_grid_file()),
                "--movements",
                "100",
                "--quiet",
                "--sigma",
                "0.0001",
            ]
        )
        == 0
    )
    err = capsys.readouterr().err
    assert (
        "the run stayed degenerate" in err and "j1" in err and "at a joint limit" in err and "--home" in err
    )
    assert main(["babble", "--robot", "planar5", "--movements", "200", "--quiet"]) == 0
    assert "degenerate" not in capsys.readouterr().err  # a run that learns: no warning


def _grid_file() -> Path:
    """Targets around the small arm's tool at the home (2, 0, 0) over j1, j2, j3, in a .npy file."""
    arm = gb_pin.KinematicTarget.from_urdf(
        SMALL_URDF, "tool", ["j1", "j2", "j3"], home=[2.0, 0.0, 0.0], onboard=False
    )
    path = Path(__file__).parent / ".cache_degenerate_targets.npy"
    np.save(path, arm.home_position + 0.05 * np.eye(3))
    return path


def test_repr_of_a_result_fits_in_20_lines() -> None:
    """repr(result) was 17.5 kB of arrays; it is a summary: robot, run, errors, shapes."""
    result = gb_pin.babble("planar20", movements=300, seed=0, record=gb_pin.Recording(every=1))
    text = repr(result)
    assert len(text.splitlines()) <= 20 and len(text) < 2000
    assert "planar20" in text and "n_prototypes=" in text and "targets=<25 x 2 array>" in text


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (
            ["show", "CKPT", "--html", "x.html"],
            "a checkpoint, not a result file: finish its run with `gb-pin babble --resume",
        ),
        (["plot", "CKPT"], "--resume"),
        (["babble", "--goals", "uniform:snp=0.1", "--movements", "5"], "did you mean 'snap'"),
        (["babble", "--robot", "erd:z1", "--movements", "5"], "needs --frame"),
    ],
)
def test_what_a_newcomer_tripped_on_is_one_clear_line(
    argv: list[str], needle: str, tmp_path: Path, capsys: Any
) -> None:
    """Checkpoints shown or plotted point to --resume; a misspelt goal parameter gets a did-you-mean."""
    ckpt = tmp_path / "run.ckpt"
    gb_pin.babble("planar3", movements=5, seed=0, checkpoint=ckpt)
    argv = [str(ckpt) if a == "CKPT" else str(tmp_path / a) if a.endswith(".html") else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    if "needs --frame" in needle:
        assert "link06" in err  # the frames at the ends of the model's chains are listed


def test_view_says_it_waits_and_names_view_wait(monkeypatch: pytest.MonkeyPatch, capsys: Any) -> None:
    """`--view` waited 60 s silently for a browser: it says so and names --view-wait."""
    pytest.importorskip("meshcat")
    import gb_pin.viewer

    class Stub:
        url = "http://127.0.0.1:7000/static/"

        def wait_for_browser(self, timeout: float) -> bool:
            return False

    monkeypatch.setattr(gb_pin.viewer, "open_viewer", lambda *a, **k: Stub())
    from gb_pin.cli.babble import _start_viewer

    args = build_parser().parse_args(["babble", "--view", "--view-wait", "0.01"])
    _start_viewer(args)
    out = capsys.readouterr().out
    assert "waiting up to 0.01 s for a browser" in out and "--view-wait" in out


def test_the_goal_study_takes_a_model_robot(tmp_path: Path) -> None:
    """`gb-pin reproduce goals --robot ...`: conditions on the onboarded robot, cached by its source.

    The cache key holds the robot source (its chain's digest): another robot, or the same model with
    other joints, never reads these trials.
    """
    from gb_pin.reproduce.goals import _cache_file, study_conditions

    arm = gb_pin.KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j2", "j3"])
    rows = study_conditions(arm, 300)
    assert [label for label, _, _ in rows][:2] == ["uniform on X*", "uniform on O"]
    label, condition, _ = rows[0]
    assert condition.label.startswith("small_arm ") and condition.to_json()["robot_source"]["kind"] == "urdf"
    other = gb_pin.KinematicTarget.from_urdf(
        SMALL_URDF, "tool", ["j1", "j2", "j4"], [0.3, -0.5, 1.0], onboard=False
    )
    other.targets = other.home_position + 0.02 * np.eye(3)
    other_condition = study_conditions(other, 300)[0][1]
    assert _cache_file(str(tmp_path), label, condition, 5, 0) != _cache_file(
        str(tmp_path), label, other_condition, 5, 0
    )
    assert main(["reproduce", "fig3", "--robot", "planar5", "--out", str(tmp_path)]) == 2  # goals only


def test_srdf_named_postures_from_the_command_line(tmp_path: Path, capsys: Any) -> None:
    """`--srdf FILE --home NAME`: the SRDF's posture is the home (the rest chosen); not with erd:NAME."""
    out = tmp_path / "ready.npz"
    srdf = SMALL_URDF.with_suffix(".srdf")
    argv = ["babble", "--robot", str(SMALL_URDF), "--frame", "tool", "--srdf", str(srdf), "--home", "ready"]
    assert main([*argv, "--movements", "20", "--quiet", "--out", str(out)]) == 0
    assert "  home      " not in capsys.readouterr().out  # given, not chosen
    np.testing.assert_allclose(gb_pin.load_result(out).target.home, [0.3, -0.5, 0.05, 1.0], atol=1e-15)
    assert main(["babble", "--robot", "erd:z1", "--frame", "link06", "--srdf", str(srdf)]) == 2
    assert "--srdf: only with --robot FILE.urdf" in capsys.readouterr().err
