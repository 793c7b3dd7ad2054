"""``gb-pin babble``: one run, optionally resumed, recorded, checkpointed or watched live.

:func:`run` reads the checkpoint to resume (if any), checks the robot, compiles the kernels,
opens the viewer, babbles and prints the summary that README.md shows.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import threading
import time
from typing import TYPE_CHECKING, Any

import gb_pin.cli.body_options as body_options
import gb_pin.cli.camera_options as camera_options
from gb_pin.cli.arm import add_arm_options
from gb_pin.cli.goal_options import add_goal_options, check_widths, goal_values
from gb_pin.cli.options import (
    add_learner_options,
    add_overwrite,
    add_quiet,
    add_robot_options,
    learner_values,
    onboarding_lines,
    robot_argument,
)
from gb_pin.cli.simulation import plant_summary
from gb_pin.exceptions import InvalidArgumentError

if TYPE_CHECKING:
    from gb_pin.cli.options import Subparsers
    from gb_pin.learn.history import Recording
    from gb_pin.runs.result import BabbleResult
    from gb_pin.viewer import Viewer


DESCRIPTION = """\
Learn a robot's inverse kinematics by trying to reach (Online Goal Babbling, Rolf, Steil and
Gienger 2011): print E^X (Eq. 9: the mean distance to the targets of the learned postures),
D^home and the number of local models; save the result with --out.

A robot given without joints, home, targets or radius (a URDF file or erd:NAME with only
--frame) gets them chosen by measurement, and the choice is printed and saved."""

EXAMPLES = """\
examples:
  gb-pin babble --robot planar20 --movements 1000 --seed 0
  gb-pin babble --robot talos_left_arm --movements 3000 --out run.npz
  gb-pin babble --robot erd:z1 --frame link06 --movements 3000
  gb-pin babble --robot my_arm.urdf --frame tool --joints j1,j2,j3 --out arm.npz
  gb-pin babble --robot examples/continuum_arm.py:robot --movements 500
  gb-pin babble --continue run.npz --movements 2000 --out more.npz
  gb-pin babble --robot planar50 --movements 100000 --checkpoint run.ckpt   (then: --resume run.ckpt)
  gb-pin babble --robot planar5 --movements 300 --view
  gb-pin babble --robot so101 --arm feetech:port=/dev/ttyACM0,calibration=arm.json --tracker cam.py:hand \\
      --movements 3000 --checkpoint so101.ckpt      (then: --resume so101.ckpt; docs/HARDWARE.md)"""


def add_babble(sub: Subparsers) -> None:
    """Register ``babble``."""
    sub.add_parser(
        "babble",
        help="learn an inverse model by goal babbling",
        description=DESCRIPTION,
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        configure=_add_options,
    )


def _add_options(b: argparse.ArgumentParser) -> None:
    """``babble``'s options: the run, the learner, output, checkpoints, recording, viewer."""
    add_robot_options(b, default="planar20")
    b.add_argument(
        "--movements", type=int, default=None, help="movements, home returns included (default 1000)"
    )
    b.add_argument("--seed", type=int, default=None, help="random seed (default 0)")
    add_learner_options(b)
    add_goal_options(b)
    body_options.add_body_options(b)
    add_arm_options(b)
    b.add_argument(
        "--out",
        default=None,
        help="save the result to this .npz file (an existing one only with --overwrite)",
    )
    add_overwrite(b, "--out")
    _add_checkpoint_options(b)
    _add_record_options(b)
    _add_view_options(b)
    add_quiet(b)
    b.set_defaults(func=run)


def _add_checkpoint_options(b: argparse.ArgumentParser) -> None:
    """--checkpoint, --checkpoint-every, --resume."""
    b.add_argument(
        "--checkpoint", default=None, help="write the run's complete state to this file as it goes (atomic)"
    )
    b.add_argument("--checkpoint-every", type=int, default=None, help="movements between checkpoints")
    b.add_argument(
        "--resume",
        default=None,
        help="continue the run of this checkpoint (bit-identical to an uninterrupted run)",
    )
    b.add_argument(
        "--continue",
        dest="continue_from",
        metavar="RESULT",
        default=None,
        help="learn --movements more from the end of a saved run (its robot, model, noise, random stream "
        "and hyperparameters; movements count from 0 again; babble(init=...))",
    )


