"""The MuJoCo model of a robot gb_pin loads, written from the very model the learner reads.

A :class:`~gb_pin.robot.target.KinematicTarget` (a preset, a URDF, an example-robot-data model)
holds Pinocchio's reduced model: the joints the learner moves, the others welded at the
reference posture with their links' masses merged into the moved bodies
(``pinocchio.buildReducedModel``). :func:`mjcf` writes that model as MJCF: one body per moved
joint, placed by the learner's own chain (:class:`~gb_pin.learn.body.chain.KinematicChain`:
the same rotations and translations, written with full float precision), its inertia from
Pinocchio, a hinge or slide joint on the chain's axis, a position servo per joint
(:class:`~gb_pin.sim.servos.Servos`) and a site at the task frame. So the simulated arm's
kinematics are the learner's to rounding (tested: 1e-9 m at random postures), every robot gb_pin
loads converts (no URDF dialect or mesh to strip), and the locked joints are welded exactly where
gb_pin locks them.

By default no geometry is written: contacts are off (the learner's chain has no self-collision
either), and MuJoCo takes the masses from the inertias. Given a collision checker
(:mod:`gb_pin.safety`), its shapes, obstacles and checked pairs are written with contacts on
(:mod:`gb_pin.sim.contacts`).
"""

from __future__ import annotations

from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import REVOLUTE, KinematicChain
from gb_pin.sim.servos import Servos

MIN_MASS = 1e-6
"""Bodies lighter than this [kg] (links without an inertial in the URDF) get this mass."""
MIN_INERTIA = 1e-9
"""Principal inertias below this [kg m^2] are raised to it (MuJoCo needs them > 0)."""


def mjcf(
    target: Any,
    servos: Servos,
    *,
    gravity: bool = True,
    timestep: float = 0.002,
    name: str = "robot",
    scene: Any = None,
    collision: Any = None,
) -> str:
    """The MJCF text of ``target``'s moved joints, with ``servos`` on them.

    Args:
        target: a :class:`~gb_pin.robot.target.KinematicTarget` (its ``chain``, ``joints`` and
            reduced Pinocchio ``model``, whose inertias give the dynamics).
        servos: one servo per entry of q.
        gravity: Pinocchio's gravity (``model.gravity``) on, or none.
        timestep: the integration step [s].
        name: the model's name.
        scene: what a camera sees (:class:`~gb_pin.sim.scene.Scene`: meshes, floor, lights, the
            marker plate, the camera), drawn only: no mass, no contact; None: no geometry.
        collision: a :class:`~gb_pin.safety.checker.CollisionChecker`: its shapes and obstacles as
            geoms, contacts on for its checked pairs; None: no geometry, contacts off.

    Raises:
        InvalidArgumentError: a robot without a Pinocchio model or inertias.
    """
    chain: KinematicChain = target.chain
    model = getattr(target, "model", None)
    if model is None or not hasattr(model, "inertias"):
        raise InvalidArgumentError(
            f"a MuJoCo plant needs a robot with a Pinocchio model (its masses): {target!r:.120}"
        )
    m = chain.n_joints
    children: dict[int, list[int]] = {i: [] for i in range(-1, m)}
    for i in range(m):
        children[int(chain.parents[i])].append(i)
    ids = [int(model.getJointId(target.joints[int(chain.q_index[i])])) for i in range(m)]
    lines: list[str] = []
    geoms: dict[int, list[str]] = {}
    meshes: list[str] = []
    pairs: list[str] = []
    if collision is not None:
        from gb_pin.sim.contacts import contact_xml

        geoms, meshes, pairs = contact_xml(collision)

    def body(i: int, depth: int) -> None:
        pad = "  " * depth
        a = int(chain.q_index[i])
        inertia = model.inertias[ids[i]]
        full = np.asarray(inertia.inertia, dtype=float)
        kind = "hinge" if chain.kinds[i] == REVOLUTE else "slide"
        lines.append(
            f"{pad}<body name={quoteattr(f'link_{a}')} pos={_v(chain.translations[i])} "
            f"quat={_v(quaternion(chain.rotations[i]))}>"
        )
        lines.append(
            f"{pad}  <inertial pos={_v(inertia.lever)} mass={_v([max(float(inertia.mass), MIN_MASS)])} "
            f"fullinertia={_v([full[0, 0], full[1, 1], full[2, 2], full[0, 1], full[0, 2], full[1, 2]])}/>"
        )
        lines.append(
            f"{pad}  <joint name={quoteattr(target.joints[a])} type={quoteattr(kind)} "
            f"axis={_v(chain.axes[i])} armature={_v([servos.armature[a]])}/>"
        )
        if chain.frame_parent == i:
            lines.append(f'{pad}  <site name="frame" pos={_v(chain.frame_translation)}/>')
        if scene is not None:
            lines.extend(f"{pad}  {line}" for line in scene.bodies.get(a, []))
        lines.extend(f"{pad}  {g}" for g in geoms.get(a, []))
        for c in children[i]:
            body(c, depth + 1)
        lines.append(f"{pad}</body>")

    if chain.frame_parent < 0:
        lines.append(f'    <site name="frame" pos={_v(chain.frame_translation)}/>')
    if scene is not None:
        lines.extend(f"    {line}" for line in scene.bodies.get(-1, []))
    lines.extend(f"    {g}" for g in geoms.get(-1, []))
    for c in children[-1]:
        body(c, 2)
    g = np.asarray(model.gravity.linear, dtype=float) if gravity else np.zeros(3)
    actuators = []
    for a, joint in enumerate(target.joints):
        limit = servos.force_limit[a]
        force = f" forcerange={_v([-limit, limit])}" if np.isfinite(limit) else ""
        actuators.append(
            f"    <position name={quoteattr(f'servo_{a}')} joint={quoteattr(joint)} "
            f"kp={_v([servos.kp[a]])} kv={_v([servos.kv[a]])}{force}/>"
        )
    return "\n".join([
        f"<mujoco model={quoteattr(name)}>",
        f'  <compiler angle="radian" balanceinertia="true" boundmass="{MIN_MASS!r}" '
        f'boundinertia="{MIN_INERTIA!r}"/>',
        f'  <option timestep="{float(timestep)!r}" integrator="implicitfast" gravity={_v(g)}>',
        *(['    <flag contact="disable"/>'] if collision is None else []),
        "  </option>",
        *([] if scene is None else scene.header),
        *(["  <asset>", *meshes, "  </asset>"] if meshes else []),
        "  <worldbody>",
        *lines,
        "  </worldbody>",
        *(["  <contact>", *pairs, "  </contact>"] if pairs else []),
        "  <actuator>",
        *actuators,
        "  </actuator>",
        "</mujoco>",
        "",
    ])  # fmt: skip


def quaternion(rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """The unit quaternion (w, x, y, z) of a rotation matrix (3, 3) (Shepperd's method)."""
    R = np.asarray(rotation, dtype=float)
    trace = R[0, 0] + R[1, 1] + R[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * np.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * np.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    out = np.array(q)
    return out / np.linalg.norm(out)


def _v(values: Any) -> str:
    """Numbers as one quoted XML attribute, each written with full precision (repr round-trips)."""
    return quoteattr(" ".join(repr(float(x)) for x in np.ravel(values)))
