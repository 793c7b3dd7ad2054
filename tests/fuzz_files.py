"""Every file reader fuzzed, every class of problem of issue 24 probed (tests/test_fuzz_files.py, or alone).

Two kinds of probes, each in a process of its own, forked from this warm one (a probe costs
milliseconds, and a crash, hang or runaway allocation stays contained):

- mutations: real files of every kind, written by gb_pin, mutated (truncation, byte flips, zeroed
  runs, appended garbage, forged zip sizes, wrong header values and arrays, ...) and given to
  their reader: results (loaded, then ``inverse``; also of a URDF robot, whose robot source is
  rebuilt), checkpoints (``resume``), sessions' checkpoints (``resume_session``, then steps),
  trial journals (``run_trials(checkpoint=)``), trial sets, sweeps, point files (``--targets`` /
  ``--eval-targets`` .csv and .npy), ``gb-pin ik --targets`` files, presets (TOML), URDFs and
  plots (``gb-pin plot`` of a result and of a trial set);
- targeted probes (tests/fuzz_probes.py), one or more per class of the issue: special files
  (FIFO, /dev/zero, a directory, a symlink to each) given to every reader, sizes declared far
  beyond what is there, integers beyond int64, files that load but are wrong, full disks (a small
  tmpfs where this process may mount one, else ENOSPC from a monkeypatched ``os.fsync``), killed
  and interrupted processes, ``--robot MODULE:NAME`` specs, the viewer server, robot descriptions
  and messages.

A probe is answered when it ends as it should: success where success is right, else gb_pin's own
error (and, for the targeted ones, the checks the probe makes: the message, what was written,
how fast); anything else (another exception, a crash, a signal, a probe over its time or memory
limit) is "other". Peak memory is each probe's own (``os.wait4``'s ``ru_maxrss``): above this
process for probes run in the fork, absolute for the ``gb-pin`` commands a probe starts. Probe i
of a reader mutates with its own generator, seeded by (seed, reader, i), so a failure is
reproduced by its number alone.

    python tests/fuzz_files.py --probes 2000 --seed 1 --large     # the large run: a table, then JSON
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

import gb_pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_classes
import fuzz_mutations
import fuzz_probes
import fuzz_round4
from fuzz_probes import Probe

_ = fuzz_classes, fuzz_round4

MEMORY_LIMIT = 3 << 30  # bytes of address space a probe may add to this process's
HARD_EXTRA = 15.0  # [s] beyond a probe's own alarm before it is killed


class ProbeTimeoutError(Exception):
    """A probe ran past its time (raised by the alarm)."""


def _alarm(signum: int, frame: Any) -> None:
    raise ProbeTimeoutError("ran past its time limit")


def _resident() -> int:
    """This process's resident memory [bytes]."""
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * resource.getpagesize()


def _address_space() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * resource.getpagesize()