def _add_record_options(b: argparse.ArgumentParser) -> None:
    """--record-every, --record-movements: steps kept for ``gb-pin replay``."""
    b.add_argument(
        "--record-every", type=int, default=None, help="record every K-th step into the result (for replay)"
    )
    b.add_argument(
        "--record-movements", default=None, help="record movements FIRST:LAST only, e.g. 0:50 (default all)"
    )


def _add_view_options(b: argparse.ArgumentParser) -> None:
    """--view and its port, pace and wait."""
    b.add_argument("--view", action="store_true", help="watch it live in a browser (meshcat, 127.0.0.1)")
    b.add_argument("--view-port", type=int, default=None, help="viewer port (default: first free from 7000)")
    b.add_argument(
        "--view-pace", type=float, default=None, help="slow motion: at most this many movements per second"
    )
    b.add_argument(
        "--view-wait",
        type=float,
        default=60.0,
        help="seconds to wait for a browser to connect before babbling (default 60; 0: start at once)",
    )


def run(args: argparse.Namespace) -> int:
    """Babble (or resume), print the summary and save the result if asked."""
    import gb_pin.cli.checks as checks
    from gb_pin.runs.api import warmup

    if args.arm is not None:  # a real arm: the hardware package, imported there only
        from gb_pin.cli.arm import run_arm

        return run_arm(args, _Progress)
    if args.tracker is not None:
        raise InvalidArgumentError("--tracker watches a real arm: give --arm too")
    checks.babble(args)  # combinations, ranges and output paths, before any work
    goal_args = goal_values(args)  # generator and point files read and checked before any work too
    if args.resume and goal_args:
        raise InvalidArgumentError(
            f"--resume continues the checkpoint's goals and sets; drop {', '.join(sorted(goal_args))}"
        )
    if args.resume:
        options = (("--plant", args.plant), ("--sensor", args.sensor),
                   ("--max-joint-step", args.max_joint_step), ("--table", args.table),
                   ("--obstacle", args.obstacle),
                   ("--self-collision", args.self_collision or None))  # fmt: skip
        given = [o for o, v in options if v is not None]
        if given:
            raise InvalidArgumentError(
                f"--resume continues the checkpoint's robot and options: drop {', '.join(given)}"
            )
    done, steps_before, wall_before = _read_resume(args)
    # --resume runs the checkpoint's robot: resume() loads its preset or rebuilds the model it records.
    # A preset stays a name; a URDF / erd model is built (and onboarded), a MODULE:NAME imported: a bad
    # robot fails here, before the kernels compile.
    init, robot = _read_continue(args) if args.continue_from else (None, None)
    if init is None and not args.resume:
        given_targets = goal_args.get("targets")  # a workspace region is no model's goal set: onboarding runs
        robot = robot_argument(args, targets=None if isinstance(given_targets, str) else given_targets)
        check_widths(args, goal_args, robot)  # a point file of the wrong width, named
    for line in onboarding_lines(robot):
        print(line, flush=True)
    if not args.resume:
        robot = body_options.plant(args, robot)  # --plant: the robot as it is, not its model
        if camera_options.wants_camera(args):  # --sensor aruco: learn in the camera's frame
            robot = camera_options.watched_robot(args, robot, goal_args.pop("targets", None))
        goal_args = {
            **goal_args, "sensor": body_options.sensor(args), "max_joint_step": args.max_joint_step,
            **body_options.safety(args),
        }  # fmt: skip
    record = _recording(args)
    compile_time = _warmup(warmup, quiet=args.quiet)
    viewer = _start_viewer(args)
    progress = _Progress(args.robot, args.movements, done, disable=args.quiet)
    start = time.perf_counter()
    try:
        result = _run(args, robot, progress, record, viewer, goal_args, init)
    finally:
        progress.close()
        if viewer is not None:
            viewer.finish()  # the last state and the learned model; browsers keep showing them
            viewer.close()
    _print_summary(args, result, time.perf_counter() - start, compile_time, (steps_before, wall_before))
    warning = result.diagnose()
    if warning is not None:
        print(f"gb-pin: warning: {warning}", file=sys.stderr)
    state = result.state
    if args.goals is not None and state is not None:
        print(f"goals            {state.goals!r}")
    if (plant_line := plant_summary(args, getattr(robot, "robot", robot))) is not None:
        print(plant_line)
    if (camera_line := camera_options.camera_summary(robot, result.error)) is not None:
        print(camera_line)
    if result.checked_asks:
        print(f"safety           {result.checked_asks} asks checked, {result.cut_asks} cut short")
    if getattr(args, "until_error", None) is not None and state is not None and state.reached:
        print(f"stopped          E^X <= {args.until_error:g} m at movement {result.movements}")
    if args.out is not None:
        from gb_pin._files import free_name, write_or_fallback

        out = args.out
        if not args.overwrite and os.path.lexists(out):  # written by another run meanwhile: keep both
            out = free_name(out)
            print(f"gb-pin: warning: {args.out} appeared during the run; saving to {out}", file=sys.stderr)
        where = write_or_fallback(out, result.save)  # a failed write never loses the result
        if where != out:
            print(f"gb-pin: warning: could not write {args.out}; saved to {where} instead", file=sys.stderr)
        print(f"saved            {where}")
    args.quick_exit = viewer is None  # everything is written and closed (gb_pin.cli.run)
    return 0


