"""Tests of stacked task maps: positions, orientations and pointing axes of frames (docs/TASKS.md).

The compiled task vector (gb_pin.learn.body.components) is checked against Pinocchio
(``framesForwardKinematics`` on the full model, ``log3``) on every preset at random
postures; the tolerance 1e-12 is the chain's (test_chain.py): a few ulps of the placements
times the chain length, and for the rotational rows s times a few ulps of the rotation.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import gb_pin
from gb_pin import InvalidArgumentError, KinematicTarget, UnknownRobotError, load_robot, robots
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.component_metrics import task_errors
from gb_pin.robot.reachability import check_reachable, sampling_bounds
from gb_pin.robot.reduction import find_frame
from gb_pin.robot.task_spec import Orientation, Pointing, Position
from gb_pin.robot.task_targets import task_grid

ATOL = 1e-12
TALOS_LEFT = tuple(f"arm_left_{i}_joint" for i in range(1, 8))
TALOS_HOME = [-0.4, 0.6, 0.0, -1.6, 0.0, 0.0, 0.0]
HAND = "gripper_left_base_link"


def _preset_names() -> list[str]:
    return [p.pattern.replace("N", "5") if p.source == "planar" else p.name for p in robots()]


def _full_configuration(target: KinematicTarget, q: np.ndarray) -> np.ndarray:
    return target.full_configuration(q)


def _pinocchio_rows(target: KinematicTarget, q: np.ndarray) -> np.ndarray:
    """The stacked vector from Pinocchio on the *full* model, references from the chain."""
    model = target.full_model
    data = model.createData()
    pin.framesForwardKinematics(model, data, _full_configuration(target, q))
    comps = target.chain.components
    assert comps is not None and target.task is not None
    rows = []
    for k, spec in enumerate(target.task):
        oMf = data.oMf[find_frame(model, spec.frame, target.name)]  # a link named like a joint: the link
        if isinstance(spec, Position):
            rows.extend(oMf.translation["xyz".index(a)] for a in spec.axes)
        elif isinstance(spec, Orientation):
            rows.extend(spec.scale * pin.log3(comps.references[k].T @ oMf.rotation))
        else:
            d0, u, v = comps.references[k]
            d = oMf.rotation @ spec.axis
            sine = np.linalg.norm(np.cross(d0, d))
            k_axis = np.cross(d0, d) / sine if sine > 0 else np.zeros(3)
            angle = math.atan2(sine, d0 @ d)
            rows.extend(spec.scale * angle * np.array([k_axis @ u, k_axis @ v]))
    return np.array(rows)


@pytest.fixture(scope="module")
def presets() -> dict[str, KinematicTarget]:
    return {name: load_robot(name) for name in _preset_names()}


def test_stacked_task_equals_pinocchio_on_every_preset(presets: dict[str, KinematicTarget]) -> None:
    """Position, orientation and pointing rows of each preset's frame equal Pinocchio's at random postures."""
    for name, preset in presets.items():
        frame = preset.frame
        task = [
            Position(frame, "xzy"[: len(preset.axes)]),
            Orientation(frame, 0.3),
            Pointing(frame, "-y", 0.7),
        ]
        target = KinematicTarget(preset.full_model, frame, preset.joints, preset.home, task=task, name=name)
        assert target.n_task == len(preset.axes) + 5
        lo, hi = sampling_bounds(target)
        rng = np.random.default_rng(sum(map(ord, name)))
        for q in np.vstack([target.home, lo + (hi - lo) * rng.random((6, target.n_joints))]):
            expected = _pinocchio_rows(target, q)
            np.testing.assert_allclose(target.forward(q), expected, rtol=0, atol=ATOL, err_msg=name)
            np.testing.assert_allclose(target.forward_pinocchio(q), expected, rtol=0, atol=ATOL)
        x_home = target.forward(target.home)
        np.testing.assert_allclose(x_home[len(preset.axes) :], 0.0, atol=1e-15)  # references at home


def test_task_presets_equal_pinocchio(presets: dict[str, KinematicTarget]) -> None:
    """The pose, pointing and bimanual presets' task vectors equal Pinocchio's on the full model."""
    for name in ("talos_left_arm_pose", "talos_left_arm_pointing", "talos_bimanual"):
        target = presets[name]
        rng = np.random.default_rng(1)
        lo, hi = sampling_bounds(target)
        for q in lo + (hi - lo) * rng.random((8, target.n_joints)):
            np.testing.assert_allclose(target.forward(q), _pinocchio_rows(target, q), rtol=0, atol=ATOL)
    assert presets["talos_left_arm_pose"].n_task == 6
    assert presets["talos_left_arm_pointing"].n_task == 5
    assert presets["talos_bimanual"].n_task == 6 and presets["talos_bimanual"].n_joints == 14


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-4, 0.5, 2.0, math.pi - 1e-3, math.pi - 1e-5, math.pi - 1e-8])
def test_orientation_is_the_rotation_vector_up_to_pi(
    presets: dict[str, KinematicTarget], angle: float
) -> None:
    """With R_ref = R_home exp(v)^T the home orientation row is s v, for |v| from 0 to almost pi."""
    preset = presets["talos_left_arm"]
    rng = np.random.default_rng(3)
    axis = rng.normal(size=3)
    v = angle * axis / np.linalg.norm(axis)
    data = preset.full_model.createData()
    pin.framesForwardKinematics(preset.full_model, data, preset.full_configuration(preset.home))
    r_home = data.oMf[preset.full_model.getFrameId(HAND)].rotation
    reference = r_home @ pin.exp3(v).T
    target = KinematicTarget(preset.full_model, HAND, TALOS_LEFT, TALOS_HOME,
                             task=[Orientation(HAND, 0.5, reference)])  # fmt: skip
    np.testing.assert_allclose(target.forward(target.home), 0.5 * v, rtol=0, atol=1e-9)


def test_pointing_rows_measure_the_angle_to_the_reference(presets: dict[str, KinematicTarget]) -> None:
    """|pointing rows| = s * angle between the axis and its home direction (the chart is equidistant)."""
    target = presets["talos_left_arm_pointing"]
    rng = np.random.default_rng(4)
    lo, hi = sampling_bounds(target)
    d0 = target.chain.components.references[1, 0]  # type: ignore[union-attr]
    model = target.full_model
    data = model.createData()
    for q in lo + (hi - lo) * rng.random((10, target.n_joints)):
        pin.framesForwardKinematics(model, data, target.full_configuration(q))
        d = data.oMf[model.getFrameId(HAND)].rotation @ np.array([0.0, 0.0, -1.0])
        angle = math.acos(np.clip(d0 @ d, -1.0, 1.0))
        assert abs(np.linalg.norm(target.forward(q)[3:]) - 0.2 * angle) < 1e-9


def test_position_task_is_the_plain_chain(presets: dict[str, KinematicTarget]) -> None:
    """task=None and task="position" give the frame-position chain (no components), as before."""
    preset = presets["talos_left_arm"]
    for task in (None, "position"):
        target = KinematicTarget(preset.full_model, HAND, TALOS_LEFT, TALOS_HOME, task=task)
        assert target.chain.components is None and target.task is None
        assert target.chain.task.arrays().kind == 0


def test_stacked_chain_round_trips_through_arrays(presets: dict[str, KinematicTarget]) -> None:
    """to_arrays / from_arrays keep a stacked chain exactly; without component_ arrays: a plain chain."""
    chain = presets["talos_bimanual"].chain
    again = KinematicChain.from_arrays(chain.to_arrays())
    q = presets["talos_bimanual"].home + 0.1
    assert np.array_equal(again.forward(q), chain.forward(q))
    plain = {k: v for k, v in chain.to_arrays().items() if not k.startswith("chain_component_")}
    assert KinematicChain.from_arrays(plain).components is None
    broken = chain.to_arrays()
    broken["chain_component_parents"] = np.array([0, 99])
    with pytest.raises(InvalidArgumentError, match="hangs on joint 99"):
        KinematicChain.from_arrays(broken)
    broken = chain.to_arrays()
    broken["chain_component_scales"] = np.array([1.0, 0.0])
    with pytest.raises(InvalidArgumentError, match="scales"):
        KinematicChain.from_arrays(broken)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"task": [Position("no_such_frame")]}, UnknownRobotError, "no_such_frame"),
        ({"task": [Orientation("torso_2_link")]}, InvalidArgumentError, "not moved by the joints"),
        ({"task": "pose", "orientation_scale": 0.0}, InvalidArgumentError, "orientation_scale"),
        ({"task": "pose", "orientation_scale": -1.0}, InvalidArgumentError, "orientation_scale"),
        ({"task": "pose", "orientation_scale": float("nan")}, InvalidArgumentError, "orientation_scale"),
        ({"task": "pointing", "pointing_axis": "w"}, InvalidArgumentError, "pointing axis"),
        ({"task": "pointing", "pointing_axis": [0, 0, 0]}, InvalidArgumentError, "nonzero"),
        ({"task": "posse"}, InvalidArgumentError, "'position', 'pose', 'pointing'"),
        ({"task": []}, InvalidArgumentError, "nonempty"),
        ({"task": [Position(HAND), Position(HAND)]}, InvalidArgumentError, "twice"),
        ({"task": ["position"]}, InvalidArgumentError, "Position, Orientation or Pointing"),
        ({"task": [{"kind": "orientation", "scal": 1}]}, InvalidArgumentError, "unknown keys"),
    ],
)
def test_bad_task_specs_raise_gb_pin_errors(
    presets: dict[str, KinematicTarget], kwargs: dict, error: type, match: str
) -> None:
    """Every bad task spec raises gb_pin's own error, naming the value."""
    preset = presets["talos_left_arm"]
    with pytest.raises(error, match=match):
        KinematicTarget(preset.full_model, HAND, TALOS_LEFT, TALOS_HOME, **kwargs)