def _in_child(probe: Probe, tmp: Path, write_fd: int) -> None:
    """The forked child: run the probe under an alarm and a memory limit, report through the pipe."""
    report: dict[str, Any] = {"start_kb": _resident() // 1024}
    try:
        log = os.open(tmp / "probe.log", os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.dup2(log, 1)
        os.dup2(log, 2)
        signal.signal(signal.SIGALRM, _alarm)
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        resource.setrlimit(resource.RLIMIT_AS, (_address_space() + MEMORY_LIMIT, resource.RLIM_INFINITY))
        signal.alarm(int(probe.seconds))
        try:
            probe.run(tmp)
            report["outcome"] = "ok"
        finally:
            signal.alarm(0)
    except gb_pin.GbPinError as exc:
        report["outcome"] = "own"
        report["detail"] = f"{type(exc).__name__}: {str(exc)[:300]}"
    except ProbeTimeoutError as exc:
        report["outcome"] = "timeout"
        report["detail"] = str(exc)
    except BaseException as exc:
        report["outcome"] = "raw"
        report["detail"] = f"{type(exc).__name__}: {str(exc)[:300]} @ {traceback.format_exc()[-400:]}"
    report["cli_peak_kb"] = fuzz_probes.CLI_PEAK_KB[0]
    report["own_errors"] = fuzz_probes.OWN_ERRORS[0]
    try:
        os.write(write_fd, json.dumps(report).encode())
    finally:
        os._exit(0)


def run_probe(probe: Probe, tmp: Path) -> dict[str, Any]:
    """Run one probe in a forked child; its outcome, answered or not, peak memory and time."""
    tmp.mkdir(parents=True, exist_ok=True)
    read_fd, write_fd = os.pipe()
    baseline = _resident()  # (if the child cannot say its own)
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        os.close(read_fd)
        _in_child(probe, tmp, write_fd)
    os.close(write_fd)
    deadline = time.monotonic() + probe.seconds + HARD_EXTRA
    while True:
        done, status, usage = os.wait4(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
        time.sleep(0.005)
    seconds = time.perf_counter() - start
    with os.fdopen(read_fd, "rb") as fh:
        raw = fh.read()
    report = json.loads(raw) if raw else {"outcome": "crash", "detail": f"wait status {status}"}
    if os.WIFSIGNALED(status):
        report = {"outcome": "crash", "detail": f"killed by signal {os.WTERMSIG(status)}"}
    cli = report.get("cli_peak_kb") or 0
    start_kb = report.get("start_kb", baseline // 1024)  # the child's resident memory when it started
    peak = cli * 1024 if cli else max(0, (usage.ru_maxrss - start_kb) * 1024)
    report["peak_mb"] = round(peak / 2**20, 1)
    report["seconds"] = round(seconds, 3)
    expected = {"error": ("own",), "ok": ("ok",), "either": ("ok", "own")}[probe.expect]
    answered = report["outcome"] in expected
    if answered and report["peak_mb"] > probe.limit_mb:
        answered = False
        report["detail"] = f"peak {report['peak_mb']} MB over the probe's {probe.limit_mb} MB"
    if answered and seconds > probe.seconds:
        answered = False
        report["detail"] = f"{seconds:.1f} s, over the probe's {probe.seconds} s"
    report["answered"] = answered
    if answered:  # keep the files (and probe.log) of the others only
        shutil.rmtree(tmp, ignore_errors=True)
    return report


def _tally(counts: dict[str, Any], key: str, probe: Probe, report: dict[str, Any]) -> None:
    c = counts.setdefault(
        key,
        {
            "tried": 0,
            "answered": 0,
            "own_error": 0,
            "other": 0,
            "peak_mb": 0.0,
            "slowest_s": 0.0,
            "failures": [],
        },
    )
    c["tried"] += 1
    c["answered" if report["answered"] else "other"] += 1
    c["own_error"] += report["answered"] and (report["outcome"] == "own" or report.get("own_errors", 0) > 0)
    c["peak_mb"] = max(c["peak_mb"], report["peak_mb"])
    c["slowest_s"] = max(c["slowest_s"], report["seconds"])
    if not report["answered"] and len(c["failures"]) < 5:
        c["failures"].append(f"{probe.name}: {report['outcome']}: {report.get('detail', '')}"[:600])


def fuzz(
    probes: int, seed: int, tmp: Path, large: bool = False, quick: bool = False, only: str = ""
) -> dict[str, Any]:
    """Run the mutations and the targeted probes; counts by reader and by class (and each probe)."""
    ctx = fuzz_probes.CTX
    ctx.originals = fuzz_mutations.originals(tmp / "originals")
    ctx.full = fuzz_probes.FullDisk(tmp / "full")
    ctx.large = large
    targeted = [p for make in fuzz_probes.REGISTRY for p in make()]
    plan = [*fuzz_mutations.probes(ctx.originals, probes, seed), *targeted]
    by_reader: dict[str, Any] = {}
    by_class: dict[str, Any] = {}
    reports = []
    try:
        for i, probe in enumerate(plan):
            if (only and only not in probe.klass and only not in probe.reader) or (quick and probe.slow):
                continue
            report = run_probe(probe, tmp / "probes" / str(i))
            suffix = f" ({probe.owner})" if probe.owner else ""
            _tally(by_reader, probe.reader + suffix, probe, report)
            _tally(by_class, probe.klass + suffix, probe, report)
            if probe.klass != "0 mutations":
                keys = ("answered", "outcome", "peak_mb", "seconds", "detail")
                reports.append({"probe": probe.name, "class": probe.klass, "owner": probe.owner,
                                **{k: report.get(k) for k in keys}})  # fmt: skip
    finally:
        ctx.full.close()
    return {"disk": ctx.full.mode, "readers": by_reader, "classes": by_class, "probes": reports}


def table(counts: dict[str, Any]) -> str:
    """The counts as a markdown table."""
    lines = [
        "| | tried | answered | of which gb_pin's error | other | peak memory [MB] | slowest [s] |",
        "|---|---|---|---|---|---|---|",
    ]
    for key, c in counts.items():
        cells = (
            c["tried"],
            c["answered"],
            c["own_error"],
            c["other"],
            f"{c['peak_mb']:.0f}",
            f"{c['slowest_s']:.2f}",
        )
        lines.append(f"| {key} | " + " | ".join(map(str, cells)) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Fuzz, print the tables (with --table) and the counts as JSON on the last line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--probes", type=int, default=200, help="mutated files per reader")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--large", action="store_true", help="large files and real timeouts (minutes)")
    parser.add_argument("--quick", action="store_true", help="leave out the slow probes (CI)")
    parser.add_argument("--only", default="", help="run only the probes of this class or reader")
    parser.add_argument("--table", action="store_true", help="print markdown tables before the JSON")
    args = parser.parse_args(argv)
    fuzz_probes.warm_up()  # compile and import before the first fork
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(143))  # unmount the tmpfs on the way out
    with tempfile.TemporaryDirectory() as tmp:
        counts = fuzz(args.probes, args.seed, Path(tmp), args.large, args.quick and not args.large, args.only)
    if args.table:
        print(
            f"disk full: {counts['disk']}\n\n" + table(counts["readers"]) + "\n\n" + table(counts["classes"])
        )
        for p in counts["probes"]:
            status = "ok   " if p["answered"] else "OTHER"
            detail = "" if p["answered"] else str(p["detail"])[:300]
            size = f"{p['peak_mb']:>7.1f} MB {p['seconds']:>6.2f} s"
            print(f"{status} {p['class']:<22} {p['probe']:<72} {size} {detail}")
    print(json.dumps(counts))
    owned = [c for k, c in counts["readers"].items() if "(" not in k]
    return 1 if any(c["other"] for c in owned) else 0


if __name__ == "__main__":
    import warnings

    warnings.simplefilter("ignore")
    sys.exit(main())