def _read_resume(args: argparse.Namespace) -> tuple[int, int, float]:
    """--resume: robot, movements and seed from the checkpoint; the movements, steps, seconds done."""
    if not args.resume:
        return 0, 0, 0.0
    from gb_pin.runs.checkpoint import read_checkpoint

    state, info = read_checkpoint(args.resume)
    if state.chain is None:  # written by a session (ask/tell): no compiled kinematics to babble on
        raise InvalidArgumentError(
            f"{args.resume}: a session's checkpoint (a robot stepped by ask/tell) resumes from Python: "
            "gb_pin.resume_session(path, robot=...)"
        )
    if info.robot is None and (info.source is None or info.source["kind"] == "module"):
        raise InvalidArgumentError(
            f"{args.resume}: a run of a custom robot resumes from Python (gb_pin.resume(path, robot=...))"
        )
    args.robot = info.robot or info.target_name  # a URDF / erd model's run: its name, for the summary
    args.movements, args.seed = info.movements, info.seed
    return int(state.movements), int(state.steps), float(info.wall_time)


def _read_continue(args: argparse.Namespace) -> tuple[BabbleResult, Any]:
    """--continue RESULT: the saved run, checked to hold its final state, and the robot to go on with.

    The robot is the run's (its preset by name, else the robot the file rebuilds), or --robot's.
    """
    from gb_pin.cli.options import result_robot
    from gb_pin.runs.result import load_result

    given = result_robot(args) if args.robot is not None or args.frame is not None else None
    init = load_result(args.continue_from, target=given)
    if init.state is None:
        raise InvalidArgumentError(
            f"{args.continue_from}: written by an older gb_pin, without the run's final state; rerun it "
            "with this version to continue it"
        )
    robot = init.target if given is not None or init.robot is None else init.robot
    args.robot = args.robot or init.robot or init.target.name  # for the summary
    return init, robot


