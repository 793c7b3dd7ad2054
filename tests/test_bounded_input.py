"""Reliability, third round (issue 24): every reader bounded, loose arguments refused, wrong files caught.

The classes of problem, each with its unit tests here (tests/test_fuzz_files.py probes them all
through every reader): regular files only and sizes checked before allocation (1), integers
beyond int64 and arguments a task would ignore (2), files that load but are wrong (3),
``--robot MODULE:NAME`` (6), robot descriptions (8), messages (9).
"""

from __future__ import annotations

import io
import json
import os
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from fuzz_probes import rewrite_npz

import gb_pin
from gb_pin import _points, _reading
from gb_pin._names import listing, printable
from gb_pin._validation import INT64_MAX, positive_int
from gb_pin.exceptions import InvalidArgumentError, ResultFileError

DATA = Path(__file__).resolve().parent / "data"


# -- 1. regular files only, sizes checked first -------------------------------------------------
@pytest.mark.parametrize("kind", ["fifo", "zero", "dir", "link_fifo", "link_zero", "link_dir"])
def test_open_regular_refuses_special_files_at_once(tmp_path: Path, kind: str) -> None:
    """A FIFO (which would block the open), /dev/zero (size 0, endless), a directory, or a link to one."""
    targets = {"fifo": tmp_path / "f", "zero": Path("/dev/zero"), "dir": tmp_path / "d"}
    os.mkfifo(targets["fifo"])
    targets["dir"].mkdir()
    path = targets[kind.removeprefix("link_")]
    if kind.startswith("link_"):
        (tmp_path / "l").symlink_to(path)
        path = tmp_path / "l"
    start = time.perf_counter()
    with pytest.raises(ResultFileError, match="not a result file"):
        _reading.open_regular(path, "x", "result file", 100, ResultFileError)
    assert time.perf_counter() - start < 1.0


def test_open_regular_checks_the_size_and_names_a_missing_file(tmp_path: Path) -> None:
    (tmp_path / "a").write_bytes(b"x" * 101)
    with pytest.raises(ResultFileError, match=r"101 bytes.*at most 100"):
        _reading.open_regular(tmp_path / "a", "a", "file", 100, ResultFileError)
    with pytest.raises(InvalidArgumentError, match="no such point file"):
        _reading.open_regular(tmp_path / "b", "b", "point file", 100, InvalidArgumentError)
    assert _reading.read_bytes(tmp_path / "a", "a", "file", 101, ResultFileError) == b"x" * 101


def _npy(shape: Any, descr: str = "<f8", data: bytes = b"") -> bytes:
    out = io.BytesIO()
    header = "{" + f"'descr': {descr!r}, 'fortran_order': False, 'shape': {shape}, " + "}"
    out.write(b"\x93NUMPY\x01\x00" + len(header.ljust(118) + "\n").to_bytes(2, "little"))
    out.write((header.ljust(118) + "\n").encode("latin-1"))
    return out.getvalue() + data


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (_npy("(10**12, 3)"), "unreadable"),  # numpy's literal parser takes no expressions
        (_npy((10**12, 3)), "declares shape"),
        (_npy((-5, 2)), "negative"),
        (_npy((3,), "|O"), "holds object"),
        (_npy((3,), "V0"), "holds"),
        (_npy((3,), data=b"\0" * 8), "declares shape"),
        (_npy((3,))[:40], "unreadable .npy header"),  # numpy: tokenize's TokenError
    ],
)
def test_read_npy_checks_the_header_before_allocating(tmp_path: Path, content: bytes, needle: str) -> None:
    path = tmp_path / "p.npy"
    path.write_bytes(content)
    with open(path, "rb") as fh, pytest.raises(ResultFileError, match=needle):
        _reading.read_npy(fh, len(content), "p.npy", 1 << 20, ResultFileError)


def test_read_npy_reads_what_numpy_writes(tmp_path: Path) -> None:
    for arr in (
        np.arange(12.0).reshape(3, 4),
        np.asfortranarray(np.arange(6).reshape(2, 3)),
        np.array("text"),
    ):
        np.save(tmp_path / "a.npy", arr)
        with open(tmp_path / "a.npy", "rb") as fh:
            got = _reading.read_npy(fh, (tmp_path / "a.npy").stat().st_size, "a", 1 << 20, ResultFileError)
        np.testing.assert_array_equal(got, arr)


