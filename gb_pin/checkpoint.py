"""Checkpoints: the complete state of a goal-babbling run in one ``.npz`` file.

A checkpoint holds everything the run needs to continue exactly as if it had
never stopped: the local-linear map, the exploration noise, the position on the
current path, the random generator's state, the history and the recording. Files
are written to a temporary name, flushed to disk and renamed, so a crash (even
SIGKILL) mid-write leaves the previous checkpoint intact. They are read with
``allow_pickle=False``.
"""

from __future__ import annotations

import json
import os
import zipfile
import zlib
from dataclasses import dataclass
from typing import Any

import numpy as np

from gb_pin.babbling import BabbleConfig, BabbleState
from gb_pin.exceptions import GbPinError, ResultFileError

FORMAT = "gb_pin.checkpoint"
FORMAT_VERSION = 1


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
    """

    robot: str | None
    target_name: str
    movements: int
    seed: int | None
    config: BabbleConfig
    wall_time: float


def open_npz(path: str) -> Any:
    """``np.load`` of an .npz archive without pickle; anything else is a ResultFileError."""
    loaded = np.load(path, allow_pickle=False)
    if not isinstance(loaded, np.lib.npyio.NpzFile):
        raise ResultFileError(f"{path}: not an .npz archive (a {type(loaded).__name__})")
    return loaded


def atomic_savez(path: str, arrays: dict[str, Any], compress: bool = False) -> None:
    """Write ``arrays`` to ``path`` as .npz: temporary file, fsync, rename."""
    directory = os.path.dirname(os.path.abspath(path))
    tmp = os.path.join(directory, f".{os.path.basename(path)}.{os.getpid()}.tmp")
    try:
        with open(tmp, "wb") as fh:
            (np.savez_compressed if compress else np.savez)(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def write_checkpoint(path: str | os.PathLike[str], state: BabbleState, info: CheckpointInfo) -> None:
    """Write the state of a run atomically."""
    from gb_pin import __version__

    meta = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "gb_pin_version": __version__,
        "robot": info.robot,
        "target_name": info.target_name,
        "movements": info.movements,
        "seed": info.seed,
        "config": info.config.as_dict(),
        "wall_time": info.wall_time,
        "rng": state.rng_state(),
    }
    arrays = state.to_arrays()
    arrays["meta"] = np.array(json.dumps(meta))
    atomic_savez(os.fspath(path), arrays)


def read_checkpoint(path: str | os.PathLike[str]) -> tuple[BabbleState, CheckpointInfo]:
    """Read a checkpoint written by :func:`write_checkpoint`.

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file.
    """
    path = os.fspath(path)
    try:
        with open_npz(path) as archive:
            arrays = {k: archive[k] for k in archive.files}
    except FileNotFoundError as exc:
        raise ResultFileError(f"{path}: no such checkpoint file") from exc
    except (OSError, ValueError, TypeError, zipfile.BadZipFile, zlib.error, EOFError, KeyError) as exc:
        raise ResultFileError(f"{path}: unreadable or corrupted checkpoint ({exc})") from exc
    try:
        meta = json.loads(str(arrays.pop("meta")))
    except (KeyError, ValueError) as exc:
        raise ResultFileError(f"{path}: not a gb_pin checkpoint (no readable header)") from exc
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise ResultFileError(f"{path}: not a gb_pin checkpoint (header {str(meta)[:80]!r})")
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool):
        raise ResultFileError(f"{path}: corrupted header (format_version {version!r})")
    if version > FORMAT_VERSION:
        raise ResultFileError(
            f"{path}: written by a newer gb_pin (checkpoint version {version}); "
            f"this gb_pin reads up to {FORMAT_VERSION}"
        )
    try:
        config = BabbleConfig(**meta["config"])
        info = CheckpointInfo(
            robot=meta["robot"],
            target_name=str(meta["target_name"]),
            movements=int(meta["movements"]),
            seed=meta["seed"],
            config=config,
            wall_time=float(meta["wall_time"]),
        )
        state = BabbleState.from_arrays(arrays, config, meta["rng"])
    except GbPinError as exc:
        raise ResultFileError(f"{path}: {exc}") from exc
    except (KeyError, TypeError, ValueError) as exc:
        raise ResultFileError(f"{path}: corrupted checkpoint ({exc!r})") from exc
    if not all(np.all(np.isfinite(state.to_arrays()[k])) for k in ("prototypes", "matrices", "offsets")):
        raise ResultFileError(f"{path}: the model in this checkpoint is not finite")
    return state, info
