"""The trial journal: finished trials, one JSON line each, so that an interrupted sweep resumes.

The file (``"format": "gb_pin.trial-journal"``, version 1) is a header line, then one
line per finished trial: its key (robot, movements, seed, schedule, parameters) and its
output. A line is appended, flushed and fsynced as its trial finishes; everything else
(creating the file, dropping a torn last line) is an atomic rewrite through
:mod:`gb_pin._files`.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import stat
import tempfile
import warnings
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from gb_pin._files import cache_root, check_writable, write_text
from gb_pin._validation import INT64_MAX
from gb_pin.exceptions import GbPinWarning, InvalidArgumentError, ResultFileError
from gb_pin.experiments._json import plain, read_lines

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
    most one incomplete last line, which is ignored (as is any line that is not a trial: its
    trial is recomputed). The file can be shared by several sweeps: a trial is reused only if
    every part of its key matches. It is read line by line (at most
    :data:`~gb_pin.experiments._json.MAX_JOURNAL_BYTES`), keeping only the parsed curves.

    If appending fails (the disk is full), the journal moves: every finished trial is written to
    a fallback file (:func:`fallback_journals`: fixed places derived from the journal's path,
    named in a :class:`GbPinWarning`) and later trials are appended there; if no file can be
    written, the run goes on unjournaled (with a warning), its results intact. Opening a journal
    reads its fallbacks too, so a rerun with the same journal recomputes nothing journaled there;
    where the journal's own file can be written again, their trials are moved back into it.

    Args:
        path: the journal file (created if missing).

    Raises:
        ResultFileError: the file exists but is not a gb_pin trial journal (or not a regular file).
        InvalidArgumentError: the file cannot be created.
    """

    HEADER: ClassVar[dict[str, Any]] = {"format": "gb_pin.trial-journal", "format_version": 1}

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = check_writable(path, "trial journal")
        self.done: dict[str, TrialOutput] = {}
        self.writing: str | None = self.path  # where lines go (a fallback after a failed write)
        self._newline = False  # the file ends inside a torn line: the next line starts on a new line
        if os.path.lexists(self.path):
            self.done.update(self._read(self.path, own=True))
        else:
            try:
                write_text(self.path, json.dumps(self.HEADER) + "\n")
            except OSError as exc:
                self._created(exc)
        self._gather()

    def _created(self, exc: OSError) -> None:
        """The journal's own file cannot be created (a full disk): start in a fallback, else refuse."""
        self.writing = None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", GbPinWarning)
            self.writing = self._move_to(fallback_journals(self.path))
        if self.writing is None:
            raise InvalidArgumentError(
                f"trial journal {self.path!r} cannot be created ({exc.strerror or exc})"
            ) from exc
        warnings.warn(
            f"cannot create the trial journal {self.path!r} ({exc.strerror or exc}); finished trials "
            f"go to {self.writing!r}, where a rerun with the same journal reads them",
            GbPinWarning,
            stacklevel=3,
        )

    def _gather(self) -> None:
        """Read the trials earlier runs moved to :func:`fallback_journals`; bring them home if possible."""
        moved: dict[str, TrialOutput] = {}
        found = []
        for other in fallback_journals(self.path):
            if other == self.writing or not os.path.lexists(other):
                continue
            try:
                trials = self._read(other, own=False)
            except (ResultFileError, InvalidArgumentError, OSError) as exc:
                note = f"ignoring the trial journal's fallback {other!r}: {exc}"
                warnings.warn(note, GbPinWarning, stacklevel=3)
                continue
            found.append(other)
            moved.update({k: o for k, o in trials.items() if k not in self.done})
        self.done.update(moved)
        if not found or self.writing != self.path:
            return
        try:  # the journal's own file takes them back (one append), then the fallbacks go
            if moved:
                self._append("\n".join(self._line(k, o) for k, o in moved.items()))
        except OSError:
            return  # they stay where they are, and are read from there again
        for other in found:
            with contextlib.suppress(OSError):
                os.remove(other)

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

    def _read(self, path: str, own: bool) -> dict[str, TrialOutput]:
        """The trials of the journal file ``path``.

        ``own``: the file this journal appends to (a torn last line is then cut off).
        """
        done: dict[str, TrialOutput] = {}
        lines = read_lines(path, "trial journal")
        first, _ = next(lines, (b"", True))
        try:
            header = json.loads(first)
        except (ValueError, RecursionError):
            header = None
        if header != self.HEADER:
            shown = first[:80].decode("utf-8", "replace").rstrip("\n")
            raise ResultFileError(f"{path}: not a gb_pin trial journal (first line {shown!r})")
        end = size = len(first)  # bytes up to the end of the last line ending in a newline, and in all
        parsed = True  # whether the last line is a trial
        for line, length in lines:
            size += length
            if line.endswith(b"\n") or not line:  # not line: an over-long line, skipped
                end = size
            try:
                entry = json.loads(line)
                out = _output(entry)
            except (ValueError, KeyError, TypeError, RecursionError, MemoryError):
                parsed = False  # the last line of a run killed mid-write, or a line that is not a trial
                continue
            parsed = True
            done[entry["key"]] = out
        if not own:
            return done
        # A last line without its newline: a torn one (killed mid-write) is cut off, so that the next
        # trial starts a line of its own; a whole trial (or the header) is kept, and a newline added.
        self._newline = size != end or not first.endswith(b"\n")
        if size != end and not parsed and first.endswith(b"\n"):
            try:
                os.truncate(path, end)
                self._newline = False
            except OSError:
                pass
        return done

    def _line(self, key: str, out: TrialOutput) -> str:
        entry = {
            "key": key,
            "error": out[0].tolist(),
            "home_distance": out[1].tolist(),
            "prototypes": int(out[2]),
        }
        if out[3] is not None:
            entry["components"] = out[3].tolist()
        return json.dumps(entry)

    def record(self, task: TrialTask, out: TrialOutput) -> None:
        """Append one finished trial durably (one line, flushed and fsynced); move the journal if it fails."""
        k = self.key(task)
        self.done[k] = out
        if self.writing is None:
            return
        try:
            self._append(self._line(k, out))
        except OSError as exc:
            self._move(exc)

    def _append(self, lines: str) -> None:
        """Append ``lines`` (without their last newline) to the file written, flushed and fsynced."""
        assert self.writing is not None
        with open(self.writing, "a", encoding="utf-8") as fh:
            fh.write(("\n" if self._newline else "") + lines + "\n")
            fh.flush()
            os.fsync(fh.fileno())
        self._newline = False

    def _move_to(self, places: list[str]) -> str | None:
        """Write every finished trial to the first of ``places`` that takes them; that place, or None."""
        lines = [json.dumps(self.HEADER), *(self._line(k, o) for k, o in self.done.items())]
        for place in places:
            if place == self.writing or not _private_parent(place):
                continue
            try:
                write_text(place, "\n".join(lines) + "\n")
            except (OSError, InvalidArgumentError):
                continue
            return place
        return None

    def _move(self, exc: OSError) -> None:
        """After a failed append: write every finished trial to a fallback file and continue there."""
        failed = self.writing
        where = self._move_to(fallback_journals(self.path))
        if where is None:
            self.writing = None
            warnings.warn(
                f"cannot append to the trial journal {failed!r} ({exc.strerror or exc}) nor write it "
                f"to {' or '.join(map(repr, fallback_journals(self.path)))}; the trials go on, no longer "
                "journaled",
                GbPinWarning,
                stacklevel=3,
            )
            return
        self.writing, self._newline = where, False
        warnings.warn(
            f"cannot append to the trial journal {failed!r} ({exc.strerror or exc}); its "
            f"{len(self.done)} finished trials are in {where!r}, and the next ones will be; a rerun "
            "with the same journal reads them from there",
            GbPinWarning,
            stacklevel=3,
        )


