"""``gb-pin babble --arm feetech:port=...,calibration=FILE --tracker MODULE:NAME``: babbling on a real arm.

The arm is a :class:`gb_pin.hardware.FeetechArm` (an SO-101 or SO-100, ``--robot``); the tracker a
Python callable named ``MODULE:NAME`` (a module or a ``.py`` file) that returns the hand's position
(3,) [m] when called, or None when it lost the hand. Ctrl-C stops the arm (held, or parked with
``on_stop=park``) after writing the checkpoint; ``--resume FILE`` goes on from it.
"""

from __future__ import annotations

import argparse
import inspect
import time
from typing import Any

from gb_pin._files import check_writable
from gb_pin._names import suggest
from gb_pin.cli.checks import no_clobber
from gb_pin.exceptions import InvalidArgumentError

KEYS = {
    "port": None, "calibration": None, "max_joint_step": "0.05", "tolerance": "1.0", "timeout": "2.0",
    "on_stop": "hold", "baudrate": "1000000", "reply_timeout": "0.02",
}  # fmt: skip
"""``--arm feetech:`` keys and defaults (tolerance in degrees; times in seconds)."""


def add_arm_options(b: argparse.ArgumentParser) -> None:
    """``--arm`` and ``--tracker``."""
    keys = ",".join(f"{k}={v or '...'}" for k, v in KEYS.items())
    b.add_argument(
        "--arm",
        default=None,
        help=f"learn on a real arm over its servo bus: feetech:{keys} (--robot so101 or so100; "
        "docs/HARDWARE.md)",
    )
    b.add_argument(
        "--tracker",
        default=None,
        help="with --arm: MODULE:NAME of a Python function returning the hand's position [m] (or None when "
        "lost), e.g. mytracker.py:hand",
    )


def arm_options(text: str) -> dict[str, Any]:
    """``feetech:key=value,...`` checked: the FeetechArm keyword arguments.

    Raises:
        InvalidArgumentError: another kind, an unknown key, a bad value, port or calibration missing.
    """
    kind, _, rest = text.partition(":")
    if kind != "feetech":
        raise InvalidArgumentError(
            f"--arm: unknown kind {kind!r}; the one known is feetech:port=...,calibration=FILE"
        )
    values = dict(KEYS)
    for item in filter(None, (part.strip() for part in rest.split(","))):
        key, sep, raw = item.partition("=")
        if not sep or key.strip() not in KEYS:
            raise InvalidArgumentError(
                f"--arm feetech: unknown key {key.strip()!r}; {suggest(key.strip(), list(KEYS))}"
            )
        values[key.strip()] = raw.strip()
    missing = [k for k in ("port", "calibration") if not values[k]]
    if missing:
        raise InvalidArgumentError(
            f"--arm feetech: {' and '.join(missing)} needed, "
            "e.g. feetech:port=/dev/ttyACM0,calibration=arm.json"
        )
    out: dict[str, Any] = {
        "port": values["port"],
        "calibration": values["calibration"],
        "on_stop": values["on_stop"],
    }
    try:
        step = str(values["max_joint_step"])
        out["max_joint_step"] = None if step == "none" else float(step)
        out["tolerance"] = float(str(values["tolerance"])) * 3.141592653589793 / 180.0
        out["timeout"] = float(str(values["timeout"]))
        out["reply_timeout"] = float(str(values["reply_timeout"]))
        out["baudrate"] = int(str(values["baudrate"]))
    except ValueError as exc:
        raise InvalidArgumentError(f"--arm feetech: {exc}") from exc
    return out


def load_tracker(spec: str) -> Any:
    """The function named ``MODULE:NAME`` (a module or a ``.py`` file), callable with no argument.

    Raises:
        InvalidArgumentError: not MODULE:NAME, cannot be imported, no such name, takes arguments.
    """
    module_name, _, attr = spec.rpartition(":")
    if not module_name or not attr:
        raise InvalidArgumentError(f"--tracker {spec!r}: expected MODULE:NAME, e.g. mytracker.py:hand")
    from gb_pin.robot.spec import import_module_or_file

    module = import_module_or_file(module_name, f"--tracker {spec!r}")
    tracker = getattr(module, attr, None)
    if tracker is None or not callable(tracker):
        raise InvalidArgumentError(f"--tracker {spec!r}: {module_name} has no function {attr!r}")
    try:
        inspect.signature(tracker).bind()
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"--tracker {spec!r}: must be callable with no argument ({exc})") from exc
    return tracker


