"""The mutation half of tests/fuzz_files.py: real files of every kind, their mutations, their readers."""

from __future__ import annotations

import io
import json
import struct
from collections.abc import Callable
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from fuzz_probes import Probe

import gb_pin

RESUME_LIMIT = 10_000  # checkpoints of longer runs are read and stepped 100 movements, not resumed
DATA = Path(__file__).resolve().parent / "data"
SMALL_URDF = DATA / "small_arm.urdf"


def originals(tmp: Path) -> dict[str, bytes]:
    """Real files of every kind, written by gb_pin itself."""
    from gb_pin.runs.checkpoint import CheckpointInfo, write_checkpoint

    tmp.mkdir(parents=True, exist_ok=True)
    res = gb_pin.babble("planar5", movements=40, seed=1, record=gb_pin.Recording(every=3, first=0, last=10))
    res.save(tmp / "result.npz")
    target = gb_pin.load_robot("planar5")
    config = gb_pin.GoalBabbling()._resolve(target.n_joints)
    st = gb_pin.BabbleState.start(
        target, target.targets, 60, config, seed=2, record=gb_pin.Recording(every=5)
    )
    st.run(25)
    write_checkpoint(tmp / "ckpt.npz", st, CheckpointInfo("planar5", "planar5", 60, 2, config, 0.1))
    session = gb_pin.babble_session("planar5", movements=30, seed=3)
    for _ in range(7 * 25 + 3):
        session.tell(target.forward(session.ask()))
    session.save_checkpoint(tmp / "session.npz")
    ts = gb_pin.run_trials(
        "planar5", trials=2, movements=8, seed=3, checkpoint=tmp / "journal.jsonl", workers=1
    )
    ts.save(tmp / "trials.json")
    gb_pin.Sweep(conditions=(gb_pin.Condition("planar5"),), results=(ts,)).save(tmp / "sweep.json")
    preset = Path(str(resources.files("gb_pin.presets"))) / "talos_left_arm.toml"
    arm = gb_pin.KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j2", "j4"], home=[0.1, 0.2, 0.3])
    gb_pin.babble(arm, movements=10, seed=4).save(tmp / "result_urdf.npz")
    np.save(tmp / "points.npy", target.targets)
    csv = "x,y\n# the preset's grid\n" + "\n".join(f"{a!r},{b!r}" for a, b in target.targets) + "\n"
    return {
        "result": (tmp / "result.npz").read_bytes(),
        "result_urdf": (tmp / "result_urdf.npz").read_bytes(),
        "checkpoint": (tmp / "ckpt.npz").read_bytes(),
        "session": (tmp / "session.npz").read_bytes(),
        "journal": (tmp / "journal.jsonl").read_bytes(),
        "trials": (tmp / "trials.json").read_bytes(),
        "sweep": (tmp / "sweep.json").read_bytes(),
        "points_csv": csv.encode(),
        "points_npy": (tmp / "points.npy").read_bytes(),
        "preset": preset.read_bytes(),
        "urdf": SMALL_URDF.read_bytes(),
    }


# -- mutations ----------------------------------------------------------------------
def bytes_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    """Truncation, flipped bytes, a zeroed run, appended garbage or a forged zip member size."""
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
    None, -1, 0, 10**12, 2**64, 2**70, -(10**9), 1e308, 1e20, float("nan"), "seed", [1, 2],
    {"a": {"b": {"c": 1}}}, True, "", "planar5000000", "PCG64", [[[]]], "\x1b[2J",
]  # fmt: skip


