"""The targeted probes of tests/fuzz_files.py: one or more for every class of problem of issue 24.

1 bounds: special files (FIFO, /dev/zero, a directory, a symlink to each) and oversized files given
to every reader, sizes declared far beyond what a file holds, counts that would allocate;
2 integers beyond int64 and arguments a task would ignore; 3 files that load but are wrong;
4 writes that fail on a full disk (the work must go elsewhere, said where); 5 processes (killed
writers, Ctrl-C, two runs on one checkpoint); 6 ``--robot MODULE:NAME``; 7 the viewer server;
8 robot descriptions; 9 messages.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import signal
import socket
import time
import warnings
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from fuzz_mutations import (
    read_checkpoint,
    read_ik_targets,
    read_journal,
    read_plot,
    read_points,
    read_preset,
    read_result,
    read_session,
    read_sweep,
    read_trials,
    read_urdf,
)
from fuzz_probes import CTX, SMALL_URDF, Probe, cli, expect_error, listed, probe, rewrite_npz, special

import gb_pin


def _doc(path: Path) -> None:
    from gb_pin.experiments.robot_bench import updated_document

    updated_document(str(path), "")


def _srdf(path: Path) -> None:
    from gb_pin.robot.models import load_urdf_model

    load_urdf_model(SMALL_URDF, srdf=path)


# reader: (the suffix of its files, read a path, a size refused [bytes] or 0)
READERS: dict[str, tuple[str, Callable[[Path], Any], int]] = {
    "result": (".npz", read_result, 2 << 30),
    "checkpoint": (".npz", read_checkpoint, 2 << 30),
    "session": (".npz", read_session, 0),
    "journal": (".jsonl", read_journal, 300 << 20),
    "trials": (".json", read_trials, 65 << 20),
    "sweep": (".json", read_sweep, 0),
    "points_csv": (".csv", read_points, 300 << 20),
    "points_npy": (".npy", read_points, 0),
    "ik_targets": (".csv", read_ik_targets, 0),
    "preset": (".toml", read_preset, 2 << 20),
    "urdf": (".urdf", read_urdf, 65 << 20),
    "srdf": (".srdf", _srdf, 0),
    "plot_result": (".npz", read_plot, 0),
    "doc": (".md", _doc, 17 << 20),
}
KINDS = ("fifo", "zero", "dir", "link_fifo", "link_zero", "link_dir")


# -- 1 bounds ------------------------------------------------------------------------------------
@listed
def _special_files() -> list[Probe]:
    out = []
    for reader, (suffix, read, size) in READERS.items():
        for kind in KINDS:

            def given(tmp: Path, read: Any = read, kind: str = kind, suffix: str = suffix) -> None:
                expect_error(lambda: read(special(kind, tmp, suffix)), within=5.0)

            name = f"{reader}: {kind.replace('_', ' to ').replace('zero', '/dev/zero')}"
            out.append(Probe(reader, "1 bounds", name, given, limit_mb=64, seconds=10))
        if size:

            def sparse(tmp: Path, read: Any = read, suffix: str = suffix, size: int = size) -> None:
                path = tmp / f"big{suffix}"
                with open(path, "wb") as fh:
                    fh.truncate(size)  # sparse: no disk used
                expect_error(lambda: read(path), within=5.0)

            out.append(
                Probe(reader, "1 bounds", f"{reader}: a file of {size >> 20} MiB", sparse, limit_mb=64)
            )
    return out


@listed
def _meshes() -> list[Probe]:
    """A URDF whose visual names a special file as its mesh: refused before pinocchio's loader."""
    out = []
    for kind in KINDS:

        def mesh(tmp: Path, kind: str = kind) -> None:
            path = special(kind, tmp, ".stl")
            cylinder = '<cylinder radius="0.05" length="0.1"/>'
            urdf = SMALL_URDF.read_text().replace(cylinder, f'<mesh filename="{path}"/>', 1)
            (tmp / "m.urdf").write_text(urdf)
            arm = gb_pin.KinematicTarget.from_urdf(tmp / "m.urdf", "tool")
            expect_error(arm.visual_model, "mesh", within=5.0)

        name = f"meshes: {kind.replace('_', ' to ').replace('zero', '/dev/zero')}"
        out.append(Probe("meshes", "1 bounds", name, mesh, limit_mb=64, seconds=10))
    return out


