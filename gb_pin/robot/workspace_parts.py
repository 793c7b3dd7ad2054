"""A workspace region in parts: sectors around the first joint's axis, a home and goals for each.

``targets="workspace:fraction=0.5,parts=2"`` learns the region with two learners, one per side of
the arm (:mod:`gb_pin.learn.parts`): a single-valued inverse must switch branches behind a
turning arm, and the reference measurements found one learner per side the only idea that
lowers the error there (docs/WORKSPACE.md).

Robot-agnostic, from forward kinematics alone:

- the axis: the circle the hand draws when the first joint turns (three postures: home with the
  first joint at a quarter, half and three quarters of its window), its centre o and plane
  (u towards the hand at home, v the direction in which the first joint's turn moves it);
- the parts: P sectors of the angle around that axis, cut at the angles that split the region's
  goal points into equal counts (for P = 2 one cut runs through the front, near home's direction,
  the other behind: left and right of the arm);
- the home of part p: the median (per joint) of the postures of its goal points;
- its goals: the region's goal postures of the part, the curriculum's stage s drawn towards the
  part's home (q = home_p + (f_s / f) (q - home_p)), so each learner grows its part from its home.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.parts import Sectors
from gb_pin.robot.workspace import AUTO, WorkspaceRegion, _model, forward_all, region_postures, window

AUTO_SPAN = np.pi  # parts=auto: 2 parts where the goals' 5-95 % angles around the axis span more than this


class RegionParts(NamedTuple):
    """What each learner of a region in parts learns.

    Attributes:
        sectors: the rule routing a point to its part.
        homes: (P, m) each part's home posture.
        goals: P goal sets (stages * N_p, n), the curriculum's blocks from the part's home outwards.
    """

    sectors: Sectors
    homes: NDArray[np.float64]
    goals: list[NDArray[np.float64]]


Vector = NDArray[np.float64]


def turn_axis(robot: Any, fraction: float) -> tuple[Vector, Vector, Vector]:
    """(o, u, v): the centre and plane of the circle the hand draws as the first joint turns.

    Raises:
        InvalidArgumentError: the hand does not circle (a first joint that does not turn, or a hand
            on its axis).
    """
    model = _model(robot)
    low, width = window(robot, fraction)
    Q = np.tile(np.asarray(model.home, dtype=float), (3, 1))
    Q[:, 0] = low[0] + width[0] * np.array([0.25, 0.5, 0.75])
    p = forward_all(robot, Q)
    A, B = p[0] - p[1], p[2] - p[1]
    G = np.array([[A @ A, A @ B], [A @ B, B @ B]])
    scale = max(float(A @ A), float(B @ B), 1e-300)
    if abs(np.linalg.det(G)) <= 1e-9 * scale**2:
        raise InvalidArgumentError(
            "a workspace region in parts splits it around the first joint's axis, but the hand does not "
            "circle when the first joint turns (a prismatic or still first joint, or the hand on its axis): "
            "use parts=1"
        )
    alpha, beta = np.linalg.solve(G, [A @ A / 2.0, B @ B / 2.0])
    centre = p[1] + alpha * A + beta * B
    home_position = forward_all(robot, np.asarray(model.home, dtype=float)[None, :])[0]
    u = home_position - centre
    plane = _unit(A, B)
    u = plane[0] * (u @ plane[0]) + plane[1] * (u @ plane[1])  # projected into the circle's plane
    if not np.linalg.norm(u) > 0.0:
        u = p[1] - centre
    u /= np.linalg.norm(u)
    v = plane[0] * (plane[0] @ B) + plane[1] * (plane[1] @ B)  # towards the turn's positive side
    v -= (v @ u) * u
    v /= np.linalg.norm(v)
    return centre, u, v


def _unit(A: NDArray[np.float64], B: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """An orthonormal basis of the plane spanned by A and B."""
    e1 = A / np.linalg.norm(A)
    e2 = B - (B @ e1) * e1
    return e1, e2 / np.linalg.norm(e2)


def region_parts(robot: Any, region: WorkspaceRegion) -> RegionParts:
    """The parts of ``region`` (``region.parts`` sectors), each part's home and curriculum goals.

    Raises:
        InvalidArgumentError: the first joint does not turn the hand, or a part holds fewer than
            two goal points.
    """
    model = _model(robot)
    P = region.parts
    u = np.random.default_rng(region.seed).random((region.points, np.asarray(model.home).shape[0]))
    Q = region_postures(robot, region.fraction, u)
    X = forward_all(robot, Q)
    origin, du, dv = turn_axis(robot, region.fraction)
    probe = Sectors(origin, du, dv, np.zeros(0))
    angle = probe.angle(X)
    edges = np.quantile(angle, np.arange(1, P) / P) if P > 1 else np.zeros(0)
    sectors = Sectors.checked(origin, du, dv, edges, X.shape[1])
    part = sectors.part_of(X)
    lower, upper = np.asarray(model.lower, dtype=float), np.asarray(model.upper, dtype=float)
    homes, goals = [], []
    for p in range(P):
        Qp = Q[part == p]
        if Qp.shape[0] < 2:
            raise InvalidArgumentError(
                f"part {p} of the workspace region holds {Qp.shape[0]} of its {region.points} goal points: "
                "give more points or fewer parts"
            )
        home = np.clip(np.median(Qp, axis=0), lower, upper)
        blocks = [home + (f / region.fraction) * (Qp - home) for f in region.stage_fractions()]
        homes.append(home)
        goals.append(forward_all(robot, np.vstack(blocks)))
    return RegionParts(sectors, np.array(homes), goals)


def auto_parts(robot: Any, region: WorkspaceRegion) -> int:
    """The parts of ``region``: as given, or for ``parts=auto`` 2 where it wraps around the first axis.

    The region wraps when the 5-95 % percentiles of its goal points' angles around the axis span
    more than :data:`AUTO_SPAN` (half a turn): points behind the arm, where one inverse must switch
    branches. At fraction 0.5 the Panda's span 260 deg and the UR5's 234 deg; the SO-101's 100, the
    TALOS left arm's 94, the G1 left arm's 166 (docs/WORKSPACE.md). A robot whose hand does not
    circle as the first joint turns, that has no compiled kinematics, or whose task is stacked (a
    pose, two hands) gets 1.
    """
    if region.parts != AUTO:
        return region.parts
    model = _model(robot)
    if getattr(model, "chain", None) is None or getattr(model.chain, "components", None) is not None:
        return 1  # no compiled kinematics, or a stacked task (pose, two hands): one learner
    try:
        origin, u, v = turn_axis(robot, region.fraction)
    except InvalidArgumentError:
        return 1
    angle = Sectors(origin, u, v, np.zeros(0)).angle(region.final_goals(robot))
    low, high = np.percentile(angle, [5.0, 95.0])
    return 2 if high - low > AUTO_SPAN else 1
