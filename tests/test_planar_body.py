"""Tests of gb_pin.learn.body.planar: the closed form of chains whose joints turn about parallel axes.

The closed form must be chosen from the chain's arrays alone (any URDF chain about parallel axes,
not only the presets), refused for every other chain, and give the general kernel's numbers: bit
for bit on the planar presets (the same operations once the products with 0 and 1 are dropped,
which keeps the fingerprint of every planar run), and to rounding elsewhere. Rounding: each
position is a sum of at most a few dozen products of numbers of order 1, so two exact-to-a-few-eps
evaluations agree to ~1e-15 m; 1e-13 m leaves a margin and still catches a wrong sign, axis or
link (errors of order 1e-2 and up). Pinocchio is held to tests/test_chain.py's 1e-12 m.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from kinematics_helpers import random_placement, random_rotation

from gb_pin import KinematicTarget
from gb_pin.learn.body.chain import Body, body_forward
from gb_pin.learn.body.planar import PARALLEL_TOLERANCE, PlanarBody, parallel_axes
from gb_pin.robot.planar import planar_chain, planar_kinematics
from gb_pin.robot.presets import load_robot

ROUNDING = 1e-13  # [m]
ATOL = 1e-12  # [m], as tests/test_chain.py


def general(chain, q: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    out = np.empty(chain.n_task)
    body_forward(np.ascontiguousarray(q, dtype=float), chain.kernel(), out)
    return out


def closed(chain, q: np.ndarray) -> np.ndarray:  # type: ignore[no-untyped-def]
    body = chain.forward_kernel()
    assert isinstance(body, PlanarBody)
    out = np.empty(chain.n_task)
    body_forward(np.ascontiguousarray(q, dtype=float), body, out)
    return out


@pytest.mark.parametrize("m", [2, 5, 20, 50])
@pytest.mark.parametrize("axes", ["xy", "xyz", "yx"])
def test_planar_presets_use_the_closed_form_bit_for_bit(m: int, axes: str) -> None:
    """planarN's closed form gives exactly the general kernel's numbers, for any angles (also beyond pi)."""
    chain = planar_kinematics(m, axes=axes)
    rng = np.random.default_rng(m)
    for q in np.vstack([rng.uniform(-np.pi, np.pi, (20, m)), rng.uniform(-50.0, 50.0, (5, m))]):
        np.testing.assert_array_equal(closed(chain, q), general(chain, q))


def parallel_model(seed: int, m: int) -> tuple[pin.Model, list[str]]:
    """A serial chain of revolute joints about parallel axes hidden by random placements.

    Each joint has a random placement rotation R_i and its own axis chosen so that R_i a_i = +-a_parent
    (alternating senses), random translations, a branch of other joints off the path, and the frame
    "tool" at a random placement on the last joint.
    """
    rng = np.random.default_rng(seed)
    model = pin.Model()
    world_axis = random_rotation(rng)[:, 0]
    parent, parent_axis, names = 0, world_axis, []
    for i in range(m):
        placement = random_placement(rng)
        sign = 1.0 if i % 2 == 0 else -1.0
        axis = sign * placement.rotation.T @ parent_axis
        parent = model.addJoint(parent, pin.JointModelRevoluteUnaligned(axis), placement, f"j{i}")
        names.append(f"j{i}")
        parent_axis = axis
        if i == 1:  # a side branch that does not carry the frame: not on the path
            side = model.addJoint(parent, pin.JointModelRX(), random_placement(rng), "side1")
            model.addJoint(side, pin.JointModelPY(), random_placement(rng), "side2")
            names += ["side1", "side2"]
    model.addFrame(pin.Frame("tool", parent, 0, random_placement(rng), pin.FrameType.OP_FRAME))
    return model, names


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_any_chain_about_parallel_axes_gets_the_closed_form(seed: int) -> None:
    """Detected from the arrays: random placements, both senses, a side branch, joints in any order of q."""
    model, names = parallel_model(seed, 6)
    order = list(np.random.default_rng(seed).permutation(names))  # q in a shuffled joint order
    target = KinematicTarget(model, "tool", joints=order, axes="xyz")
    chain = target.chain
    body = chain.forward_kernel()
    assert isinstance(body, PlanarBody) and body.joints.shape == (6,)
    assert set(body.signs.tolist()) == {-1.0, 1.0}
    rng = np.random.default_rng(10 + seed)
    for q in rng.uniform(-np.pi, np.pi, (20, len(names))):
        x = closed(chain, q)
        np.testing.assert_allclose(x, general(chain, q), rtol=0, atol=ROUNDING)
        np.testing.assert_allclose(x, target.forward_pinocchio(q), rtol=0, atol=ATOL)
        np.testing.assert_array_equal(target.forward(q), x)  # forward is what the learner executes


def test_other_chains_keep_the_general_kernel() -> None:
    """Joints about different axes, a prismatic joint on the path, stacked tasks, a frame on the world."""
    assert parallel_axes(load_robot("panda").chain) is None
    assert isinstance(load_robot("panda").chain.forward_kernel(), Body)
    # One axis of a planar chain tilted by far more than the tolerance, and by less.
    for tilt, parallel in [(1e3 * PARALLEL_TOLERANCE, False), (1e-3 * PARALLEL_TOLERANCE, True)]:
        chain = planar_kinematics(5)
        axes = chain.axes.copy()
        axes[3] = [np.sin(tilt), 0.0, np.cos(tilt)]
        tilted = type(chain)(**{**chain.__dict__, "axes": axes})
        assert (parallel_axes(tilted) is not None) == parallel
    model = planar_chain(4)
    prismatic = pin.Model()
    joint = prismatic.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "r1")
    joint = prismatic.addJoint(joint, pin.JointModelPX(), random_placement(np.random.default_rng(0)), "p")
    joint = prismatic.addJoint(joint, pin.JointModelRZ(), pin.SE3.Identity(), "r2")
    prismatic.addFrame(pin.Frame("tip", joint, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    assert parallel_axes(KinematicTarget(prismatic, "tip").chain) is None
    assert parallel_axes(KinematicTarget(model, "tip", task="pose").chain) is None
    model.addFrame(pin.Frame("fixed", 0, 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    assert parallel_axes(KinematicTarget(model, "fixed").chain) is None


def test_the_loop_runs_planar_presets_on_the_closed_form() -> None:
    """babble()'s compiled loop gets the closed form for planarN and the general kernel for a 3-D arm."""
    import gb_pin
    from gb_pin.learn.state import BabbleState
    from gb_pin.runs.setup import resolve_robot

    for name, kind in [("planar5", PlanarBody), ("talos_left_arm", Body)]:
        target, _, _ = resolve_robot(name)
        config = gb_pin.GoalBabbling()._resolve(target.n_joints)
        state = BabbleState.start(target, target.targets, 2, config, seed=0)
        assert isinstance(state.kernel_args()[1].body, kind)
