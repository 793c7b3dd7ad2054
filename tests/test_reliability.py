"""Reliability (issue 15): files are untrusted input, checkpoints come when promised, no hang, no lost result.

Each test names the class of problem it holds: tampered or oversized files, output paths checked
before the work, loose argument types, the viewer's log, worker processes, checkpoint locks.
"""

from __future__ import annotations

import io
import json
import os
import socket
import subprocess
import sys
import time
import zipfile
from fractions import Fraction
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin import _files
from gb_pin.cli import main
from gb_pin.learn import GoalBabbling, layout
from gb_pin.runs.checkpoint import CheckpointInfo, checkpoint_lock, write_checkpoint


def _checkpoint(path: Path, movements: int = 60, record: Any = None) -> None:
    target = gb_pin.load_robot("planar5")
    config = GoalBabbling()._resolve(target.n_joints)
    st = gb_pin.BabbleState.start(target, target.targets, movements, config, seed=2, record=record)
    st.run(20)
    write_checkpoint(path, st, CheckpointInfo("planar5", "planar5", movements, 2, config, 0.1))


def _rewrite(path: Path, change: Any) -> None:
    """Rewrite the .npz at ``path`` with ``change(arrays, meta)`` applied."""
    with np.load(path, allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = json.loads(str(arrays.pop("meta")))
    change(arrays, meta)
    np.savez(path, meta=np.array(json.dumps(meta)), **arrays)


def _set(arrays: dict[str, Any], key: str, index: int, value: int) -> None:
    a = arrays[key].copy()
    a[index] = value
    arrays[key] = a


# -- 1. tampered checkpoints, through the file ---------------------------------------
@pytest.mark.parametrize(
    "change",
    [
        lambda a, m: _set(a, "istate", layout.EVAL_CURSOR, -(10**9)),
        lambda a, m: _set(a, "istate", layout.RECORDED, -(10**9)),
        lambda a, m: _set(a, "istate", layout.KIND, 7),
        lambda a, m: a.update(rec_posture=a["rec_posture"][:, :-1]),
        lambda a, m: a.update(lower=a["lower"][:1]),
        lambda a, m: m.update(movements=2**64),
        lambda a, m: m.update(movements="60"),
        lambda a, m: m.update(seed="seed"),
        lambda a, m: m.update(wall_time=-1.0),
        lambda a, m: m.update(config={**m["config"], "path_length": 2**64}),
        lambda a, m: m.update(robot=5),
    ],
)
def test_a_tampered_checkpoint_file_is_refused_by_resume(tmp_path: Path, change: Any) -> None:
    """write_checkpoint, mutate the .npz, gb_pin.resume: ResultFileError, at once."""
    path = tmp_path / "c.npz"
    _checkpoint(path, record=gb_pin.Recording(every=2))
    _rewrite(path, change)
    start = time.perf_counter()
    with pytest.raises(gb_pin.ResultFileError):
        gb_pin.resume(path)
    assert time.perf_counter() - start < 1.0


# -- 2. checkpoint_every honoured -----------------------------------------------------
def test_checkpoints_come_at_every_multiple_of_checkpoint_every(tmp_path: Path) -> None:
    """checkpoint_every=999 over 5000 movements writes at 999, 1998, 2997, 3996, 4995 and 5000."""
    target = gb_pin.load_robot("planar5")
    seen: list[int] = []
    learner = GoalBabbling()
    learner.fit(
        target,
        target.targets,
        5000,
        seed=0,
        checkpoint=lambda st: seen.append(st.movements),
        checkpoint_every=999,
    )
    assert seen == [999, 1998, 2997, 3996, 4995, 5000]


def test_cli_checkpoint_every_leaves_a_file_soon_after_start(tmp_path: Path) -> None:
    """`gb-pin babble --checkpoint-every 7` writes its first checkpoint within seconds, not at the end."""
    path = tmp_path / "c.npz"
    cmd = [sys.executable, "-m", "gb_pin.cli", "babble", "--robot", "planar5", "--movements", "10000000",
           "--checkpoint", str(path), "--checkpoint-every", "7", "--quiet"]  # fmt: skip
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while not path.exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        assert path.exists(), proc.stderr.read().decode() if proc.poll() is not None else "no checkpoint"
    finally:
        proc.kill()
        proc.wait()


# -- 3. resource exhaustion from small inputs -----------------------------------------
def _forged(path: Path, size: int) -> None:
    """A result file whose first zip member claims ``size`` bytes (central directory and local header)."""
    data = bytearray(path.read_bytes())
    pos = data.find(b"PK\x01\x02")
    data[pos + 24 : pos + 28] = (size & 0xFFFFFFFF).to_bytes(4, "little")
    path.write_bytes(bytes(data))


def test_declared_sizes_are_checked_before_anything_is_allocated(tmp_path: Path) -> None:
    """A zip member claiming 4 GiB, or an .npy header claiming 10^12 elements: ResultFileError, fast."""
    res = gb_pin.babble("planar5", movements=20, seed=0)
    path = tmp_path / "r.npz"
    np.savez(path, meta=np.array(json.dumps({"format": "gb_pin.result", "format_version": 1})))
    _forged(path, 2**32 - 16)
    with pytest.raises(gb_pin.ResultFileError):
        gb_pin.load_result(path)
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10**12,)})
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("meta.npy", header.getvalue())
    start = time.perf_counter()
    with pytest.raises(gb_pin.ResultFileError):
        gb_pin.load_result(path)
    assert time.perf_counter() - start < 1.0
    res.save(path)  # a real file still loads
    assert gb_pin.load_result(path).movements == 20


