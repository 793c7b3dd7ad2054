"""Values that used to be taken silently wrong: complex numbers, SRDF states, inverted limits.

Before (main 995bb8d): complex forward-model outputs and complex IK targets lost their imaginary
part; an SRDF state naming a missing joint or holding nan became the home; a URDF whose lower
limit exceeds its upper was reported as "no home candidate has a reachable goal grid".
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gb_pin
import gb_pin.ik
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.robot.models import load_urdf_model

DATA = Path(__file__).resolve().parent / "data"
URDF = DATA / "small_arm.urdf"


def test_complex_forward_outputs_and_ik_targets_are_refused() -> None:
    with pytest.raises(InvalidArgumentError, match="complex"):
        gb_pin.FunctionTarget(lambda q: np.array([np.cos(q).sum(), np.sin(q).sum()]) + 0j, [0.3, 0.6])
    with pytest.raises(InvalidArgumentError, match="complex"):
        gb_pin.ik.solve("planar5", np.array([[0.3 + 1e-3j, 0.3]]), seed="home")
    result = gb_pin.babble("planar5", movements=20, seed=0)
    with pytest.raises(InvalidArgumentError, match="complex"):
        result.inverse(np.array([0.3 + 0j, 0.3]))


def _srdf(tmp: Path, joints: str) -> Path:
    path = tmp / "arm.srdf"
    path.write_text(
        f'<robot name="small_arm"><group_state name="ready" group="arm">{joints}</group_state></robot>'
    )
    return path


_ALL = '<joint name="j1" value="0.3"/><joint name="j2" value="-0.5"/><joint name="j3" value="0.05"/>'


def test_srdf_states_holding_nan_are_refused(tmp_path: Path) -> None:
    good = load_urdf_model(URDF, srdf=_srdf(tmp_path, '<joint name="j1" value="0.5"/>'))
    assert [e.key() for e in good.referenceConfigurations] == ["ready"]
    with pytest.raises(InvalidArgumentError, match="'j1' the value 'nan'"):
        load_urdf_model(URDF, srdf=_srdf(tmp_path, '<joint name="j1" value="nan"/>'))


def test_a_used_srdf_state_naming_a_missing_joint_and_leaving_a_chain_joint_unset_is_refused(
    tmp_path: Path,
) -> None:
    """A typo (j4x for j4) in the state used as home: one line naming the joint, the state, the file."""
    srdf = _srdf(tmp_path, _ALL + '<joint name="j4x" value="1.0"/>')
    with pytest.raises(InvalidArgumentError) as info:
        gb_pin.KinematicTarget.from_urdf(URDF, "tool", home="ready", srdf=srdf, onboard=False)
    said = str(info.value)
    assert "\n" not in said and str(srdf) in said
    assert "group_state 'ready' sets joint 'j4x', which the URDF does not have" in said
    assert "leaves joint 'j4' of the chain to 'tool' unset" in said
    # The only state is also the reference posture, the home when none is given: refused as well,
    # before any onboarding, for the joints given.
    with pytest.raises(InvalidArgumentError, match=r"'j4x'.*leaves joint 'j4'"):
        gb_pin.KinematicTarget.from_urdf(URDF, "tool", joints=["j1", "j4"], srdf=srdf)
    # Joints it leaves unset that the chain does not move are locked at 0, as pinocchio does.
    assert gb_pin.KinematicTarget.from_urdf(URDF, "tool", joints=["j1", "j2"], srdf=srdf, onboard=False)


def test_srdf_joints_that_are_not_needed_are_ignored(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """A state naming a gripper joint this URDF lacks, and setting every joint the target needs: loaded."""
    srdf = _srdf(tmp_path, _ALL + '<joint name="j4" value="1.0"/><joint name="gripper" value="0.01"/>')
    with caplog.at_level("DEBUG", logger="gb_pin.robot.description_checks"):
        arm = gb_pin.KinematicTarget.from_urdf(URDF, "tool", home="ready", srdf=srdf, onboard=False)
    np.testing.assert_allclose(arm.home, [0.3, -0.5, 0.05, 1.0])
    assert any("gripper" in r.getMessage() for r in caplog.records)
    # Leaving a needed joint unset without naming a missing one stays allowed (it keeps its 0).
    partial = _srdf(tmp_path, '<joint name="j1" value="0.3"/>')
    arm = gb_pin.KinematicTarget.from_urdf(URDF, "tool", home="ready", srdf=partial, onboard=False)
    assert arm.home[0] == 0.3


def test_example_robot_data_srdfs_naming_joints_of_fuller_robots_load(tmp_path: Path) -> None:
    """Romeo's half_sitting names toes, fingers and eyes its URDF lacks: ignored for an arm.

    A typo in one of the arm's joints in a copy of the same SRDF is refused.
    """
    from gb_pin.robot.models import example_robot_data_dir, load_example_robot_states

    _, entry, urdf, states = load_example_robot_states("romeo")
    assert states is not None and "LToePitch" in states.missing["half_sitting"]
    arm = gb_pin.KinematicTarget.from_example_robot_data("romeo", "l_wrist", onboard=False,
                                                         joints=["LShoulderPitch", "LElbowYaw"])  # fmt: skip
    assert arm.n_joints == 2
    assert entry.srdf is not None
    text = (example_robot_data_dir() / entry.srdf).read_text()
    typo = tmp_path / "romeo.srdf"
    typo.write_text(text.replace('name="LElbowYaw"', 'name="LElbowYawX"', 1))
    with pytest.raises(InvalidArgumentError, match=r"romeo\.srdf.*'half_sitting' sets joint 'LElbowYawX'"):
        gb_pin.KinematicTarget.from_urdf(urdf, "l_wrist", joints=["LShoulderPitch", "LElbowYaw"], srdf=typo,
                                         floating_base=True, onboard=False)  # fmt: skip


def test_a_joint_with_lower_above_upper_is_reported_as_such(tmp_path: Path) -> None:
    text = URDF.read_text().replace('lower="-2.0" upper="2.0"', 'lower="2.0" upper="-2.0"', 1)
    (tmp_path / "inverted.urdf").write_text(text)
    with pytest.raises(InvalidArgumentError, match="joint 'j1' has lower limit"):
        gb_pin.KinematicTarget.from_urdf(tmp_path / "inverted.urdf", "tool")
