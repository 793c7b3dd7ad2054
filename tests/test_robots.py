"""Tests of gb_pin.robot.presets: the planar presets of paper Sec. III and the preset registry."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from gb_pin import (
    InvalidArgumentError,
    KinematicTarget,
    RobotPreset,
    UnknownRobotError,
    grid_targets,
    load_robot,
    planar_chain,
    planar_home,
    robots,
)
from gb_pin.learn.config import NAMES
from gb_pin.robot.presets import _load_preset, _read_preset, format_presets

EPS = np.finfo(float).eps


def paper_grid() -> np.ndarray:
    """The 5 x 5 target grid over x in [0.3, 0.8], y in [-0.4, 0.4] [m], x varying slowest."""
    return np.array([[x, y] for x in np.linspace(0.3, 0.8, 5) for y in np.linspace(-0.4, 0.4, 5)])


@pytest.mark.parametrize("m", [2, 5, 20, 50])
def test_load_planar(m: int) -> None:
    """load_robot("planarN"): N joints, frame tip, axes xy, the paper's home and the 5 x 5 grid."""
    target = load_robot(f"planar{m}")
    assert isinstance(target, KinematicTarget)
    assert target.n_joints == m
    assert target.frame == "tip"
    assert target.axes == "xy"
    assert target.n_task == 2
    assert target.name == f"planar{m}"
    np.testing.assert_array_equal(target.home, planar_home(m))
    assert target.targets is not None
    np.testing.assert_allclose(target.targets, paper_grid(), rtol=0, atol=1e-15)


def test_planar5_home_is_paper_posture() -> None:
    """planar5 home = [-pi/3, pi/6, pi/6, pi/6, pi/6] (paper Sec. III-A)."""
    np.testing.assert_allclose(
        planar_home(5), [-math.pi / 3, math.pi / 6, math.pi / 6, math.pi / 6, math.pi / 6], rtol=1e-15
    )


@pytest.mark.parametrize("m", [2, 3, 5, 10, 20, 50])
def test_planar_home_has_effector_at_zero_height(m: int) -> None:
    """q_1 = -pi/3, q_i = 2 pi / (3 (m - 1)): absolute angles run symmetrically from -pi/3 to pi/3, so y = 0.

    y is a sum of m terms of size 1/m that cancel pairwise; rounding leaves a few eps.
    """
    home = planar_home(m)
    assert home[0] == pytest.approx(-math.pi / 3, rel=1e-15)
    np.testing.assert_allclose(home[1:], 2 * math.pi / (3 * (m - 1)), rtol=1e-15)
    np.testing.assert_allclose(np.cumsum(home)[-1], math.pi / 3, rtol=1e-14)
    target = load_robot(f"planar{m}")
    x = target.home_position
    assert abs(x[1]) < 10 * m * EPS
    assert 0.0 < x[0] < 1.0  # bent arm of total length 1 m reaching forward


def test_planar_chain_is_pinocchio_model() -> None:
    """planar_chain(m) is a pin.Model with m revolute z-joints, equal segments and the "tip" frame."""
    for m in (1, 3, 7):
        model = planar_chain(m, total_length=2.0)
        assert isinstance(model, pin.Model)
        assert (model.njoints, model.nq, model.nv) == (m + 1, m, m)
        assert [j.shortname() for j in model.joints[1:]] == ["JointModelRZ"] * m
        assert list(model.names)[1:] == [f"joint{i + 1}" for i in range(m)]
        assert model.existFrame("tip")
        data = model.createData()
        pin.framesForwardKinematics(model, data, np.zeros(m))
        # Stretched along x: the tip at total_length; joint i at (i - 1) segments.
        np.testing.assert_allclose(data.oMf[model.getFrameId("tip")].translation, [2.0, 0, 0], atol=1e-15)
        for i in range(1, m + 1):
            np.testing.assert_allclose(data.oMi[i].translation, [2.0 * (i - 1) / m, 0, 0], atol=1e-15)


