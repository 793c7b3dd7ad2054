"""Save and load results as one ``.npz`` file, read with ``allow_pickle=False``."""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from gb_pin._archive import atomic_savez, read_archive
from gb_pin.api import BabbleResult
from gb_pin.babbling import BabbleConfig, History, RecordedSteps
from gb_pin.exceptions import GbPinError, ResultFileError
from gb_pin.llm import LocalLinearMap
from gb_pin.robots import load_robot
from gb_pin.target import KinematicTarget

FORMAT = "gb_pin.result"
FORMAT_VERSION = 1
_REC_KEYS = ("rec_step", "rec_movement", "rec_posture", "rec_target", "rec_position")
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


def save_result(result: BabbleResult, path: str | os.PathLike[str]) -> None:
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
    }
    path = os.fspath(path)
    recording: dict[str, Any] = {}
    if result.recording is not None:
        rec = result.recording
        recording = {
            "rec_step": rec.step,
            "rec_movement": rec.movement,
            "rec_posture": rec.posture,
            "rec_target": rec.target,
            "rec_position": rec.position,
        }
    atomic_savez(
        path,
        {
            **recording,
            "movements": result.history.movements,
            "error": result.history.error,
            "home_distance": result.history.home_distance,
            "targets": result.targets,
            "prototypes": result.model.prototypes_,
            "matrices": result.model.matrices_,
            "offsets": result.model.offsets_,
        },
        meta,
        compress=True,
    )


def load_result(path: str | os.PathLike[str], target: KinematicTarget | None = None) -> BabbleResult:
    """Read a result written by :func:`save_result`.

    Args:
        path: the ``.npz`` file.
        target: the robot, needed only for results of a custom (non-preset) target.

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file.
    """
    path = os.fspath(path)
    arrays, meta = read_archive(path, "result file", FORMAT, FORMAT_VERSION, required=_KEYS[1:])
    rec_keys = [k for k in _REC_KEYS if k in arrays]
    if rec_keys and len(rec_keys) != len(_REC_KEYS):
        raise ResultFileError(f"{path}: incomplete recording (has {rec_keys})")
    try:
        if target is None:
            if meta["robot"] is None:
                raise ResultFileError(
                    f"{path}: saved from a custom KinematicTarget {meta['target_name']!r}; "
                    "pass target= to load_result"
                )
            target = load_robot(meta["robot"])
        if (target.n_joints, target.n_task) != (meta["n_joints"], meta["n_task"]):
            raise ResultFileError(
                f"{path}: saved for {meta['n_joints']} joints and {meta['n_task']} task axes, "
                f"but the target has {target.n_joints} and {target.n_task}"
            )
        config = BabbleConfig(**meta["config"])
        P, W, O = arrays["prototypes"], arrays["matrices"], arrays["offsets"]
        K = P.shape[0]
        if K < 1 or W.shape != (K, target.n_joints, target.n_task) or O.shape != (K, target.n_joints):
            raise ResultFileError(
                f"{path}: model arrays of inconsistent shapes {P.shape}, {W.shape}, {O.shape}"
            )
        model = LocalLinearMap(radius=config.radius, learning_rate=config.learning_rate)
        model.initialize(P[0], O[0], capacity=K)
        model._P[:K], model._W[:K], model._O[:K] = P, W, O
        model._K = K
        recording = None
        if "rec_step" in arrays:
            recording = RecordedSteps(
                step=arrays["rec_step"].astype(np.int64),
                movement=arrays["rec_movement"].astype(np.int64),
                posture=arrays["rec_posture"].astype(float),
                target=arrays["rec_target"].astype(float),
                position=arrays["rec_position"].astype(float),
            )
            R = recording.step.shape[0]
            if recording.posture.shape != (R, target.n_joints) or recording.target.shape != (
                R,
                target.n_task,
            ):
                raise ResultFileError(f"{path}: recording arrays of inconsistent shapes")
        history = History(
            movements=arrays["movements"].astype(np.int64),
            error=arrays["error"].astype(float),
            home_distance=arrays["home_distance"].astype(float),
        )
        return BabbleResult(
            target=target,
            targets=arrays["targets"].astype(float),
            history=history,
            model=model,
            config=config,
            seed=meta["seed"],
            robot=meta["robot"],
            movements=int(meta["movements"]),
            steps=int(meta["steps"]),
            wall_time=float(meta["wall_time"]),
            recording=recording,
        )
    except GbPinError as exc:
        if isinstance(exc, ResultFileError):
            raise
        raise ResultFileError(f"{path}: {exc}") from exc
    except (KeyError, TypeError, ValueError) as exc:
        raise ResultFileError(f"{path}: corrupted result file ({exc!r})") from exc
