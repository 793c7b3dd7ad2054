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


def test_srdf_states_naming_missing_joints_or_holding_nan_are_refused(tmp_path: Path) -> None:
    good = load_urdf_model(URDF, srdf=_srdf(tmp_path, '<joint name="j1" value="0.5"/>'))
    assert [e.key() for e in good.referenceConfigurations] == ["ready"]
    with pytest.raises(InvalidArgumentError, match="'ready' sets joint 'nope'"):
        load_urdf_model(URDF, srdf=_srdf(tmp_path, '<joint name="nope" value="0.5"/>'))
    with pytest.raises(InvalidArgumentError, match="'j1' the value 'nan'"):
        load_urdf_model(URDF, srdf=_srdf(tmp_path, '<joint name="j1" value="nan"/>'))


def test_a_joint_with_lower_above_upper_is_reported_as_such(tmp_path: Path) -> None:
    text = URDF.read_text().replace('lower="-2.0" upper="2.0"', 'lower="2.0" upper="-2.0"', 1)
    (tmp_path / "inverted.urdf").write_text(text)
    with pytest.raises(InvalidArgumentError, match="joint 'j1' has lower limit"):
        gb_pin.KinematicTarget.from_urdf(tmp_path / "inverted.urdf", "tool")
