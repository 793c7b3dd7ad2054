"""Runs the docs' code blocks for tests/test_docs.py: many blocks in one interpreter, one result line each.

    python tests/docs_runner.py STEPS.json RESULTS.jsonl

STEPS.json is a list of ``{"id", "lang", "text", "folder"}`` (the blocks as tests/test_docs.py prepared
them: small runs, stand-ins in ``folder``). Each block runs in its own folder (the working directory
while it runs), its output captured at the file-descriptor level (the C libraries' and subprocesses'
output included):

- a python block in a fresh namespace (``__name__ == "__main__"``), as ``python -c`` would run it;
- a bash block line by line: a line of ``gb-pin`` commands (joined by ``&&``) runs in this process
  through :func:`gb_pin.cli.main` (what the ``gb-pin`` program calls), any other line in ``bash -e``.
  A ``gb-pin`` command that writes nothing and reads no file of its folder, identical to one that
  passed before in this run, is not run again (the same command on the same inputs).

Each result is appended to RESULTS.jsonl as soon as the block ends (``{"id", "ok", "report", "seconds"}``:
CPU and wall seconds; ``DOCS_TIMES=FILE pytest tests/test_docs.py`` writes them all to FILE), so a
block that kills the interpreter loses nothing of the others: tests/test_docs.py starts a new runner
for the blocks after it. The interpreter is the one a reader's would be after its first block: numba's
compiled kernels, Pinocchio's models and MuJoCo loaded once instead of once a block (tests/test_docs.py,
warm numba cache, one run each on the loaded 2-core machine: 455 s of CPU with an interpreter a
block, 75 s with this runner; camera runs made smaller took it further).
"""

from __future__ import annotations

import json
import os
import re
import resource
import shlex
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

BLOCK_TIMEOUT = 600  # seconds a block may take (a cold numba cache compiles for 10-20 s per kernel set)
WRITES = re.compile(r"(?:^|\s)(?:--out|-o|--json|--html|--checkpoint|--doc|--figure|--resume|--continue)\b")
SHELL = re.compile(r"[|;<>$`*?(){}\\]")


class BlockFailedError(Exception):
    """A line of a bash block ended with a non-zero status."""


class Timeout(BaseException):
    """The block ran past :data:`BLOCK_TIMEOUT` (raised by SIGALRM in the main thread)."""


def _alarm(signum: int, frame: Any) -> None:
    raise Timeout(f"the block ran past {BLOCK_TIMEOUT} s")


def run_python(text: str, name: str) -> None:
    """The block as ``python -c`` runs it: a fresh ``__main__`` namespace; exit status 0 or a failure."""
    code = compile(text, name, "exec")
    try:
        exec(code, {"__name__": "__main__", "__builtins__": __builtins__})
    except SystemExit as exc:
        if exc.code not in (None, 0):
            raise BlockFailedError(f"the block exited with status {exc.code!r}") from exc


def _cli(argv: list[str]) -> int:
    from gb_pin.cli import main

    try:
        return main(argv)
    except SystemExit as exc:  # argparse's usage errors (status 2), --help, --version
        return exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)


def _same_inputs(command: str, folder: Path) -> bool:
    """Whether ``command`` writes nothing and reads no file of ``folder`` (same result anywhere)."""
    return not WRITES.search(command) and not any((folder / token).exists() for token in shlex.split(command))


def run_bash(text: str, folder: Path, passed: dict[str, str], where: str) -> list[str]:
    """The block's lines in order, ``gb-pin`` in this process; notes on the commands not run again."""
    notes = []
    for line in text.splitlines():
        code = line.partition(" #")[0].strip()
        if not code or code.startswith("#"):
            continue
        commands = [c.strip() for c in code.split("&&")]
        if SHELL.search(code) or not all(c.startswith("gb-pin ") for c in commands):
            done = subprocess.run(
                ["bash", "-e", "-o", "pipefail", "-c", line], timeout=BLOCK_TIMEOUT, check=False
            )
            if done.returncode != 0:
                raise BlockFailedError(f"{line!r}: exit status {done.returncode}")
            continue
        for command in commands:
            dedupe = _same_inputs(command, folder)
            if dedupe and command in passed:
                notes.append(f"{command!r}: passed in {passed[command]}, not run again")
                continue
            print(f"$ {command}", flush=True)
            status = _cli(shlex.split(command)[1:])
            sys.stdout.flush()
            sys.stderr.flush()
            if status != 0:
                raise BlockFailedError(f"{command!r}: exit status {status}")
            if dedupe:
                passed[command] = where
    return notes


