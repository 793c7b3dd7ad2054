"""Tests of gb_pin.robot.models: our loader of example-robot-data robots and URDF files.

example-robot-data 6.x ships robot files but no Python loader; these tests walk the whole registry
(robots are data: every entry must load) and check the errors a user meets with bad files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from gb_pin import InvalidArgumentError, UnknownRobotError
from gb_pin.exceptions import GbPinError
from gb_pin.robot.models import (
    DESCRIPTIONS,
    build_visual_model,
    describe,
    example_robot_data_dir,
    load_example_robot,
    load_urdf_model,
)

DATA = Path(__file__).parent / "data"


def test_example_robot_data_directory_is_found() -> None:
    """The installed package's robots directory holds the robots' folders."""
    root = example_robot_data_dir()
    assert root.is_dir()
    assert (root / "talos_data").is_dir()
    assert root.parts[-3:] == ("share", "example-robot-data", "robots")


@pytest.mark.parametrize("name", sorted(DESCRIPTIONS))
def test_every_registry_entry_loads(name: str) -> None:
    """Every entry builds a model; mobile ones get a free-flyer root; SRDF configurations have nq entries."""
    model, entry, urdf = load_example_robot(name)
    assert entry.name == name
    assert urdf.is_file()
    assert model.njoints > 1
    first = model.joints[1].shortname()
    assert (first == "JointModelFreeFlyer") == entry.floating_base
    refs = {c.key(): np.asarray(c.data()) for c in model.referenceConfigurations}
    if entry.srdf is not None:
        assert refs, f"{entry.srdf} gave no reference configuration"
    for q in refs.values():
        assert q.shape == (model.nq,)


def test_humanoid_reference_postures() -> None:
    """TALOS, Romeo and iCub carry half_sitting; the base stands above the ground."""
    for name in ("talos", "romeo", "icub"):
        model, _, _ = load_example_robot(name)
        refs = {c.key(): np.asarray(c.data()) for c in model.referenceConfigurations}
        assert "half_sitting" in refs
        assert refs["half_sitting"].shape == (model.nq,)
    model, _, _ = load_example_robot("talos")
    half_sitting = {c.key(): np.asarray(c.data()) for c in model.referenceConfigurations}["half_sitting"]
    assert 0.9 < half_sitting[2] < 1.1  # base height [m]


def test_unknown_robot_lists_closest_names() -> None:
    """An unknown name raises UnknownRobotError naming it and the closest registry names."""
    with pytest.raises(UnknownRobotError, match=r"'tallos'.*closest: talos"):
        describe("tallos")
    with pytest.raises(UnknownRobotError, match="valid:"):
        describe(42)  # type: ignore[arg-type]


def test_missing_and_malformed_files(tmp_path: Path) -> None:
    """Missing or malformed URDF/SRDF raise InvalidArgumentError naming the file."""
    with pytest.raises(InvalidArgumentError, match="does not exist"):
        load_urdf_model(tmp_path / "nope.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    with pytest.raises(InvalidArgumentError, match=r"malformed URDF file .*bad\.urdf"):
        load_urdf_model(bad)
    jointless = tmp_path / "one_link.urdf"
    jointless.write_text("<robot name='x'><link name='a'/></robot>")
    with pytest.raises(InvalidArgumentError, match="no joint"):
        load_urdf_model(jointless)
    with pytest.raises(InvalidArgumentError, match=r"SRDF file .* does not exist"):
        load_urdf_model(DATA / "small_arm.urdf", srdf=tmp_path / "nope.srdf")
    bad_srdf = tmp_path / "bad.srdf"
    bad_srdf.write_text(
        "<robot name='small_arm'><group_state name='x' group='arm'><joint name='j1' value='a'/>"
    )
    with pytest.raises(InvalidArgumentError, match="malformed SRDF"):
        load_urdf_model(DATA / "small_arm.urdf", srdf=bad_srdf)


def test_urdf_model_with_srdf_and_floating_base() -> None:
    """The test arm loads with its 'ready' configuration; floating_base adds a free flyer (nq + 7)."""
    model = load_urdf_model(DATA / "small_arm.urdf", srdf=DATA / "small_arm.srdf")
    assert list(model.names)[1:] == ["j1", "j2", "j3", "j4"]
    assert model.nq == 5  # j2 is continuous: (cos, sin)
    refs = {c.key(): np.asarray(c.data()) for c in model.referenceConfigurations}
    np.testing.assert_allclose(refs["ready"], [0.3, np.cos(-0.5), np.sin(-0.5), 0.05, 1.0], atol=1e-15)
    mobile = load_urdf_model(DATA / "small_arm.urdf", floating_base=True)
    assert mobile.joints[1].shortname() == "JointModelFreeFlyer"
    assert mobile.nq == 12


def test_visual_model_on_demand() -> None:
    """The visual geometry is built only when asked, one object per <visual> of the URDF."""
    model = load_urdf_model(DATA / "small_arm.urdf")
    visual = build_visual_model(model, DATA / "small_arm.urdf")
    assert isinstance(visual, pin.GeometryModel)
    assert visual.ngeoms == 5


def test_visual_model_with_missing_meshes_is_a_gb_pin_error(tmp_path: Path) -> None:
    """A URDF whose mesh file is missing: GbPinError naming the URDF, not a raw Pinocchio error."""
    urdf = tmp_path / "meshy.urdf"
    urdf.write_text(
        "<robot name='m'><link name='a'/><link name='b'><visual><geometry>"
        "<mesh filename='package://nowhere/missing.stl'/></geometry></visual></link>"
        "<joint name='j' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
        "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>"
    )
    model = load_urdf_model(urdf)
    with pytest.raises(GbPinError, match=r"meshy\.urdf"):
        build_visual_model(model, urdf, package_dirs=[str(tmp_path)])
