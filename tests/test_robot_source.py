"""Files record a robot that is no preset; load_result, show, plot and resume rebuild it (robot_source)."""

from __future__ import annotations

import io
import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.robot import spec as robot_spec
from gb_pin.runs.checkpoint import read_checkpoint

SMALL_URDF = Path(__file__).parent / "data" / "small_arm.urdf"
ARM = ["--frame", "tool", "--joints", "j1,j2,j4", "--home", "0.1,0.2,0.3"]
ROMEO = [
    "--robot",
    "erd:romeo",
    "--frame",
    "LHand",
    "--joints",
    "LShoulderPitch,LShoulderYaw,LElbowRoll,LElbowYaw",
]


def _header(path: Path) -> dict[str, Any]:
    with np.load(path, allow_pickle=False) as f:
        return dict(json.loads(str(f["meta"])))


def _rewrite(path: Path, out: Path, **changes: Any) -> Path:
    """A copy of the .npz ``path`` with header entries replaced.

    A file that carries a digest (a checkpoint) gets a matching one, as a forger would write it: what
    is tested is the check behind the digest.
    """
    from gb_pin.runs.archive import DIGEST, content_digest

    with np.load(path, allow_pickle=False) as f:
        arrays = {k: f[k] for k in f.files}
    meta = {**json.loads(str(arrays["meta"])), **changes}
    if DIGEST in meta:
        meta[DIGEST] = content_digest({k: v for k, v in arrays.items() if k != "meta"}, meta)
    arrays["meta"] = np.array(json.dumps(meta))
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    out.write_bytes(buffer.getvalue())
    return out


@pytest.fixture(scope="module")
def arm_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(a copy of the small arm's URDF, the result of `gb-pin babble --robot COPY ...` on it)."""
    tmp = tmp_path_factory.mktemp("arm")
    urdf = tmp / "arm.urdf"
    shutil.copy(SMALL_URDF, urdf)
    out = tmp / "arm.npz"
    assert (
        main(["babble", "--robot", str(urdf), *ARM, "--movements", "30", "--quiet", "--out", str(out)]) == 0
    )
    return urdf, out


def test_a_urdf_run_round_trips_with_no_robot_options(arm_run: tuple[Path, Path], tmp_path: Path) -> None:
    """babble --robot FILE.urdf -> --out: load_result, show --html and plot rebuild it from the file alone."""
    urdf, out = arm_run
    source = _header(out)["robot_source"]
    assert source["kind"] == "urdf" and source["path"] == str(urdf.resolve())
    assert source["joints"] == ["j1", "j2", "j4"] and source["home"] == [0.1, 0.2, 0.3]
    res = gb_pin.load_result(out)
    assert res.robot is None and res.target.joints == ("j1", "j2", "j4") and res.target.frame == "tool"
    np.testing.assert_array_equal(res.target.home, [0.1, 0.2, 0.3])
    assert main(["show", str(out), "--html", str(tmp_path / "arm.html")]) == 0
    assert main(["plot", str(out), "-o", str(tmp_path / "arm.png")]) == 0
    assert (tmp_path / "arm.html").is_file() and (tmp_path / "arm.png").is_file()


def test_a_python_built_urdf_target_is_recorded_too(tmp_path: Path) -> None:
    """KinematicTarget.from_urdf in Python, babble, save: load_result rebuilds the same kinematics."""
    arm = gb_pin.KinematicTarget.from_urdf(
        SMALL_URDF, "tool", ["j1", "j2"], home=[0.2, 0.5], axes="xy", name="arm"
    )
    gb_pin.babble(arm, movements=5, seed=1).save(tmp_path / "r.npz")
    res = gb_pin.load_result(tmp_path / "r.npz")
    assert (res.target.name, res.target.axes, res.target.joints) == ("arm", "xy", ("j1", "j2"))
    np.testing.assert_array_equal(res.target.home, arm.home)


def test_an_example_robot_data_run_round_trips_and_resumes(tmp_path: Path, capsys: Any) -> None:
    """babble --robot erd:romeo: the file records it; load_result, show, plot and --resume rebuild it."""
    out, ck = tmp_path / "romeo.npz", tmp_path / "ck.npz"
    assert (
        main(["babble", *ROMEO, "--movements", "10", "--quiet", "--out", str(out), "--checkpoint", str(ck)])
        == 0
    )
    expected = gb_pin.load_result(out)
    assert _header(out)["robot_source"]["kind"] == "erd" and _header(out)["robot_source"]["robot"] == "romeo"
    assert expected.target.n_joints == 4 and expected.target.frame == "LHand"
    assert main(["show", str(out), "--html", str(tmp_path / "romeo.html")]) == 0
    assert main(["plot", str(out)]) == 0 and (tmp_path / "romeo.png").is_file()
    assert read_checkpoint(ck)[1].source == _header(out)["robot_source"]
    assert gb_pin.resume(ck).movements == 10  # the checkpoint's robot, rebuilt
    capsys.readouterr()
    assert main(["babble", "--resume", str(ck), "--quiet"]) == 0
    assert "romeo (4 joints" in capsys.readouterr().out


def test_a_moved_or_edited_urdf_gets_a_message_naming_it_and_the_options(
    arm_run: tuple[Path, Path], tmp_path: Path, capsys: Any
) -> None:
    """The URDF moved: ResultFileError with the recorded path and the --robot options; passing them works."""
    urdf, out = arm_run
    moved = tmp_path / "elsewhere.urdf"
    shutil.copy(urdf, moved)
    gone = _rewrite(
        out, tmp_path / "gone.npz", robot_source={**_header(out)["robot_source"], "path": "/no/arm.urdf"}
    )
    with pytest.raises(
        ResultFileError, match=r"/no/arm\.urdf.*--robot /no/arm\.urdf --frame tool --joints j1,j2,j4"
    ):
        gb_pin.load_result(gone)
    assert main(["show", str(gone), "--html", str(tmp_path / "x.html")]) == 2
    assert "pass it: --robot /no/arm.urdf" in capsys.readouterr().err
    model = ["--robot", str(moved), *ARM]
    assert main(["plot", str(gone), "-o", str(tmp_path / "gone.png"), *model]) == 0
    edited = tmp_path / "edited.urdf"
    edited.write_text(urdf.read_text().replace('xyz="0 0 0.3"', 'xyz="0 0 0.35"', 1))
    assert edited.read_text() != urdf.read_text()
    changed = _rewrite(
        out, tmp_path / "c.npz", robot_source={**_header(out)["robot_source"], "path": str(edited)}
    )
    with pytest.raises(ResultFileError, match="kinematics differ"):
        gb_pin.load_result(changed)


def test_a_module_robot_is_recorded_but_never_imported_from_a_file(tmp_path: Path, capsys: Any) -> None:
    """MODULE:NAME: the file records the spec; without --robot it is refused (not imported); --robot works.

    ``plot`` needs no robot (the curves are in the file): it plots without --robot, importing nothing.
    """
    marker = tmp_path / "imported.txt"
    module = tmp_path / "my_arm.py"
    module.write_text(
        "import gb_pin\n"
        f"open({str(marker)!r}, 'a').write('x')\n"
        f"robot = gb_pin.KinematicTarget.from_urdf({str(SMALL_URDF)!r}, 'tool', ['j1', 'j2'],\n"
        "                                          home=[0.2, 0.5], axes='xy')\n"
    )
    spec = f"{module}:robot"
    out = tmp_path / "m.npz"
    assert main(["babble", "--robot", spec, "--movements", "5", "--quiet", "--out", str(out)]) == 0
    assert _header(out)["robot_source"] == {"kind": "module", "spec": spec}
    robot_spec._LOADED.clear()  # a new process: nothing loaded
    imports = marker.read_text()
    with pytest.raises(ResultFileError, match=r"does not import.*--robot " + str(module)):
        gb_pin.load_result(out)
    assert main(["show", str(out), "--html", str(tmp_path / "m.html")]) == 2
    assert "--robot" in capsys.readouterr().err
    assert main(["plot", str(out), "-o", str(tmp_path / "m.png")]) == 0  # curves need no robot
    assert marker.read_text() == imports  # the module was not run
    assert main(["plot", str(out), "-o", str(tmp_path / "m2.png"), "--robot", spec]) == 0  # the user's choice
    robot_spec._LOADED.clear()


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"kind": "python"}, "kind"),
        ({"path": "relative/arm.urdf"}, "absolute path"),
        ({"path": "x" * 10_000}, "path must be"),
        ({"joints": "j1,j2,j4"}, "joints must be"),
        ({"joints": ["j1", "j1", "j4"]}, "distinct"),
        ({"home": [0.1, 0.2]}, "home must be 3 finite numbers"),
        ({"home": [0.1, True, 0.3]}, "home must be"),
        ({"axes": "xyzw"}, "axes"),
        ({"chain_sha256": "0" * 64}, "kinematics differ"),
        ({"chain_sha256": 5}, "chain_sha256"),
        ({"code": "import os"}, "keys"),
        ({"frame": None}, "frame must be"),
        ({"name": "arm\x1b[2J"}, "name must be"),
    ],
)
def test_a_tampered_robot_source_is_a_clear_error(
    arm_run: tuple[Path, Path], tmp_path: Path, change: dict[str, Any], needle: str
) -> None:
    """Each wrong entry of robot_source: ResultFileError naming it, before any model is built."""
    out = arm_run[1]
    bad = _rewrite(out, tmp_path / "bad.npz", robot_source={**_header(out)["robot_source"], **change})
    with pytest.raises(ResultFileError, match=needle):
        gb_pin.load_result(bad)