def _run(
    args: argparse.Namespace,
    robot: Any,
    progress: _Progress,
    record: Recording | None,
    viewer: Viewer | None,
    goal_args: dict[str, Any],
    init: BabbleResult | None = None,
) -> BabbleResult:
    """The run: ``resume(...)`` of the checkpoint, or ``babble(...)`` (from ``init``'s end, if given)."""
    from gb_pin.runs.api import babble, resume

    common: dict[str, Any] = {
        "callback": progress,
        "checkpoint_every": args.checkpoint_every,
        "viewer": viewer,
        # At full speed the viewer shows at most 30 frames/s anyway: observing every 10th movement
        # keeps the core's per-chunk cost small; with --view-pace every movement is shown.
        "observe_every": 1 if args.view_pace is not None else 10,
    }
    if args.resume:
        return resume(args.resume, **common)
    learner = learner_values(args)
    if init is not None:  # the run goes on with its hyperparameters, unless given
        learner = {k: v if v is not None else getattr(init.config, k) for k, v in learner.items()}
    return babble(
        robot=robot,
        movements=args.movements,
        seed=0 if args.seed is None else args.seed,  # --continue: init's random stream goes on
        checkpoint=args.checkpoint,
        record=record,
        init=init,
        **common,
        **learner,
        **goal_args,
    )


class _Progress:
    """The progress callback: a tqdm bar, created on the first report so that errors come without a bar."""

    def __init__(self, robot: str, total: int, done: int, *, disable: bool) -> None:
        self._tqdm: Any = None
        if not disable:  # --quiet: tqdm (and the multiprocessing lock it makes) is never imported
            from tqdm import tqdm  # imported here, before the run is timed

            self._tqdm = tqdm
        self._robot, self._total, self._done, self._disable = robot, total, done, disable
        self._bar: Any = None

    def __call__(self, r: int) -> None:
        if self._tqdm is None:
            return
        if self._bar is None:
            self._bar = self._tqdm(
                total=self._total,
                initial=self._done,
                unit="mv",
                desc=f"babbling {self._robot}",
                disable=self._disable,
            )
        self._bar.update(r - self._done)
        self._done = r

    def close(self) -> None:
        """Close the bar, if one was shown."""
        if self._bar is not None:
            self._bar.close()


def _warmup(warmup: Any, quiet: bool, after: float = 1.0) -> float:
    """Load (or compile) the kernels; a line on stderr if that takes over ``after`` seconds.

    A first run without the install's precompiled kernels compiles for 8-11 s before the progress
    bar shows: the line says what the pause is (from a timer thread: numba's compiler lets it run).
    """
    note = threading.Timer(
        after,
        lambda: print(
            "gb-pin: compiling the numba kernels (once: they are cached for the next runs; "
            "`pip install -e .` compiles them ahead)...",
            file=sys.stderr,
            flush=True,
        ),
    )
    note.daemon = True
    if not quiet:
        note.start()
    try:
        return float(warmup())
    finally:
        note.cancel()


def _task_words(task: Any) -> str:
    """A stacked task in words: ``position xyz + orientation (s 0.1 m/rad)``."""
    words = []
    for spec in task:
        kind = type(spec).__name__.lower()
        if kind == "position":
            words.append(f"position {spec.axes}")
        elif kind == "pointing":
            axis = ",".join(f"{v + 0.0:g}" for v in spec.axis)  # + 0.0: no "-0"
            words.append(f"pointing of axis ({axis}) (s {spec.scale:g} m/rad)")
        else:
            words.append(f"{kind} (s {spec.scale:g} m/rad)")
    return " + ".join(words)