def _npy_header(shape: tuple[int, ...], descr: str = "<f8") -> bytes:
    out = io.BytesIO()
    np.lib.format.write_array_header_1_0(out, {"descr": descr, "fortran_order": False, "shape": shape})
    return out.getvalue()


@probe("points_npy", "1 bounds", "points .npy declaring 10^12 rows in 128 bytes", limit_mb=64)
def _npy_rows(tmp: Path) -> None:
    (tmp / "t.npy").write_bytes(_npy_header((10**12, 3)))
    expect_error(lambda: read_points(tmp / "t.npy"), "declares shape", within=3.0)


@probe("result", "1 bounds", "result .npz member declaring 10^12 values", limit_mb=64)
def _npz_member(tmp: Path) -> None:
    with zipfile.ZipFile(tmp / "r.npz", "w") as z:
        z.writestr("meta.npy", _npy_header((10**12,)))
    expect_error(lambda: read_result(tmp / "r.npz"), within=3.0)


@probe("result", "1 bounds", "result .npz end record declaring 65535 members", limit_mb=64)
def _zip_directory(tmp: Path) -> None:
    count = (65535).to_bytes(2, "little")
    (tmp / "r.npz").write_bytes(
        b"PK\x05\x06" + bytes(4) + count * 2 + (10**8).to_bytes(4, "little") + bytes(6)
    )
    expect_error(lambda: read_result(tmp / "r.npz"), "members", within=3.0)


@probe("points_csv", "1 bounds", "points .csv of 10^6 + 1 rows", limit_mb=128, slow=True)
def _csv_rows(tmp: Path) -> None:
    (tmp / "p.csv").write_bytes(b"0.5,0.25\n" * (10**6 + 1))
    expect_error(lambda: read_points(tmp / "p.csv"), "more than", within=10.0)


@probe("points_csv", "1 bounds", "points .csv with a line of 1 MiB", limit_mb=64)
def _csv_line(tmp: Path) -> None:
    (tmp / "p.csv").write_bytes(b"0.5," * (1 << 18))
    expect_error(lambda: read_points(tmp / "p.csv"), "a line of more than", within=3.0)


@probe("journal", "1 bounds", "journal with a line of 20 MiB (skipped, recomputed)", limit_mb=200)
def _journal_line(tmp: Path) -> None:
    path = tmp / "j.jsonl"
    gb_pin.run_trials("planar5", trials=2, movements=8, seed=3, checkpoint=path, workers=1)
    with open(path, "a") as fh:
        fh.write('{"key": "' + "x" * (20 << 20) + '"}\n')
    gb_pin.run_trials("planar5", trials=2, movements=8, seed=3, checkpoint=path, workers=1)


@listed
def _counts() -> list[Probe]:
    from gb_pin.learn.metrics import evaluation_schedule

    calls: dict[str, Callable[[], Any]] = {
        "run_trials(trials=10**9)": lambda: gb_pin.run_trials("planar5", trials=10**9, workers=1),
        "run_trials(workers=10**6)": lambda: gb_pin.run_trials("planar5", trials=2, workers=10**6),
        "run_sweep(learning_rate=[0.1] * 10**5)": lambda: gb_pin.run_sweep(learning_rate=[0.1] * 10**5),
        "planar_home(10**12)": lambda: gb_pin.planar_home(10**12),
        "planar_chain(10**9)": lambda: gb_pin.planar_chain(10**9),
        "evaluation_schedule(10**12, dense_until=10**12)": lambda: evaluation_schedule(10**12, 10**12),
    }
    out = [
        Probe("api", "1 bounds", n, lambda t, c=c: expect_error(c, within=3.0), limit_mb=64)
        for n, c in calls.items()
    ]
    path = lambda t: gb_pin.babble("planar5", movements=5).solve_path([0.5, 0.1], [0.6, 0.0], steps=10**9)  # noqa: E731
    return [*out, Probe("ik", "1 bounds", "solve_path(steps=10**9)", path, "error", owner="ik")]


