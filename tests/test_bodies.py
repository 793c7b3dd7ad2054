"""Bodies that change while learning: helpers (gb_pin.robot.bodies), babble(changes=...), babble(init=...)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.robot.bodies import locked, scaled, with_tool


def _model(result: gb_pin.BabbleResult) -> dict[str, np.ndarray]:
    return result.model.to_arrays()


def _same_model(a: gb_pin.BabbleResult, b: gb_pin.BabbleResult) -> None:
    for key, value in _model(a).items():
        np.testing.assert_array_equal(_model(b)[key], value, err_msg=key)


def test_helpers_change_the_kinematics_as_described() -> None:
    """Scaled links, a tool along the last link, a locked joint: positions as computed by hand."""
    arm = gb_pin.load_robot("planar5")
    q = arm.home
    np.testing.assert_allclose(scaled(arm, 1.15).forward(q), 1.15 * arm.forward(q), atol=1e-12)
    np.testing.assert_allclose(with_tool(arm, 0.1).forward(np.zeros(5)), [1.1, 0.0], atol=1e-12)
    np.testing.assert_allclose(with_tool(arm, [0.0, 0.1, 0.0]).forward(np.zeros(5)), [1.0, 0.1], atol=1e-12)
    stuck = locked(arm, 1, 0.3)
    moved = q.copy()
    moved[1] = 0.3
    np.testing.assert_allclose(stuck.forward(q + 0.7 * np.eye(5)[1]), arm.forward(moved), atol=1e-12)
    talos = gb_pin.load_robot("talos_left_arm")
    bent = talos.home.copy()
    bent[3] = 0.4
    np.testing.assert_allclose(locked(talos, 3, 0.4).forward(talos.home), talos.forward(bent), atol=1e-12)
    both = with_tool(scaled(arm, 2.0), 0.2)
    np.testing.assert_allclose(both.forward(np.zeros(5)), [2.2, 0.0], atol=1e-12)


def test_helpers_refuse_bad_arguments() -> None:
    """Bad factors, offsets, joints and robots get gb_pin's errors."""
    arm = gb_pin.load_robot("planar5")
    for call, match in [
        (lambda: scaled(arm, 0.0), "> 0"),
        (lambda: scaled(arm, [1.0, 2.0]), "one per link"),
        (lambda: with_tool(arm, [0.1, 0.2]), "offset"),
        (lambda: locked(arm, 5, 0.0), "0..4"),
        (lambda: locked(arm, 1, float("nan")), "finite"),
        (lambda: scaled("planar5", 1.1), "compiled kinematic chain"),
    ]:
        with pytest.raises(gb_pin.InvalidArgumentError, match=match):
            call()


def test_init_continues_a_run_bit_for_bit() -> None:
    """babble(150) then babble(150, init=...) learns exactly what babble(300) learns."""
    first = gb_pin.babble("planar5", movements=150, seed=5)
    second = gb_pin.babble("planar5", movements=150, init=first)
    whole = gb_pin.babble("planar5", movements=300, seed=5)
    _same_model(second, whole)
    assert first.steps + second.steps == whole.steps and second.seed == 5
    np.testing.assert_array_equal(second.history.error[0], first.history.error[-1])


def test_init_on_another_body_and_bad_inits() -> None:
    """init carries over to a changed body of the same joints; other dimensions or no state are refused."""
    first = gb_pin.babble("planar5", movements=60, seed=0)
    grown = gb_pin.babble(scaled(gb_pin.load_robot("planar5"), 1.15), movements=60, init=first)
    assert grown.history.error[0] > first.history.error[-1]  # the grown arm misses at first
    with pytest.raises(gb_pin.InvalidArgumentError, match="5 joints"):
        gb_pin.babble("planar6", movements=10, init=first)
    with pytest.raises(gb_pin.InvalidArgumentError, match="init must be"):
        gb_pin.babble("planar5", movements=10, init="previous")  # type: ignore[arg-type]


def test_changes_in_babble_equal_init_on_the_changed_body() -> None:
    """babble(changes={60: grown}) learns what a run continued with init= on the grown arm learns."""
    arm = gb_pin.load_robot("planar5")
    grown = scaled(arm, 1.15)
    changed = gb_pin.babble("planar5", movements=120, seed=2, changes={60: grown})
    before = gb_pin.babble("planar5", movements=60, seed=2)
    after = gb_pin.babble(grown, movements=60, init=before)
    _same_model(changed, after)
    np.testing.assert_array_equal(changed.history.error[:61], before.history.error)
    np.testing.assert_array_equal(changed.history.error[61:], after.history.error[1:])


@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_resume_keeps_the_change_schedule(tmp_path: Path) -> None:
    """A checkpointed run with a body change, resumed with gb_pin.resume, ends as the uninterrupted run."""
    arm = gb_pin.load_robot("planar5")
    changes = {50: with_tool(arm, 0.1), 80: locked(arm, 2, 0.5)}
    whole = gb_pin.babble("planar5", movements=120, seed=3, changes=changes)
    path = tmp_path / "ck.npz"
    # a run stopped at movement 60 (after the first change), checkpointed there
    part = gb_pin.babble_session("planar5", movements=120, seed=3, changes=changes, checkpoint=path,
                                 checkpoint_every=60)  # fmt: skip
    while part.movements < 60:
        q = part.ask()  # the body changes, if due, at the ask
        part.tell(part.state.chain.forward(q))
    part.close()  # the session's lock on the file goes, as with a crash
    resumed = gb_pin.resume(path)
    _same_model(whole, resumed)
    np.testing.assert_array_equal(whole.history.error, resumed.history.error)


def test_a_change_to_a_session_is_applied_between_movements() -> None:
    """A session with changes, driven by the current body's kinematics, equals babble(changes=...)."""
    arm = gb_pin.load_robot("planar5")
    changes = {40: scaled(arm, 1.1)}
    ref = gb_pin.babble("planar5", movements=80, seed=1, changes=changes)
    session = gb_pin.babble_session("planar5", movements=80, seed=1, changes=changes)
    while not session.done:
        q = session.ask()
        body = arm if session.movements < 40 else changes[40]
        session.tell(body.chain.forward(q))
    _same_model(ref, session.result())
