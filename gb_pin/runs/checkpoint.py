"""Checkpoints: the complete state of a goal-babbling run in one ``.npz`` file.

A checkpoint holds everything the run needs to continue exactly as if it had
never stopped: the local-linear map, the exploration noise, the position on the
current path, the random generator's state, the history and the recording. Files
are written to a temporary name, flushed to disk and renamed, so a crash (even
SIGKILL) mid-write leaves the previous checkpoint intact. They are read member by
member (:func:`gb_pin.runs.archive.read_archive`): plain arrays only, never pickle.
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import os
import stat
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from gb_pin.exceptions import GbPinError, InvalidArgumentError, ResultFileError
from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.goals import make_goals
from gb_pin.learn.state import BabbleState
from gb_pin.runs import fields, robot_source
from gb_pin.runs.archive import atomic_savez, check_digest, read_archive
from gb_pin.safety.record import read_settings

FORMAT = "gb_pin.checkpoint"
FORMAT_VERSION = 2
"""2: the header holds a SHA-256 digest of the arrays and the header
(:func:`~gb_pin.runs.archive.content_digest`), verified on reading. Version 1 (no digest) is
still read, unless it holds a simulated plant's state: a plant state edited within plausible
bounds gave readings 0.11-0.38 m off that no check can see.
"""


@dataclass(frozen=True)
class CheckpointInfo:
    """What a checkpoint says about its run.

    Attributes:
        robot: preset name, or None for a custom KinematicTarget.
        target_name: the target's name.
        movements: movements the run was asked for in total.
        seed: the integer seed, or None if a Generator was given.
        config: hyperparameters.
        wall_time: seconds of babbling before the checkpoint.
        source: how to rebuild a robot that is no preset (:mod:`gb_pin.runs.robot_source`), or None.
        evaluate: where a session's E^X comes from (``"model"``, ``"movements"``, ``"none"``).
        unobserved: test targets of a session's evaluation movements whose reading never arrived.
        robot_state: the arrays of a robot with a state of its own (a simulated plant), or None.
        safety: a safe run's obstacles, collision settings and counts
            (:func:`gb_pin.safety.record.settings_of`), or None: the run was not checked.
    """

    robot: str | None
    target_name: str
    movements: int
    seed: int | None
    config: BabbleConfig
    wall_time: float
    source: dict[str, Any] | None = None
    evaluate: str = "model"
    unobserved: int = 0
    robot_state: dict[str, Any] | None = None
    safety: dict[str, Any] | None = None


ROBOT_STATE = "robot_state."
"""Prefix of the arrays of a robot's own state (a simulated plant's) in a checkpoint."""
MAX_ROBOT_ARRAYS = 16


def write_checkpoint(path: str | os.PathLike[str], state: BabbleState, info: CheckpointInfo) -> None:
    """Write the state of a run atomically."""
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "robot": info.robot,
        "target_name": info.target_name,
        "movements": info.movements,
        "seed": info.seed,
        "config": info.config.as_dict(),
        "wall_time": info.wall_time,
        **state_header(state),
        "evaluate": info.evaluate,
        "unobserved": info.unobserved,
    }
    if info.source is not None:
        meta["robot_source"] = info.source
    if info.safety is not None:  # a safe run: resumed with the same check
        meta["safety"] = info.safety
    arrays = dict(state.to_arrays())
    for key, value in (info.robot_state or {}).items():
        arrays[ROBOT_STATE + key] = value
    atomic_savez(os.fspath(path), arrays, meta, digest=True)


def state_header(state: BabbleState) -> dict[str, Any]:
    """The header entries of a state beside its arrays: the random generators' states and the goals."""
    header: dict[str, Any] = {
        "rng": state.rng_state(),
        "goals": {"name": state.goals.name, "params": state.goals.get_params()},
    }
    if state.sensor is not None:
        header["sensor_rng"] = state.sensor_rng_state()
    return header