def test_huge_planar_chains_are_refused_at_once_and_large_ones_load_fast(tmp_path: Path) -> None:
    """planar5000000 in a header is refused (N <= 500); load_robot no longer builds pinocchio's Data."""
    from gb_pin.robot.presets import MAX_PLANAR_JOINTS

    start = time.perf_counter()
    for name in ("planar5000000", "planar" + "9" * 10000, f"planar{MAX_PLANAR_JOINTS + 1}"):
        with pytest.raises(gb_pin.UnknownRobotError, match=str(MAX_PLANAR_JOINTS)):
            gb_pin.load_robot(name)
    robot = gb_pin.load_robot(f"planar{MAX_PLANAR_JOINTS}")
    assert robot.n_joints == MAX_PLANAR_JOINTS and time.perf_counter() - start < 5.0
    res = gb_pin.babble("planar5", movements=10, seed=0)
    path = tmp_path / "r.npz"
    res.save(path)
    _rewrite(path, lambda a, m: m.update(robot="planar5000000"))
    with pytest.raises(gb_pin.ResultFileError, match="500"):
        gb_pin.load_result(path)
    assert main(["replay", str(path)]) == 2


def test_path_length_movements_grids_recordings_have_documented_maxima() -> None:
    """path_length <= 10^6, movements <= 10^12, grids <= 10^6 points, recordings <= 2 GiB: checked first."""
    from gb_pin.learn.state import MAX_RECORD_BYTES

    start = time.perf_counter()
    with pytest.raises(gb_pin.InvalidArgumentError, match="path_length"):
        gb_pin.babble("planar5", movements=1, path_length=2**64)
    with pytest.raises(gb_pin.InvalidArgumentError, match="movements"):
        gb_pin.babble("planar5", movements=10**30)
    with pytest.raises(gb_pin.InvalidArgumentError, match="MAX_GRID_POINTS"):
        gb_pin.grid_targets([0], [1], [10**9])
    with pytest.raises(gb_pin.InvalidArgumentError, match="MAX_GRID_POINTS"):
        gb_pin.grid_targets([0, 0], [1, 1], [10**5, 10**5])
    with pytest.raises(gb_pin.InvalidArgumentError, match="MAX_RECORD_BYTES"):
        gb_pin.babble("planar50", movements=10**6, record=gb_pin.Recording(every=1))
    assert MAX_RECORD_BYTES == 2 * 2**30 and time.perf_counter() - start < 1.0


def test_recording_buffers_grow_as_the_run_goes() -> None:
    """A recording is allocated lazily: a long one starts small and ends with every step."""
    target = gb_pin.load_robot("planar5")
    config = GoalBabbling()._resolve(target.n_joints)
    st = gb_pin.BabbleState.start(target, target.targets, 400, config, seed=0, record=gb_pin.Recording())
    assert st.rec["step"].shape[0] <= 4096
    st.run(400)
    rec = st.recorded()
    assert rec is not None and rec.step.shape[0] == 400 * config.path_length