def run_arm(args: argparse.Namespace, progress_bar: Any) -> int:
    """Babble on the arm of ``--arm`` watched by ``--tracker``; print a summary; save ``--out``.

    ``progress_bar(robot, total, done, disable=)``: babble's progress callback class.
    """
    given = [o for o, v in (("--plant", args.plant), ("--sensor", args.sensor), ("--view", args.view or None),
                            ("--continue", args.continue_from), ("--max-joint-step", args.max_joint_step),
                            ("--goals", getattr(args, "goals", None))) if v is not None]  # fmt: skip
    if given:
        raise InvalidArgumentError(
            f"--arm learns the arm itself: drop {', '.join(given)} (max_joint_step is --arm's key)"
        )
    if args.tracker is None:
        raise InvalidArgumentError(
            "--arm needs --tracker MODULE:NAME: a function returning the hand's position [m]"
        )
    if args.resume and (args.checkpoint or args.movements is not None or args.seed is not None):
        raise InvalidArgumentError(
            "--resume continues the checkpoint's run: drop --checkpoint, --movements, --seed"
        )
    robot = args.robot or "so101"
    options = arm_options(args.arm)
    tracker = load_tracker(args.tracker)
    checkpoint = args.resume or args.checkpoint
    for path, option in ((checkpoint, "--checkpoint"), (args.out, "--out")):
        if path is not None:
            check_writable(path, option)
    no_clobber(args.out, "--out", getattr(args, "overwrite", False))
    from gb_pin.hardware import FeetechArm
    from gb_pin.hardware.babbling import babble_on_arm

    movements = args.movements or 1000
    done = 0
    if args.resume:
        from gb_pin.runs.checkpoint import read_checkpoint

        state, info = read_checkpoint(args.resume)
        movements, done = info.movements, int(state.movements)
    progress = progress_bar(robot, movements, done, disable=args.quiet)
    start = time.perf_counter()
    with FeetechArm(robot=robot, **options) as arm:
        print(f"arm              {robot} on {arm.bus.port}, {len(arm.ids)} servos answered; "
              f"on Ctrl-C: {arm.on_stop}", flush=True)  # fmt: skip
        try:
            result = babble_on_arm(
                arm, tracker, movements=movements, seed=args.seed or 0, checkpoint=checkpoint,
                resume=bool(args.resume), checkpoint_every=args.checkpoint_every, callback=progress,
            )  # fmt: skip
        except KeyboardInterrupt:
            progress.close()
            where = f"; the checkpoint {checkpoint} holds it: --resume {checkpoint}" if checkpoint else ""
            raise KeyboardInterrupt(
                f"interrupted (Ctrl-C); the arm is {'held' if arm.on_stop == 'hold' else 'parked'}{where}"
            ) from None
        finally:
            progress.close()
        wall = time.perf_counter() - start
        steps = max(result.steps, 1)
        print(f"movements        {result.movements} ({result.steps} steps), {arm.moves} moves this session, "
              f"{1e3 * wall / max(arm.moves, 1):.1f} ms each")  # fmt: skip
        print(f"missing readings {result.missing} ({result.missing / steps:.1%} of the steps)")
        faults = ", ".join(f"{k} {v}" for k, v in sorted(arm.bus.faults.items())) or "none"
        print(f"bus              {arm.bus.transactions} transactions; faults recovered: {faults}")
        stalled = ", ".join(f"{k} {v}" for k, v in arm.stalled.items())
        print(f"stalls           {arm.stalls}{f' ({stalled})' if stalled else ''}")
    reach = result.history.reach
    if reach is not None and reach.size:
        print(f"reach (observed) {reach[-1]:.5f} m   median miss at the end of the last goal movements")
    if args.out is not None:
        where = result.save(args.out)
        print(f"saved            {where or args.out}")
    args.quick_exit = True
    return 0