@pytest.mark.parametrize("bad", [0.0, -0.1, float("inf"), "1", True])
def test_spec_objects_check_their_scale(bad: object) -> None:
    """Orientation and Pointing refuse scales that are not finite numbers > 0."""
    with pytest.raises(InvalidArgumentError, match="scale"):
        Orientation(HAND, bad)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="scale"):
        Pointing(HAND, "z", bad)  # type: ignore[arg-type]
    with pytest.raises(InvalidArgumentError, match="axes"):
        Position(HAND, "xw")


def test_task_targets_are_reachable_and_turned_up_to_the_limit(presets: dict[str, KinematicTarget]) -> None:
    """The pose preset's targets: the grid's positions, orientations <= 20 deg from home, all reachable."""
    target = presets["talos_left_arm_pose"]
    X = target.targets
    assert X is not None and X.shape == (27, 6)
    angles = np.degrees(np.linalg.norm(X[:, 3:], axis=1) / 0.2)
    assert np.all(angles <= 20.0 + 1e-9) and angles.max() > 10.0
    assert check_reachable(target, X).reachable.all()
    pairs = presets["talos_bimanual"].targets
    assert pairs is not None
    np.testing.assert_array_equal(pairs[:, 3:], pairs[:, :3] * [1.0, -1.0, 1.0])  # mirrored hands
    with pytest.raises(InvalidArgumentError, match="turn"):
        task_grid(target, [0.4, 0.2, 1.1], [0.5, 0.3, 1.2], [2, 2, 2], turn=200.0)


