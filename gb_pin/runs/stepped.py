"""``babble()`` on a robot given as a forward model: the ask/tell stepping driven by the model itself."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.runs import setup
from gb_pin.runs.result import BabbleResult
from gb_pin.runs.session import BabbleSession


def babble_function(
    run: setup.Prepared,
    callback: Callable[[int], Any] | None,
    viewer: Any | None,
    checkpoint: str | os.PathLike[str] | None,
    checkpoint_every: int | None,
    observe_every: int = 10,
) -> BabbleResult:
    """babble() on a :class:`~gb_pin.robot.function.FunctionTarget`, by the ask/tell stepping.

    A Python ``forward()`` is called once per step; a compiled kernel runs inside compiled code,
    whole movements at a time. Checkpoints are written as in a session (every ``checkpoint_every``
    movements, and at the end). A viewer draws a simulated plant's kinematic robot (its ``target``)
    at the asked postures, every ``observe_every`` movements.

    Raises:
        InvalidArgumentError: a viewer was asked for a robot without a kinematic robot to draw.
    """
    target: Any = run.target
    drawn = getattr(target, "target", target)  # a simulated plant: the kinematic robot it was built from
    if viewer is not None and getattr(drawn, "chain", None) is None:
        raise InvalidArgumentError(
            "viewer= needs a robot with a compiled chain (a KinematicTarget) or a plant built on one"
        )
    name = run.name if getattr(target, "chain", None) is not None else None  # resume() rebuilds a preset
    session = BabbleSession(
        target, setup.start_state(run), run.movements, robot=name, seed=run.seed, checkpoint=checkpoint,
        checkpoint_every=checkpoint_every, guard=run.guard,
    )  # fmt: skip
    every = max(1, run.movements // 100)
    if viewer is not None:
        assert session.state is not None
        viewer.start(drawn, session.state.eval_targets)
    with session:
        if getattr(target, "kernel", None) is not None and run.guard is None:  # whole movements compiled
            stepper = session._stepper
            assert stepper is not None
            while not session.done:
                until = min(run.movements, session.movements + every)
                if checkpoint is not None:
                    until = min(until, (session.movements // session.every + 1) * session.every)
                stepper.run_kernel(target.kernel, until)
                if checkpoint is not None and (
                    session.movements % session.every == 0 or session.movements >= run.movements
                ):
                    session._checkpoint_or_fall_back()
                if callback is not None:
                    callback(session.movements)
            return _with_counts(session)

        return drive(session, target.forward, callback, every, viewer, observe_every)


def drive(
    session: BabbleSession,
    forward: Callable[[Any], Any],
    callback: Callable[[int], Any] | None,
    every: int,
    viewer: Any | None = None,
    observe_every: int = 10,
) -> BabbleResult:
    """Step ``session`` with ``forward`` (which checks each reading) to its end; its result."""
    while not session.done:
        if not session.tell(forward(session.ask())):
            continue
        if callback is not None and session.movements % every == 0:
            callback(session.movements)
        if viewer is not None and session.movements % observe_every == 0:
            viewer.update(session.state)
    return _with_counts(session)


def resume_guarded(
    checkpoint: str | os.PathLike[str],
    robot: Any,
    callback: Callable[[int], Any] | None,
    checkpoint_every: int | None,
) -> BabbleResult:
    """:func:`gb_pin.resume` of a safe run: stepped, checked with the checkpoint's obstacles and settings."""
    from gb_pin.runs.session import resume_session

    with resume_session(checkpoint, robot, checkpoint_every=checkpoint_every) as session:
        every = max(1, session.total // 100)
        return drive(session, robot.forward, callback, every)


def _with_counts(session: BabbleSession) -> BabbleResult:
    """The session's result (a safe session's carries its guard's settings and counts)."""
    return session.result()
