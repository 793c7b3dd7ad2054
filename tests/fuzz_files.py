"""Fuzzing of every file reader over mutated real files (run by tests/test_fuzz_files.py, or alone).

Readers: result files (``load_result``, then ``inverse``; also of a URDF robot, whose recorded robot
source is rebuilt), checkpoints (``resume`` to the end when
the run is short, else ``read_checkpoint`` and 100 movements of the compiled loop on the state read),
trial journals (``run_trials(checkpoint=)``), trial sets (``TrialSet.load``) and robot presets
(``robots/*.toml``). Mutations: truncation, byte flips, zeroed runs, appended garbage, forged zip
sizes, and semantic ones (header values and arrays replaced by wrong types, shapes, ranges,
non-finite or huge values). Every outcome must be success or gb_pin's own error, each within a
time bound (``signal.alarm``: an overrun is a failure naming the probe); the process runs under a
memory limit, so an allocation a file talks us into fails. Probe i of a reader mutates with its own
generator, seeded by (seed, reader, i): a failure is reproduced by its probe number alone.

    python tests/fuzz_files.py --probes 2000 --seed 1      # prints the counts as JSON
"""

from __future__ import annotations

import argparse
import io
import json
import resource
import signal
import struct
import sys
import time
import traceback
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

import gb_pin
from gb_pin.robot.presets import _read_preset

MEMORY_LIMIT = 3 << 30  # bytes of address space beyond what is in use at the start
TIME_LIMIT = 5  # seconds per probe (signal.alarm)
RESUME_LIMIT = 10_000  # checkpoints of longer runs are read and stepped 100 movements, not resumed


class ProbeTimeoutError(Exception):
    """A probe ran past TIME_LIMIT (raised by the alarm)."""


def _alarm(signum: int, frame: Any) -> None:
    raise ProbeTimeoutError(f"ran past {TIME_LIMIT} s")


def _originals(tmp: Path) -> dict[str, bytes]:
    """Real files of every kind, written by gb_pin itself."""
    from gb_pin.runs.checkpoint import CheckpointInfo, write_checkpoint

    res = gb_pin.babble("planar5", movements=40, seed=1, record=gb_pin.Recording(every=3, first=0, last=10))
    res.save(tmp / "result.npz")
    target = gb_pin.load_robot("planar5")
    config = gb_pin.GoalBabbling()._resolve(target.n_joints)
    st = gb_pin.BabbleState.start(
        target, target.targets, 60, config, seed=2, record=gb_pin.Recording(every=5)
    )
    st.run(25)
    write_checkpoint(tmp / "ckpt.npz", st, CheckpointInfo("planar5", "planar5", 60, 2, config, 0.1))
    ts = gb_pin.run_trials(
        "planar5", trials=2, movements=8, seed=3, checkpoint=tmp / "journal.jsonl", workers=1
    )
    ts.save(tmp / "trials.json")
    preset = Path(str(resources.files("gb_pin.presets"))) / "talos_left_arm.toml"
    urdf = Path(__file__).resolve().parent / "data" / "small_arm.urdf"
    arm = gb_pin.KinematicTarget.from_urdf(urdf, "tool", ["j1", "j2", "j4"], home=[0.1, 0.2, 0.3])
    gb_pin.babble(arm, movements=10, seed=4).save(tmp / "result_urdf.npz")
    return {
        "result_urdf": (tmp / "result_urdf.npz").read_bytes(),
        "result": (tmp / "result.npz").read_bytes(),
        "checkpoint": (tmp / "ckpt.npz").read_bytes(),
        "journal": (tmp / "journal.jsonl").read_bytes(),
        "trials": (tmp / "trials.json").read_bytes(),
        "preset": preset.read_bytes(),
    }


# -- mutations ----------------------------------------------------------------------
def _bytes_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    b = bytearray(data)
    how = rng.integers(0, 5)
    if how == 0:  # truncate
        return bytes(b[: rng.integers(0, len(b))])
    if how == 1:  # flip a few bytes
        for _ in range(rng.integers(1, 9)):
            b[rng.integers(0, len(b))] ^= int(rng.integers(1, 256))
        return bytes(b)
    if how == 2:  # zero a run
        i = int(rng.integers(0, len(b)))
        b[i : i + int(rng.integers(1, 64))] = bytes(min(len(b) - i, 64))[: len(b[i : i + 64])]
        return bytes(b)
    if how == 3:  # append garbage
        return bytes(b) + rng.bytes(int(rng.integers(1, 200)))
    # forge the declared (uncompressed) size of a zip member: central directory and local header
    pos = data.find(b"PK\x01\x02", int(rng.integers(0, max(1, len(data) - 4))))
    if pos < 0:
        pos = data.find(b"PK\x01\x02")
    if pos >= 0:
        b[pos + 24 : pos + 28] = struct.pack("<I", int(rng.choice([0xFFFFFFF0, 2**31, 10**9, 1])))
    return bytes(b)