def test_component_errors_split_e_x(presets: dict[str, KinematicTarget]) -> None:
    """task_errors: the total is E^X of the history; components in m and deg; a pose run learns both.

    The orientation error first rises (for about 1000 movements, docs/TASKS.md): 2500 movements.
    """
    result = gb_pin.babble(robot="talos_left_arm_pose", movements=2500, seed=0)
    errors = task_errors(result.model, result.target, result.targets)
    assert errors.kinds == ("position", "orientation") and errors.units == ("m", "deg")
    assert abs(errors.total.mean() - result.error) < 1e-12
    diff = np.hypot(errors.errors[:, 0], np.radians(errors.errors[:, 1]) * 0.2)
    np.testing.assert_allclose(diff, errors.total, rtol=1e-12)
    start = task_errors(gb_pin.babble(robot="talos_left_arm_pose", movements=1, seed=0).model, result.target,
                        result.targets)  # fmt: skip
    assert np.all(errors.mean < start.mean)
    assert "orientation gripper_left_base_link: mean" in errors.summary(result.target.component_labels)


def test_component_history_observes_without_changing_the_run(presets: dict[str, KinematicTarget]) -> None:
    """ComponentHistory records (T, C) errors every k movements; the run's E^X history is unchanged."""
    from gb_pin.learn.component_metrics import ComponentHistory
    from gb_pin.learn.learner import GoalBabbling

    target = presets["talos_bimanual"]
    assert target.targets is not None
    history = ComponentHistory(target, target.targets)
    observed = GoalBabbling(radius=0.15).fit(
        target, target.targets, 300, seed=1, observer=history, observe_every=100
    )
    plain = GoalBabbling(radius=0.15).fit(target, target.targets, 300, seed=1)
    assert np.array_equal(observed.history_.error, plain.history_.error, equal_nan=True)
    assert history.movements.tolist() == [100, 200, 300] and history.errors.shape == (3, 2)
    final = task_errors(plain.model_, target, target.targets)
    np.testing.assert_array_equal(history.errors[-1], final.mean)


