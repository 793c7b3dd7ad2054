"""The result file: one ``.npz`` of plain arrays and a JSON header, read without pickle (``runs.archive``)."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

from gb_pin._files import check_writable
from gb_pin.exceptions import GbPinError, ResultFileError
from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.history import History, RecordedSteps
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.parts import PartedMap
from gb_pin.robot.presets import load_robot
from gb_pin.robot.target import KinematicTarget
from gb_pin.runs import fields, robot_source
from gb_pin.runs.archive import atomic_savez, read_archive

if TYPE_CHECKING:
    from gb_pin.runs.result import BabbleResult

FORMAT = "gb_pin.result"
FORMAT_VERSION = 1
STATE = "state_"  # the final state's arrays, as a checkpoint holds them, prefixed (older files: none)
_KEYS = (
    "meta",
    "movements",
    "error",
    "home_distance",
    "targets",
    "prototypes",
    "matrices",
    "offsets",
)


def write_result(result: BabbleResult, path: str | os.PathLike[str]) -> None:
    """Write ``result`` to ``path`` (an ``.npz`` archive of plain arrays and a JSON header).

    The file is written to a temporary name, flushed and renamed, so a crash never leaves half a file.
    """
    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "robot": result.robot,
        "target_name": result.target.name,
        "n_joints": result.target.n_joints,
        "n_task": result.target.n_task,
        "config": result.config.as_dict(),
        "seed": result.seed,
        "movements": result.movements,
        "steps": result.steps,
        "wall_time": result.wall_time,
        "missing": result.missing,
    }
    source = robot_source.describe(result.target, result.robot)
    if source is not None:  # how to rebuild a robot that is no preset (files of 0.1 have none)
        meta["robot_source"] = source
    path = check_writable(path, "result file")
    recording = {} if result.recording is None else result.recording.to_arrays()
    components = result.history.components
    extra = {} if components is None else {"history_components": components}  # stacked tasks only
    if result.history.reach is not None:
        extra["history_reach"] = result.history.reach
    if result.goal_targets is not None:  # a goal set other than the test set
        extra["goal_targets"] = result.goal_targets
    if result.goals is not None:  # a goal generator other than the paper's
        meta["goals"] = result.goals
    if result.home_error is not None:  # a continued run: the first run's E_0
        meta["home_error"] = result.home_error
    if result.safety is not None:  # a safe run: its obstacles, collision settings and counts
        meta["safety"] = result.safety
    if result.state is not None:  # the final state: babble(init=load_result(...)) continues the run
        from gb_pin.runs.checkpoint import state_header

        extra.update({STATE + k: v for k, v in result.state.to_arrays().items()})
        meta["state"] = state_header(result.state)
    atomic_savez(
        path,
        {
            **recording,
            **extra,
            "movements": result.history.movements,
            "error": result.history.error,
            "home_distance": result.history.home_distance,
            "targets": result.targets,
            **result.model.to_arrays(),
        },
        meta,
        compress=True,
    )


def read_result(path: str | os.PathLike[str], target: KinematicTarget | None = None) -> dict[str, Any]:
    """The fields of a :class:`~gb_pin.runs.result.BabbleResult` written by :func:`write_result`.

    Args:
        path: the ``.npz`` file.
        target: the robot; default the preset the file names, else the URDF or example-robot-data
            model its ``robot_source`` records, rebuilt (:mod:`gb_pin.runs.robot_source`).

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file, or a robot
            that cannot be rebuilt from what the file records (the message says how to pass it).
    """
    path = os.fspath(path)
    arrays, meta = read_archive(path, "result file", FORMAT, FORMAT_VERSION, required=_KEYS[1:])
    try:
        robot = fields.optional_str(path, meta, "robot")
        seed = fields.seed(path, meta)
        movements, steps = fields.count(path, meta, "movements"), fields.count(path, meta, "steps")
        wall_time = fields.seconds(path, meta, "wall_time")
        for key in ("n_joints", "n_task"):
            if isinstance(meta.get(key), bool) or not isinstance(meta.get(key), int):
                raise ResultFileError(f"{path}: {key} must be an integer, got {str(meta.get(key))[:80]!r}")
        source = robot_source.check(path, meta.get("robot_source"))
        if target is None:
            target = _rebuild(path, robot, source, meta.get("target_name"))
        if (target.n_joints, target.n_task) != (meta["n_joints"], meta["n_task"]):
            raise ResultFileError(
                f"{path}: saved for {meta['n_joints']} joints and {meta['n_task']} task axes, "
                f"but the target has {target.n_joints} and {target.n_task}"
            )
        config = BabbleConfig(**fields.config(path, meta))
        model: Any = (
            PartedMap.from_arrays(arrays, config.radius, config.learning_rate, config.cutoff)
            if "part_sizes" in arrays  # a workspace region learnt in parts (gb_pin.runs.parted)
            else LocalLinearMap.from_arrays(arrays, config.radius, config.learning_rate, cutoff=config.cutoff)
        )
        if (model.n_outputs_, model.n_inputs_) != (target.n_joints, target.n_task):
            raise ResultFileError(
                f"{path}: model arrays of {model.n_outputs_} outputs, {model.n_inputs_} inputs"
            )
        recording = RecordedSteps.from_arrays(arrays, target.n_joints, target.n_task)
        moves, error, home_distance = fields.history(path, arrays)
        components = fields.components(path, arrays, moves.shape[0])
        history = History(
            movements=moves, error=error, home_distance=home_distance, components=components,
            reach=fields.reach(path, arrays, moves.shape[0]),
        )  # fmt: skip
        return dict(
            target=target,
            targets=fields.targets(path, arrays, target.n_task),
            history=history,
            model=model,
            config=config,
            seed=seed,
            robot=robot,
            movements=movements,
            steps=steps,
            wall_time=wall_time,
            recording=recording,
            goals=fields.goals(path, meta),
            goal_targets=fields.targets(path, arrays, target.n_task, "goal_targets")
            if "goal_targets" in arrays
            else None,
            state=_state(path, arrays, meta, config, target),
            missing=fields.count(path, meta, "missing") if "missing" in meta else 0,
            home_error=fields.seconds(path, meta, "home_error") if "home_error" in meta else None,
            **_safety(meta),
        )
    except GbPinError as exc:
        if isinstance(exc, ResultFileError):
            raise
        raise ResultFileError(f"{path}: {exc}") from exc
    except (KeyError, TypeError, ValueError) as exc:
        raise ResultFileError(f"{path}: corrupted result file ({exc!r})") from exc


def _safety(meta: dict[str, Any]) -> dict[str, Any]:
    """The result fields of a safe run's recorded settings (none for a run that was not checked)."""
    from gb_pin.safety.record import read_settings

    safety = read_settings(meta.get("safety"))
    if safety is None:
        return {}
    return {"safety": safety, "checked_asks": safety["checked_asks"], "cut_asks": safety["cut_asks"]}


