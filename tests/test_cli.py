"""The gb-pin command line: babble, bench, robots, clean errors for bad input, options and imports."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main


def test_babble_prints_summary_and_saves(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin babble` ends with E^X, D^home, prototypes and wall time, and --out saves a loadable result."""
    out = tmp_path / "run.npz"
    code = main(["babble", "--robot", "planar5", "--movements", "30", "--seed", "3", "--out", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    for word in ("E^X", "D^home", "prototypes", "wall time"):
        assert word in text
    loaded = gb_pin.load_result(out)
    direct = gb_pin.babble("planar5", movements=30, seed=3)
    np.testing.assert_array_equal(loaded.history.error, direct.history.error)
    np.testing.assert_array_equal(loaded.inverse(loaded.targets), direct.inverse(direct.targets))


def test_bench_prints_a_table(capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin bench` runs and prints microseconds per step for each robot (no timing asserted)."""
    assert main(["bench", "--robots", "planar3", "--movements", "4", "--repeat", "1"]) == 0
    text = capsys.readouterr().out
    assert "us/step" in text
    assert "| planar3 | 4 | 100 |" in text


def test_robots_lists_planar(capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin robots` lists the planarN family."""
    assert main(["robots"]) == 0
    assert "planarN" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["babble", "--robot", "plnar5"], "plnar5"),
        (["babble", "--robot", "planar1"], "planar1"),
        (["babble", "--movements", "0"], "movements"),
        (["babble", "--learning-rate", "-1"], "learning_rate"),
        (["babble", "--learning-rate", "nan"], "learning_rate"),
        (["babble", "--radius", "0"], "radius"),
        (["babble", "--sigma", "-0.1"], "sigma"),
    ],
)
def test_bad_input_exits_2_without_traceback(argv, needle) -> None:  # type: ignore[no-untyped-def]
    """A user mistake prints one error line naming the value and exits with status 2."""
    proc = subprocess.run(
        [sys.executable, "-m", "gb_pin.cli", *argv, "--quiet"], capture_output=True, text=True, timeout=600
    )  # 600 s: under a load of 20 on two cores one such start took 124 s (issue 35)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert needle in proc.stderr


@pytest.mark.parametrize("command", ["babble", "trials"])
def test_learner_options_come_from_the_hyperparameter_table(command: str, capsys) -> None:  # type: ignore[no-untyped-def]
    """Each hyperparameter is an option of babble and trials: its name, type and help, default None."""
    from gb_pin.cli import build_parser
    from gb_pin.learn.config import HYPERPARAMETERS

    with pytest.raises(SystemExit) as exit_:
        main([command, "--help"])
    assert exit_.value.code == 0
    text = " ".join(capsys.readouterr().out.split())
    defaults = build_parser().parse_args([command])
    for h in HYPERPARAMETERS:
        assert h.option in text and " ".join(h.help.split()) in text
        assert getattr(defaults, h.name) is None
        value = getattr(build_parser().parse_args([command, h.option, "3"]), h.name)
        assert type(value) is h.type and value == 3


def test_learner_options_reach_babble(capsys) -> None:  # type: ignore[no-untyped-def]
    """--path-length goes on to babble(): 10 movements of 5 steps."""
    assert main(["babble", "--robot", "planar3", "--movements", "10", "--path-length", "5", "--quiet"]) == 0
    assert "10 (50 steps)" in capsys.readouterr().out


def test_learner_options_reach_run_trials(monkeypatch, capsys) -> None:  # type: ignore[no-untyped-def]
    """trials passes on the learner options given (and only those) by their table names."""
    from gb_pin.exceptions import InvalidArgumentError
    from gb_pin.experiments import trials

    seen: dict[str, object] = {}

    def fake_run_trials(**kwargs: object) -> None:
        seen.update(kwargs)
        raise InvalidArgumentError("stop here")

    monkeypatch.setattr(trials, "run_trials", fake_run_trials)
    argv = ["trials", "--robot", "planar3", "--learning-rate", "0.2", "--path-length", "7", "--p-home", "0"]
    assert main(argv) == 2
    assert "gb-pin: error: stop here" in capsys.readouterr().err
    assert {k: seen[k] for k in ("learning_rate", "path_length", "p_home")} == {
        "learning_rate": 0.2,
        "path_length": 7,
        "p_home": 0.0,
    }
    assert not {"sigma", "sigma_delta", "radius"} & set(seen)


def test_help_is_cheap() -> None:
    """`gb-pin --help` imports neither numba nor pinocchio (commands import what they run when run)."""
    code = (
        "import sys\n"
        "from gb_pin.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit as exc:\n    assert exc.code == 0\n"
        "heavy = {'numba', 'pinocchio', 'gb_pin.learn.state'} & set(sys.modules)\n"
        "assert not heavy, heavy\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "babble" in proc.stdout


def _imports(path: Path) -> set[str]:
    """Modules imported anywhere in ``path``, inside functions and TYPE_CHECKING blocks included."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            found.update(f"{node.module}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
    return found


def test_cli_imports_go_one_way() -> None:
    """__init__ -> parser -> commands -> options; nothing outside gb_pin/cli imports gb_pin.cli."""
    package = Path(gb_pin.__file__).parent
    cli = package / "cli"
    commands = {"babble", "bench", "ik", "plot", "reproduce", "robots", "trials", "viewing"}
    # option helpers (goal, body, plant, real-arm options), the checks of arguments made before any work
    helpers = {"options", "goal_options", "body_options", "simulation", "checks", "arm", "camera_options"}
    allowed = {"__init__": {"parser"}, "parser": {*commands, "options"}, "options": set(), "checks": set(),
               "goal_options": set(), "body_options": set(), "simulation": {"body_options"},
               "arm": {"checks"}, "camera_options": {"body_options"}}  # fmt: skip
    for path in sorted(cli.glob("*.py")):
        if path.stem == "__main__":
            continue  # `python -m gb_pin.cli`: from gb_pin.cli import run
        imported = _imports(path)
        assert "gb_pin.cli" not in imported, f"{path.name} imports through gb_pin/cli/__init__.py"
        inner = {m.removeprefix("gb_pin.cli.").split(".")[0] for m in imported if m.startswith("gb_pin.cli.")}
        assert inner <= allowed.get(path.stem, helpers), (path.name, inner)
    for path in package.rglob("*.py"):
        if cli not in path.parents and path != package / "__main__.py":  # `python -m gb_pin` runs the CLI
            assert not any(m.startswith("gb_pin.cli") for m in _imports(path)), path


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_ik_solves_coordinates_and_csv_targets_and_rejects_bad_input(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin ik run.npz X Y` and `--targets points.csv [--json]`; bad input: one error line, exit 2."""
    import json

    result = gb_pin.babble("planar5", movements=300, seed=1)
    run = str(tmp_path / "run.npz")
    result.save(run)
    x, y = result.targets[0]
    assert main(["ik", run, str(x), str(y)]) == 0
    out = capsys.readouterr().out
    assert "1/1 solved to 0.0001 m" in out and "joints: " in out
    csv = tmp_path / "points.csv"
    csv.write_text("x,y\n# two targets\n" + "\n".join(f"{a},{b}" for a, b in result.targets[:2]) + "\n\n")
    assert main(["ik", run, "--targets", str(csv), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["axes"] == "xy" and len(data["solutions"]) == 2
    assert all(s["success"] and s["residual"] <= 1e-4 for s in data["solutions"])
    np.testing.assert_allclose([s["target"] for s in data["solutions"]], result.targets[:2])
    assert main(["ik", run, "5", "5"]) == 1  # beyond the arm's reach: printed, status 1
    bad_csv = tmp_path / "bad.csv"
    bad_csv.write_text("0.3,0.1\n0.3\n")
    cases = [
        ([run, "0.3"], "expected 2 coordinates"),
        ([run, "0.3", "abc"], "'abc' is not a finite number"),
        ([run, "--targets", str(bad_csv)], "bad.csv:2: expected 2 comma-separated coordinates"),
        ([run, "--targets", str(tmp_path / "none.csv")], "cannot read"),
        ([str(tmp_path / "none.npz"), "0.3", "0.1"], "no such result file"),
        ([run], "expected 2 coordinates"),
    ]
    for argv, needle in cases:
        proc = subprocess.run(
            [sys.executable, "-m", "gb_pin.cli", "ik", *argv], capture_output=True, text=True, timeout=120
        )
        assert proc.returncode == 2, (argv, proc.stderr)
        assert proc.stderr.count("\n") == 1 and proc.stderr.startswith("gb-pin: error: ")
        assert needle in proc.stderr


def test_version_and_python_m_gb_pin() -> None:
    """`gb-pin --version` prints the version; `python -m gb_pin` is the same command line."""
    for args in (["-m", "gb_pin", "--version"], ["-m", "gb_pin.cli", "--version"]):
        out = subprocess.run([sys.executable, *args], capture_output=True, text=True, check=True).stdout
        assert out.strip() == f"gb-pin {gb_pin.__version__}"


def test_program_exit_keeps_output_files_and_status(tmp_path: Path) -> None:
    """`gb-pin babble` as a program ends with os._exit after flushing: nothing it wrote is lost.

    The summary reaches a pipe whole, the result and checkpoint files are complete, and errors keep
    exit status 2; ``main()`` called in-process returns instead (it never ends the caller).
    """
    out, ckpt = tmp_path / "run.npz", tmp_path / "run.ckpt"
    argv = ["babble", "--robot", "planar3", "--movements", "40", "--seed", "2", "--quiet", "--out", str(out),
            "--checkpoint", str(ckpt), "--checkpoint-every", "20"]  # fmt: skip
    proc = subprocess.run(
        [sys.executable, "-m", "gb_pin", *argv], capture_output=True, text=True, timeout=300
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("robot            planar3") and lines[-1] == f"saved            {out}"
    saved = gb_pin.load_result(str(out))
    again = gb_pin.babble("planar3", movements=40, seed=2)
    np.testing.assert_array_equal(saved.history.error, again.history.error)
    np.testing.assert_array_equal(gb_pin.resume(str(ckpt)).history.error, again.history.error)
    bad = subprocess.run(
        [sys.executable, "-m", "gb_pin", "babble", "--robot", "planar1x"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert bad.returncode == 2 and bad.stderr.startswith("gb-pin: error: unknown robot")
    assert main([*argv[:-4], "--overwrite"]) == 0  # in-process: returns (run.npz exists: replaced on purpose)


def test_resume_reports_this_sessions_steps(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """After --resume, the time per step is this session's time over the steps this session ran."""
    path = tmp_path / "run.ckpt"

    class _StopError(Exception):
        pass

    def stop(r: int) -> None:
        if r >= 20:
            raise _StopError

    with pytest.raises(_StopError):
        gb_pin.babble("planar5", movements=40, seed=1, checkpoint=path, checkpoint_every=10, callback=stop)
    from gb_pin.runs.checkpoint import read_checkpoint

    state, _ = read_checkpoint(path)
    assert main(["babble", "--resume", str(path), "--quiet"]) == 0
    text = capsys.readouterr().out
    full = gb_pin.babble("planar5", movements=40, seed=1)
    assert f"for this session's {full.steps - state.steps} steps" in text


def test_bad_result_files_get_gb_pins_messages(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """Text, .npy, pickled, object-array files named .npz: one gb_pin line, no numpy allow_pickle advice."""
    import pickle

    files = {"text.npz": b"hello\n", "pickled.npz": pickle.dumps({"a": 1})}
    for name, data in files.items():
        (tmp_path / name).write_bytes(data)
    np.save(tmp_path / "array.npy", np.arange(3))
    (tmp_path / "array.npz").write_bytes((tmp_path / "array.npy").read_bytes())
    np.savez(tmp_path / "objects.npz", a=np.array([object()], dtype=object))
    for name in ("text.npz", "pickled.npz", "array.npz", "objects.npz"):
        assert main(["show", str(tmp_path / name), "--html", str(tmp_path / "x.html")]) == 2
        err = capsys.readouterr().err
        assert err.startswith("gb-pin: error: ") and name in err
        assert "allow_pickle" not in err, err


def test_babble_any_urdf_or_example_robot_data_model(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`--robot FILE.urdf --frame F [--joints] [--home]`, `--robot erd:NAME ...`; show/plot rebuild it."""
    urdf = str(Path(__file__).parent / "data" / "small_arm.urdf")
    out = tmp_path / "arm.npz"
    args = ["babble", "--robot", urdf, "--frame", "tool", "--joints", "j1,j2,j4", "--home", "0.1,0.2,0.3"]
    assert main([*args, "--movements", "30", "--quiet", "--out", str(out)]) == 0
    assert "3 joints" in capsys.readouterr().out
    model = ["--robot", urdf, "--frame", "tool", "--joints", "j1,j2,j4", "--home", "0.1,0.2,0.3"]
    assert main(["show", str(out), "--html", str(tmp_path / "arm.html"), *model]) == 0
    assert main(["plot", str(out), *model]) == 0
    assert (tmp_path / "arm.html").is_file() and (tmp_path / "arm.png").is_file()
    capsys.readouterr()
    joints = "LShoulderPitch,LShoulderYaw,LElbowRoll,LElbowYaw"
    erd = ["babble", "--robot", "erd:romeo", "--frame", "LHand", "--joints", joints, "--movements", "10"]
    assert main([*erd, "--quiet"]) == 0
    assert "4 joints" in capsys.readouterr().out
    for bad, needle in (
        (["babble", "--robot", "erd:romeo", "--movements", "5"], "needs --frame"),
        (["babble", "--robot", "planar5", "--frame", "tool", "--movements", "5"], "--frame"),
        (["babble", "--robot", urdf, "--frame", "no_such_frame", "--movements", "5"], "no_such_frame"),
    ):
        assert main(bad) == 2
        assert needle in capsys.readouterr().err


def test_a_long_warmup_says_it_compiles(capsys) -> None:  # type: ignore[no-untyped-def]
    """A warmup over the threshold prints one line on stderr (not with --quiet, not when fast)."""
    import time

    from gb_pin.cli.babble import _warmup

    def slow() -> float:
        time.sleep(0.5)
        return 0.5

    assert _warmup(slow, quiet=False, after=0.05) == 0.5
    assert capsys.readouterr().err.count("compiling the numba kernels") == 1
    _warmup(slow, quiet=True, after=0.05)
    _warmup(lambda: 0.0, quiet=False, after=0.3)
    time.sleep(0.4)  # a cancelled note never prints later
    assert "compiling" not in capsys.readouterr().err
