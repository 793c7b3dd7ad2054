"""What the probes of tests/fuzz_files.py are made of: the probe, its registry, and their helpers.

A probe runs in a forked process (tests/fuzz_files.py); ``expect`` says how it must end:
``"error"`` (gb_pin's own error), ``"ok"`` (it returns: probes that check a message, a file or a
time raise AssertionError when the check fails) or ``"either"``. ``owner`` names the engineer
whose change a probe waits for (reported apart, not required); ``slow`` probes run only in the
large run (``--large``) or without ``--quick``.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gb_pin

DATA = Path(__file__).resolve().parent / "data"
SMALL_URDF = DATA / "small_arm.urdf"
CLI_PEAK_KB = [0]  # the largest peak memory of a gb-pin command run by the current probe [KiB]
OWN_ERRORS = [0]  # gb_pin errors the current probe saw where it expected them (expect_error)


@dataclass(frozen=True)
class Probe:
    """One probe: ``run(tmp)`` in a process of its own, within ``seconds`` and ``limit_mb``."""

    reader: str
    klass: str
    name: str
    run: Callable[[Path], Any]
    expect: str = "ok"
    limit_mb: float = 384.0  # a gb-pin process that loads pinocchio, numba and MuJoCo peaks near 260 MB
    seconds: float = 20.0
    owner: str = ""
    slow: bool = False


@dataclass
class Context:
    """What the targeted probes share: the original files, the full disk, the size of the run."""

    originals: dict[str, bytes] = field(default_factory=dict)
    full: Any = None
    large: bool = False


CTX = Context()
REGISTRY: list[Callable[[], list[Probe]]] = []  # functions listing probes, called once CTX is set


def probe(reader: str, klass: str, name: str, **options: Any) -> Callable[[Callable[[Path], Any]], Any]:
    """Register the decorated ``run(tmp)`` as a probe (``options``: expect, limit_mb, seconds, ...)."""

    def register(run: Callable[[Path], Any]) -> Callable[[Path], Any]:
        REGISTRY.append(lambda: [Probe(reader, klass, name, run, **options)])
        return run

    return register


def listed(make: Callable[[], list[Probe]]) -> Callable[[], list[Probe]]:
    """Register a function that lists several probes (built once the context is known)."""
    REGISTRY.append(make)
    return make


def warm_up() -> None:
    """Compile and import, once, what the forked probes use (they then start in milliseconds)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.figure
    import tornado.web

    import gb_pin.cli.plot
    import gb_pin.viewer.server

    gb_pin.babble("planar5", movements=2, seed=0)
    gb_pin.load_robot("talos_left_arm")
    _ = (matplotlib.figure, tornado.web, gb_pin.cli.plot, gb_pin.viewer.server)


# -- running gb-pin -------------------------------------------------------------------------------
ENOSPC = """
import errno, os
full = os.environ.get("GB_PIN_FUZZ_ENOSPC")
if full:  # no tmpfs: a file system that is full under this directory, seen through fsync
    real = os.fsync
    def fsync(fd):
        try:
            where = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            where = ""
        if where.startswith(full + os.sep):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real(fd)
    os.fsync = fsync
"""
PRELUDE = (
    ENOSPC
    + """
import sys
sys.argv = ["gb-pin", *sys.argv[1:]]
from gb_pin.cli import run
run()
"""
)


