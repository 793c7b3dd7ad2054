"""Sessions ready for hardware: missing readings, robots without a model, evaluation moves, step limits."""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.learn.sensor import observe_into
from gb_pin.robot.external import ExternalRobot
from gb_pin.robot.plant import Plant
from gb_pin.runs.session import resume_session


def _same(a: gb_pin.BabbleResult, b: gb_pin.BabbleResult) -> None:
    np.testing.assert_array_equal(a.history.error, b.history.error)
    np.testing.assert_array_equal(a.history.home_distance, b.history.home_distance)
    for key, value in a.model.to_arrays().items():
        np.testing.assert_array_equal(b.model.to_arrays()[key], value, err_msg=key)
    assert (a.movements, a.steps, a.missing) == (b.movements, b.steps, b.missing)


def test_a_missing_reading_teaches_nothing_and_the_movement_goes_on() -> None:
    """tell(None): the map is unchanged, t advances, the arm moved; the count is in the result."""
    target = gb_pin.load_robot("planar5")
    session = gb_pin.babble_session("planar5", movements=30, seed=2)
    for _ in range(40):
        session.tell(target.forward(session.ask()))
    before = {k: v.copy() for k, v in session.state.llm.to_arrays().items()}
    prev = session.state.vectors["q_prev"].copy()
    steps = session.steps
    q = session.ask()
    assert session.tell(None) is False
    assert session.steps == steps + 1 and session.missing == 1
    after = session.state.llm.to_arrays()
    assert all(np.array_equal(before[k], after[k]) for k in before)
    np.testing.assert_array_equal(session.state.vectors["q_prev"], prev)  # weights compare observed steps
    np.testing.assert_array_equal(session.state.vectors["q_exec"], q)  # the arm did move
    while not session.done:
        session.tell(target.forward(session.ask()))
    assert session.result().missing == 1


def test_a_session_told_a_sensors_readings_is_babble_of_the_plant_bit_for_bit() -> None:
    """The compiled loop's sensor (noise, lost readings) and a session told its readings agree exactly."""
    plant = Plant("so101", offset_std=0.05, length_std=0.03, noise=0.0015, loss=0.2, seed=7)
    ref = gb_pin.babble(plant, movements=120, seed=3)
    session = gb_pin.babble_session(plant, movements=120, seed=3)
    stream = session.state.sensor  # the readings continue the stream home's reading started
    while not session.done:
        x = plant.forward(session.ask())
        session.tell(x if observe_into(stream, x) else None)
    got = session.result()
    _same(ref, got)
    assert got.missing > 0
    np.testing.assert_array_equal(ref.history.reach, got.history.reach)


def test_max_joint_step_bounds_every_step_and_is_the_same_in_babble_and_sessions() -> None:
    """No ask moves a joint farther than max_joint_step; babble() and a session agree; off is the default."""
    target = gb_pin.load_robot("planar5")
    ref = gb_pin.babble("planar5", movements=80, seed=1, max_joint_step=0.02, record=gb_pin.Recording())
    assert ref.recording is not None
    steps = np.abs(np.diff(np.vstack([target.home, ref.recording.posture]), axis=0))
    assert steps.max() <= 0.02 + 1e-12
    session = gb_pin.babble_session("planar5", movements=80, seed=1, max_joint_step=0.02)
    last = target.home
    while not session.done:
        q = session.ask()
        assert np.abs(q - last).max() <= 0.02 + 1e-12
        last = q
        session.tell(target.forward(q))
    _same(ref, session.result())
    free = gb_pin.babble("planar5", movements=80, seed=1, record=gb_pin.Recording())
    assert free.recording is not None
    assert np.abs(np.diff(free.recording.posture, axis=0)).max() > 0.02  # the limit changed something
    for bad in (0, -0.1, math.nan, "x"):
        with pytest.raises(gb_pin.InvalidArgumentError, match="max_joint_step"):
            gb_pin.babble_session("planar5", movements=5, max_joint_step=bad)


def _external_planar5() -> tuple[ExternalRobot, gb_pin.KinematicTarget]:
    arm = gb_pin.load_robot("planar5")
    return ExternalRobot(arm.home, 2, arm.targets, lower=arm.lower, upper=arm.upper, name="arm"), arm