def test_a_urdf_with_thousands_of_links_is_refused_before_the_parser(tmp_path: Path) -> None:
    """pinocchio's URDF parser crashes on a 5000-link chain: the file is refused first."""
    parts = ['<robot name="r">', '<link name="l0"/>']
    for i in range(1, 5001):
        parts.append(
            f'<link name="l{i}"/><joint name="j{i}" type="revolute"><parent link="l{i - 1}"/>'
            f'<child link="l{i}"/><axis xyz="0 0 1"/>'
            '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        )
    path = tmp_path / "long.urdf"
    path.write_text("\n".join([*parts, "</robot>"]))
    start = time.perf_counter()
    with pytest.raises(gb_pin.InvalidArgumentError, match="MAX_URDF_ELEMENTS"):
        gb_pin.KinematicTarget.from_urdf(path, "l5000")
    assert time.perf_counter() - start < 1.0


# -- 4. output paths --------------------------------------------------------------------
@pytest.mark.parametrize("where", ["/nonexistent/dir/x.npz", "/proc/x.npz", "DIR", ""])
def test_unwritable_outputs_are_refused_before_the_work(tmp_path: Path, where: str) -> None:
    """check_writable: a missing parent, /proc, a directory, ''; in Python and on the command line."""
    path = str(tmp_path) if where == "DIR" else where
    with pytest.raises(gb_pin.InvalidArgumentError):
        _files.check_writable(path, "--out")
    with pytest.raises(gb_pin.InvalidArgumentError, match="checkpoint"):
        gb_pin.babble("planar5", movements=10**9, checkpoint=path)
    res = gb_pin.babble("planar5", movements=5, seed=0)
    with pytest.raises(gb_pin.InvalidArgumentError):
        res.save(path)
    start = time.perf_counter()
    for argv in (
        ["babble", "--movements", "1000000000", "--out", path],
        ["babble", "--movements", "1000000000", "--checkpoint", path],
        ["trials", "--movements", "1000000000", "--json", path],
        ["trials", "--movements", "1000000000", "--checkpoint", path],
        ["robots", "--benchmark", "--movements", "1000000000", "--json", path],
        ["robots", "--benchmark", "--movements", "1000000000", "--figure", path],
    ):
        assert main(argv) == 2, argv
    assert time.perf_counter() - start < 5.0
    with pytest.raises(gb_pin.InvalidArgumentError, match="file path"):
        _files.check_writable(5, "checkpoint")


def test_a_failed_final_write_falls_back_and_says_where(tmp_path: Path, monkeypatch: Any) -> None:
    """write_or_fallback: the result goes to the current directory when its own path fails."""
    monkeypatch.chdir(tmp_path)
    calls: list[str] = []

    def write(path: Any) -> None:
        calls.append(os.fspath(path))
        if len(calls) == 1:
            raise OSError("disk full")
        Path(path).write_text("ok")

    where = _files.write_or_fallback("/somewhere/x.npz", write)
    assert Path(where).parent == tmp_path and Path(where).read_text() == "ok"


# -- 6. files that load but are wrong ---------------------------------------------------
@pytest.mark.parametrize(
    "change",
    [
        lambda a, m: a.update(matrices=a["matrices"] * np.inf),
        lambda a, m: a.update(targets=a["targets"] * np.nan),
        lambda a, m: a.update(error=a["error"][:-1]),
        lambda a, m: a.update(movements=a["movements"][::-1].copy()),
        lambda a, m: a.update(prototypes=a["prototypes"].astype(complex)),
        lambda a, m: a.update(targets=np.array(1.0)),
        lambda a, m: a.update(rec_step=np.array(1)),
        lambda a, m: m.update(seed="seed"),
        lambda a, m: m.update(movements=-3),
        lambda a, m: m.update(wall_time=float("nan")),
        lambda a, m: m.update(robot=["planar5"]),
        lambda a, m: m.update(config=[1, 2]),
    ],
)
def test_result_files_that_load_but_are_wrong_fail_at_load(tmp_path: Path, change: Any) -> None:
    """Every field of a result file is checked at load: ResultFileError, not IndexError in show."""
    res = gb_pin.babble("planar5", movements=30, seed=0, record=gb_pin.Recording(every=5, last=4))
    path = tmp_path / "r.npz"
    res.save(path)
    _rewrite(path, change)
    with pytest.raises(gb_pin.ResultFileError):
        gb_pin.load_result(path)


def test_trial_files_and_journals_are_validated(tmp_path: Path) -> None:
    """A trials file with a string seed or a nested JSON header is refused; a bad journal line is ignored."""
    ts = gb_pin.run_trials(
        "planar5", trials=2, movements=8, seed=3, workers=1, checkpoint=tmp_path / "j.jsonl"
    )
    path = tmp_path / "t.json"
    ts.save(path)
    raw = json.loads(path.read_text())
    for bad in (
        {**raw, "seed": "3"},
        {**raw, "prototypes": raw["prototypes"][:1]},
        {**raw, "error": [[1e999]]},
    ):
        path.write_text(json.dumps(bad))
        with pytest.raises(gb_pin.ResultFileError):
            gb_pin.TrialSet.load(path)
    path.write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(gb_pin.ResultFileError):
        gb_pin.TrialSet.load(path)
    journal = tmp_path / "j.jsonl"
    lines = journal.read_text().splitlines()
    entry = json.loads(lines[1])
    journal.write_text("\n".join([lines[0], json.dumps({**entry, "error": entry["error"][:-1]})]) + "\n")
    again = gb_pin.run_trials("planar5", trials=2, movements=8, seed=3, workers=1, checkpoint=journal)
    np.testing.assert_array_equal(again.error, ts.error)  # the bad line was recomputed, not reused


# -- 7. loose argument types ------------------------------------------------------------
def test_numpy_scalars_are_accepted_and_stored_as_python_numbers(tmp_path: Path) -> None:
    """np.float32 / np.int64 hyperparameters work in babble(), save() and checkpoints."""
    res = gb_pin.babble(
        "planar5", movements=np.int64(20), seed=np.int64(1), learning_rate=np.float32(0.1),
        path_length=np.int64(25), checkpoint=tmp_path / "c.npz",
    )  # fmt: skip
    assert type(res.config.learning_rate) is float and type(res.config.path_length) is int
    res.save(tmp_path / "r.npz")
    assert gb_pin.load_result(tmp_path / "r.npz").config == res.config


@pytest.mark.parametrize(
    "kwargs",
    [
        {"record": "yes"},
        {"viewer": 5},
        {"callback": 5},
        {"checkpoint": 5},
        {"movements": 10**30},
        {"schedule": [0, 2.5, 10]},
        {"learning_rate": "0.1"},
        {"path_length": Fraction(5, 2)},
    ],
)
def test_loose_arguments_are_refused_before_any_work(kwargs: dict[str, Any]) -> None:
    """Wrong types and non-integer schedules: InvalidArgumentError naming the value, no silent truncation."""
    with pytest.raises(gb_pin.InvalidArgumentError):
        gb_pin.babble("planar5", **{"movements": 10, **kwargs})


@pytest.mark.parametrize(
    "argv",
    [
        ["show", "x.npz", "--postures", "-1"],
        ["replay", "x.npz", "--speed", "nan"],
        ["babble", "--view-wait", "nan"],
        ["babble", "--out", ""],
        ["babble", "--sigma", "0"],
        ["babble", "--checkpoint-every", "5"],
        ["babble", "--resume", "x.npz", "--robot", "planar5"],
        ["babble", "--resume", "x.npz", "--movements", "5"],
        ["babble", "--movements", "0"],
        ["bench", "--repeat", "0"],
        ["trials", "--scheduler", "garbage"],
    ],
)
def test_cli_refuses_bad_options_in_one_line(argv: list[str], capsys: Any) -> None:
    """Each bad option or combination: exit 2 and one line naming it, before any work."""
    start = time.perf_counter()
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's own refusal (unknown option, not a number)
        code = int(exc.code or 0)
    assert code == 2 and time.perf_counter() - start < 5.0
    err = capsys.readouterr().err.strip().splitlines()
    assert err and "Traceback" not in "\n".join(err)


# -- 8. the viewer's log ------------------------------------------------------------------
def test_the_viewer_logs_only_sanitised_request_lines(capfd: Any) -> None:
    """Raw socket requests with %1b escapes and %00: no escape sequence, no traceback on the terminal."""
    import logging

    from gb_pin.viewer.server import LocalServer, sanitize

    assert sanitize("a\x1b[31mb\x00") == "a\\x1b[31mb\\x00"
    logging.getLogger("gb_pin.viewer").setLevel(logging.DEBUG)
    server = LocalServer()
    try:
        port = server.port
        host = f"Host: 127.0.0.1:{port}".encode()
        for path in (b"/static/%1b[31mRED%1b[0m", b"/static/%00", b"/\x1b[2J"):
            with socket.create_connection(("127.0.0.1", port), timeout=5) as c:
                c.sendall(b"GET " + path + b" HTTP/1.1\r\n" + host + b"\r\n\r\n")
                assert c.recv(64).startswith(b"HTTP/1.1 4")
    finally:
        server.close()
        logging.getLogger("gb_pin.viewer").setLevel(logging.NOTSET)
    out, err = capfd.readouterr()
    assert "\x1b" not in out + err and "Traceback" not in out + err


# -- 9. processes and locks ----------------------------------------------------------------
def test_workers_exit_when_their_parent_dies(tmp_path: Path) -> None:
    """watch_parent: a worker whose parent is killed exits within a second or two."""
    script = tmp_path / "parent.py"
    script.write_text(
        "import os, sys, time\n"
        "from concurrent.futures import ProcessPoolExecutor\n"
        "from gb_pin.experiments.pool import watch_parent\n"
        "def work():\n    time.sleep(300)\n"
        "if __name__ == '__main__':\n"
        "    pool = ProcessPoolExecutor(1, initializer=watch_parent, initargs=(os.getpid(),))\n"
        "    pool.submit(work)\n"
        "    time.sleep(1)\n"
        "    print(*[p.pid for p in pool._processes.values()], flush=True)\n"
        "    os._exit(0)\n"  # the parent vanishes without shutting the pool down
    )
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60).stdout
    pid = int(out.split()[0])
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return
        time.sleep(0.1)
    os.kill(pid, 9)
    pytest.fail(f"worker {pid} outlived its parent")


