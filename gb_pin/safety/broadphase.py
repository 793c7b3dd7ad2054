"""The checker's prefilter, compiled: which checked pairs' bounding spheres come within the clearance.

For a batch of postures at once (the samples of a segment), each posture's joint frames from the
learner's compiled forward kinematics (:func:`gb_pin.learn.body.joints.joints_forward`, the same
arrays as the reduced Pinocchio model), each shape's bounding-sphere centre placed by its joint,
and each checked pair's gap: centre distance less both radii (two shapes), or the centre's
distance from the obstacle less the shape's radius (a table: height above it; a box: distance
from the box; a sphere: distance from the surface). Only pairs whose gap is below the clearance
(plus :data:`SLACK`) go to coal, which decides. The spheres contain their shapes, so the prefilter
never drops a pair coal would find within the clearance.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import njit
from gb_pin.learn.body.joints import joints_forward

TABLE, BOX, SPHERE = 0, 1, 2
SLACK = 1e-9
"""Added to the clearance [m]: rounding in the forward kinematics never drops a pair."""


class Spheres(NamedTuple):
    """The shapes' bounding spheres, the checked pairs and the obstacles (what the prefilter takes).

    Attributes:
        chain_of: (s,) each shape's joint (index into the chain), -1: fixed to the world.
        centres: (s, 3) each sphere's centre in its joint frame (the world for -1).
        radii: (s,) the spheres' radii.
        pair_a: (P,) a shape of each checked pair.
        pair_b: (P,) the other: a shape, or b >= s for obstacle b - s.
        kind: per obstacle TABLE, BOX or SPHERE.
        where: (obstacles, 3) its centre (a table: its height in where[o, 2]).
        size: (obstacles, 3) a box's half extents, a sphere's radius in size[o, 0].
    """

    chain_of: NDArray[np.int64]
    centres: NDArray[np.float64]
    radii: NDArray[np.float64]
    pair_a: NDArray[np.int64]
    pair_b: NDArray[np.int64]
    kind: NDArray[np.int64]
    where: NDArray[np.float64]
    size: NDArray[np.float64]


@njit(cache=True, nogil=True, error_model="numpy")
def sphere_candidates(Q, joints, rot_ws, pos_ws, spheres, threshold, out):  # type: ignore[no-untyped-def]
    """out[k, p]: whether pair p's bounding spheres come within ``threshold`` at posture Q[k].

    Args:
        Q: (n, m) postures.
        joints: the chain (:class:`~gb_pin.learn.body.joints.Joints`).
        rot_ws: (m, 3, 3) scratch.
        pos_ws: (m, 3) scratch.
        spheres: the shapes, pairs and obstacles (:class:`Spheres`).
        threshold: the clearance (and :data:`SLACK`) [m].
        out: (n, P) bool.
    """
    chain_of, centres, radii, pair_a, pair_b, kind, where, size = spheres
    s = centres.shape[0]
    world = np.empty((s, 3))
    for k in range(Q.shape[0]):
        joints_forward(Q[k], joints, rot_ws, pos_ws)
        for i in range(s):
            j = chain_of[i]
            c0, c1, c2 = centres[i, 0], centres[i, 1], centres[i, 2]
            if j < 0:
                world[i, 0], world[i, 1], world[i, 2] = c0, c1, c2
            else:
                r = rot_ws[j]
                world[i, 0] = r[0, 0] * c0 + r[0, 1] * c1 + r[0, 2] * c2 + pos_ws[j, 0]
                world[i, 1] = r[1, 0] * c0 + r[1, 1] * c1 + r[1, 2] * c2 + pos_ws[j, 1]
                world[i, 2] = r[2, 0] * c0 + r[2, 1] * c1 + r[2, 2] * c2 + pos_ws[j, 2]
        for p in range(pair_a.shape[0]):
            a = pair_a[p]
            b = pair_b[p]
            if b < s:
                d0 = world[a, 0] - world[b, 0]
                d1 = world[a, 1] - world[b, 1]
                d2 = world[a, 2] - world[b, 2]
                gap = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) - radii[a] - radii[b]
            else:
                o = b - s
                if kind[o] == TABLE:
                    dist = world[a, 2] - where[o, 2]
                elif kind[o] == BOX:
                    e0 = max(abs(world[a, 0] - where[o, 0]) - size[o, 0], 0.0)
                    e1 = max(abs(world[a, 1] - where[o, 1]) - size[o, 1], 0.0)
                    e2 = max(abs(world[a, 2] - where[o, 2]) - size[o, 2], 0.0)
                    dist = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
                else:
                    d0 = world[a, 0] - where[o, 0]
                    d1 = world[a, 1] - where[o, 1]
                    d2 = world[a, 2] - where[o, 2]
                    dist = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) - size[o, 0]
                gap = dist - radii[a]
            out[k, p] = gap < threshold
