"""Ask/tell sessions (gb_pin.babble_session) and robots given as forward functions (gb_pin.FunctionTarget)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.runs.session import resume_session


def _drive(session: gb_pin.BabbleSession, forward) -> gb_pin.BabbleResult:  # type: ignore[no-untyped-def]
    while not session.done:
        session.tell(forward(session.ask()))
    return session.result()


def _same(a: gb_pin.BabbleResult, b: gb_pin.BabbleResult) -> None:
    np.testing.assert_array_equal(a.history.error, b.history.error)
    np.testing.assert_array_equal(a.history.home_distance, b.history.home_distance)
    for key, value in a.model.to_arrays().items():
        np.testing.assert_array_equal(b.model.to_arrays()[key], value, err_msg=key)
    assert (a.movements, a.steps) == (b.movements, b.steps)


@pytest.mark.parametrize("robot", ["planar5", "talos_left_arm"])
def test_ask_tell_with_the_robots_kinematics_equals_babble_bit_for_bit(robot: str) -> None:
    """Driven by the compiled forward kinematics a session is babble() itself, recording included."""
    target = gb_pin.load_robot(robot)
    record = gb_pin.Recording(every=3, first=10, last=40)
    ref = gb_pin.babble(robot, movements=150, seed=4, record=record)
    got = _drive(gb_pin.babble_session(robot, movements=150, seed=4, record=record), target.chain.forward)
    _same(ref, got)
    assert ref.recording is not None and got.recording is not None
    np.testing.assert_array_equal(ref.recording.position, got.recording.position)


@pytest.mark.parametrize("robot", ["planar5", "talos_left_arm"])
def test_ask_tell_driven_by_target_forward_equals_babble(robot: str) -> None:
    """target.forward is the learner's kinematics: driven by it, a session is babble() bit for bit."""
    target = gb_pin.load_robot(robot)
    _same(
        gb_pin.babble(robot, movements=120, seed=2),
        _drive(gb_pin.babble_session(robot, movements=120, seed=2), target.forward),
    )


def test_ask_tell_driven_by_pinocchio_agrees_to_rounding() -> None:
    """Driven by Pinocchio's own forward kinematics (another rounding), the run agrees to ~1e-12."""
    target = gb_pin.load_robot("talos_left_arm")
    ref = gb_pin.babble("talos_left_arm", movements=60, seed=2)
    got = _drive(gb_pin.babble_session("talos_left_arm", movements=60, seed=2), target.forward_pinocchio)
    np.testing.assert_allclose(got.history.error, ref.history.error, rtol=0, atol=1e-9)


def test_bad_tells_and_asks_are_refused_and_change_nothing() -> None:
    """Wrong shape, NaN, a tell without an ask, an ask twice: package errors; the run goes on unchanged."""
    target = gb_pin.load_robot("planar5")
    session = gb_pin.babble_session("planar5", movements=20, seed=1)
    with pytest.raises(gb_pin.InvalidArgumentError, match="without ask"):
        session.tell([0.5, 0.0])
    q = session.ask()
    with pytest.raises(gb_pin.InvalidArgumentError, match="twice"):
        session.ask()
    bads: list[object] = [[0.5], [np.nan, 0.0], [[0.5, 0.0]], "far", np.array([0.5 + 1j, 0.0])]
    for bad in bads:
        with pytest.raises(gb_pin.InvalidArgumentError, match="position"):
            session.tell(bad)  # type: ignore[arg-type]
    assert session.waiting
    session.tell(target.forward(q))
    _same(gb_pin.babble("planar5", movements=20, seed=1), _drive(session, target.forward))
    with pytest.raises(gb_pin.InvalidArgumentError, match="complete"):
        session.ask()


def test_a_checkpointed_session_resumes_exactly(tmp_path: Path) -> None:
    """A session checkpointed every 30 movements, stopped mid-movement and resumed, ends as babble()."""
    target = gb_pin.load_robot("planar5")
    path = tmp_path / "run.npz"
    session = gb_pin.babble_session("planar5", movements=90, seed=6, checkpoint=path, checkpoint_every=30)
    while session.movements < 45:
        session.tell(target.forward(session.ask()))
    session.ask()  # an unanswered ask: not saved, asked again after the resume
    with pytest.raises(gb_pin.InvalidArgumentError, match="another run"):
        resume_session(path)  # the live session holds the file
    session.close()  # as a crash would (the lock dies with the process)
    again = resume_session(path)
    assert again.movements == 30
    _same(gb_pin.babble("planar5", movements=90, seed=6), _drive(again, target.forward))
    again.close()
    assert gb_pin.resume(path).movements == 90


def _planar_forward(q: np.ndarray) -> np.ndarray:
    """planar5's forward kinematics in plain numpy (five 0.2 m links)."""
    angles = np.cumsum(q)
    return 0.2 * np.array([np.cos(angles).sum(), np.sin(angles).sum()])


def test_a_function_target_learns_as_the_compiled_robot() -> None:
    """A black-box forward model of planar5 learns the same (to rounding) as the compiled chain."""
    target = gb_pin.load_robot("planar5")
    robot = gb_pin.FunctionTarget(_planar_forward, target.home, lower=target.lower, upper=target.upper,
                                  targets=target.targets, name="numpy-planar5")  # fmt: skip
    got = gb_pin.babble(robot, movements=100, seed=3)
    ref = gb_pin.babble("planar5", movements=100, seed=3)
    assert got.movements == 100 and got.steps == ref.steps
    assert np.all(np.isfinite(got.history.error))
    assert got.error == pytest.approx(ref.error, rel=0.5)
    np.testing.assert_allclose(got.history.error[:5], ref.history.error[:5], rtol=1e-9)
    session = gb_pin.babble_session(robot, movements=5, seed=0)
    assert session.ask().shape == (5,)