WEIRD: list[Any] = [
    None, -1, 0, 10**12, 2**64, -(10**9), 1e308, float("nan"), "seed", [1, 2], {"a": {"b": {"c": 1}}},
    True, "", "planar5000000", "PCG64", [[[]]],
]  # fmt: skip


def _weird_array(arr: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    how = rng.integers(0, 9)
    if how == 0:
        return arr[..., :-1] if arr.ndim and arr.shape[-1] else arr.reshape(-1)[:0]
    if how == 1:
        return arr.astype(complex) if arr.dtype.kind in "fi" else arr
    if how == 2:
        return np.array(1.0)
    if how == 3:
        return np.full(arr.shape, np.nan) if arr.size else arr
    if how == 4:
        return np.full(arr.shape, np.inf) if arr.size else arr
    if how == 5:
        return (arr * -(10**9)).astype(arr.dtype) if arr.dtype.kind in "fi" else arr
    if how == 6:
        return np.zeros((0, *arr.shape[1:]), dtype=arr.dtype)
    if how == 7:
        return np.concatenate([arr, arr]) if arr.ndim else arr
    return np.array(["text"])


def _archive_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    """Rewrite an .npz with one header value or one array replaced by something wrong."""
    with np.load(io.BytesIO(data), allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = json.loads(str(arrays["meta"]))
    if rng.random() < 0.4:
        key = str(rng.choice(sorted(meta)))
        value = WEIRD[int(rng.integers(0, len(WEIRD)))]
        if isinstance(meta[key], dict) and meta[key] and rng.random() < 0.5:
            sub = str(rng.choice(sorted(meta[key])))
            meta[key] = {**meta[key], sub: value}
        else:
            meta[key] = value
        if rng.random() < 0.1:
            meta = {"format": meta.get("format"), "format_version": 1, "x": json.loads("[" * 50 + "]" * 50)}
        arrays["meta"] = np.array(json.dumps(meta))
    else:
        key = str(rng.choice(sorted(k for k in arrays if k != "meta")))
        arrays[key] = _weird_array(arrays[key], rng)
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


SOURCE_TRICKS: list[Any] = [
    "relative/arm.urdf", "/etc/passwd", "/dev/zero", "/no/such/arm.urdf", "erd:romeo", "os:system", "module",
    "urdf", "erd", "0" * 64, "x" * 100_000, ["j1"] * 3, ["j1", "j2"], [0.1, "a", 0.3], "xx", "xyzx",
]  # fmt: skip


def _source_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    """Rewrite a result file's ``robot_source`` with one entry wrong, added, or the whole kind changed."""
    with np.load(io.BytesIO(data), allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = json.loads(str(arrays["meta"]))
    source = dict(meta["robot_source"])
    values = SOURCE_TRICKS + WEIRD
    key = str(rng.choice([*sorted(source), "extra"]))
    source[key] = values[int(rng.integers(0, len(values)))]
    if rng.random() < 0.2:
        source = {"kind": "module", "spec": str(rng.choice(["os:system", "builtins:print", "x.py:robot"]))}
    meta["robot_source"] = source
    arrays["meta"] = np.array(json.dumps(meta))
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


def _text_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    text = data.decode("utf-8", errors="replace")
    how = rng.integers(0, 3)
    if how == 0:
        lines = text.splitlines()
        i = int(rng.integers(0, len(lines)))
        lines[i] = lines[i][: int(rng.integers(0, len(lines[i]) + 1))] + str(
            WEIRD[int(rng.integers(0, len(WEIRD)))]
        )
        return "\n".join(lines).encode()
    if how == 1:
        for token in ("0.1", "3", "[", "true", "1e308"):
            if token in text and rng.random() < 0.5:
                text = text.replace(
                    token, str(rng.choice(["-1", "1e999", "NaN", "null", '"x"', "[[", "99999999"])), 1
                )
        return text.encode()
    return _bytes_mutation(data, rng)


# -- readers ------------------------------------------------------------------------
def _read_result(path: Path) -> None:
    res = gb_pin.load_result(path)
    res.inverse(res.targets)


def _read_checkpoint(path: Path) -> None:
    from gb_pin.runs.checkpoint import read_checkpoint

    state, info = read_checkpoint(path)
    if info.movements <= RESUME_LIMIT:
        gb_pin.resume(path)
    else:  # a legitimately long run: the compiled loop on the state read, for 100 movements
        state.run(min(info.movements, state.movements + 100))


def _read_journal(path: Path) -> None:
    gb_pin.run_trials("planar5", trials=2, movements=8, seed=3, checkpoint=path, workers=1)


def _read_trials(path: Path) -> None:
    ts = gb_pin.TrialSet.load(path)
    ts.quantiles()


def _read_preset_file(path: Path) -> None:
    _read_preset(path.read_text(encoding="utf-8", errors="replace"), path.name)


READERS: dict[
    str, tuple[str, Callable[[Path], None], list[Callable[[bytes, np.random.Generator], bytes]]]
] = {
    "result": ("x.npz", _read_result, [_bytes_mutation, _archive_mutation, _archive_mutation]),
    "checkpoint": ("x.npz", _read_checkpoint, [_bytes_mutation, _archive_mutation, _archive_mutation]),
    "journal": ("x.jsonl", _read_journal, [_text_mutation]),
    "trials": ("x.json", _read_trials, [_text_mutation]),
    "preset": ("x.toml", _read_preset_file, [_text_mutation]),
    # a URDF robot's result: its robot source is rebuilt, so it is mutated too
    "result_urdf": ("x.npz", _read_result, [_source_mutation, _source_mutation, _archive_mutation]),
}


def fuzz(probes: int, seed: int, tmp: Path) -> dict[str, Any]:
    """Run ``probes`` mutated files per reader; count tried / answered (ok or own error) / failed."""
    originals = _originals(tmp)
    counts: dict[str, Any] = {}
    previous = signal.signal(signal.SIGALRM, _alarm)
    try:
        for k, (kind, (name, read, mutations)) in enumerate(READERS.items()):
            counts[kind] = _fuzz_reader(kind, originals[kind], tmp / name, read, mutations, (seed, k, probes))
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    return counts


def _fuzz_reader(
    kind: str,
    original: bytes,
    path: Path,
    read: Callable[[Path], None],
    mutations: list[Callable[[bytes, np.random.Generator], bytes]],
    plan: tuple[int, int, int],
) -> dict[str, Any]:
    """Probe one reader ``plan[2]`` times; probe i mutates with the generator seeded (seed, reader, i)."""
    seed, k, probes = plan
    c: dict[str, Any] = {
        "tried": 0,
        "loaded": 0,
        "own_error": 0,
        "failed": 0,
        "slowest_s": 0.0,
        "failures": [],
    }
    for i in range(probes):
        rng = np.random.default_rng([seed, k, i])
        mutate = mutations[int(rng.integers(0, len(mutations)))]
        probe = f"{kind} probe {i} (seed {seed}, {mutate.__name__})"
        try:
            path.write_bytes(mutate(original, rng))
        except Exception:
            continue
        c["tried"] += 1
        start = time.perf_counter()
        failure = None
        try:
            signal.alarm(TIME_LIMIT)
            try:
                read(path)
            finally:
                signal.alarm(0)
            c["loaded"] += 1
        except gb_pin.GbPinError:
            c["own_error"] += 1
        except ProbeTimeoutError as exc:
            failure = f"{probe}: {exc}"
        except Exception as exc:
            failure = f"{probe}: {type(exc).__name__}: {exc!s:.200} @ {traceback.format_exc()[-300:]}"
        c["slowest_s"] = max(c["slowest_s"], round(time.perf_counter() - start, 3))
        if failure is not None:
            c["failed"] += 1
            if len(c["failures"]) < 5:
                c["failures"].append(failure)
    return c


def main(argv: list[str] | None = None) -> int:
    """Fuzz under a memory limit and print the counts."""
    import tempfile

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--probes", type=int, default=200, help="mutated files per reader")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    gb_pin.babble("planar5", movements=2, seed=0)  # compile before the limit
    used = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    with open("/proc/self/statm") as fh:
        used = max(used, int(fh.read().split()[0]) * resource.getpagesize())
    resource.setrlimit(resource.RLIMIT_AS, (used + MEMORY_LIMIT, resource.RLIM_INFINITY))
    with tempfile.TemporaryDirectory() as tmp:
        counts = fuzz(args.probes, args.seed, Path(tmp))
    print(json.dumps(counts))
    return 1 if any(c["failed"] for c in counts.values()) else 0


if __name__ == "__main__":
    import warnings

    warnings.simplefilter("ignore")
    sys.exit(main())