def read_state(
    path: str, arrays: dict[str, Any], header: dict[str, Any], config: BabbleConfig
) -> BabbleState:
    """The state whose arrays and :func:`state_header` entries a file holds, checked.

    Raises:
        ResultFileError, InvalidArgumentError: corrupted entries (arrays out of range, a bad generator).
        KeyError, TypeError, ValueError: missing or malformed entries (the caller names the file).
    """
    goals = header.get("goals")  # files of gb_pin 0.1 have none: the paper's uniform choice
    if goals is not None and not (isinstance(goals, dict) and isinstance(goals.get("params"), dict)):
        raise ResultFileError(f"{path}: corrupted goal generator entry {goals!r}")
    generator = None if goals is None else make_goals(goals.get("name"), goals["params"])
    return BabbleState.from_arrays(
        arrays, config, header["rng"], goals=generator, sensor_rng=header.get("sensor_rng")
    )


def read_checkpoint(path: str | os.PathLike[str]) -> tuple[BabbleState, CheckpointInfo]:
    """Read a checkpoint written by :func:`write_checkpoint`.

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file; contents that do
            not match their digest (edited); a version-1 file holding a plant's state.
    """
    path = os.fspath(path)
    arrays, meta = read_archive(path, "checkpoint", FORMAT, FORMAT_VERSION)
    if meta["format_version"] >= 2:
        check_digest(path, "checkpoint", arrays, meta)
    elif any(k.startswith(ROBOT_STATE) for k in arrays):
        raise ResultFileError(
            f"{path}: a checkpoint of format version 1 (no digest) holding a simulated plant's state, "
            "which cannot be verified; this gb_pin resumes plants from version 2 on: start the run again"
        )
    own = {k[len(ROBOT_STATE) :]: arrays.pop(k) for k in sorted(arrays) if k.startswith(ROBOT_STATE)}
    if len(own) > MAX_ROBOT_ARRAYS:
        raise ResultFileError(f"{path}: {len(own)} robot state arrays (at most {MAX_ROBOT_ARRAYS})")
    try:
        config = BabbleConfig(**fields.config(path, meta))
        movements = fields.count(path, meta, "movements")
        info = CheckpointInfo(
            robot=fields.optional_str(path, meta, "robot"),
            target_name=str(fields.optional_str(path, meta, "target_name")),
            movements=movements,
            seed=fields.seed(path, meta),
            config=config,
            wall_time=fields.seconds(path, meta, "wall_time"),
            source=robot_source.check(path, meta.get("robot_source")),
            evaluate=_evaluate_mode(path, meta.get("evaluate", "model")),
            unobserved=fields.count(path, meta, "unobserved") if "unobserved" in meta else 0,
            robot_state=own or None,
            safety=read_settings(meta.get("safety")),
        )
        state = read_state(path, arrays, meta, config)
    except GbPinError as exc:
        raise ResultFileError(f"{path}: {exc}") from exc
    except (KeyError, TypeError, ValueError) as exc:
        raise ResultFileError(f"{path}: corrupted checkpoint ({exc!r})") from exc
    return state, info


def checkpoint_robot(path: str | os.PathLike[str], info: CheckpointInfo) -> Any:
    """The robot of a checkpoint's run: its preset, else the model its robot source records, rebuilt.

    Raises:
        InvalidArgumentError: the checkpoint records neither (a robot built in Python): pass it.
        ResultFileError: the recorded robot cannot be rebuilt (the message says how to pass it).
    """
    from gb_pin.robot.presets import load_robot

    if info.robot is not None:
        return load_robot(info.robot)
    if info.source is None:
        raise InvalidArgumentError(
            f"{os.fspath(path)}: the run used a custom robot {info.target_name!r} that the checkpoint "
            "cannot rebuild; pass it as robot= to resume"
        )
    return robot_source.rebuild(os.fspath(path), info.source)


def robot_state(robot: Any) -> dict[str, Any] | None:
    """The arrays of a robot's own state (``robot.robot_state()``: a simulated plant's), or None."""
    save = getattr(robot, "robot_state", None)
    return None if save is None else dict(save())


