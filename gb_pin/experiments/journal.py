"""The trial journal: finished trials, one JSON line each, so that an interrupted sweep resumes.

The file (``"format": "gb_pin.trial-journal"``, version 1) is a header line, then one
line per finished trial: its key (robot, movements, seed, schedule, parameters) and its
output. A line is appended, flushed and fsynced as its trial finishes; everything else
(creating the file, dropping a torn last line) is an atomic rewrite through
:mod:`gb_pin._files`.
"""

from __future__ import annotations

import json
import os
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin._files import check_writable, write_text
from gb_pin.exceptions import ResultFileError
from gb_pin.experiments._json import check_size, plain

# What one trial needs: (robot, movements, seed, movement counts to record, babble arguments); the
# robot is a preset name, a MODULE:NAME, or the robot source (a JSON object) of a URDF or
# example-robot-data model (gb_pin.runs.robot_source), which each worker rebuilds.
TrialTask = tuple[str | dict[str, Any], int, int, NDArray[np.int64], dict[str, Any]]
# What one trial gives: (E^X at the schedule, D^home at the schedule, prototypes at the end, E^X per
# task component at the schedule (T, C) for a stacked task, else None).
TrialOutput = tuple[NDArray[np.float64], NDArray[np.float64], int, NDArray[np.float64] | None]


class TrialJournal:
    """Finished trials, appended one JSON line each, so an interrupted sweep recomputes nothing finished.

    Each line holds a trial's key (robot, movements, seed, schedule, parameters) and its
    output; lines are flushed and fsynced as trials finish. A crash mid-write leaves at
    most one incomplete last line, which is ignored. The file can be shared by several
    sweeps: a trial is reused only if every part of its key matches.

    Args:
        path: the journal file (created if missing).

    Raises:
        ResultFileError: the file exists but is not a gb_pin trial journal.
    """

    HEADER: ClassVar[dict[str, Any]] = {"format": "gb_pin.trial-journal", "format_version": 1}

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = check_writable(path, "trial journal")
        self.done: dict[str, TrialOutput] = {}
        if os.path.exists(self.path):
            self._read()
        else:
            write_text(self.path, json.dumps(self.HEADER) + "\n")

    @staticmethod
    def key(task: TrialTask) -> str:
        """A canonical string naming one trial."""
        robot, movements, seed, schedule, parameters = task
        return json.dumps(
            [
                robot,
                int(movements),
                int(seed),
                [int(v) for v in schedule],
                {k: plain(v) for k, v in parameters.items()},
            ],
            sort_keys=True,
        )

    def _read(self) -> None:
        check_size(self.path)
        try:
            with open(self.path, encoding="utf-8") as fh:
                lines = fh.read().split("\n")
        except (OSError, UnicodeDecodeError) as exc:
            raise ResultFileError(f"{self.path}: unreadable trial journal ({exc})") from exc
        try:
            header = json.loads(lines[0])
        except (ValueError, RecursionError):
            header = None
        if header != self.HEADER:
            raise ResultFileError(f"{self.path}: not a gb_pin trial journal (first line {lines[0][:80]!r})")
        complete = []
        for line in lines[1:]:
            try:
                entry = json.loads(line)
                out = _output(entry)
            except (ValueError, KeyError, TypeError, RecursionError):
                continue  # the last line of a run killed mid-write, or a line that is not a trial
            self.done[entry["key"]] = out
            complete.append(line)
        # Rewrite without a torn line, so that appended lines start on a fresh line.
        if len(complete) != len([ln for ln in lines[1:] if ln]):
            write_text(self.path, "\n".join([lines[0], *complete]) + "\n")

    def record(self, task: TrialTask, out: TrialOutput) -> None:
        """Append one finished trial durably (one line, flushed and fsynced)."""
        k = self.key(task)
        self.done[k] = out
        entry = {
            "key": k,
            "error": out[0].tolist(),
            "home_distance": out[1].tolist(),
            "prototypes": int(out[2]),
        }
        if out[3] is not None:
            entry["components"] = out[3].tolist()
        line = json.dumps(entry)
        with open(self.path, "a", encoding="utf-8") as fh:
            fh.write(line + "\n")
            fh.flush()
            os.fsync(fh.fileno())


def _output(entry: Any) -> TrialOutput:
    """A journal line's trial output, checked: a key string, two real 1-D curves of one length, a count.

    Raises:
        ValueError: anything else (the line is then ignored, and the trial recomputed).
    """
    if not isinstance(entry, dict) or not isinstance(entry.get("key"), str):
        raise ValueError("not a trial line")
    curves = []
    for name in ("error", "home_distance"):
        values = entry[name]
        if not isinstance(values, list) or not all(
            v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in values
        ):
            raise ValueError(f"{name} is not a list of numbers")
        curves.append(np.array([np.nan if v is None else v for v in values], dtype=float))
    prototypes = entry["prototypes"]
    if isinstance(prototypes, bool) or not isinstance(prototypes, int) or prototypes < 1:
        raise ValueError("prototypes is not a count")
    if curves[0].shape != curves[1].shape or np.any(np.isinf(curves[0])) or np.any(np.isinf(curves[1])):
        raise ValueError("curves of different lengths or infinite")
    components = None
    if entry.get("components") is not None:  # journals written before per-component curves have none
        rows = entry["components"]
        if not isinstance(rows, list) or len(rows) != curves[0].shape[0]:
            raise ValueError("components is not one row per recorded count")
        flat = [v for row in rows for v in (row if isinstance(row, list) else [None, "bad"])]
        if not all(v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in flat):
            raise ValueError("components is not a table of numbers")
        components = np.array([[np.nan if v is None else v for v in row] for row in rows], dtype=float)
        if components.ndim != 2 or not 1 <= components.shape[1] <= 64 or np.any(np.isinf(components)):
            raise ValueError("components is not a (T, C) table of finite numbers")
    return curves[0], curves[1], prototypes, components