def test_point_files_are_read_line_by_line_within_their_limits(tmp_path: Path, monkeypatch: Any) -> None:
    """CSV: comments, blank lines, an axes header; too many points refused while read; .npy by its header."""
    path = tmp_path / "p.csv"
    path.write_text("x,y\n# comment\n0.5, 0.1  # trailing\n\n0.6,-0.2\n")
    np.testing.assert_array_equal(_points.read_points(path, axes="xy"), [[0.5, 0.1], [0.6, -0.2]])
    with pytest.raises(InvalidArgumentError, match=r"p\.csv:1"):
        _points.read_points(path)  # no axes known: "x,y" is not a point
    monkeypatch.setattr(_points, "MAX_POINTS", 1)
    with pytest.raises(InvalidArgumentError, match="more than 1 points"):
        _points.read_points(path, axes="xy")
    np.save(tmp_path / "p.npy", np.zeros((2, 2)))
    with pytest.raises(InvalidArgumentError, match="1 <= N <= 1"):
        _points.read_points(tmp_path / "p.npy")
    (tmp_path / "q.csv").write_text("0.5,nan\n")
    with pytest.raises(InvalidArgumentError, match=r"q\.csv:1: 'nan' is not a finite number"):
        _points.read_points(tmp_path / "q.csv")


def test_a_zip_directory_declaring_thousands_of_members_is_refused_before_zipfile(tmp_path: Path) -> None:
    count = (65535).to_bytes(2, "little")
    (tmp_path / "r.npz").write_bytes(
        b"PK\x05\x06" + bytes(4) + count * 2 + (10**8).to_bytes(4, "little") + bytes(6)
    )
    with pytest.raises(ResultFileError, match="65535 members"):
        gb_pin.load_result(tmp_path / "r.npz")


def test_json_documents_and_journals_have_their_own_limits(tmp_path: Path) -> None:
    from gb_pin.experiments._json import MAX_JSON_BYTES, read_lines

    with open(tmp_path / "t.json", "wb") as fh:
        fh.truncate(MAX_JSON_BYTES + 1)
    with pytest.raises(ResultFileError, match="at most"):
        gb_pin.TrialSet.load(tmp_path / "t.json")
    (tmp_path / "j").write_bytes(b"a\n" + b"x" * (17 << 20) + b"\nb")
    assert [(line, n) for line, n in read_lines(str(tmp_path / "j"), "journal")] == [
        (b"a\n", 2), (b"", (17 << 20) + 1), (b"b", 1)
    ]  # fmt: skip


def test_counts_that_would_allocate_are_refused_at_once() -> None:
    from gb_pin.experiments.execute import MAX_TRIALS
    from gb_pin.experiments.pool import max_workers

    start = time.perf_counter()
    with pytest.raises(InvalidArgumentError, match="trials"):
        gb_pin.run_trials("planar5", trials=10**9, workers=1)
    with pytest.raises(InvalidArgumentError, match=f"at most {MAX_TRIALS}"):
        gb_pin.run_sweep(robot="planar5", learning_rate=[0.1, 0.2], trials=MAX_TRIALS)
    with pytest.raises(InvalidArgumentError, match="workers"):
        gb_pin.run_trials("planar5", trials=2, workers=max_workers() + 1)
    with pytest.raises(InvalidArgumentError, match="MAX_CONDITIONS"):
        gb_pin.run_sweep(robot="planar5", learning_rate=[0.1] * 10**5)
    with pytest.raises(InvalidArgumentError, match="m must be"):
        gb_pin.planar_home(10**12)
    assert time.perf_counter() - start < 2.0


# -- 2. integers beyond int64, arguments a task ignores --------------------------------------------
def test_every_checked_integer_fits_int64() -> None:
    assert positive_int("n", np.int64(5)) == 5 and positive_int("n", INT64_MAX) == INT64_MAX
    with pytest.raises(InvalidArgumentError, match=r"2\*\*63 - 1"):
        positive_int("n", 2**70)
    for kwargs in (
        {"changes": {2**70: gb_pin.load_robot("planar5")}},
        {"schedule": [0, 2**70]},
        {"observe_every": 2**70},
        {"record": None, "goals": f"cyclic:start={2**70}"},
    ):
        with pytest.raises(InvalidArgumentError):
            gb_pin.babble("planar5", movements=5, **kwargs)
    with pytest.raises(InvalidArgumentError, match="every"):
        gb_pin.Recording(every=2**70)


def test_task_arguments_that_the_task_ignores_are_refused() -> None:
    def arm(**kw: Any) -> Any:
        home = [0.1, 0.2, 0.3]
        return gb_pin.KinematicTarget.from_urdf(
            DATA / "small_arm.urdf", "tool", ["j1", "j2", "j4"], home=home, **kw
        )

    with pytest.raises(InvalidArgumentError, match="pointing_axis='z' goes with task='pointing'"):
        arm(task="pose", pointing_axis="z")
    with pytest.raises(InvalidArgumentError, match="orientation_scale"):
        arm(orientation_scale=0.1)
    assert arm(task="pointing", pointing_axis="-z").n_task == 5  # 3 position, 2 direction rows


