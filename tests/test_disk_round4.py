"""Writes on a full disk: gb_pin's own error naming the file (and still an OSError for fallbacks)."""

from __future__ import annotations

import errno
from pathlib import Path
from typing import Any

import pytest

import gb_pin
from gb_pin.exceptions import FileWriteError


def test_an_explicit_checkpoint_on_a_full_disk_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    session = gb_pin.babble_session("planar5", movements=20, seed=0)
    session.tell(session.target.forward(session.ask()))

    def full(path: Any, state: Any, info: Any) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr("gb_pin.runs.checkpoint.write_checkpoint", full)
    where = tmp_path / "run.ckpt"
    with pytest.raises(
        FileWriteError, match=r"cannot write the checkpoint .*run.ckpt.*No space left"
    ) as info:
        session.save_checkpoint(where)
    assert isinstance(info.value, OSError) and info.value.errno == errno.ENOSPC
