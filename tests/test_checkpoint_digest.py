"""Checkpoints verify themselves: a SHA-256 digest of every array and the header, checked on reading.

A plant state edited within every plausibility bound (the joints a little elsewhere, at rest) was
resumed, and the plant's readings were 0.11-0.38 m off the arm the session had learnt (issue 33).
No bound can tell such a state from a true one; the digest written with the file can.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin.exceptions import ResultFileError
from gb_pin.runs.archive import DIGEST, atomic_savez, content_digest, read_archive
from gb_pin.runs.checkpoint import FORMAT, FORMAT_VERSION, read_checkpoint
from gb_pin.runs.session import resume_session


def _arrays(path: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    return read_archive(str(path), "checkpoint", FORMAT, FORMAT_VERSION)


def _rewrite(path: Path, arrays: dict[str, Any], meta: dict[str, Any]) -> None:
    """What an editor does: the arrays and header changed, written back as a plain .npz."""
    with open(path, "wb") as fh:  # (np.savez adds ".npz" to a name without it)
        np.savez(fh, meta=np.array(json.dumps(meta)), **arrays)


def test_the_digest_covers_every_array_and_the_header(tmp_path: Path) -> None:
    path = tmp_path / "run.ckpt"
    gb_pin.babble("planar5", movements=30, seed=0, checkpoint=path)
    arrays, meta = _arrays(path)
    assert meta["format_version"] == 2 and meta[DIGEST] == content_digest(arrays, meta)
    read_checkpoint(path)  # untouched: read
    edits = {
        "an array's value": lambda a, m: a.__setitem__("noise_b", a["noise_b"] + 1e-12),
        "an array's dtype": lambda a, m: a.__setitem__("noise_b", a["noise_b"].astype(np.float32)),
        "an array's shape": lambda a, m: a.__setitem__("noise_b", a["noise_b"][None]),
        "a header entry": lambda a, m: m.__setitem__("wall_time", m["wall_time"] + 1.0),
        "a new array": lambda a, m: a.__setitem__("extra", np.zeros(1)),
        "the map": lambda a, m: a.__setitem__("offsets", a["offsets"] * (1 + 1e-9)),
        "the digest itself": lambda a, m: m.__setitem__(DIGEST, "sha256:" + "0" * 64),
    }
    for what, edit in edits.items():
        a, m = {k: v.copy() for k, v in arrays.items()}, dict(meta)
        edit(a, m)
        _rewrite(path, a, m)
        with pytest.raises(ResultFileError, match=r"run\.ckpt: its contents do not match the digest"):
            gb_pin.resume(path)
            raise AssertionError(what)  # pragma: no cover
    m = dict(meta)
    del m[DIGEST]
    _rewrite(path, arrays, m)
    with pytest.raises(ResultFileError, match=r"run\.ckpt: .*format version 2 without its digest"):
        gb_pin.resume(path)


def test_a_version_1_checkpoint_without_a_plant_is_still_resumed(tmp_path: Path) -> None:
    """Files of the previous format (no digest) continue bit-identical, as before."""
    path = tmp_path / "old.ckpt"
    gb_pin.babble("planar5", movements=60, seed=1, checkpoint=path, checkpoint_every=30)
    whole = gb_pin.babble("planar5", movements=60, seed=1)
    arrays, meta = _arrays(path)
    meta = {k: v for k, v in meta.items() if k != DIGEST}
    meta["format_version"] = 1
    _rewrite(path, arrays, meta)
    resumed = gb_pin.resume(path)
    np.testing.assert_array_equal(resumed.history.error, whole.history.error)


def test_a_plant_state_edited_within_its_bounds_is_refused(tmp_path: Path) -> None:
    """The arm's joints moved by 0.3 rad and at rest: plausible, and refused by the digest."""
    pytest.importorskip("mujoco")
    from gb_pin.sim import MujocoPlant

    plant = MujocoPlant("so101", period=0.02, seed=2)
    path = tmp_path / "plant.ckpt"
    session = gb_pin.babble_session(plant, movements=6, seed=0, checkpoint=path, checkpoint_every=3)
    while session.movements < 3:
        session.tell(plant.forward(session.ask()))
    session.close()
    arrays, meta = _arrays(path)
    nq = plant.mj_model.nq
    state = arrays["robot_state.mujoco"].copy()
    state[1 : 1 + nq] = np.clip(state[1 : 1 + nq] + 0.3, plant.lower, plant.upper)  # within the limits
    state[1 + nq : 1 + 2 * nq] = 0.0  # at rest
    edited = {**arrays, "robot_state.mujoco": state}
    MujocoPlant("so101", period=0.02, seed=2).set_robot_state(
        {k[len("robot_state.") :]: v for k, v in edited.items() if k.startswith("robot_state.")}
    )  # the plant itself finds nothing wrong with it
    _rewrite(path, edited, meta)
    with pytest.raises(ResultFileError, match=r"plant\.ckpt: its contents do not match the digest"):
        resume_session(path, robot=MujocoPlant("so101", period=0.02, seed=2))
    # The same edit in a file of format version 1 (no digest): refused for its plant state.
    old = {k: v for k, v in meta.items() if k != DIGEST}
    old["format_version"] = 1
    _rewrite(path, edited, old)
    with pytest.raises(ResultFileError, match=r"plant\.ckpt: a checkpoint of format version 1 .*plant"):
        resume_session(path, robot=MujocoPlant("so101", period=0.02, seed=2))


def test_a_digest_recomputed_after_an_edit_still_meets_the_other_checks(tmp_path: Path) -> None:
    """The digest is integrity, not a signature: arrays are still validated one by one behind it."""
    path = tmp_path / "run.ckpt"
    gb_pin.babble("planar5", movements=30, seed=0, checkpoint=path)
    arrays, meta = _arrays(path)
    atomic_savez(str(path), {**arrays, "lower": arrays["lower"][:1]}, meta, digest=True)
    with pytest.raises(ResultFileError) as info:
        gb_pin.resume(path)
    assert "lower must be" in str(info.value)