@probe(
    "trials", "1 bounds", "a trial set of just under 64 MiB of numbers", limit_mb=1500, seconds=120, slow=True
)
def _big_trial_set(tmp: Path) -> None:
    """The largest trial set read: its peak memory while parsed (JSON numbers become Python objects)."""
    from gb_pin.experiments._json import MAX_JSON_BYTES

    raw = json.loads(CTX.originals["trials"])
    columns = (MAX_JSON_BYTES - 4096) // 45  # a movement count (8 bytes), 4 numbers "0.123456," (36)
    head = {k: v for k, v in raw.items() if k not in ("movements", "error", "home_distance")}
    with open(tmp / "t.json", "w") as fh:  # in chunks: this process stays small (it is measured)
        fh.write(json.dumps(head)[:-1] + ', "movements": [')
        for start in range(0, columns, 100_000):
            sep = "," if start else ""
            fh.write(sep + ",".join(map(str, range(start, min(columns, start + 100_000)))))
        for key in ("error", "home_distance"):
            fh.write(f'], "{key}": [')
            for trial in range(2):
                fh.write(("," if trial else "") + "[" + ",".join(["0.123456"] * columns) + "]")
        fh.write("]}")
    assert (tmp / "t.json").stat().st_size <= MAX_JSON_BYTES
    read_trials(tmp / "t.json")