def fallback_journals(path: str | os.PathLike[str]) -> list[str]:
    """Where the journal ``path`` moves when its own file cannot be written, in order of preference.

    The places are fixed for a journal (the name holds a digest of its absolute path), so that
    :class:`TrialJournal` reads them whenever it opens the same journal: gb_pin's cache folder
    (:func:`gb_pin._files.cache_root`, ``journals/``), then this user's folder in the temporary
    directory (``gb_pin-UID/journals/``).
    """
    full = os.path.abspath(os.fspath(path))
    tag = hashlib.sha256(full.encode("utf-8", "surrogateescape")).hexdigest()[:16]
    name = f"{os.path.basename(full)[:120]}.{tag}.jsonl"
    folders = (
        os.path.join(cache_root(), "journals"),
        os.path.join(tempfile.gettempdir(), f"gb_pin-{os.geteuid()}", "journals"),
    )
    return [os.path.join(folder, name) for folder in folders]


def remove_journal(path: str | os.PathLike[str]) -> None:
    """Remove a journal whose trials are saved elsewhere now, and its fallbacks (what is there)."""
    for where in (os.fspath(path), *fallback_journals(path)):
        with contextlib.suppress(OSError):
            os.remove(where)


def _private_parent(place: str) -> bool:
    """Create the folder of a fallback journal (mode 700); False where it is not a folder of this user's."""
    folder = os.path.dirname(place)
    try:
        os.makedirs(folder, mode=0o700, exist_ok=True)
        infos = [os.lstat(folder), os.lstat(os.path.dirname(folder))]  # planted by another user: skipped
    except OSError:
        return False
    return all(stat.S_ISDIR(i.st_mode) and i.st_uid == os.geteuid() for i in infos)


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
    if isinstance(prototypes, bool) or not isinstance(prototypes, int) or not 1 <= prototypes <= INT64_MAX:
        raise ValueError("prototypes is not a count")
    if curves[0].shape != curves[1].shape or any(np.any(np.isinf(c) | (c < 0)) for c in curves):
        raise ValueError("curves of different lengths, infinite or negative")
    components = None
    if entry.get("components") is not None:  # journals written before per-component curves have none
        rows = entry["components"]
        if not isinstance(rows, list) or len(rows) != curves[0].shape[0]:
            raise ValueError("components is not one row per recorded count")
        flat = [v for row in rows for v in (row if isinstance(row, list) else [None, "bad"])]
        if not all(v is None or (isinstance(v, int | float) and not isinstance(v, bool)) for v in flat):
            raise ValueError("components is not a table of numbers")
        components = np.array([[np.nan if v is None else v for v in row] for row in rows], dtype=float)
        if (
            components.ndim != 2
            or not 1 <= components.shape[1] <= 64
            or np.any(np.isinf(components) | (components < 0))
        ):
            raise ValueError("components is not a (T, C) table of finite numbers")
    return curves[0], curves[1], prototypes, components