def test_function_target_checks_its_arguments() -> None:
    """Bad forward models and limits get gb_pin's errors."""
    with pytest.raises(gb_pin.InvalidArgumentError, match="callable"):
        gb_pin.FunctionTarget(3, [0.0])  # type: ignore[arg-type]
    with pytest.raises(gb_pin.InvalidArgumentError, match="non-finite"):
        gb_pin.FunctionTarget(lambda q: [np.nan], [0.0])
    with pytest.raises(gb_pin.InvalidArgumentError, match="lower <= home"):
        gb_pin.FunctionTarget(lambda q: q, [0.0], lower=1.0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="returned None"):
        gb_pin.FunctionTarget(lambda q: None, [0.0])
    robot = gb_pin.FunctionTarget(lambda q: np.array([q[0], q[0]]), [0.0])
    with pytest.raises(gb_pin.InvalidArgumentError, match="targets="):
        gb_pin.babble(robot, movements=3)
    with pytest.raises(gb_pin.InvalidArgumentError, match="compiled chain"):
        gb_pin.babble(robot, movements=3, targets=[[0.1, 0.1]], viewer=_NoViewer())


class _NoViewer:
    def start(self, target: object, targets: object) -> None: ...
    def update(self, state: object) -> None: ...


def test_cli_babbles_a_robot_given_as_module_and_name(capsys) -> None:  # type: ignore[no-untyped-def]
    """gb-pin babble --robot FILE.py:NAME learns a FunctionTarget; a bad spec exits 2 without traceback."""
    from gb_pin.cli import main

    example = Path(__file__).resolve().parents[1] / "examples" / "continuum_arm.py"
    assert main(["babble", "--robot", f"{example}:robot", "--movements", "20", "--quiet"]) == 0
    assert "3 joints" in capsys.readouterr().out
    assert main(["babble", "--robot", f"{example}:nothing", "--movements", "5", "--quiet"]) == 2
    assert "has no 'nothing'" in capsys.readouterr().err


NO_PINOCCHIO = """
import math, sys
sys.modules["pinocchio"] = None  # any import of pinocchio now fails
import numpy as np
from gb_pin.learn import GoalBabbling
from gb_pin.learn.asktell import AskTell
from gb_pin.learn.state import BabbleState
from gb_pin.robot.function import FunctionTarget

def forward(q):
    h = np.cumsum(q)
    return 0.5 * np.array([np.cos(h).sum(), np.sin(h).sum()])

targets = [[0.5, 0.5], [0.7, 0.2], [0.2, 0.7]]
robot = FunctionTarget(forward, [0.3, 0.6], lower=-3.0, upper=3.0, targets=targets)
state = BabbleState.start(robot, robot.targets, 40, GoalBabbling()._resolve(2), seed=0)
run = AskTell(state, 40, forward=robot.forward)
while state.movements < 40:
    run.tell(forward(run.ask()))
run.finish()
assert state.errors[-1] < state.errors[0], state.errors
print("ok")
"""


def test_a_function_target_learns_through_ask_tell_without_pinocchio() -> None:
    """FunctionTarget and the ask/tell stepping run with pinocchio unimportable (a fresh interpreter)."""
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", NO_PINOCCHIO], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_trials_take_a_robot_named_module_and_name() -> None:
    """run_trials(robot="FILE.py:NAME"): each worker loads the robot by its spec; bad specs are refused."""
    example = Path(__file__).resolve().parents[1] / "examples" / "continuum_arm.py"
    trials = gb_pin.run_trials(robot=f"{example}:robot", trials=2, movements=15, workers=1)
    direct = gb_pin.babble(f"{example}:robot", movements=15, seed=0)
    assert trials.error.shape[0] == 2
    assert trials.error[0, -1] == direct.error
    with pytest.raises(gb_pin.InvalidArgumentError, match="cannot import"):
        gb_pin.babble("no_such_module_xyz:robot", movements=2)


def test_a_compiled_forward_model_runs_in_compiled_code() -> None:
    """FunctionTarget.from_kernel: a numba kernel(q, x) learns as the Python forward model of the same arm."""
    import math

    from numba import njit

    @njit
    def planar(q, x):  # type: ignore[no-untyped-def]
        h = 0.0
        x[0] = 0.0
        x[1] = 0.0
        for v in q:
            h += v
            x[0] += 0.2 * math.cos(h)
            x[1] += 0.2 * math.sin(h)

    arm = gb_pin.load_robot("planar5")
    compiled = gb_pin.FunctionTarget.from_kernel(planar, arm.home, 2, lower=arm.lower, upper=arm.upper,
                                                 targets=arm.targets)  # fmt: skip
    got = gb_pin.babble(compiled, movements=60, seed=1)
    ref = gb_pin.babble("planar5", movements=60, seed=1)
    assert got.steps == ref.steps
    np.testing.assert_allclose(got.history.error, ref.history.error, rtol=1e-6)
    with pytest.raises(gb_pin.InvalidArgumentError, match="njit"):
        gb_pin.FunctionTarget.from_kernel(_planar_forward, arm.home, 2)