@listed
def _big_commands() -> list[Probe]:
    """gb-pin ik --targets and babble --targets on large CSV files: the whole command's peak memory."""
    large = CTX.large
    rows, width = (10**6, 60) if large else (20_000, 20)  # 10^6 lines of 60 bytes: the 60 MB

    def ik_targets(tmp: Path) -> None:
        gb_pin.babble("planar5", movements=50, seed=0).save(tmp / "run.npz")
        points = 0.45 + 0.1 * np.random.default_rng(0).random((rows, 2))
        digits = (width - 2) // 2 - 2
        with open(tmp / "p.csv", "w") as fh:  # in chunks: this process stays small (its size would be
            for chunk in np.array_split(points, max(1, rows // 10_000)):  # counted in the command's peak)
                fh.write("".join(f"{a:.{digits}f},{b:.{digits}f}\n" for a, b in chunk))
        done = cli(["ik", "run.npz", "--targets", "p.csv"], tmp, timeout=600)
        assert done.rc in (0, 1), done.err[-500:]

    def babble_targets(tmp: Path) -> None:
        size = (256 << 20) if large else (12 << 20)
        with open(tmp / "p.csv", "wb") as fh:
            for _ in range(size // (9 << 16)):
                fh.write(b"0.5,0.25\n" * (1 << 16))
        done = cli(["babble", "--robot", "planar5", "--movements", "1", "--targets", "p.csv", "--quiet"], tmp)
        assert done.rc == 2 and "more than" in done.err and "Traceback" not in done.err, done.err[-500:]

    mb = rows * width / 1e6
    return [
        Probe(
            "ik_targets",
            "1 bounds",
            f"gb-pin ik --targets, a CSV of {mb:.1f} MB ({rows} points)",
            ik_targets,
            limit_mb=1200 if large else 600,
            seconds=600,
            slow=True,
        ),
        Probe(
            "points_csv",
            "1 bounds",
            f"gb-pin babble --targets, a CSV of {256 if large else 12} MiB (more than 10^6 points)",
            babble_targets,
            limit_mb=600,
            seconds=120,
            slow=True,
        ),
    ]


# -- 2 integers ----------------------------------------------------------------------------------
@listed
def _integers() -> list[Probe]:
    big = 2**70
    planar5 = gb_pin.load_robot

    def target(**kw: Any) -> Callable[[], Any]:
        home = [0.1, 0.2, 0.3]
        return lambda: gb_pin.KinematicTarget.from_urdf(
            SMALL_URDF, "tool", ["j1", "j2", "j4"], home=home, **kw
        )

    calls: dict[str, Callable[[Path], Any]] = {
        "babble(changes={2**70: body})": lambda t: gb_pin.babble(
            "planar5", 5, changes={big: planar5("planar5")}
        ),
        "Recording(every=2**70)": lambda t: gb_pin.Recording(every=big),
        "Recording(last=2**70)": lambda t: gb_pin.Recording(last=big),
        "babble(schedule=[0, 2**70])": lambda t: gb_pin.babble("planar5", 5, schedule=[0, big]),
        "babble(checkpoint_every=2**70)": lambda t: gb_pin.babble(
            "planar5", 5, checkpoint=t / "c.npz", checkpoint_every=big
        ),
        "babble(observe_every=2**70)": lambda t: gb_pin.babble("planar5", 5, observe_every=big),
        "babble(goals='cyclic:start=2**70')": lambda t: gb_pin.babble(
            "planar5", 5, goals=f"cyclic:start={big}"
        ),
        "run_trials(seed=2**70)": lambda t: gb_pin.run_trials("planar5", 1, 2, seed=big, workers=1),
        "KinematicTarget(task='pose', pointing_axis='z')": lambda t: target(task="pose", pointing_axis="z")(),
        "KinematicTarget(orientation_scale=0.1) (position task)": lambda t: target(orientation_scale=0.1)(),
    }
    out = [Probe("api", "2 integers", n, c, "error") for n, c in calls.items()]
    out.append(
        Probe(
            "api",
            "2 integers",
            "babble(movements=np.int64(5)) works",
            lambda t: gb_pin.babble("planar5", np.int64(5)),
        )
    )
    ik = lambda t: gb_pin.babble("planar5", 5).solve([[0.5, 0.1]], max_iterations=big)  # noqa: E731
    return [*out, Probe("ik", "2 integers", "solve(max_iterations=2**70)", ik, "error", owner="ik")]


# -- 3 files that load but are wrong --------------------------------------------------------------
@probe("result", "3 wrong files", "result with an empty history", limit_mb=64)
def _empty_history(tmp: Path) -> None:
    (tmp / "r.npz").write_bytes(CTX.originals["result"])
    rewrite_npz(
        tmp / "r.npz", lambda a, m: a.update({k: a[k][:0] for k in ("movements", "error", "home_distance")})
    )
    expect_error(lambda: read_result(tmp / "r.npz"), "history is empty")


@probe("points_npy", "3 wrong files", ".npy header cut short (numpy: tokenize's TokenError)", limit_mb=64)
def _cut_header(tmp: Path) -> None:
    (tmp / "p.npy").write_bytes(CTX.originals["points_npy"][:40])
    expect_error(lambda: read_points(tmp / "p.npy"), "header")


@probe("checkpoint", "3 wrong files", "0-d arrays in every checkpoint field", limit_mb=128, seconds=60)
def _zero_d(tmp: Path) -> None:
    with np.load(io.BytesIO(CTX.originals["checkpoint"]), allow_pickle=False) as f:
        keys = [k for k in f.files if k != "meta"]
    for key in keys:
        for value in (np.array(1.0), np.array(3)):
            (tmp / "c.npz").write_bytes(CTX.originals["checkpoint"])
            rewrite_npz(tmp / "c.npz", lambda a, m, k=key, v=value: a.update({k: v}))
            with contextlib.suppress(gb_pin.GbPinError):
                read_checkpoint(tmp / "c.npz")


@probe("trials", "3 wrong files", "trial set: movements 1e20, 2**70, 1.5; prototypes 1.5; text", limit_mb=64)
def _trial_counts(tmp: Path) -> None:
    raw = json.loads(CTX.originals["trials"])
    text = [["0.1"] * len(raw["movements"])] * 2
    for bad in ({"movements": [0, 1e20]}, {"movements": [0, 2**70]}, {"movements": [0, 1.5]},
                {"prototypes": [1.5, 2]}, {"error": text}):  # fmt: skip
        (tmp / "t.json").write_text(json.dumps({**raw, **bad}))
        expect_error(lambda: read_trials(tmp / "t.json"))


@probe("preset", "3 wrong files", "preset TOML that is not UTF-8", limit_mb=64)
def _non_utf8(tmp: Path) -> None:
    (tmp / "x.toml").write_bytes(CTX.originals["preset"].replace(b"talos", b"tal\xffos", 1))
    expect_error(lambda: read_preset(tmp / "x.toml"), "utf-8")


@probe("plot_result", "3 wrong files", "E_0 = 0 (home the only target): the figure", limit_mb=128)
def _home_only(tmp: Path) -> None:
    from gb_pin.learn.history import versus_initial

    arm = gb_pin.load_robot("planar5")
    res = gb_pin.babble("planar5", movements=20, targets=[arm.forward(arm.home)])
    assert res.history.initial_error == 0 and "inf" not in versus_initial(res.error, 0.0)
    res.save(tmp / "r.npz")
    read_plot(tmp / "r.npz")
    assert (tmp / "r.png").stat().st_size > 1000


@probe(
    "plot_result", "3 wrong files", "E_0 = 0: gb-pin babble's summary, gb-pin plot", limit_mb=600, slow=True
)
def _home_only_cli(tmp: Path) -> None:
    home = gb_pin.load_robot("planar5")
    np.save(tmp / "home.npy", home.forward(home.home)[None])
    args = [
        "babble",
        "--robot",
        "planar5",
        "--movements",
        "20",
        "--targets",
        "home.npy",
        "--quiet",
        "--out",
        "r.npz",
    ]
    done = cli(args, tmp)
    assert done.rc == 0 and "inf" not in done.out and "E_0 = 0 m" in done.out, done.out + done.err
    plotted = cli(["plot", "r.npz"], tmp)
    assert plotted.rc == 0 and (tmp / "r.png").exists(), plotted.err


# -- 4 failed writes ------------------------------------------------------------------------------
@probe("result", "4 failed writes", "babble --out on a full disk", limit_mb=600, seconds=60)
def _babble_out(tmp: Path) -> None:
    CTX.full.clear()
    env = CTX.full.fill()
    out = str(CTX.full.path / "r.npz")
    done = cli(["babble", "--robot", "planar20", "--movements", "300", "--quiet", "--out", out], tmp, env=env)
    assert done.rc == 0 and "saved to" in done.err, done.err[-500:]
    gb_pin.load_result(tmp / "r.npz")


@probe(
    "journal",
    "4 failed writes",
    "trials --checkpoint: the journal fills the disk mid-run",
    limit_mb=900,
    seconds=120,
)
def _trials_journal(tmp: Path) -> None:
    CTX.full.clear()
    journal = CTX.full.path / "j.jsonl"  # one finished trial, then the disk fills
    gb_pin.run_trials("planar5", trials=1, movements=300, seed=0, checkpoint=journal, workers=1)
    env = CTX.full.fill()
    args = ["trials", "--robot", "planar5", "--trials", "6", "--movements", "300", "--workers", "2",
            "--quiet", "--checkpoint", str(journal), "--json", "t.json"]  # fmt: skip
    done = cli(args, tmp, env=env)
    assert done.rc == 0, done.err[-800:]
    assert gb_pin.TrialSet.load(tmp / "t.json").trials == 6
    moved = [w for w in done.err.splitlines() if "trial journal" in w and "are in" in w]
    assert moved, done.err[-800:]
    where = Path(moved[0].split("are in '")[1].split("'")[0])
    assert len(where.read_text().splitlines()) == 1 + 6, where.read_text()[:300]
    where.unlink()  # the journal's fallback, in the user's cache folder


@probe("trials", "4 failed writes", "trials --json on a full disk", limit_mb=600, seconds=60, slow=True)
def _trials_json(tmp: Path) -> None:
    CTX.full.clear()
    env = CTX.full.fill()
    args = ["trials", "--robot", "planar5", "--trials", "4", "--movements", "300", "--workers", "1",
            "--quiet", "--json", str(CTX.full.path / "t.json")]  # fmt: skip
    done = cli(args, tmp, env=env)
    assert done.rc == 0 and "saved to" in done.err, done.err[-500:]
    assert gb_pin.TrialSet.load(tmp / "t.json").trials == 4


@probe("trials", "4 failed writes", "robots --benchmark --json --figure on a full disk", limit_mb=900,
       seconds=180, slow=True)  # fmt: skip
def _benchmark(tmp: Path) -> None:
    CTX.full.clear()
    env = CTX.full.fill()
    json_path, figure = str(CTX.full.path / "b.json"), str(CTX.full.path / "b.png")
    args = ["robots", "--benchmark", "--robots", "planar5", "--trials", "2", "--movements", "300",
            "--workers", "1", "--quiet", "--json", json_path, "--figure", figure]  # fmt: skip
    done = cli(args, tmp, env=env)
    assert done.rc == 0, done.err[-500:]
    assert (tmp / "b.json").exists() and (tmp / "b.png").exists(), (done.err[-500:], list(tmp.iterdir()))
    assert done.err.count("saved to") == 2, done.err[-500:]


@probe("checkpoint", "4 failed writes", "babble(checkpoint=) on a full disk, mid-run", seconds=60)
def _checkpoint_full(tmp: Path) -> None:
    CTX.full.clear()
    CTX.full.fill()
    CTX.full.patch()
    os.chdir(tmp)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = gb_pin.babble(
            "planar20", movements=30, seed=0, checkpoint=CTX.full.path / "c.npz", checkpoint_every=5
        )
    assert res.movements == 30
    assert any("from now on" in str(w.message) for w in caught), [str(w.message) for w in caught]
    gb_pin.resume(tmp / "c.npz")


# -- 5 processes -----------------------------------------------------------------------------------
@probe("files", "5 processes", "SIGKILL mid-write: the stale temporary removed, a live one kept", seconds=30)
def _stale_temporaries(tmp: Path) -> None:
    from gb_pin import _files

    path, ready = tmp / "r.json", tmp / "ready"
    ready.mkdir()

    def writer(hold: bool) -> int:
        pid = os.fork()
        if pid == 0:
            with _files.atomic_write(path, text=True) as fh:
                fh.write("x" * 1000)
                fh.flush()
                (ready / str(os.getpid())).write_text("")
                if hold:
                    time.sleep(60)
                os.kill(os.getpid(), signal.SIGKILL)  # killed mid-write
        return pid

    killed, live = writer(False), writer(True)
    os.waitpid(killed, 0)
    while len(list(ready.iterdir())) < 2:
        time.sleep(0.01)
    temps = [p for p in tmp.iterdir() if p.name.startswith(".r.json.")]
    assert len(temps) == 2, temps
    old = time.time() - 2 * _files.STALE_SECONDS
    for t in temps:
        os.utime(t, (old, old))
    _files.write_text(path, "new")  # the next write to the path
    left = [p for p in tmp.iterdir() if p.name.startswith(".r.json.")]
    os.kill(live, signal.SIGKILL)
    os.waitpid(live, 0)
    assert len(left) == 1 and path.read_text() == "new", left  # the live writer's is kept


@probe(
    "journal",
    "5 processes",
    "Ctrl-C in gb-pin trials: prompt, journaled, one line, 130",
    limit_mb=900,
    seconds=60,
)
def _ctrl_c_trials(tmp: Path) -> None:
    # About a minute of trials (each ~0.2 s): Ctrl-C at 4 s finds them running, some journaled.
    args = ["trials", "--robot", "planar20", "--trials", "400", "--movements", "3000", "--workers", "2",
            "--checkpoint", "j.jsonl", "--quiet"]  # fmt: skip
    done = cli(args, tmp, interrupt=4.0)
    assert done.rc == 130, (done.rc, done.err[-500:])
    assert done.after_interrupt < 5.0, f"{done.after_interrupt:.1f} s to exit after Ctrl-C"
    lines = [ln for ln in done.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "journaled in j.jsonl" in lines[0], done.err[-500:]
    journaled = len((tmp / "j.jsonl").read_text().splitlines()) - 1
    assert journaled >= 1 and f"{journaled} of 400 trials finished" in lines[0], (journaled, lines)


@probe("result", "5 processes", "Ctrl-C in gb-pin babble without a checkpoint: one useful line", limit_mb=600,
       seconds=30, slow=True)  # fmt: skip
def _ctrl_c_babble(tmp: Path) -> None:
    done = cli(["babble", "--robot", "planar20", "--movements", "10000000", "--quiet"], tmp, interrupt=4.0)
    lines = [ln for ln in done.err.splitlines() if ln.strip()]
    assert done.rc == 130 and len(lines) == 1 and "checkpoint" in lines[0], (done.rc, done.err[-300:])


@probe("checkpoint", "5 processes", "babble() and resume() beside another run on one checkpoint")
def _two_runs(tmp: Path) -> None:
    from gb_pin.runs.checkpoint import checkpoint_lock

    path = tmp / "c.npz"
    gb_pin.babble("planar5", movements=10, checkpoint=path)
    with checkpoint_lock(path):
        expect_error(lambda: gb_pin.babble("planar5", movements=10, checkpoint=path), "another run")
        expect_error(lambda: gb_pin.resume(path), "another run")


# -- 6 MODULE:NAME ---------------------------------------------------------------------------------
MODULE = """import os
from os import getcwd
VALUE = 3
def needs(q):
    return q
def raises():
    raise RuntimeError("broken factory")
def number():
    return 5
class Arm:
    pass
"""


@listed
def _module_specs() -> list[Probe]:
    from gb_pin.robot.spec import load_robot_spec

    def spec(name: str) -> Callable[[Path], None]:
        def run(tmp: Path) -> None:
            (tmp / "mod.py").write_text(MODULE)
            text = name if ":" in name else f"{tmp / 'mod.py'}:{name}"
            expect_error(lambda: load_robot_spec(text), "robot")

        return run

    names = ["sys:exit", "os:abort", "os:system", "builtins:exec", "numpy:zeros", "getcwd", "os", "VALUE",
             "needs", "raises", "number", "Arm", "missing"]  # fmt: skip
    return [Probe("robot spec", "6 MODULE:NAME", f"--robot {n}", spec(n), limit_mb=64) for n in names]


# -- 7 the viewer server ---------------------------------------------------------------------------
@probe("viewer", "7 viewer server", "300 idle connections, a 100 MB body, out of descriptors", seconds=60)
def _viewer(tmp: Path) -> None:
    from gb_pin.viewer import listener
    from gb_pin.viewer.server import LocalServer

    if not CTX.large:
        listener.IDLE_SECONDS = 0.5  # the real 10 s in the large run
    os.dup2(os.open(tmp / "stderr", os.O_WRONLY | os.O_CREAT, 0o644), 2)
    server = LocalServer()
    host = f"Host: 127.0.0.1:{server.port}".encode()

    def connect() -> socket.socket:
        return socket.create_connection(("127.0.0.1", server.port), timeout=5)

    try:
        idle = [connect() for _ in range(300)]
        with connect() as c:
            c.sendall(b"GET /static/ HTTP/1.1\r\n" + host + b"\r\n\r\n")
            assert c.recv(16).startswith(b"HTTP/1.1 200"), "the browser starved by 300 idle connections"
        with connect() as c:
            c.sendall(b"POST /static/ HTTP/1.1\r\n" + host + b"\r\nContent-Length: 100000000\r\n\r\n")
            assert c.recv(16).startswith(b"HTTP/1.1 400"), "a 100 MB body accepted"
        time.sleep(listener.IDLE_SECONDS + 1.0)
        still = 0
        for c in idle:
            c.setblocking(False)
            try:
                still += c.recv(1) != b""
            except BlockingIOError:
                still += 1
            except OSError:
                pass
        assert still == 0, f"{still} idle connections still open after the timeout"
        soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        resource.setrlimit(resource.RLIMIT_NOFILE, (len(os.listdir("/proc/self/fd")) + 8, hard))
        more = []
        for _ in range(40):
            with contextlib.suppress(OSError):
                more.append(socket.socket())
                more[-1].settimeout(1)
                more[-1].connect(("127.0.0.1", server.port))
        time.sleep(1.5)
        for c in [*more, *idle]:
            c.close()
        resource.setrlimit(resource.RLIMIT_NOFILE, (soft, hard))
    finally:
        server.close()
    lines = (tmp / "stderr").read_text().splitlines()
    assert len(lines) <= 4 and not any("Traceback" in ln for ln in lines), lines[:10]


# -- 8 robot descriptions --------------------------------------------------------------------------
TILTED = """<robot name="tilted">
 <link name="base"/><link name="l1"/><link name="l2"/><link name="tool"/>
 <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0.6 0.8 0"/></joint>
 <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.3 0 0"/>
  <axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
 <joint name="j3" type="fixed"><parent link="l2"/><child link="tool"/><origin xyz="0.3 0 0"/></joint>
</robot>"""


@probe("urdf", "8 robot descriptions", "a continuous joint about an unaligned axis", seconds=60)
def _unaligned(tmp: Path) -> None:
    (tmp / "t.urdf").write_text(TILTED)
    arm = gb_pin.KinematicTarget.from_urdf(tmp / "t.urdf", "tool", home=[0.3, 1.0])
    for q in np.random.default_rng(0).uniform(-2, 2, (20, 2)):
        assert np.allclose(arm.forward(q), arm.forward_pinocchio(q), atol=1e-12)
    x = arm.forward(arm.home)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = gb_pin.babble(arm, movements=100, seed=0, targets=[x, x + np.array([0.01, 0.01, 0.0])])
    assert np.isfinite(res.error)


@probe("urdf", "8 robot descriptions", "link and joint names with escape bytes", limit_mb=600, seconds=60)
def _escapes(tmp: Path) -> None:
    urdf = (
        TILTED.replace('"j2"', '"j2\x1b[31m"')
        .replace('"l2"', '"l2\x1b[2J"')
        .replace('"tool"', '"to\x1b]0;x\x07"')
    )
    (tmp / "e.urdf").write_text(urdf)
    expect_error(lambda: gb_pin.KinematicTarget.from_urdf(tmp / "e.urdf", "nope"), "nope")
    expect_error(lambda: gb_pin.KinematicTarget.from_urdf(tmp / "e.urdf", "l1", ["nope"]), "nope")
    done = cli(["babble", "--robot", "e.urdf", "--frame", "nope", "--movements", "2"], tmp)
    assert done.rc == 2 and "\x1b" not in done.err + done.out, repr(done.err[-300:])


# -- 9 messages --------------------------------------------------------------------------------------
@probe("api", "9 messages", "a compiled forward model returning NaN", seconds=60)
def _compiled_nan(tmp: Path) -> None:
    from numba import njit

    @njit
    def kernel(q, x):  # type: ignore[no-untyped-def]
        x[0] = 0.5 * (np.cos(q[0]) + np.cos(q[0] + q[1]))
        x[1] = 0.5 * (np.sin(q[0]) + np.sin(q[0] + q[1]))
        if q[1] > 0.8:
            x[0] = np.nan

    arm = gb_pin.FunctionTarget.from_kernel(
        kernel, [0.3, 0.6], 2, lower=-3, upper=3, targets=[[0.5, 0.5], [0.7, 0.2]]
    )
    expect_error(lambda: gb_pin.babble(arm, movements=300, seed=0), "forward model", within=60)


@probe("api", "9 messages", "a Python forward model returning inf while stepping", owner="lead")
def _python_inf(tmp: Path) -> None:
    calls = [0]

    def forward(q: Any) -> Any:
        calls[0] += 1
        h = np.cumsum(q)
        return (
            np.array([np.inf, 0.0]) if calls[0] >= 310 else 0.5 * np.array([np.cos(h).sum(), np.sin(h).sum()])
        )

    arm = gb_pin.FunctionTarget(forward, [0.3, 0.6], lower=-3, upper=3, targets=[[0.5, 0.5], [0.7, 0.2]])
    expect_error(lambda: gb_pin.babble(arm, movements=50, seed=0), "forward")
