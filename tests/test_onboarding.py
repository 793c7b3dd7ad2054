"""Onboarding: the joints, home, goal grid, radius and sigma of a robot given by its frame alone.

Issue 25: ``gb-pin babble --robot erd:NAME --frame FRAME`` must learn every arm of example-robot-data
(median E^X at most 0.15 E_0 after 3000 movements); the README's URDF command must work on the
test arm. Measured with ``gb-pin robots --erd`` (docs/ROBOTS.md): every arm's median is below
0.03 E_0; the statistical test below runs the four arms the issue named, 3 seeds each.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import gb_pin
from gb_pin import KinematicTarget
from gb_pin.exceptions import InvalidArgumentError, ResultFileError
from gb_pin.learn.config import default_sigma
from gb_pin.robot import onboarding
from gb_pin.robot.models import load_example_robot
from gb_pin.runs import robot_source

SMALL_URDF = Path(__file__).parent / "data" / "small_arm.urdf"


@pytest.fixture(scope="module")
def z1() -> KinematicTarget:
    """Unitree Z1's link06 from its frame alone (its SRDF postures sit on its joint limits)."""
    return KinematicTarget.from_example_robot_data("z1", "link06")


@pytest.fixture(scope="module")
def small_arm() -> KinematicTarget:
    """The README's URDF robot: the small test arm's tool over j1, j2, j3, the rest onboarded."""
    return KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j2", "j3"])


def test_the_joints_that_move_the_frame_leave_the_base_legs_and_wrist_out() -> None:
    """simple_humanoid's l_wrist: the waist and arm joints on its path; the base and legs locked.

    Its three wrist joints rotate about axes through the frame's origin: their Jacobian columns are
    zero (checked with Pinocchio), so they are left out, and recorded as left out.
    """
    model, _, _ = load_example_robot("simple_humanoid")
    path = onboarding.path_joints(model, model.getFrameId("l_wrist"), "simple_humanoid")
    assert path[:3] == ["WAIST_P", "WAIST_R", "CHEST"] and path[3:] == [
        "LARM_SHOULDER_P", "LARM_SHOULDER_R", "LARM_SHOULDER_Y", "LARM_ELBOW",
        "LARM_WRIST_Y", "LARM_WRIST_P", "LARM_WRIST_R",
    ]  # fmt: skip
    target = KinematicTarget.from_example_robot_data("simple_humanoid", "l_wrist")
    assert target.joints == tuple(path[:7])
    assert target.onboarding is not None and target.onboarding.dropped == tuple(path[7:])
    data = model.createData()
    q = np.array(target.reference)
    fid = model.getFrameId("l_wrist")
    J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)[:3]
    for name in path[7:]:
        assert np.linalg.norm(J[:, model.joints[model.getJointId(name)].idx_v]) < 1e-12


def test_the_home_is_inside_the_limits_away_from_them_and_from_singularities(z1: KinematicTarget) -> None:
    """Z1's reference postures sit on its limits; the chosen home keeps every joint >= 15 % of its range away.

    Candidates are drawn in the central 70 % of each range (or are the middle of the limits), so the
    margin is at least 0.15; the smallest singular value of the task Jacobian is far from 0; the
    same model gives the same home bit for bit (seeded), and its grid is reachable (auto_grid).
    """
    a = z1
    b = KinematicTarget.from_example_robot_data("z1", "link06")
    np.testing.assert_array_equal(a.home, b.home)
    np.testing.assert_array_equal(a.targets, b.targets)
    record = a.onboarding
    assert record is not None and record.chosen == ("joints", "home", "targets", "radius")
    span = a.upper - a.lower
    assert np.all(np.minimum(a.home - a.lower, a.upper - a.home) >= onboarding.BAND * span - 1e-12)
    assert record.margin >= onboarding.BAND - 1e-12 and record.sigma_min > 0.05
    refs = {c.key(): np.asarray(c.data()) for c in a.full_model.referenceConfigurations}
    assert refs["home"][1] == 0.0 == a.full_model.lowerPositionLimit[1]  # why z1 needed this
    assert record.half_width == pytest.approx(0.5 * record.largest_half_width, abs=0.005)
    assert record.radius == pytest.approx(onboarding.RADIUS_FACTOR * record.half_width)
    np.testing.assert_allclose(a.targets.mean(axis=0), a.home_position, atol=1e-12)
    assert a.learner_defaults == {"radius": record.radius}


def test_a_home_given_is_kept_and_only_the_rest_is_chosen() -> None:
    """Joints and home given: onboarding chooses the grid, radius (and sigma) around that home, no more."""
    joints = [f"arm_left_{i}_joint" for i in range(1, 8)]
    home = [-0.4, 0.6, 0.0, -1.6, 0.0, 0.0, 0.0]
    target = KinematicTarget.from_example_robot_data("talos", "gripper_left_base_link", joints, home)
    assert target.joints == tuple(joints)
    np.testing.assert_array_equal(target.home, home)
    record = target.onboarding
    assert record is not None and record.chosen[:2] == ("targets", "radius")  # and sigma, if capped
    assert "joints" not in record.chosen and "home" not in record.chosen
    given = KinematicTarget.from_example_robot_data(
        "talos", "gripper_left_base_link", joints, home, targets=[target.home_position]
    )
    assert given.onboarding is None and given.learner_defaults == {}  # everything given: nothing chosen