def test_histories_split_e_x_by_component_in_compiled_code(
    presets: dict[str, KinematicTarget], tmp_path: Path
) -> None:
    """history.components (T, C) equals the Python observer at its counts, survives files and checkpoints."""
    from gb_pin.learn.component_metrics import ComponentHistory
    from gb_pin.learn.learner import GoalBabbling
    from gb_pin.learn.state import BabbleState

    target = presets["talos_left_arm_pose"]
    assert target.targets is not None
    observer = ComponentHistory(target, target.targets)
    fitted = GoalBabbling().fit(target, target.targets, 200, seed=2, observer=observer, observe_every=100)
    h = fitted.history_
    assert h.components is not None and h.components.shape == (h.movements.size, 2)
    for r, expected in zip(observer.movements, observer.errors, strict=True):
        np.testing.assert_allclose(h.components[h.movements == r][0], expected, rtol=1e-12)
    # Checkpoint arrays: a resumed run measures the same components, bit for bit.
    st = BabbleState.start(target, target.targets, 200, fitted.config_, seed=2)
    st.run(77)
    again = BabbleState.from_arrays(st.to_arrays(), st.config, st.rng_state())
    again.run(200)
    assert np.array_equal(again.components, h.components, equal_nan=True)
    # Result files keep them; the paper's position task has none.
    result = gb_pin.babble("talos_left_arm_pose", movements=20, seed=0)
    result.save(tmp_path / "pose.npz")
    loaded = gb_pin.load_result(tmp_path / "pose.npz")
    assert np.array_equal(loaded.history.components, result.history.components, equal_nan=True)
    assert gb_pin.babble("planar5", movements=5, seed=0).history.components is None