def test_a_garbage_scheduler_address_is_refused_at_once() -> None:
    """--scheduler garbage: InvalidArgumentError before Dask is asked; no 40 s hang."""
    from gb_pin.experiments.distributed import check_address

    start = time.perf_counter()
    for bad in ("garbage", "tcp://host", "tcp://host:99999", "tcp://a b:1"):
        with pytest.raises(gb_pin.InvalidArgumentError):
            gb_pin.run_trials("planar5", trials=1, movements=5, scheduler=bad)
    assert check_address("tcp://head:8786") == ("tcp", "head", 8786)
    assert time.perf_counter() - start < 1.0


def test_two_runs_cannot_write_one_checkpoint(tmp_path: Path) -> None:
    """The checkpoint is locked for the duration of a run: a second run on it is refused."""
    path = tmp_path / "c.npz"
    with checkpoint_lock(path), pytest.raises(gb_pin.InvalidArgumentError, match="another run"):
        gb_pin.babble("planar5", movements=10, checkpoint=path)
    gb_pin.babble("planar5", movements=10, checkpoint=path)  # free again
    assert path.exists() and not (tmp_path / ".c.npz.lock").exists()


def test_sigma_zero_warns_that_nothing_is_explored() -> None:
    """babble(sigma=0) runs, with a clear warning (the CLI refuses --sigma 0)."""
    with pytest.warns(gb_pin.GbPinWarning, match="no exploration"):
        gb_pin.babble("planar5", movements=5, sigma=0)


def test_a_failing_checkpoint_write_moves_to_a_fallback(tmp_path: Path, monkeypatch: Any) -> None:
    """A checkpoint write that fails mid-run (disk full) goes to a fallback file, with a warning."""
    from gb_pin.runs import checkpoint as module

    monkeypatch.chdir(tmp_path)
    real = module.write_checkpoint
    calls: list[str] = []

    def flaky(path: Any, state: Any, info: Any) -> None:
        calls.append(os.fspath(path))
        if len(calls) == 1:
            raise OSError("No space left on device")
        real(path, state, info)

    monkeypatch.setattr(module, "write_checkpoint", flaky)
    (tmp_path / "out").mkdir()
    with pytest.warns(gb_pin.GbPinWarning, match="from now on"):
        gb_pin.babble("planar5", movements=30, checkpoint=tmp_path / "out" / "c.npz", checkpoint_every=10)
    assert (tmp_path / "c.npz").exists() and not (tmp_path / "out" / "c.npz").exists()