def test_a_robot_without_a_model_is_asked_home_first_and_nothing_else_moves_it() -> None:
    """An ExternalRobot: the first ask is home (again while unseen), then babbling as on the model."""
    robot, arm = _external_planar5()
    session = gb_pin.babble_session(robot, movements=40, seed=5)
    np.testing.assert_array_equal(session.ask(), arm.home)
    assert session.ask_kind == "home"
    session.tell(None)
    session.ask()
    session.tell(arm.forward(arm.home))
    asks = 0
    while not session.done:
        q = session.ask()
        assert session.ask_kind == "learn"
        session.tell(arm.forward(q))
        asks += 1
    result = session.result()
    ref = gb_pin.babble("planar5", movements=40, seed=5)
    for key, value in ref.model.to_arrays().items():  # what was learnt is the model's run
        np.testing.assert_array_equal(result.model.to_arrays()[key], value)
    assert asks == ref.steps
    assert np.all(np.isnan(result.history.error))  # no model, no evaluation asked for: no E^X
    assert result.history.reach is not None and np.isfinite(result.history.reach[-1])
    with pytest.raises(gb_pin.InvalidArgumentError, match="babble_session"):
        gb_pin.babble(robot, movements=5)


def test_evaluation_movements_measure_e_x_on_the_robot_and_learn_nothing() -> None:
    """evaluate='movements': E^X from the test postures' readings is the model's; learning unchanged."""
    robot, arm = _external_planar5()
    session = gb_pin.babble_session(robot, movements=60, seed=5, evaluate="movements", max_joint_step=0.3)
    kinds: dict[str, int] = {}
    last = None
    while not session.done:
        q = session.ask()
        if last is not None:
            assert np.abs(q - last).max() <= 0.3 + 1e-12
        last = q
        kinds[session.ask_kind] = kinds.get(session.ask_kind, 0) + 1
        session.tell(arm.forward(q))
    got = session.result()
    ref = gb_pin.babble("planar5", movements=60, seed=5, schedule=got.history.movements, max_joint_step=0.3)
    np.testing.assert_allclose(got.history.error, ref.history.error, rtol=1e-12)
    np.testing.assert_allclose(got.history.home_distance, ref.history.home_distance, rtol=1e-12)
    for key, value in ref.model.to_arrays().items():
        np.testing.assert_array_equal(got.model.to_arrays()[key], value)
    T = got.history.movements.shape[0]
    assert kinds["evaluation"] == T * arm.targets.shape[0] and kinds["transit"] >= T
    assert kinds["learn"] == ref.steps
    assert T < 15  # a sparse schedule by default: evaluations cost robot time


def _noisy_forward(q: np.ndarray) -> np.ndarray | None:
    """planar5 read by a tracker whose noise and losses are a fixed function of the posture (replayable)."""
    angles = np.cumsum(q)
    x = 0.2 * np.array([np.cos(angles).sum(), np.sin(angles).sum()])
    rng = np.random.default_rng(int.from_bytes(hashlib.sha256(q.tobytes()).digest()[:8], "little"))
    if rng.random() < 0.1:
        return None
    return x + rng.normal(0.0, 0.001, 2)


def test_a_function_robots_session_resumes_bit_identical_with_its_readings_replayed(tmp_path: Path) -> None:
    """A session on a Python forward model (noisy, lossy), stopped and resumed, ends as one run."""
    arm = gb_pin.load_robot("planar5")
    robot = gb_pin.FunctionTarget(
        lambda q: np.zeros(2), arm.home, lower=arm.lower, upper=arm.upper, targets=arm.targets
    )  # its E^X is not what this test checks: the readings come from _noisy_forward

    def drive(session: gb_pin.BabbleSession, stop: int | None = None) -> None:
        while not session.done and (stop is None or session.movements < stop):
            session.tell(_noisy_forward(session.ask()))

    whole = gb_pin.babble_session(robot, movements=90, seed=4)
    drive(whole)
    path = tmp_path / "run.ckpt"
    part = gb_pin.babble_session(robot, movements=90, seed=4, checkpoint=path, checkpoint_every=20)
    drive(part, stop=50)
    part.close()
    again = resume_session(path, robot=robot)
    assert again.movements == 40
    drive(again)
    _same(whole.result(), again.result())
    with pytest.raises(gb_pin.InvalidArgumentError, match="pass it as robot"):
        resume_session(path)
    with pytest.raises(gb_pin.ResultFileError, match="joints"):
        resume_session(path, robot=gb_pin.load_robot("planar7"))


def test_an_external_robots_session_is_checkpointed_after_home(tmp_path: Path) -> None:
    """No checkpoint before home's reading; after it, resume continues exactly."""
    robot, arm = _external_planar5()
    path = tmp_path / "ext.ckpt"
    session = gb_pin.babble_session(robot, movements=30, seed=1, checkpoint=path, checkpoint_every=10)
    with pytest.raises(gb_pin.InvalidArgumentError, match="home"):
        session.save_checkpoint()
    while session.movements < 15:
        session.tell(arm.forward(session.ask()))
    session.close()
    again = resume_session(path, robot=robot)
    while not again.done:
        again.tell(arm.forward(again.ask()))
    whole = gb_pin.babble_session(robot, movements=30, seed=1)
    while not whole.done:
        whole.tell(arm.forward(whole.ask()))
    _same(whole.result(), again.result())


