"""The robot drawn as a stick figure: a sphere per joint, a cylinder per link, a sphere on the frame.

A *figure* turns a posture into (path, 4x4 world transform) pairs of the nodes that
move; the same pairs drive the live view and the keyframes of a replay animation.
The stick figure works for any target (procedural planar chains carry no visual
geometry). It reads the kinematic tree from the target's chain (the arrays the
learner uses, filled from the Pinocchio model on the robot side) and evaluates it
with the learner's compiled forward kinematics: no Pinocchio call here (only the
frame's orientation, which the chain does not hold, is read off the target's model).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.learn.body.joints import joints_forward
from gb_pin.viewer import shapes
from gb_pin.viewer.geometry import Transforms, align_y, translation
from gb_pin.viewer.style import EFFECTOR_COLOR, JOINT_COLOR, LINK_COLOR, ROBOT

if TYPE_CHECKING:
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.viewer.commands import Window


class StickFigure:
    """A robot drawn with simple geometry: a sphere per joint, a cylinder per link, a sphere on the frame.

    A link joins a joint to each child joint and to the operational frame; every
    piece hangs under its joint's node, so a posture moves one node per joint.
    Joint ``j`` (1..m, numbered as in the target's Pinocchio model; 0 is the fixed
    world) is chain joint ``j - 1``.

    Args:
        target: the robot.
        root: meshcat path of the figure.
    """

    def __init__(self, target: KinematicTarget, root: str = ROBOT) -> None:
        self.target = target
        self.root = root
        chain = target.chain
        self.n_joints = chain.n_joints
        self._joints = chain.joints
        self._rotations = np.empty((self.n_joints, 3, 3))
        self._positions = np.empty((self.n_joints, 3))
        self.frame_id = target.frame_id
        self._frame_joint = int(chain.frame_parent) + 1
        self._frame_translation = np.array(chain.frame_translation, dtype=float)
        # The chain keeps the frame's position only; its orientation orients the effector's node.
        self._frame_rotation = np.array(target.model.frames[self.frame_id].placement.rotation, dtype=float)
        # Links in the parent joint's frame: (joint, start, end).
        links: list[tuple[int, NDArray[np.float64], NDArray[np.float64]]] = [
            (int(chain.parents[i]) + 1, np.zeros(3), np.array(chain.translations[i], dtype=float))
            for i in range(self.n_joints)
        ]
        links.append((self._frame_joint, np.zeros(3), self._frame_translation.copy()))
        links += self._rails(target)
        self.links = [(j, a, b) for j, a, b in links if np.linalg.norm(b - a) > 1e-9]
        length = sum(float(np.linalg.norm(b - a)) for _, a, b in self.links)
        self.size = length if length > 0 else 1.0
        shortest = min((float(np.linalg.norm(b - a)) for _, a, b in self.links), default=self.size)
        # Thin enough that joints do not merge on arms of many short links (planar50: 2 cm links).
        self.joint_radius = min(0.016 * self.size, 0.25 * shortest)
        self.link_radius = min(0.008 * self.size, 0.5 * self.joint_radius)
        self.effector_radius = 0.02 * self.size
        self._joint_paths = [self.joint_path(j) for j in range(1, self.n_joints + 1)]

    def _rails(self, target: KinematicTarget) -> list[tuple[int, NDArray[np.float64], NDArray[np.float64]]]:
        """A stroke along each prismatic joint's travel, in its parent's frame: (parent, start, end).

        A prismatic joint's motion is no link (its placement is fixed, the slide comes after it), so
        without this stroke the joint's sphere moved through empty space. The rail spans the joint's
        limits (0.3 of the arm's other links' length each way where a limit is infinite).
        """
        from gb_pin.learn.body.joints import PRISMATIC

        joints = self._joints
        fixed = sum(float(np.linalg.norm(t)) for t in joints.translations) or 1.0
        lower = np.asarray(target.lower, dtype=float)
        upper = np.asarray(target.upper, dtype=float)
        rails = []
        for i in range(self.n_joints):
            if int(joints.kinds[i]) != PRISMATIC:
                continue
            k = int(joints.q_index[i])
            lo = lower[k] if np.isfinite(lower[k]) else -0.3 * fixed
            hi = upper[k] if np.isfinite(upper[k]) else 0.3 * fixed
            direction = np.asarray(joints.rotations[i], dtype=float) @ np.asarray(joints.axes[i], dtype=float)
            origin = np.asarray(joints.translations[i], dtype=float)
            rails.append((int(joints.parents[i]) + 1, origin + lo * direction, origin + hi * direction))
        return rails

    def joint_path(self, j: int) -> str:
        """meshcat path of joint ``j``'s node (``j`` = 0: the fixed base)."""
        return f"{self.root}/base" if j == 0 else f"{self.root}/j{j}"

    @property
    def effector_path(self) -> str:
        """meshcat path of the operational frame's marker."""
        return f"{self.root}/effector"

    def effector_marker(self) -> Any:
        """Command drawing the operational frame's sphere."""
        return shapes.sphere(
            f"{self.effector_path}/sphere", self.effector_radius, shapes.lambert(EFFECTOR_COLOR)
        )

    def load(self, window: Window) -> None:
        """Send the geometry (once)."""
        joint_material, link_material = shapes.lambert(JOINT_COLOR), shapes.lambert(LINK_COLOR)
        for j in range(1, self.n_joints + 1):
            window.send(shapes.sphere(f"{self.joint_path(j)}/joint", self.joint_radius, joint_material))
        for i, (j, a, b) in enumerate(self.links):
            d = b - a
            p = f"{self.joint_path(j)}/link{i}"
            window.send(shapes.cylinder(p, float(np.linalg.norm(d)), self.link_radius, link_material))
            T = translation((a + b) / 2.0)
            T[:3, :3] = align_y(d)
            window.send(shapes.place(p, T))
        window.send(self.effector_marker())

    def _forward(self, q: NDArray[np.float64]) -> None:
        """Each joint's world rotation and position at posture ``q`` (the learner's compiled kinematics)."""
        joints_forward(
            np.ascontiguousarray(q, dtype=np.float64), self._joints, self._rotations, self._positions
        )

    def _joint_pose(self, j: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World rotation and position of joint ``j`` after :meth:`_forward` (the world for ``j`` = 0)."""
        if j == 0:
            return np.eye(3), np.zeros(3)
        return self._rotations[j - 1], self._positions[j - 1]

    def _effector_transform(self) -> NDArray[np.float64]:
        """World transform of the operational frame after :meth:`_forward`."""
        R, p = self._joint_pose(self._frame_joint)
        T = np.eye(4)
        T[:3, :3] = R @ self._frame_rotation
        T[:3, 3] = R @ self._frame_translation + p
        return T

    def effector_transform(self, q: NDArray[np.float64]) -> tuple[str, NDArray[np.float64]]:
        """(path, world transform) of the operational frame's marker at posture ``q``."""
        self._forward(q)
        return self.effector_path, self._effector_transform()

    def transforms(self, q: NDArray[np.float64]) -> Transforms:
        """(path, world transform) of each moving node at posture ``q``; the effector's comes last."""
        self._forward(q)
        T = np.zeros((self.n_joints, 4, 4))
        T[:, :3, :3] = self._rotations
        T[:, :3, 3] = self._positions
        T[:, 3, 3] = 1.0
        out: Transforms = list(zip(self._joint_paths, T, strict=True))
        out.append((self.effector_path, self._effector_transform()))
        return out

    def skeleton(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(2S, 3) endpoints of the links at posture ``q`` (world frame) [m]."""
        self._forward(q)
        pts = []
        for j, a, b in self.links:
            R, p = self._joint_pose(j)
            pts.append(R @ a + p)
            pts.append(R @ b + p)
        return np.array(pts)

    def outline(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """(P, 3) points the camera frames at posture ``q`` [m]: the links' endpoints."""
        return self.skeleton(q)

    def effector(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """3-D position of the operational frame at ``q`` [m]."""
        self._forward(q)
        return self._effector_transform()[:3, 3].copy()