def test_a_tampered_checkpoint_source_is_refused(tmp_path: Path) -> None:
    """A checkpoint's robot_source is validated on read; a checkpoint recording none asks for robot=."""
    arm = gb_pin.KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j2"], home=[0.2, 0.5], axes="xy")
    gb_pin.babble(arm, movements=4, seed=0, checkpoint=tmp_path / "ck.npz")
    source = read_checkpoint(tmp_path / "ck.npz")[1].source
    assert source is not None and source["kind"] == "urdf"
    bad = _rewrite(tmp_path / "ck.npz", tmp_path / "bad.npz", robot_source={**source, "home": "up"})
    with pytest.raises(ResultFileError, match="home must be"):
        gb_pin.resume(bad)
    none = _rewrite(tmp_path / "ck.npz", tmp_path / "none.npz", robot_source=None)
    with pytest.raises(InvalidArgumentError, match="pass it as robot="):
        gb_pin.resume(none)


def test_a_robot_whose_source_a_reader_would_refuse_is_not_recorded(tmp_path: Path) -> None:
    """A name with a control character: no robot_source is written, and the file loads with target=."""
    arm = gb_pin.KinematicTarget.from_urdf(
        SMALL_URDF, "tool", ["j1", "j2"], home=[0.2, 0.5], axes="xy", name="arm\n2"
    )
    gb_pin.babble(arm, movements=3, seed=0).save(tmp_path / "r.npz")
    assert "robot_source" not in _header(tmp_path / "r.npz")
    assert gb_pin.load_result(tmp_path / "r.npz", target=arm).target is arm
    with pytest.raises(ResultFileError, match="pass it"):
        gb_pin.load_result(tmp_path / "r.npz")