def _weird_array(arr: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    how = rng.integers(0, 10)
    if how == 0:
        return arr[..., :-1] if arr.ndim and arr.shape[-1] else arr.reshape(-1)[:0]
    if how == 1:
        return arr.astype(complex) if arr.dtype.kind in "fi" else arr
    if how == 2:
        return np.array(1.0) if rng.random() < 0.5 else np.array(3)  # 0-d
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
    if how == 8:
        return arr.astype(np.uint64) if arr.dtype.kind == "i" else arr.astype(np.float32)
    return np.array(["text"])


def archive_mutation(data: bytes, rng: np.random.Generator) -> bytes:
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
        if rng.random() < 0.1:  # the whole history emptied at once
            for k in ("movements", "error", "home_distance"):
                if k in arrays:
                    arrays[k] = arrays[k][:0]
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


SOURCE_TRICKS: list[Any] = [
    "relative/arm.urdf", "/etc/passwd", "/dev/zero", "/no/such/arm.urdf", "erd:romeo", "os:system", "module",
    "urdf", "erd", "0" * 64, "x" * 100_000, ["j1"] * 3, ["j1", "j2"], [0.1, "a", 0.3], "xx", "xyzx",
    "j1\x1b[31m",
]  # fmt: skip


def source_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    """Rewrite a result file's ``robot_source`` with one entry wrong, added, or the whole kind changed."""
    with np.load(io.BytesIO(data), allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = json.loads(str(arrays["meta"]))
    source = dict(meta["robot_source"])
    values = SOURCE_TRICKS + WEIRD
    key = str(rng.choice([*sorted(source), "extra"]))
    source[key] = values[int(rng.integers(0, len(values)))]
    if rng.random() < 0.2:
        source = {
            "kind": "module",
            "spec": str(rng.choice(["os:system", "builtins:print", "x.py:robot", "sys:exit"])),
        }
    meta["robot_source"] = source
    arrays["meta"] = np.array(json.dumps(meta))
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


def text_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    """A line cut and extended, a token replaced, or a bytes mutation."""
    text = data.decode("utf-8", errors="replace")
    how = rng.integers(0, 4)
    if how == 0:
        lines = text.splitlines()
        i = int(rng.integers(0, len(lines)))
        lines[i] = lines[i][: int(rng.integers(0, len(lines[i]) + 1))] + str(
            WEIRD[int(rng.integers(0, len(WEIRD)))]
        )
        return "\n".join(lines).encode()
    if how == 1:
        for token in ("0.1", "3", "[", "true", "1e308", "8", '"', "0,", "name="):
            if token in text and rng.random() < 0.5:
                replacement = str(
                    rng.choice(["-1", "1e999", "NaN", "null", '"x"', "[[", "99999999", "1e20", "\x00"])
                )
                text = text.replace(token, replacement, 1)
        return text.encode()
    if how == 2:  # not UTF-8
        b = bytearray(data)
        b[int(rng.integers(0, len(b)))] = 0xFF
        return bytes(b)
    return bytes_mutation(data, rng)


def npy_mutation(data: bytes, rng: np.random.Generator) -> bytes:
    """An .npy whose header is cut, forged (shape, dtype, order) or whose data is cut."""
    head_len = 10 + struct.unpack("<H", data[8:10])[0]
    how = rng.integers(0, 4)
    if how == 0:  # the header cut short (tokenize's TokenError in numpy's parser)
        return data[: int(rng.integers(0, head_len))]
    if how == 1:  # data cut
        return data[: int(rng.integers(head_len, len(data)))]
    shape = rng.choice(["(1000000000000, 2)", "(-5, 2)", "(25,)", "()", "(0, 2)", "(2**70, 2)", "(25, 2, 1)"])
    descr = rng.choice(["'<f8'", "'<c16'", "'|O'", "'<U3'", "'V0'", "[('a', '<f8')]", "'<i8'", "'|b1'"])
    header = (
        "{" + f"'descr': {descr}, 'fortran_order': {rng.choice(['False', 'True'])}, 'shape': {shape}, " + "}"
    )
    header = header.ljust(118) + "\n"
    return data[:8] + struct.pack("<H", len(header)) + header.encode("latin-1") + data[head_len:]


# -- readers ------------------------------------------------------------------------
def read_result(path: Path) -> None:
    res = gb_pin.load_result(path)
    res.inverse(res.targets)


def read_checkpoint(path: Path) -> None:
    from gb_pin.runs.checkpoint import read_checkpoint

    state, info = read_checkpoint(path)
    if info.movements <= RESUME_LIMIT:
        gb_pin.resume(path)
    else:  # a legitimately long run: the compiled loop on the state read, for 100 movements
        state.run(min(info.movements, state.movements + 100))


def read_session(path: Path) -> None:
    from gb_pin.runs.session import resume_session

    session = resume_session(path)
    target = gb_pin.load_robot("planar5") if session.robot == "planar5" else session.target
    for _ in range(60):
        if session.done:
            break
        session.tell(target.forward(session.ask()))


def read_journal(path: Path) -> None:
    gb_pin.run_trials("planar5", trials=2, movements=8, seed=3, checkpoint=path, workers=1)


def read_trials(path: Path) -> None:
    gb_pin.TrialSet.load(path).quantiles()


def read_sweep(path: Path) -> None:
    gb_pin.Sweep.load(path)


def read_points(path: Path) -> None:
    from gb_pin._points import read_points

    read_points(path, "--targets")


def read_ik_targets(path: Path) -> None:
    from gb_pin.cli.ik import read_targets_csv

    read_targets_csv(str(path), "xy")


def read_preset(path: Path) -> None:
    from gb_pin.robot.presets import _preset_bytes, _read_preset

    _read_preset(_preset_bytes(path), path.name)


def read_urdf(path: Path) -> None:
    target = gb_pin.KinematicTarget.from_urdf(path, "tool")
    target.forward(target.home)


def read_plot(path: Path) -> None:
    from gb_pin.cli import main

    code = main(["plot", str(path), "-o", str(path.with_suffix(".png")), "--overwrite"])
    if code:
        raise gb_pin.GbPinError(f"gb-pin plot exited with status {code}")


Mutation = Callable[[bytes, np.random.Generator], bytes]
# reader: (file name, the original's key, the reader, its mutations, share of the probes)
READERS: dict[str, tuple[str, str, Callable[[Path], None], list[Mutation], float]] = {
    "result": ("x.npz", "result", read_result, [bytes_mutation, archive_mutation, archive_mutation], 1.0),
    "result_urdf": (
        "x.npz",
        "result_urdf",
        read_result,
        [source_mutation, source_mutation, archive_mutation],
        1.0,
    ),
    "checkpoint": (
        "x.npz",
        "checkpoint",
        read_checkpoint,
        [bytes_mutation, archive_mutation, archive_mutation],
        1.0,
    ),
    "session": ("x.npz", "session", read_session, [bytes_mutation, archive_mutation, archive_mutation], 1.0),
    "journal": ("x.jsonl", "journal", read_journal, [text_mutation], 1.0),
    "trials": ("x.json", "trials", read_trials, [text_mutation], 1.0),
    "sweep": ("x.json", "sweep", read_sweep, [text_mutation], 0.5),
    "points_csv": ("x.csv", "points_csv", read_points, [text_mutation], 1.0),
    "points_npy": ("x.npy", "points_npy", read_points, [npy_mutation, npy_mutation, bytes_mutation], 1.0),
    "ik_targets": ("x.csv", "points_csv", read_ik_targets, [text_mutation], 0.5),
    "preset": ("x.toml", "preset", read_preset, [text_mutation], 1.0),
    "urdf": ("x.urdf", "urdf", read_urdf, [text_mutation], 1.0),
    "plot_result": ("x.npz", "result", read_plot, [bytes_mutation, archive_mutation], 0.2),
    "plot_trials": ("x.json", "trials", read_plot, [text_mutation], 0.2),
}


def probes(originals: dict[str, bytes], count: int, seed: int) -> list[Probe]:
    """``count`` mutated files per reader (a share of it for the slow ones), each a probe."""
    out = []
    for k, (reader, (name, key, read, mutations, share)) in enumerate(READERS.items()):
        for i in range(max(1, int(count * share))):
            out.append(
                Probe(
                    reader=reader,
                    klass="0 mutations",
                    name=f"{reader} probe {i} (seed {seed})",
                    run=_mutated(originals[key], name, read, mutations, (seed, k, i)),
                    expect="either",
                    limit_mb=512,
                    seconds=20,
                )
            )
    return out


def _mutated(
    original: bytes,
    name: str,
    read: Callable[[Path], None],
    mutations: list[Mutation],
    plan: tuple[int, int, int],
) -> Callable[[Path], None]:
    """Probe i of reader k: mutate with the generator seeded (seed, k, i), write, read."""

    def run(tmp: Path) -> None:
        rng = np.random.default_rng(list(plan))
        mutate = mutations[int(rng.integers(0, len(mutations)))]
        try:
            data = mutate(original, rng)
        except Exception:  # a mutation that does not apply to this file: the original
            data = original
        path = tmp / name
        path.write_bytes(data)
        read(path)

    return run
