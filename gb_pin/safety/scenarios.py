"""The scenes of issue 34, as data: the SO-101 by its table around a post, a Panda with a table and a box.

The SO-101's two scenes: the issue's (its post at (0.21, 0, 0.045) m) and our earlier one (post at x
= 0.26 m among a tighter grid: three times as obstructed, docs/SAFETY.md).

Used by ``scripts/safe_babbling.py`` (the acceptance runs) and the tests.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin.safety.obstacles import Box, Obstacle, Table


class Scene(NamedTuple):
    """A robot preset, its obstacles, its goals [m], a servo gain for its MuJoCo plant [N m/rad], its speed.

    ``speed``: the plant's ``speed`` [rad/s] (its servo targets move along each ask's segment), None:
    they jump to each ask.
    """

    robot: str
    obstacles: tuple[Obstacle, ...]
    goals: NDArray[np.float64]
    kp: float
    speed: float | None = None


SO101_POST = Box((0.26, 0.0, 0.045), (0.02, 0.02, 0.045))
"""A 4 x 4 x 9 cm post standing on the SO-101's table, in the middle of its goal region."""


def so101_scene() -> Scene:
    """Goals 1 to 8 cm above the table the SO-101 stands on (z = 0), around the post.

    A 5 x 5 x 3 grid over x 0.19-0.33 m, y +-0.07 m, z 0.01-0.08 m, less the goals within 3 cm of the
    post (the gripper cannot be there): 48 goals. Servos of kp 100 N m/rad sag 1.9 mm at home, within
    the clearance (kp 10 sags 18 mm: the checked posture would not be where the arm is).
    """
    g = np.mgrid[0.19:0.33:5j, -0.07:0.07:5j, 0.01:0.08:3j].reshape(3, -1).T
    return Scene("so101", (Table(0.0), SO101_POST), g[~SO101_POST.contains(g, margin=0.03)], 100.0)


ISSUE_POST = Box((0.21, 0.0, 0.045), (0.02, 0.02, 0.045))
"""The issue's own post (its CLI example ``box:center=0.21,0,0.045,half=0.02,0.02,0.045``)."""


def so101_issue_scene(half_width: float = 0.15) -> Scene:
    """Goals 1 to 8 cm above the table around the issue's post at (0.21, 0): 72 goals.

    A 5 x 5 x 3 grid over x 0.21 +- ``half_width``, y +- ``half_width``, z 0.01-0.08 m, centred on
    the post, less the goals within 3 cm of it. The half-width 0.15 m is the one whose run without
    obstacles is as obstructed as the issue measured its scene (``scripts/scene_obstruction.py``).

    Raises:
        InvalidArgumentError: ``half_width`` not a positive number.
    """
    h = check.positive_float("half_width", half_width)
    g = np.mgrid[0.21 - h : 0.21 + h : 5j, -h:h:5j, 0.01:0.08:3j].reshape(3, -1).T
    return Scene("so101", (Table(0.0), ISSUE_POST), g[~ISSUE_POST.contains(g, margin=0.03)], 100.0)


PANDA_BOX = Box((0.40, 0.09, 0.40), (0.04, 0.04, 0.04))
"""An 8 cm cube among the Panda's goals (between its grid points), in the way of its movements."""


def panda_scene() -> Scene:
    """The Panda's preset goals (3 x 3 x 3, half-width 0.185 m around home) over a table at z = 0, a box.

    Servos of kp 3000 N m/rad sag 4.0 mm at home (kp 1000: 12 mm), within the clearance. Their targets
    move at 1 rad/s along each ask's segment: made to jump 0.5 rad at once, the stiff arm left the checked
    segment by more than the clearance (the hand touched the box, 1 mm deep, seed 0 of 10^4 movements).
    """
    from gb_pin.robot.presets import load_robot

    goals = load_robot("panda").targets
    assert goals is not None
    return Scene("panda", (Table(0.0), PANDA_BOX), goals, 3000.0, speed=1.0)


SCENES: dict[str, Callable[[], Scene]] = {
    "so101-issue": so101_issue_scene,
    "so101": so101_scene,
    "panda": panda_scene,
}
"""The scenes by name (``scripts/safe_babbling.py --robots``, ``scripts/scene_obstruction.py --scene``)."""