def test_sigma_is_capped_where_the_exploration_would_drown_a_small_grid(
    small_arm: KinematicTarget, z1: KinematicTarget
) -> None:
    """The README's URDF command: the small arm's j1-j3 (a 10 cm prismatic shell) get a 1 cm grid.

    Eq. 12's sigma would move the tool by about 0.2 m at home (37 times the grid's half-width: the
    run diverged to 14 795 prototypes); the cap keeps sigma sqrt(1 + |x|^2) |J|_F at half of it.
    """
    arm = small_arm
    record = arm.onboarding
    assert record is not None and record.sigma is not None and "sigma" in record.chosen
    x = arm.home_position
    J = onboarding._jacobians(arm, arm.home[None, :])[0]
    exploration = record.sigma * math.sqrt(1 + x @ x) * np.linalg.norm(J)
    assert exploration == pytest.approx(onboarding.DEVIATION_SHARE * record.half_width)
    assert record.sigma < default_sigma(3) / 10
    assert arm.learner_defaults == {"radius": record.radius, "sigma": record.sigma}
    assert z1.onboarding is not None and z1.onboarding.sigma is None  # Eq. 12's: no cap needed


def test_fewer_joints_than_task_axes_is_an_error_naming_axes() -> None:
    """Two joints cannot reach a 3-D grid around any home: the error says to choose fewer axes."""
    with pytest.raises(InvalidArgumentError, match=r"moved by 2 joint.*--axes"):
        KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j4"])
    arm = KinematicTarget.from_urdf(SMALL_URDF, "tool", ["j1", "j4"], axes="xy")
    assert arm.targets is not None and arm.targets.shape == (9, 2)


def test_presets_are_not_onboarded() -> None:
    """Presets give joints, home, targets and learner defaults: nothing is measured, nothing changes."""
    for name in ("ur5", "panda", "talos_left_arm", "planar5"):
        robot = gb_pin.load_robot(name)
        assert getattr(robot, "onboarding", None) is None and robot.learner_defaults == {}


def test_onboarding_is_recorded_in_files_and_rebuilt_without_measuring(
    small_arm: KinematicTarget, tmp_path: Path, monkeypatch: Any
) -> None:
    """A result records what was chosen; load_result rebuilds the same grid, radius and sigma, unmeasured."""
    arm = small_arm
    result = gb_pin.babble(arm, movements=20, seed=0, schedule=[0, 20])
    assert result.config.radius == arm.onboarding.radius and result.config.sigma == arm.onboarding.sigma
    result.save(tmp_path / "arm.npz")

    def no_measuring(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("a rebuilt robot must not measure its home or grid again")

    monkeypatch.setattr(onboarding, "choose_home", no_measuring)
    monkeypatch.setattr(onboarding, "goal_grid", no_measuring)
    loaded = gb_pin.load_result(tmp_path / "arm.npz")
    assert loaded.target.onboarding == arm.onboarding or (
        loaded.target.onboarding.to_json() == arm.onboarding.to_json()
    )
    np.testing.assert_array_equal(loaded.target.targets, arm.targets)
    assert loaded.target.learner_defaults == arm.learner_defaults


@pytest.mark.parametrize(
    ("change", "needle"),
    [
        ({"chosen": ["home", "wings"]}, "onboarding.chosen"),
        ({"radius": -1.0}, "onboarding.radius"),
        ({"half_width": math.nan}, "onboarding.half_width"),
        ({"shape": [3, 3]}, "onboarding.shape"),
        ({"dropped": ["a\x1b[2J"]}, "onboarding.dropped"),
        ({"extra": 1}, "onboarding"),
    ],
)
def test_a_corrupted_onboarding_record_is_refused(
    small_arm: KinematicTarget, change: dict[str, Any], needle: str
) -> None:
    """Every entry of a file's onboarding record is checked before anything is built from it."""
    source = robot_source.describe(small_arm, None)
    assert source is not None
    source["onboarding"] = {**source["onboarding"], **change}
    with pytest.raises(ResultFileError, match=needle):
        robot_source.check("f.npz", json.loads(json.dumps(source, allow_nan=True)))


@pytest.mark.slow
@pytest.mark.parametrize(
    ("robot", "frame"),
    [
        ("z1", "link06"),
        ("kinova", "j2s6s200_end_effector"),
        ("xarm7", "link_eef"),
        ("simple_humanoid", "l_wrist"),
    ],
)
def test_the_arms_the_issue_named_learn_from_their_frame_alone(robot: str, frame: str) -> None:
    """Issue 25's criterion on its four failures: median E^X <= 0.15 E_0 after 3000 movements (3 seeds).

    Before: z1 2 prototypes at 0.82 E_0, kinova refused, xarm7 0.47 E_0 after 500, simple_humanoid
    3 prototypes at 0.74 E_0. Measured with onboarding (`gb-pin robots --erd`, 5 seeds): medians
    0.009, 0.011, 0.012 and 0.018 E_0, worst trials 0.014 to 0.022; 0.15 is the issue's criterion.
    """
    target = KinematicTarget.from_example_robot_data(robot, frame)
    ratios = []
    for seed in range(3):
        result = gb_pin.babble(target, movements=3000, seed=seed, schedule=[0, 3000])
        ratios.append(result.error / result.history.error[0])
        assert result.n_prototypes > 10
    assert np.median(ratios) <= 0.15, ratios