def test_bad_readings_and_options_are_refused_and_change_nothing(tmp_path: Path) -> None:
    """Bad readings, checkpoint_every=0, a taken checkpoint file, unknown options: gb_pin's errors."""
    session = gb_pin.babble_session("planar5", movements=10, seed=0)
    session.ask()
    steps = session.steps
    for bad in ([0.1], [math.inf, 0.0], np.array([0.1 + 1j, 0.0]), [True, False], "x", {"x": 1}):
        with pytest.raises(gb_pin.InvalidArgumentError, match="position"):
            session.tell(bad)  # type: ignore[arg-type]
    assert session.waiting and session.steps == steps
    with pytest.raises(gb_pin.InvalidArgumentError, match="checkpoint_every"):
        gb_pin.babble_session("planar5", movements=10, checkpoint=tmp_path / "c", checkpoint_every=0)
    held = gb_pin.babble_session("planar5", movements=10, checkpoint=tmp_path / "c")
    with pytest.raises(gb_pin.InvalidArgumentError, match="another run"):
        gb_pin.babble("planar5", movements=10, checkpoint=tmp_path / "c")
    held.close()
    with pytest.raises(gb_pin.InvalidArgumentError, match="checkpoint"):
        session.save_checkpoint(tmp_path / "missing_dir" / "c")
    with pytest.raises(gb_pin.InvalidArgumentError, match="evaluate"):
        gb_pin.babble_session("planar5", movements=10, evaluate="camera")
    with pytest.raises(gb_pin.InvalidArgumentError, match="unknown run option 'sigm'"):
        gb_pin.babble_session("planar5", movements=10, sigm=0.1)


def test_a_full_disk_during_a_sessions_checkpoint_is_written_elsewhere(tmp_path, monkeypatch):  # type: ignore[no-untyped-def]
    """ENOSPC inside tell(): the step stands, the checkpoint goes to a fallback file with a warning."""
    import errno

    from gb_pin.runs import checkpoint as ckpt

    target = gb_pin.load_robot("planar5")
    path = tmp_path / "run.ckpt"
    real = ckpt.write_checkpoint

    def full(where, state, info):  # type: ignore[no-untyped-def]
        if str(where) == str(path):
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(where, state, info)

    monkeypatch.setattr(ckpt, "write_checkpoint", full)
    monkeypatch.chdir(tmp_path)
    session = gb_pin.babble_session("planar5", movements=20, seed=0, checkpoint=path, checkpoint_every=5)
    with pytest.warns(gb_pin.GbPinWarning, match="writing it to"):
        while session.movements < 5:
            session.tell(target.forward(session.ask()))
    assert session.checkpoint != str(path) and Path(session.checkpoint).exists()
    while not session.done:  # the session goes on (a retried tell is not needed)
        session.tell(target.forward(session.ask()))
    session.close()
    _same(gb_pin.babble("planar5", movements=20, seed=0), session.result())


KILLED_SESSION = """
import sys, time
import numpy as np
import gb_pin
sys.path.insert(0, {tests!r})
from test_hardware_session import _noisy_forward

arm = gb_pin.load_robot("planar5")
robot = gb_pin.FunctionTarget(lambda q: np.zeros(2), arm.home, lower=arm.lower, upper=arm.upper,
                              targets=arm.targets)
session = gb_pin.babble_session(robot, movements=400, seed=8, checkpoint={path!r}, checkpoint_every=25)
while not session.done:
    session.tell(_noisy_forward(session.ask()))
    if session.movements >= 60:
        print("past 60", flush=True)
        time.sleep(60)  # killed here, mid-run
"""


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_a_session_killed_by_sigkill_resumes_bit_identical(tmp_path: Path) -> None:
    """SIGKILL a session on a Python forward model; resumed with its readings replayed, it is one run."""
    import os
    import signal
    import subprocess
    import sys

    path = tmp_path / "killed.ckpt"
    code = KILLED_SESSION.format(tests=str(Path(__file__).parent), path=str(path))
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    assert proc.stdout.readline().startswith("past 60")
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    arm = gb_pin.load_robot("planar5")
    robot = gb_pin.FunctionTarget(
        lambda q: np.zeros(2), arm.home, lower=arm.lower, upper=arm.upper, targets=arm.targets
    )
    again = resume_session(path, robot=robot)  # the dead process's lock went with it
    assert again.movements == 50
    while not again.done:
        again.tell(_noisy_forward(again.ask()))
    whole = gb_pin.babble_session(robot, movements=400, seed=8)
    while not whole.done:
        whole.tell(_noisy_forward(whole.ask()))
    _same(whole.result(), again.result())
    assert again.result().missing > 0
