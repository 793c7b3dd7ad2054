"""Seeded random rigid placements shared by the kinematics tests."""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """Rotation matrix of a uniformly random unit quaternion drawn from ``rng``."""
    quaternion = rng.normal(size=4)
    w, x, y, z = quaternion / np.linalg.norm(quaternion)
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    return R


def random_placement(rng: np.random.Generator, scale: float = 0.4) -> pin.SE3:
    return pin.SE3(random_rotation(rng), rng.uniform(-scale, scale, 3))