@pytest.mark.parametrize("bad", [0, -1, 2.0, True])
def test_planar_chain_rejects_bad_m(bad: object) -> None:
    """m must be a positive integer."""
    with pytest.raises(InvalidArgumentError):
        planar_chain(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("name", ["planar1", "planar0", "planar-3", "plnar5", "ur10_unknown", "", "Planar5"])
def test_unknown_robot_names(name: str) -> None:
    """Invalid names raise UnknownRobotError (a ValueError) naming the value and the planarN preset."""
    with pytest.raises(UnknownRobotError) as info:
        load_robot(name)
    assert isinstance(info.value, ValueError)
    message = str(info.value)
    assert repr(name) in message
    assert "planarN" in message


def test_non_string_robot_name_lists_presets() -> None:
    """load_robot(5) raises UnknownRobotError naming the value and the valid presets."""
    with pytest.raises(UnknownRobotError, match=r"5.*planarN"):
        load_robot(5)  # type: ignore[arg-type]


def test_non_string_robot_name_raises() -> None:
    """load_robot(5) raises UnknownRobotError (a ValueError) naming the value."""
    with pytest.raises(UnknownRobotError, match="5"):
        load_robot(5)  # type: ignore[arg-type]


def test_close_name_is_suggested() -> None:
    """A misspelt preset name suggests the closest valid one."""
    with pytest.raises(UnknownRobotError, match="did you mean planar5"):
        load_robot("plnar5")


def test_robots_lists_presets() -> None:
    """robots() lists the presets sorted by name, the planar family once as planarN."""
    presets = robots()
    assert presets
    assert all(isinstance(p, RobotPreset) for p in presets)
    assert [p.name for p in presets] == sorted(p.name for p in presets)
    planar = [p for p in presets if p.pattern == "planarN"]
    assert len(planar) == 1
    assert planar[0].frame == "tip"
    assert planar[0].axes == "xy"
    np.testing.assert_allclose(planar[0].targets, paper_grid(), rtol=0, atol=1e-15)


def test_every_preset_loads() -> None:
    """Every preset in the registry loads (families with N = 5) and its targets match its axes."""
    for preset in robots():
        name = preset.pattern.replace("N", "5") if preset.source == "planar" else preset.name
        target = load_robot(name)
        assert target.frame == preset.frame
        assert target.axes == preset.axes
        assert target.targets is not None and target.targets.shape[1] == target.n_task
        assert np.all(target.clip(target.home) == target.home)


def test_grid_targets() -> None:
    """grid_targets makes a regular grid, first axis slowest; a 1-point axis sits mid-way."""
    np.testing.assert_allclose(grid_targets([0.3, -0.4], [0.8, 0.4], [5, 5]), paper_grid(), atol=1e-15)
    np.testing.assert_array_equal(grid_targets([0.0, 1.0], [2.0, 3.0], [1, 2]), [[1.0, 1.0], [1.0, 3.0]])
    with pytest.raises(InvalidArgumentError):
        grid_targets([0.0], [1.0, 2.0], [2, 2])
    with pytest.raises(InvalidArgumentError):
        grid_targets([0.0, 0.0], [1.0, 1.0], [0, 2])


# -- presets as data -----------------------------------------------------------------------------

DATA = Path(__file__).parent / "data"

URDF_PRESET = """
name = "small"
description = "the test arm"
kind = "arm"
source = "urdf"
urdf = "{urdf}"
srdf = "{srdf}"
frame = "tool"
joints = ["j1", "j2", "j3", "j4"]
home = "ready"
axes = "xyz"
[targets]
auto = true
shape = [2, 2, 2]
[learner]
radius = 0.05
"""


def test_close_preset_names_are_suggested() -> None:
    """A misspelt spatial preset suggests the closest preset names."""
    with pytest.raises(UnknownRobotError, match=r"did you mean talos_left_arm"):
        load_robot("talos_left")
    with pytest.raises(UnknownRobotError, match=r"'pnada'.*did you mean panda"):
        load_robot("pnada")


def test_preset_listing() -> None:
    """format_presets: a header and one row per preset with name, DOF, axes, frame, source, targets."""
    lines = format_presets().splitlines()
    assert lines[0].split() == ["name", "DOF", "axes", "frame", "source", "targets", "kind"]
    rows = {line.split()[0]: line.split() for line in lines[1:]}
    assert len(rows) == len(robots()) >= 9
    assert rows["planarN"][1:6] == ["N", "xy", "tip", "planar", "25"]
    assert rows["talos_left_arm"][1:6] == ["7", "xyz", "gripper_left_base_link", "erd:talos", "27"]
    assert rows["talos_torso_left_arm"][1] == "9"


def test_cli_robots_prints_the_table(capsys: pytest.CaptureFixture[str]) -> None:
    """`gb-pin robots` prints the preset table and exits 0."""
    from gb_pin.cli import main

    assert main(["robots"]) == 0
    out = capsys.readouterr().out
    assert out.strip() == format_presets()


def test_urdf_preset_loads_with_auto_targets() -> None:
    """A preset of source "urdf" (paths absolute or relative to robots/) loads; auto targets resolve."""
    text = URDF_PRESET.format(urdf=DATA / "small_arm.urdf", srdf=DATA / "small_arm.srdf")
    preset = _read_preset(text, "small.toml")
    assert (preset.source, preset.origin, preset.dof, preset.n_targets) == (
        "urdf",
        "urdf:small_arm.urdf",
        "4",
        8,
    )
    assert preset.targets is None and preset.learner == {"radius": 0.05}
    target = _load_preset(preset, None, "small")
    np.testing.assert_allclose(target.home, [0.3, -0.5, 0.05, 1.0], atol=1e-15)
    assert target.targets is not None and target.targets.shape == (8, 3)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (('source = "urdf"', 'source = "mesh"'), "source must be one of"),
        (('kind = "arm"', 'kind = "arm"\ncolour = "red"'), r"unknown keys \['colour'\]"),
        (('frame = "tool"\n', ""), "frame"),
        (
            ("auto = true\nshape = [2, 2, 2]", "lower = [0, 0]\nupper = [1, 1]\nshape = [2, 2]"),
            "axes 'xyz' need 3",
        ),
        (("auto = true\nshape = [2, 2, 2]", "spacing = 0.1"), r"\[targets\] must be"),
        (('home = "ready"', "home = [0.1, 0.2]"), "home has 2 values for 4 joints"),
        (("radius = 0.05", "radius = 0.05\nalpha = 1"), r"unknown learner keys \['alpha'\]"),
        (("radius = 0.05", "radius = -0.05"), r"\[learner\] radius must be a positive .*got -0\.05"),
        (("radius = 0.05", "path_length = 2.5"), r"\[learner\] path_length must be an integer .*got 2\.5"),
        (("radius = 0.05", "p_home = 1.5"), r"\[learner\] p_home must be a probability .*got 1\.5"),
        (("[learner]", "[learner"), "malformed robot preset"),
    ],
)
def test_malformed_presets_raise(change: tuple[str, str], message: str) -> None:
    """A broken preset file raises InvalidArgumentError naming the file and the problem."""
    text = URDF_PRESET.format(urdf=DATA / "small_arm.urdf", srdf=DATA / "small_arm.srdf")
    assert change[0] in text
    with pytest.raises(InvalidArgumentError, match=message) as info:
        _read_preset(text.replace(change[0], change[1]), "broken.toml")
    assert "broken.toml" in str(info.value)


def test_preset_learner_keys_are_the_hyperparameter_table() -> None:
    """[learner] tables take exactly the names of gb_pin.learn.config.NAMES; values come back validated."""
    values = (0.2, 0.01, 0.001, 0.05, 30, 0.2, 4.0)
    table = "\n".join(f"{k} = {v}" for k, v in zip(NAMES, values, strict=True))
    text = URDF_PRESET.format(urdf=DATA / "small_arm.urdf", srdf=DATA / "small_arm.srdf")
    preset = _read_preset(text.replace("radius = 0.05", table), "all.toml")
    assert list(preset.learner) == list(NAMES)
    assert preset.learner["path_length"] == 30 and isinstance(preset.learner["path_length"], int)
    for p in robots():
        assert set(p.learner) <= set(NAMES)