# -- 3. files that load but are wrong ---------------------------------------------------------------
def test_a_result_with_an_empty_history_is_refused_at_load(tmp_path: Path) -> None:
    gb_pin.babble("planar5", movements=5, seed=0).save(tmp_path / "r.npz")
    rewrite_npz(
        tmp_path / "r.npz",
        lambda a, m: a.update({k: a[k][:0] for k in ("movements", "error", "home_distance")}),
    )
    with pytest.raises(ResultFileError, match="history is empty"):
        gb_pin.load_result(tmp_path / "r.npz")


def test_a_0d_array_in_any_checkpoint_field_is_refused(tmp_path: Path) -> None:
    """A 0-d integer in place of each field (chain_task_axes raised IndexError)."""
    path = tmp_path / "c.npz"
    gb_pin.babble("planar5", movements=10, seed=0, checkpoint=path, checkpoint_every=5)
    with np.load(path) as f:
        keys = [k for k in f.files if k != "meta"]
    original = path.read_bytes()
    accepted = []
    for key in keys:  # each either refused (ResultFileError) or, where a 0-d value is right, resumed
        path.write_bytes(original)
        rewrite_npz(path, lambda a, m, k=key: a.update({k: np.array(3)}))
        try:
            gb_pin.resume(path)
            accepted.append(key)
        except ResultFileError:
            pass
    assert set(accepted) <= {"chain_frame_parent", "until_error", "max_joint_step"}, accepted  # 0-d in files


def test_trial_set_counts_must_be_whole_numbers_within_int64(tmp_path: Path) -> None:
    ts = gb_pin.run_trials("planar5", trials=2, movements=5, workers=1)
    raw = ts.to_json()
    for bad in ({"movements": [0, 1e20]}, {"movements": [0, 1.5]}, {"prototypes": [1.5, 2.0]},
                {"error": [["0.1"] * len(raw["movements"])] * 2}):  # fmt: skip
        (tmp_path / "t.json").write_text(json.dumps({**raw, **bad}))
        with pytest.raises(ResultFileError, match="malformed trials file"):
            gb_pin.TrialSet.load(tmp_path / "t.json")


def test_a_preset_that_is_not_utf8_is_the_preset_readers_error() -> None:
    from gb_pin.robot.presets import _read_preset

    with pytest.raises(InvalidArgumentError, match=r"malformed robot preset x\.toml: 'utf-8'"):
        _read_preset(b'name = "tal\xffos"', "x.toml")


def test_e0_zero_and_a_schedule_without_movement_0_have_no_ratio(tmp_path: Path) -> None:
    """Home reaches the only target: E_0 = 0, no 'inf%' and no division by zero in the figure."""
    pytest.importorskip("matplotlib")
    from gb_pin.learn.history import versus_initial

    arm = gb_pin.load_robot("planar5")
    res = gb_pin.babble("planar5", movements=10, seed=0, targets=[arm.forward(arm.home)])
    assert res.history.initial_error == 0.0
    assert versus_initial(res.error, 0.0) == "E_0 = 0 m: home reaches every target, no ratio to E_0"
    res.plot(tmp_path / "r.png")
    later = gb_pin.babble("planar5", movements=10, seed=0, schedule=[5, 10])
    assert np.isnan(later.history.initial_error) and "not recorded" in versus_initial(later.error, np.nan)
    later.plot(tmp_path / "later.png")
    assert versus_initial(0.015, 0.3) == "E_0 = 0.3000 m, 5.0% of E_0"  # the README's summary