class Captured:
    """File descriptors 1 and 2 (and sys.stdout/err) into a temporary file while the block runs."""

    def __enter__(self) -> Captured:
        sys.stdout.flush()
        sys.stderr.flush()
        self.file = tempfile.TemporaryFile(mode="w+b")
        self.saved = (os.dup(1), os.dup(2))
        os.dup2(self.file.fileno(), 1)
        os.dup2(self.file.fileno(), 2)
        return self

    def __exit__(self, *exc: object) -> None:
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(self.saved[0], 1)
        os.dup2(self.saved[1], 2)
        os.close(self.saved[0])
        os.close(self.saved[1])

    def text(self, limit: int = 5000) -> str:
        """The last ``limit`` characters of what the block printed."""
        self.file.seek(0)
        data = self.file.read().decode(errors="replace")
        self.file.close()
        return data[-limit:]


def run_step(step: dict[str, str], passed: dict[str, str]) -> dict[str, Any]:
    """One block in its folder; the result line."""
    folder = Path(step["folder"])
    home = os.getcwd()
    cpu, wall = _cpu(), time.perf_counter()
    ok, notes, failure = True, [], ""
    path, modules = list(sys.path), set(sys.modules)
    with Captured() as out:
        os.chdir(folder)
        signal.alarm(BLOCK_TIMEOUT)
        try:
            if step["lang"] == "python":
                run_python(step["text"], step["id"])
            else:
                notes = run_bash(step["text"], folder, passed, step["id"])
        except BaseException as exc:  # every failure is the block's, reported
            if isinstance(exc, KeyboardInterrupt):
                raise
            ok, failure = False, "".join(traceback.format_exception(exc))
        finally:
            signal.alarm(0)
            os.chdir(home)
            _forget(path, modules, folder)
            if "matplotlib.pyplot" in sys.modules:  # the block's figures: nothing more draws into them
                sys.modules["matplotlib.pyplot"].close("all")
    output = out.text()
    report = "\n".join(notes) if ok else f"{output}\n{failure}"
    seconds = {"cpu": round(_cpu() - cpu, 3), "wall": round(time.perf_counter() - wall, 3)}
    return {"id": step["id"], "ok": ok, "report": report, "seconds": seconds}


def _forget(path: list[str], modules: set[str], folder: Path) -> None:
    """Undo what a block did to the import system: its sys.path entries, its own modules.

    The modules it imported from its folder (``examples/``) go, so that a later block that forgot
    ``sys.path.insert(0, "examples")`` does not pass on an earlier block's import. Installed modules
    stay (numpy cannot be imported twice).
    """
    sys.path[:] = path
    installed = tuple(
        os.path.realpath(p) for p in (sys.prefix, sys.base_prefix, Path(__file__).parents[1] / "gb_pin")
    )
    for name in set(sys.modules) - modules:
        where = getattr(sys.modules[name], "__file__", None)
        if where and not os.path.realpath(folder / where).startswith(installed):
            del sys.modules[name]


def _cpu() -> float:
    """CPU seconds of this process and of the subprocesses it waited for."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def main(steps_file: str, results_file: str) -> None:
    steps = json.loads(Path(steps_file).read_text())
    passed: dict[str, str] = {}
    signal.signal(signal.SIGALRM, _alarm)
    for step in steps:
        result = run_step(step, passed)
        with open(results_file, "a") as fh:
            fh.write(json.dumps(result) + "\n")


if __name__ == "__main__":
    main(*sys.argv[1:3])