def read_curves(path: str | os.PathLike[str]) -> tuple[History, str, int]:
    """(the history E^X / D^home, the robot's name, movements) of a result file, no robot rebuilt.

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file.
    """
    path = os.fspath(path)
    arrays, meta = read_archive(path, "result file", FORMAT, FORMAT_VERSION, required=_KEYS[1:])
    try:
        name = fields.optional_str(path, meta, "robot") or fields.optional_str(path, meta, "target_name")
        moves, error, home_distance = fields.history(path, arrays)
        history = History(movements=moves, error=error, home_distance=home_distance)
        return history, str(name or "robot"), fields.count(path, meta, "movements")
    except (KeyError, TypeError, ValueError) as exc:
        raise ResultFileError(f"{path}: corrupted result file ({exc!r})") from exc


def _state(path: str, arrays: dict[str, Any], meta: dict[str, Any], config: BabbleConfig, target: Any) -> Any:
    """The run's final state the file holds (None for files without one), checked against the robot."""
    header = meta.get("state")
    if header is None:
        return None
    from gb_pin.runs.checkpoint import read_state

    if not isinstance(header, dict):
        raise ResultFileError(f"{path}: state must be an object, got {str(header)[:80]!r}")
    state = read_state(
        path, {k[len(STATE) :]: v for k, v in arrays.items() if k.startswith(STATE)}, header, config
    )
    if (state.home.shape[0], state.targets.shape[1]) != (target.n_joints, target.n_task):
        raise ResultFileError(f"{path}: the final state is of another number of joints or task axes")
    return state


def _rebuild(path: str, robot: str | None, source: dict[str, Any] | None, name: Any) -> Any:
    """The run's robot, from the preset name or the robot source the file records.

    Raises:
        ResultFileError: the file records neither (a robot given as a Python object), or the
            recorded robot cannot be rebuilt.
    """
    if robot is not None:
        return load_robot(robot)
    if source is not None:
        return robot_source.rebuild(path, source)
    raise ResultFileError(
        f"{path}: saved from a custom robot {str(name)[:80]!r} that the file cannot rebuild (built in "
        "Python from a pin.Model or a function); pass it: load_result(path, target=...) in Python, or "
        "--robot (a URDF or erd:NAME with --frame, --joints, --home, --axes; or MODULE:NAME) in gb-pin"
    )