def _print_summary(
    args: argparse.Namespace,
    result: BabbleResult,
    wall: float,
    compile_time: float,
    before: tuple[int, float] = (0, 0.0),
) -> None:
    """The summary of README.md: E^X, D^home, prototypes, wall time.

    The time per step is this session's: its babbling time over the steps it ran (after ``--resume``,
    ``before`` holds the steps and seconds of the checkpoint's sessions, which are not counted).
    """
    from gb_pin._names import printable
    from gb_pin.learn.history import versus_initial

    task = getattr(result.target, "task", None)
    if task is not None:  # a stacked task: x holds positions [m] and scaled rotations (docs/TASKS.md)
        what = f"task {_task_words(task)}: {result.target.n_task} values"
        unit = " (task units: m, rotations as s x rad)"
    else:
        what = f"task axes {getattr(result.target, 'axes', None) or f'{result.target.n_task} dimensions'}"
        unit = " m"
    e0 = versus_initial(
        result.error, result.initial_error, unit if task is None else ""
    )  # --continue: home's
    print(f"robot            {printable(args.robot)} ({result.target.n_joints} joints, {what})")
    seed = "continued" if args.continue_from else args.seed
    print(f"movements        {result.movements} ({result.steps} steps), seed {seed}")
    print(f"E^X              {result.error:.5f}{unit}   ({e0})")
    if getattr(getattr(result.target, "chain", None), "components", None) is not None:  # docs/TASKS.md
        from gb_pin.learn.component_metrics import task_errors

        errors = task_errors(result.model, result.target, result.targets)
        for line in errors.summary(getattr(result.target, "component_labels", None)).splitlines():
            print(f"  {printable(line, 400)}")  # labels name the model's frames
    from gb_pin.robot.workspace import is_workspace_spec

    if is_workspace_spec(getattr(args, "targets", None)):
        # a workspace region: the reach error over its test points (never learnt), docs/WORKSPACE.md
        print(f"test points      {result.workspace_errors().summary()}")
    print(f"D^home           {result.home_distance:.4f} rad")
    print(f"prototypes       {result.n_prototypes}")
    if result.missing:
        print(f"missing readings {result.missing} ({result.missing / max(result.steps, 1):.1%} of the steps)")
    reach = result.history.reach
    watched = getattr(args, "plant", None) or getattr(args, "sensor", None) or result.missing
    if watched and reach is not None and reach.size and math.isfinite(float(reach[-1])):
        import numpy as np

        extent = float(np.linalg.norm(np.ptp(np.asarray(result.targets), axis=0)))
        if float(reach[-1]) <= extent:
            print(
                f"reach (observed) {reach[-1]:.5f} m   median miss of the last goal movements, "
                "less the noise's share"
            )
        else:  # the noise's share is estimated with the learned Jacobian: meaningless before it is learnt
            print(
                f"reach (observed) not yet meaningful: {reach[-1]:.3g} m, more than the goal set's "
                f"extent ({extent:.3g} m), after {result.movements} movements (its Jacobian is young)"
            )
    steps_before, wall_before = before
    steps = result.steps - steps_before
    per_step = f"{1e6 * (result.wall_time - wall_before) / steps:.2f} us/step" if steps > 0 else "no steps"
    session = f" for this session's {steps} steps" if steps_before else ""
    print(
        f"wall time        {wall:.2f} s ({per_step}{session}, "
        f"evaluation included; plus {compile_time:.2f} s to compile or load the kernels)"
    )


def _recording(args: argparse.Namespace) -> Recording | None:
    """The Recording asked for by --record-every / --record-movements, or None."""
    if args.record_every is None and args.record_movements is None:
        return None
    from gb_pin.learn.history import Recording
    from gb_pin.viewer import parse_range

    first, last = parse_range(args.record_movements or "0:", "--record-movements")
    return Recording(every=1 if args.record_every is None else args.record_every, first=first, last=last)


def _start_viewer(args: argparse.Namespace) -> Viewer | None:
    """--view: a live viewer on 127.0.0.1 (or a warning and None); waits for a browser to connect."""
    if not args.view:
        return None
    import warnings

    from gb_pin.viewer import ViewerWarning, open_viewer

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ViewerWarning)
        viewer = open_viewer(args.view_port, pace=args.view_pace)
    for w in caught:
        print(f"gb-pin: warning: {w.message}", file=sys.stderr)
    if viewer is None:
        return None
    print(f"viewer           {viewer.url}  (open it in a browser; served on 127.0.0.1 only)", flush=True)
    if args.view_pace is None:
        print("                 (full speed; --view-pace 30 shows every movement, 30 per second)", flush=True)
    if args.view_wait > 0:
        print(
            f"                 waiting up to {args.view_wait:g} s for a browser to open it "
            "(--view-wait SECONDS to change, 0 to start at once)...",
            flush=True,
        )
        if not viewer.wait_for_browser(args.view_wait):
            print(f"                 no browser within {args.view_wait:g} s: babbling anyway", flush=True)
    return viewer
