"""Tests of gb_pin.learn.body.chain: compiled forward kinematics against Pinocchio and the planar closed form.

``KinematicTarget.chain.forward`` (compiled) is compared with ``KinematicTarget.forward``
(``pin.framesForwardKinematics``). Both are sums of at most a few hundred products of
numbers of order 1 (positions of a few metres), so they agree to ~1e-14; the
tolerance 1e-12 [m] leaves two orders of margin and still catches any wrong
placement, axis or composition order (errors of order 1e-2 and up).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from kinematics_helpers import random_placement

from gb_pin import KinematicChain, KinematicTarget
from gb_pin.learn.body.chain import PRISMATIC, REVOLUTE
from gb_pin.robot.planar import planar_chain

ATOL = 1e-12  # [m]


def unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def joint_factories(rng: np.random.Generator) -> list[tuple[str, object, int]]:
    """(name, joint model, kind) for every joint type the chain supports."""
    return [
        ("rx", pin.JointModelRX(), REVOLUTE),
        ("ry", pin.JointModelRY(), REVOLUTE),
        ("rz", pin.JointModelRZ(), REVOLUTE),
        ("runaligned", pin.JointModelRevoluteUnaligned(unit(rng)), REVOLUTE),
        ("px", pin.JointModelPX(), PRISMATIC),
        ("py", pin.JointModelPY(), PRISMATIC),
        ("pz", pin.JointModelPZ(), PRISMATIC),
        ("punaligned", pin.JointModelPrismaticUnaligned(unit(rng)), PRISMATIC),
        ("rubx", pin.JointModelRUBX(), REVOLUTE),
        ("ruby", pin.JointModelRUBY(), REVOLUTE),
        ("rubz", pin.JointModelRUBZ(), REVOLUTE),
    ]


def serial_model(seed: int) -> tuple[pin.Model, list[int]]:
    """A serial chain of every supported joint type, in a seeded shuffled order, random placements."""
    rng = np.random.default_rng(seed)
    joints = joint_factories(rng)
    order = rng.permutation(len(joints))
    model = pin.Model()
    parent = 0
    kinds = []
    for i in order:
        name, joint, kind = joints[i]
        parent = model.addJoint(parent, joint, random_placement(rng), name)
        kinds.append(kind)
    model.addFrame(pin.Frame("tool", parent, 0, random_placement(rng), pin.FrameType.OP_FRAME))
    return model, kinds


def random_posture(rng: np.random.Generator, kinds: list[int]) -> np.ndarray:
    """Angles uniform in [-pi, pi] [rad], prismatic displacements in [-0.5, 0.5] [m]."""
    return np.array([rng.uniform(-np.pi, np.pi) if k == REVOLUTE else rng.uniform(-0.5, 0.5) for k in kinds])


def assert_chain_matches_pinocchio(
    target: KinematicTarget, kinds: list[int], seed: int, count: int = 20
) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = random_posture(rng, kinds)
        x = target.chain.forward(q)
        assert x.shape == (target.n_task,)
        np.testing.assert_allclose(x, target.forward_pinocchio(q), rtol=0, atol=ATOL)
        np.testing.assert_array_equal(target.forward(q), x)  # forward is the learner's kinematics


def planar_closed_form(q: np.ndarray, length: float = 1.0) -> np.ndarray:
    """x = sum_i l cos(sum_{j<=i} q_j), y = sum_i l sin(...), l = length / m (paper Sec. III)."""
    angles = np.cumsum(q)
    segment = length / q.shape[0]
    return np.array([segment * np.cos(angles).sum(), segment * np.sin(angles).sum()])


@pytest.mark.parametrize("m", [2, 3, 5, 20, 50])
def test_planar_chain_matches_closed_form_and_pinocchio(m: int) -> None:
    """Compiled and Pinocchio FK of the planar chain both equal the closed form (Sec. III arms).

    Each is a sum of m terms of size 1/m, each exact to a few eps: 1e-12 is generous.
    """
    target = KinematicTarget(planar_chain(m), "tip", axes="xy")
    rng = np.random.default_rng(m)
    for q in rng.uniform(-np.pi, np.pi, (20, m)):
        expected = planar_closed_form(q)
        np.testing.assert_allclose(target.chain.forward(q), expected, rtol=0, atol=ATOL)
        np.testing.assert_allclose(target.forward(q), expected, rtol=0, atol=ATOL)


def test_planar_chain_z_is_zero() -> None:
    """The planar chain moves in the plane z = 0 ("xyz" axes of the same chain)."""
    target = KinematicTarget(planar_chain(5), "tip", axes="xyz")
    q = np.random.default_rng(0).uniform(-np.pi, np.pi, 5)
    x = target.chain.forward(q)
    np.testing.assert_allclose(x[:2], planar_closed_form(q), rtol=0, atol=ATOL)
    assert x[2] == 0.0


@pytest.mark.parametrize("axes", ["xyz", "xz", "y", "zx", "zyx"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_every_joint_type_matches_pinocchio(seed: int, axes: str) -> None:
    """RX/RY/RZ, RevoluteUnaligned, PX/PY/PZ, PrismaticUnaligned, RUBX/Y/Z joints, random placements."""
    model, kinds = serial_model(seed)
    target = KinematicTarget(model, "tool", axes=axes)
    assert target.n_joints == len(kinds)
    assert target.chain.n_task == len(axes)
    assert_chain_matches_pinocchio(target, kinds, seed=100 + seed)


def test_axes_select_and_order_world_coordinates() -> None:
    """The task vector lists the world coordinates in the order of the axes string."""
    model, kinds = serial_model(3)
    full = KinematicTarget(model, "tool", axes="xyz")
    q = random_posture(np.random.default_rng(4), kinds)
    xyz = full.chain.forward(q)
    for axes in ["xz", "y", "zx", "zyx", "yx"]:
        part = KinematicTarget(model, "tool", axes=axes)
        expected = [xyz["xyz".index(c)] for c in axes]
        np.testing.assert_array_equal(part.chain.forward(q), expected)


def branching_model(seed: int) -> pin.Model:
    """A tree: root -> (a1 -> a2) and root -> (b1 -> b2 -> b3), branches added interleaved.

    Frames: "hand" on b3, "foot" on a2, "base" on the root joint, "world_marker" on the universe.
    """
    rng = np.random.default_rng(seed)
    model = pin.Model()
    root = model.addJoint(0, pin.JointModelRZ(), random_placement(rng), "root")
    a1 = model.addJoint(root, pin.JointModelRY(), random_placement(rng), "a1")
    b1 = model.addJoint(root, pin.JointModelRX(), random_placement(rng), "b1")
    a2 = model.addJoint(a1, pin.JointModelPX(), random_placement(rng), "a2")
    b2 = model.addJoint(b1, pin.JointModelRUBZ(), random_placement(rng), "b2")
    b3 = model.addJoint(b2, pin.JointModelRevoluteUnaligned(unit(rng)), random_placement(rng), "b3")
    model.addFrame(pin.Frame("hand", b3, 0, random_placement(rng), pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("foot", a2, 0, random_placement(rng), pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("base", root, 0, random_placement(rng), pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("world_marker", 0, 0, random_placement(rng), pin.FrameType.OP_FRAME))
    return model


# Model order of branching_model: root, a1, b1, a2, b2, b3.
TREE_KINDS = [REVOLUTE, REVOLUTE, REVOLUTE, PRISMATIC, REVOLUTE, REVOLUTE]


@pytest.mark.parametrize("frame", ["hand", "foot", "base", "world_marker"])
@pytest.mark.parametrize("seed", [0, 1])
def test_branching_tree_matches_pinocchio(seed: int, frame: str) -> None:
    """A frame on one branch of a tree (or on the root, or on the universe) matches Pinocchio."""
    target = KinematicTarget(branching_model(seed), frame)
    assert_chain_matches_pinocchio(target, TREE_KINDS, seed=200 + seed)


def test_other_branch_does_not_move_the_frame() -> None:
    """Moving the joints of the other branch leaves the frame exactly where it was."""
    target = KinematicTarget(branching_model(5), "hand")
    rng = np.random.default_rng(6)
    q = random_posture(rng, TREE_KINDS)
    x = target.chain.forward(q)
    for _ in range(5):
        q2 = q.copy()
        q2[[1, 3]] = random_posture(rng, TREE_KINDS)[[1, 3]]  # a1, a2
        np.testing.assert_array_equal(target.chain.forward(q2), x)


def test_frame_on_universe_is_fixed() -> None:
    """A frame attached to the universe sits at its placement whatever the posture."""
    model = branching_model(7)
    target = KinematicTarget(model, "world_marker")
    placement = model.frames[model.getFrameId("world_marker")].placement.translation
    for q in np.random.default_rng(8).uniform(-1, 1, (5, 6)):
        np.testing.assert_array_equal(target.chain.forward(q), placement)


def test_chain_arrays() -> None:
    """KinematicChain exposes m, n, parents before children, unit axes and kinds."""
    model, kinds = serial_model(9)
    chain = KinematicTarget(model, "tool", axes="xz").chain
    assert isinstance(chain, KinematicChain)
    assert chain.n_joints == len(kinds)
    assert chain.n_task == 2
    np.testing.assert_array_equal(chain.task_axes, [0, 2])
    np.testing.assert_array_equal(chain.parents, np.arange(-1, len(kinds) - 1))
    np.testing.assert_array_equal(chain.kinds, kinds)
    np.testing.assert_allclose(np.linalg.norm(chain.axes, axis=1), 1.0, rtol=1e-15)
    body = chain.kernel()
    assert len(body.joints) == 6 and body.task.axes is chain.task_axes
    assert body.rot_ws.shape == (len(kinds), 3, 3)
    assert body.pos_ws.shape == (len(kinds), 3)
    chain.validate()
    again = KinematicChain.from_arrays(chain.to_arrays())
    for name, value in chain.to_arrays().items():
        np.testing.assert_array_equal(np.asarray(getattr(again, name.removeprefix("chain_"))), value)

    tree = KinematicTarget(branching_model(0), "hand").chain
    assert all(p < i for i, p in enumerate(tree.parents))


def test_chain_forward_rejects_wrong_length() -> None:
    """KinematicChain.forward refuses a posture whose length is not the number of joints."""
    chain = KinematicTarget(planar_chain(5), "tip", axes="xy").chain
    with pytest.raises(ValueError):
        chain.forward(np.zeros(2))