# -- 6. --robot MODULE:NAME -------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("name", "needle"),
    [
        ("sys:exit", "standard library"),
        ("os:abort", "standard library"),
        ("numpy:zeros", "a built-in function"),
        ("active_count", "imported into"),
        ("needs", "a function taking arguments (q)"),
        ("number", "number() returned an object of type int"),
        ("raises", "raised RuntimeError"),
        ("Arm", "a class (Arm)"),
        ("VALUE", "an object of type int"),
    ],
)
def test_module_specs_call_only_robot_factories(tmp_path: Path, name: str, needle: str) -> None:
    from gb_pin.robot.spec import load_robot_spec

    (tmp_path / "mod.py").write_text(
        "from threading import active_count\nVALUE = 3\ndef needs(q):\n    return q\n"
        "def number():\n    return 5\ndef raises():\n    raise RuntimeError('x')\nclass Arm:\n    pass\n"
    )
    spec = name if ":" in name else f"{tmp_path / 'mod.py'}:{name}"
    with pytest.raises(InvalidArgumentError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        load_robot_spec(spec)


# -- 8. robot descriptions --------------------------------------------------------------------------
def test_urdf_text_parsing_builds_the_model_the_path_does() -> None:
    import pinocchio as pin

    from gb_pin.robot.models import load_urdf_model

    assert load_urdf_model(DATA / "small_arm.urdf") == pin.buildModelFromUrdf(str(DATA / "small_arm.urdf"))
    model = load_urdf_model(DATA / "small_arm.urdf", srdf=DATA / "small_arm.srdf")
    assert "ready" in model.referenceConfigurations


def test_a_urdf_that_is_not_utf8_loads_with_printable_names(tmp_path: Path) -> None:
    """pinocchio read such a file itself and gave names Python could not decode (UnicodeDecodeError)."""
    (tmp_path / "l.urdf").write_bytes((DATA / "small_arm.urdf").read_bytes().replace(b'"j2"', b'"j\xff2"'))
    arm = gb_pin.KinematicTarget.from_urdf(tmp_path / "l.urdf", "tool")
    assert arm.joints == ("j1", "j\xff2", "j3", "j4")


def test_negative_distances_in_files_are_refused_and_plots_take_any_history(tmp_path: Path) -> None:
    """E^X and D^home are distances: a file with negative ones is wrong; a history of zeros still plots."""
    import dataclasses

    pytest.importorskip("matplotlib")
    res = gb_pin.babble("planar5", movements=10, seed=0)
    res.save(tmp_path / "r.npz")
    rewrite_npz(tmp_path / "r.npz", lambda a, m: a.update(error=-a["error"]))
    with pytest.raises(ResultFileError, match="negative"):
        gb_pin.load_result(tmp_path / "r.npz")
    zeros = dataclasses.replace(res.history, error=np.zeros_like(res.history.error))
    dataclasses.replace(res, history=zeros).plot(tmp_path / "zeros.png")  # log axes need a positive value


def test_a_continuous_joint_about_an_unaligned_axis_is_read_as_pinocchio_does(tmp_path: Path) -> None:
    (tmp_path / "t.urdf").write_text(
        '<robot name="t"><link name="b"/><link name="l1"/><link name="tool"/>'
        '<joint name="j1" type="continuous"><parent link="b"/><child link="l1"/>'
        '<axis xyz="0.6 0.8 0"/></joint>'
        '<joint name="j2" type="continuous"><parent link="l1"/><child link="tool"/>'
        '<origin xyz="0.3 0 0.1"/><axis xyz="0 0.6 0.8"/></joint></robot>'
    )
    arm = gb_pin.KinematicTarget.from_urdf(tmp_path / "t.urdf", "tool", ["j1", "j2"], home=[0.3, 1.0])
    for q in np.random.default_rng(0).uniform(-3, 3, (50, 2)):
        np.testing.assert_allclose(arm.forward(q), arm.forward_pinocchio(q), atol=1e-12)


def test_names_with_escape_bytes_are_printed_escaped(tmp_path: Path) -> None:
    assert printable("a\x1b[31mb\x00\u202e") == "a\\x1b[31mb\\x00\\u202e"
    assert listing(["j\x1b1", "ok"]) == "j\\x1b1, ok"
    urdf = (DATA / "small_arm.urdf").read_text().replace('"j2"', '"j2\x1b[2J"')
    (tmp_path / "e.urdf").write_text(urdf)
    with pytest.raises(InvalidArgumentError) as caught:
        gb_pin.KinematicTarget.from_urdf(tmp_path / "e.urdf", "tool", ["j2[2J"])
    assert "\x1b" not in str(caught.value) and "j2\\x1b[2J" in str(caught.value)


# -- 9. messages -------------------------------------------------------------------------------------
@pytest.mark.slow  # one of the heaviest in CPU time (issue 35): not in -m 'not slow'
def test_a_compiled_forward_model_returning_nan_is_named_as_the_cause() -> None:
    from numba import njit

    @njit
    def kernel(q, x):  # type: ignore[no-untyped-def]
        x[0] = 0.5 * (np.cos(q[0]) + np.cos(q[0] + q[1]))
        x[1] = 0.5 * (np.sin(q[0]) + np.sin(q[0] + q[1])) if q[1] < 0.8 else np.nan

    arm = gb_pin.FunctionTarget.from_kernel(
        kernel, [0.3, 0.6], 2, lower=-3, upper=3, targets=[[0.5, 0.5], [0.7, 0.2]]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(gb_pin.DivergenceError, match="forward model returned the non-finite position"):
            gb_pin.babble(arm, movements=300, seed=0)
    with pytest.raises(gb_pin.DivergenceError, match=r"learning_rate=1000000\.0 too high"):
        gb_pin.babble("planar5", movements=50, seed=0, learning_rate=1e6)