def restore_robot_state(path: str | os.PathLike[str], robot: Any, arrays: dict[str, Any] | None) -> None:
    """Put a robot with a state of its own back in the state a checkpoint saved (``set_robot_state``).

    Raises:
        ResultFileError: the checkpoint holds such a state and the robot takes none, or the other
            way round, or the robot refuses the arrays (malformed, or another plant's).
    """
    where = os.fspath(path)
    restore = getattr(robot, "set_robot_state", None)
    if arrays is None and restore is None:
        return
    if arrays is None:
        raise ResultFileError(
            f"{where}: written without the state of a simulated robot; {robot!r:.120} needs one"
        )
    if restore is None:
        raise ResultFileError(
            f"{where}: holds the state of a simulated robot; resume with that robot (e.g. its MujocoPlant), "
            f"not {robot!r:.120}"
        )
    try:
        restore(arrays)
    except GbPinError as exc:
        raise ResultFileError(f"{where}: {exc}") from exc


def _evaluate_mode(path: str, value: Any) -> str:
    if value not in ("model", "movements", "none"):
        raise ResultFileError(
            f"{path}: evaluate must be 'model', 'movements' or 'none', got {str(value)[:40]!r}"
        )
    return str(value)


def same_robot(path: str | os.PathLike[str], robot: Any, state: BabbleState) -> None:
    """Refuse a robot other than the checkpoint's: other dimensions, home, limits or kinematics.

    Raises:
        ResultFileError: naming what differs.
    """
    m, n = state.home.shape[0], state.targets.shape[1]
    where = os.fspath(path)
    if (getattr(robot, "n_joints", None), getattr(robot, "n_task", None)) != (m, n):
        raise ResultFileError(
            f"{where}: written for a robot of {m} joints and {n} task axes, got {robot!r:.120}"
        )
    # After a scheduled body change the state's chain is the changed body's, not the robot's.
    changed = any(at <= state.movements for at, _ in state.changes)
    chain = getattr(robot, "chain", None)
    if not changed and (chain is None) != (state.chain is None):
        kind = "with" if state.chain is not None else "without"
        raise ResultFileError(f"{where}: written for a robot {kind} compiled kinematics, got {robot!r:.120}")
    if not changed and chain is not None:
        for f in dataclasses.fields(chain):
            if not np.array_equal(
                np.asarray(getattr(chain, f.name)), np.asarray(getattr(state.chain, f.name))
            ):
                raise ResultFileError(
                    f"{where}: written for a robot whose kinematics differ from {robot.name!r} "
                    f"({f.name} differs)"
                )
    for name in ("home", "lower", "upper"):
        if not np.array_equal(np.asarray(getattr(robot, name), dtype=float), getattr(state, name)):
            raise ResultFileError(f"{where}: written for a robot of another {name} than {robot.name!r}")


@contextlib.contextmanager
def checkpoint_lock(path: str | os.PathLike[str] | None) -> Iterator[None]:
    """Hold an exclusive lock on ``path`` (a lock file beside it) for the duration of a run.

    Two runs writing one checkpoint would silently alternate; the second is refused instead.
    Nothing is locked for ``path`` None, or where the file system has no ``flock``.

    Raises:
        InvalidArgumentError: another run holds the lock.
    """
    if path is None:
        yield
        return
    full = os.path.abspath(os.fspath(path))
    lock = os.path.join(os.path.dirname(full), f".{os.path.basename(full)}.lock")
    while True:
        try:  # never through a symlink planted at the lock's name, never a FIFO or device
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            raise InvalidArgumentError(
                f"checkpoint {os.fspath(path)!r}: cannot create its lock {lock!r} ({exc.strerror or exc})"
            ) from exc
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            os.close(fd)
            raise InvalidArgumentError(
                f"checkpoint {os.fspath(path)!r}: its lock {lock!r} is not a regular file"
            )
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError as exc:
            os.close(fd)
            raise InvalidArgumentError(
                f"checkpoint {os.fspath(path)!r} is being written by another run (it holds {lock!r}); "
                "give this run another checkpoint file"
            ) from exc
        except OSError:  # no flock on this file system: run unlocked
            os.close(fd)
            yield
            return
        try:
            same = os.fstat(fd).st_ino == os.stat(lock).st_ino  # not unlinked by a finishing run meanwhile
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            os.remove(lock)
        os.close(fd)