def test_scene_draws_target_and_reached_triads(presets: dict[str, KinematicTarget]) -> None:
    """The viewer draws a triad per target and reached pose (R_ref exp(x / s)) and the second hand's sets."""
    from gb_pin.viewer.cache import OfflineWindow
    from gb_pin.viewer.scene import Scene

    target = presets["talos_left_arm_pose"]
    assert target.targets is not None
    scene = Scene(OfflineWindow(), target, target.targets)
    scene.draw_static()
    drawn = scene.overlay(np.tile(target.home, (27, 1)))  # every estimate at home: home triads
    length = 0.035 * scene.figure.size
    data = target.full_model.createData()
    pin.framesForwardKinematics(target.full_model, data, target.full_configuration(target.home))
    oMf = data.oMf[target.full_model.getFrameId(HAND)]
    for a, key in enumerate("xyz"):
        segs = drawn[f"task_{key}"]
        assert segs.shape == (54, 3)
        np.testing.assert_allclose(segs[::2], np.tile(oMf.translation, (27, 1)), atol=1e-12)
        np.testing.assert_allclose(
            segs[1::2] - segs[::2], np.tile(length * oMf.rotation[:, a], (27, 1)), atol=1e-12
        )
    bimanual = presets["talos_bimanual"]
    assert bimanual.targets is not None
    scene = Scene(OfflineWindow(), bimanual, bimanual.targets)
    scene.draw_static()
    drawn = scene.overlay(np.tile(bimanual.home, (27, 1)))
    np.testing.assert_allclose(drawn["task_others"], np.tile(bimanual.forward(bimanual.home)[3:], (27, 1)))
    np.testing.assert_array_equal(scene.embed(bimanual.targets), bimanual.targets[:, :3])


def test_pose_results_and_checkpoints_round_trip(tmp_path: Path) -> None:
    """A pose run saves and loads (result file) and resumes from its checkpoint bit for bit."""
    full = gb_pin.babble(robot="talos_left_arm_pose", movements=120, seed=2)
    path = tmp_path / "pose.npz"
    full.save(path)
    loaded = gb_pin.load_result(path)
    assert loaded.target.n_task == 6 and np.array_equal(loaded.history.error, full.history.error)
    ckpt = tmp_path / "pose.ckpt.npz"
    gb_pin.babble(robot="talos_left_arm_pose", movements=120, seed=2, checkpoint=ckpt, checkpoint_every=60)
    resumed = gb_pin.resume(ckpt)
    assert np.array_equal(resumed.history.error, full.history.error, equal_nan=True)
    np.testing.assert_array_equal(resumed.model.predict(full.targets), full.model.predict(full.targets))


def test_auto_targets_of_a_custom_pose_target(presets: dict[str, KinematicTarget]) -> None:
    """Auto targets of a stacked task: a position grid at the home orientation, every pose reachable."""
    panda = presets["panda"]
    target = KinematicTarget(panda.full_model, panda.frame, panda.joints, panda.home, task="pose", name="p")
    X = target.auto_targets()
    assert X.shape == (27, 6)
    np.testing.assert_allclose(X[:, 3:], 0.0, atol=1e-15)
    assert check_reachable(target, X).reachable.all()
    assert np.ptp(X[:, 0]) > 0.05


def test_trials_keep_the_component_curves(tmp_path: Path) -> None:
    """Trials of a stacked task keep E^X per component (trials, T, C), in files and journals too."""
    journal = tmp_path / "journal.jsonl"
    ts = gb_pin.run_trials("talos_left_arm_pose", trials=2, movements=10, workers=1, checkpoint=journal)
    assert ts.components is not None and ts.components.shape == (2, ts.movements.size, 2)
    one = gb_pin.babble("talos_left_arm_pose", movements=10, seed=1, schedule=ts.movements)
    assert one.history.components is not None
    np.testing.assert_array_equal(ts.components[1], one.history.components)
    ts.save(tmp_path / "trials.json")
    back = gb_pin.TrialSet.load(tmp_path / "trials.json")
    assert back.components is not None and np.array_equal(back.components, ts.components)
    again = gb_pin.run_trials("talos_left_arm_pose", trials=2, movements=10, workers=1, checkpoint=journal)
    assert again.components is not None and np.array_equal(
        again.components, ts.components
    )  # from the journal
    assert gb_pin.run_trials("planar5", trials=1, movements=5, workers=1).components is None