def rewrite_npz(path: Path, change: Callable[[dict[str, Any], dict[str, Any]], None]) -> None:
    """Rewrite the .npz at ``path`` with ``change(arrays, header)`` applied."""
    import json

    import numpy as np

    with np.load(path, allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = json.loads(str(arrays.pop("meta")))
    change(arrays, meta)
    np.savez(path, meta=np.array(json.dumps(meta)), **arrays)


@dataclass
class Command:
    """What a gb-pin command did: exit status, output, and (after ``interrupt``) seconds it took to exit."""

    rc: int
    out: str
    err: str
    after_interrupt: float = 0.0


def cli(
    args: list[str],
    cwd: Path,
    *,
    env: dict[str, str] | None = None,
    interrupt: float = 0.0,
    timeout: float = 120,
) -> Command:
    """Run ``gb-pin args`` in ``cwd``; its peak memory (with its workers') goes to :data:`CLI_PEAK_KB`.

    With ``interrupt``, SIGINT reaches its process group (as Ctrl-C does in a terminal) after that
    many seconds.
    """
    stamp = time.monotonic_ns()
    out, err = cwd / f".cli{stamp}.out", cwd / f".cli{stamp}.err"
    with open(out, "w") as fo, open(err, "w") as fe:
        proc = subprocess.Popen(
            [sys.executable, "-c", PRELUDE, *args],
            cwd=cwd,
            stdout=fo,
            stderr=fe,
            env={**os.environ, **(env or {})},
            start_new_session=True,
        )
        start = time.monotonic()
        sent = 0.0
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            now = time.monotonic()
            if interrupt and not sent and now - start > interrupt:
                os.killpg(proc.pid, signal.SIGINT)
                sent = now
            if now - start > timeout:
                os.killpg(proc.pid, signal.SIGKILL)
            time.sleep(0.01)
    CLI_PEAK_KB[0] = max(CLI_PEAK_KB[0], usage.ru_maxrss)
    return Command(
        os.waitstatus_to_exitcode(status),
        out.read_text(),
        err.read_text(),
        time.monotonic() - sent if sent else 0.0,
    )


def expect_error(call: Callable[[], Any], *needles: str, within: float = 5.0) -> None:
    """``call()`` must raise gb_pin's error, whose message holds every needle, within ``within`` seconds."""
    start = time.perf_counter()
    try:
        call()
    except gb_pin.GbPinError as exc:
        text = str(exc)
        missing = [n for n in needles if n not in text]
        assert not missing, f"message lacks {missing}: {text[:300]}"
        assert "\x1b" not in text, f"an escape byte in the message: {text[:300]!r}"
        assert time.perf_counter() - start < within, f"{time.perf_counter() - start:.1f} s"
        OWN_ERRORS[0] += 1
        return
    raise AssertionError("no error")


def special(kind: str, tmp: Path, suffix: str) -> Path:
    """A special file given as a path: a FIFO, /dev/zero, a directory, or a symlink to one."""
    targets = {"fifo": tmp / f"fifo{suffix}", "zero": Path("/dev/zero"), "dir": tmp / f"dir{suffix}"}
    if not targets["fifo"].exists():
        os.mkfifo(targets["fifo"])
        targets["dir"].mkdir()
    base = kind.removeprefix("link_")
    if kind.startswith("link_"):
        link = tmp / f"{kind}{suffix}"
        link.symlink_to(targets[base])
        return link
    return targets[base]


class FullDisk:
    """A directory on a nearly full file system: a small tmpfs, else ENOSPC from a patched fsync.

    :meth:`fill` leaves ``room`` bytes free (tmpfs) and returns the environment that makes a
    gb-pin command (:func:`cli`) see the directory full in the fallback mode; :meth:`patch` does
    the same inside this process.
    """

    SIZE = 1 << 20

    def __init__(self, path: Path) -> None:
        self.path = path
        path.mkdir(parents=True, exist_ok=True)
        self.mounted = False
        if os.geteuid() == 0 and sys.platform == "linux" and shutil.which("mount"):
            done = subprocess.run(
                ["mount", "-t", "tmpfs", "-o", f"size={self.SIZE}", "tmpfs", str(path)],
                capture_output=True,
                check=False,
            )
            self.mounted = done.returncode == 0
        self.mode = f"tmpfs of {self.SIZE >> 10} KiB" if self.mounted else "ENOSPC from a patched os.fsync"

    def clear(self) -> None:
        """Empty the directory."""
        for entry in self.path.iterdir():
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry)
            else:
                entry.unlink()

    def fill(self, room: int = 4096) -> dict[str, str]:
        """Fill the file system to ``room`` bytes free (tmpfs); the environment of a full disk."""
        if not self.mounted:
            return {"GB_PIN_FUZZ_ENOSPC": str(self.path)}
        fs = os.statvfs(self.path)
        free = fs.f_bavail * fs.f_frsize
        with open(self.path / f".filler{time.monotonic_ns()}", "wb") as fh:
            fh.write(b"\0" * max(0, free - room))
        return {}

    def patch(self) -> None:
        """In this process: fsync fails with ENOSPC under the directory (fallback mode only)."""
        if not self.mounted:
            os.environ["GB_PIN_FUZZ_ENOSPC"] = str(self.path)
            exec(ENOSPC, {})

    def close(self) -> None:
        """Unmount the tmpfs (if one was mounted)."""
        if self.mounted:
            subprocess.run(["umount", str(self.path)], capture_output=True, check=False)
            self.mounted = False
