"""The checker's prefilter, compiled: which checked pairs' bounding spheres come within the clearance.

For a batch of postures at once (the samples of a segment), each posture's joint frames from the
learner's compiled forward kinematics (:func:`gb_pin.learn.body.joints.joints_forward`, the same
arrays as the reduced Pinocchio model), each shape's bounding-sphere centre placed by its joint,
and each checked pair's gap: centre distance less both radii (two shapes), or the centre's
distance from the obstacle less the shape's radius (a table: height above it; a box: distance
from the box; a sphere: distance from the surface). Only pairs whose gap is below the clearance
(plus :data:`SLACK`) go to coal, which decides. The spheres contain their shapes, so the prefilter
never drops a pair coal would find within the clearance.

A shape near an obstacle gets a second, tighter test before coal (:func:`first_candidate`): its
points (a convex hull's vertices, a box's corners, a capsule's two ends, a sphere's centre, each
inflated by ``inflate``: the capsule's or sphere's radius) placed in the world. Against a table
the lowest of them is the shape's exact height above it; against a box, the gap between the box
and the points' axis-aligned bounds is a lower bound of their distance. Both only prove pairs
clear (never drop one coal would find within the clearance): the arm working a few centimetres
above its table no longer sends every sample to coal.

:func:`first_candidate` walks a segment's samples in compiled code and stops at the first one with
a pair not proven clear, so that Python (Pinocchio, coal) sees only those samples.
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
        points: (T, 3) the shapes' points in their joint frames (see the module docstring).
        first: (s + 1,) shape i's points are points[first[i]:first[i + 1]] (none: the sphere alone).
        inflate: (s,) the radius around shape i's points that the shape stays within [m].
        corners: (s, 8, 3) the corners of the box that bounds shape i's points in its joint frame
            (tested first: 8 points instead of a hull's hundreds).
        coarse: (C, 3) a few dozen of each shape's points (farthest-point sampled), tested next.
        coarse_first: (s + 1,) shape i's are coarse[coarse_first[i]:coarse_first[i + 1]].
        coarse_inflate: (s,) the radius around them that holds the shape (inflate plus the
            farthest any point lies from the nearest of them).
    """

    chain_of: NDArray[np.int64]
    centres: NDArray[np.float64]
    radii: NDArray[np.float64]
    pair_a: NDArray[np.int64]
    pair_b: NDArray[np.int64]
    kind: NDArray[np.int64]
    where: NDArray[np.float64]
    size: NDArray[np.float64]
    points: NDArray[np.float64]
    first: NDArray[np.int64]
    inflate: NDArray[np.float64]
    corners: NDArray[np.float64]
    coarse: NDArray[np.float64]
    coarse_first: NDArray[np.int64]
    coarse_inflate: NDArray[np.float64]


class Scratch(NamedTuple):
    """The arrays :func:`first_candidate` works in (``mask`` holds its answer's pairs)."""

    rot_ws: NDArray[np.float64]  # (m, 3, 3) joint rotations
    pos_ws: NDArray[np.float64]  # (m, 3) joint positions
    q: NDArray[np.float64]  # (m,) the sample
    mask: NDArray[np.bool_]  # (P,) the pairs not proven clear
    world: NDArray[np.float64]  # (s, 3) sphere centres
    bounds: NDArray[np.float64]  # (s, 6) a shape's points' bounds in the world
    boxes: NDArray[np.float64]  # (s, 8, 3) a shape's bounding box's corners in the world
    boxed: NDArray[np.bool_]  # (s,) whether boxes[i] is this sample's


def scratch(m: int, pairs: int, shapes: int) -> Scratch:
    """Scratch arrays for ``m`` joints, ``pairs`` checked pairs and ``shapes`` robot shapes."""
    return Scratch(
        np.empty((m, 3, 3)), np.empty((m, 3)), np.empty(m), np.zeros(pairs, dtype=np.bool_),
        np.empty((shapes, 3)), np.empty((shapes, 6)), np.empty((shapes, 8, 3)),
        np.zeros(shapes, dtype=np.bool_),
    )  # fmt: skip


@njit(cache=True, nogil=True, error_model="numpy")
def first_candidate(a, b, n, k0, joints, spheres, threshold, ws):  # type: ignore[no-untyped-def]
    """The first sample k >= k0 of the segment a -> b in n steps with a checked pair not proven clear.

    Sample k is ``a + (k / n) * (b - a)`` (sample n is ``b``); a pair is proven clear when its
    bounding spheres, or its shape's points against an obstacle, keep ``threshold`` apart.

    Args:
        a: (m,) the segment's start.
        b: (m,) its end.
        n: its samples.
        k0: the first sample to look at (1 for a whole segment).
        joints: the chain (:class:`~gb_pin.learn.body.joints.Joints`).
        spheres: the shapes, pairs and obstacles (:class:`Spheres`).
        threshold: the clearance (and :data:`SLACK`) [m].
        ws: :class:`Scratch`; ``ws.mask``: at the sample returned, the pairs not proven clear.

    Returns:
        That sample's k, or n + 1 when every sample from k0 on is proven clear.
    """
    m = a.shape[0]
    q = ws.q
    for k in range(k0, n + 1):
        if k == n:
            for j in range(m):
                q[j] = b[j]
        else:
            t = k / n
            for j in range(m):
                q[j] = a[j] + t * (b[j] - a[j])
        if _mark(q, joints, spheres, threshold, ws):
            return k
    return n + 1


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _mark(q, joints, spheres, threshold, ws):  # type: ignore[no-untyped-def]
    """ws.mask[p]: pair p is not proven clear at posture q; whether any is."""
    chain_of, centres, radii, pair_a, pair_b, kind, where, size, points, first, inflate = spheres[:11]
    corners, coarse, coarse_first, coarse_inflate = spheres[11:]
    rot_ws, pos_ws, _, mask, world, bounds, boxes, boxed = ws
    s = centres.shape[0]
    joints_forward(q, joints, rot_ws, pos_ws)
    for i in range(s):
        boxed[i] = False
        j = chain_of[i]
        c0, c1, c2 = centres[i, 0], centres[i, 1], centres[i, 2]
        if j < 0:
            world[i, 0], world[i, 1], world[i, 2] = c0, c1, c2
        else:
            r = rot_ws[j]
            world[i, 0] = r[0, 0] * c0 + r[0, 1] * c1 + r[0, 2] * c2 + pos_ws[j, 0]
            world[i, 1] = r[1, 0] * c0 + r[1, 1] * c1 + r[1, 2] * c2 + pos_ws[j, 1]
            world[i, 2] = r[2, 0] * c0 + r[2, 1] * c1 + r[2, 2] * c2 + pos_ws[j, 2]
    found = False
    for p in range(pair_a.shape[0]):
        a = pair_a[p]
        b = pair_b[p]
        if b < s:
            d0 = world[a, 0] - world[b, 0]
            d1 = world[a, 1] - world[b, 1]
            d2 = world[a, 2] - world[b, 2]
            gap = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) - radii[a] - radii[b]
            if gap < threshold and first[a + 1] > first[a] and first[b + 1] > first[b]:
                for i in (a, b):  # the two bounding boxes, separated along one of their 6 axes?
                    if not boxed[i]:
                        _place_box(corners[i], chain_of[i], rot_ws, pos_ws, boxes[i])
                        boxed[i] = True
                gap = max(gap, _box_gap(boxes[a], boxes[b]) - inflate[a] - inflate[b])
        else:
            o = b - s
            gap = _obstacle_gap(world[a], radii[a], kind[o], where[o], size[o])
            if gap < threshold and first[a + 1] > first[a] and chain_of[a] >= 0:
                # the bounding box, then a few dozen of the points (grown to hold the others), then all
                j = chain_of[a]
                for stage in range(3):
                    if stage == 0:
                        _bounds(corners[a], 0, 8, rot_ws[j], pos_ws[j], bounds[a])
                    elif stage == 1:
                        _bounds(coarse, coarse_first[a], coarse_first[a + 1], rot_ws[j], pos_ws[j], bounds[a])
                    else:
                        _bounds(points, first[a], first[a + 1], rot_ws[j], pos_ws[j], bounds[a])
                    grow = coarse_inflate[a] if stage == 1 else inflate[a]
                    gap = _points_gap(bounds[a], grow, kind[o], where[o], size[o], gap)
                    if gap >= threshold:
                        break
                    if stage == 1 and (
                        _nearest(coarse, coarse_first[a], coarse_first[a + 1], rot_ws[j], pos_ws[j], kind[o],
                                 where[o], size[o]) - inflate[a] < threshold
                    ):  # fmt: skip
                        break  # some of the shape's own points are that close: coal decides, no need for all
        mask[p] = gap < threshold
        found = found or mask[p]
    return found


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _obstacle_gap(c, radius, kind, where, size):  # type: ignore[no-untyped-def]
    """The gap between a bounding sphere (centre c, radius) and an obstacle."""
    if kind == TABLE:
        dist = c[2] - where[2]
    elif kind == BOX:
        e0 = max(abs(c[0] - where[0]) - size[0], 0.0)
        e1 = max(abs(c[1] - where[1]) - size[1], 0.0)
        e2 = max(abs(c[2] - where[2]) - size[2], 0.0)
        dist = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    else:
        d0 = c[0] - where[0]
        d1 = c[1] - where[1]
        d2 = c[2] - where[2]
        dist = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2) - size[0]
    return dist - radius


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _bounds(points, lo, hi, r, t, out):  # type: ignore[no-untyped-def]
    """out: min x, y, z then max x, y, z of points[lo:hi] placed by rotation r and translation t."""
    for axis in range(3):
        out[axis] = np.inf
        out[3 + axis] = -np.inf
    for i in range(lo, hi):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        for axis in range(3):
            v = r[axis, 0] * x + r[axis, 1] * y + r[axis, 2] * z + t[axis]
            out[axis] = min(out[axis], v)
            out[3 + axis] = max(out[3 + axis], v)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _nearest(points, lo, hi, r, t, kind, where, size):  # type: ignore[no-untyped-def]
    """The smallest distance of points[lo:hi] (placed by r, t) from an obstacle (< 0: inside)."""
    best = np.inf
    for i in range(lo, hi):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        p0 = r[0, 0] * x + r[0, 1] * y + r[0, 2] * z + t[0]
        p1 = r[1, 0] * x + r[1, 1] * y + r[1, 2] * z + t[1]
        p2 = r[2, 0] * x + r[2, 1] * y + r[2, 2] * z + t[2]
        if kind == TABLE:
            d = p2 - where[2]
        elif kind == BOX:
            e0 = max(abs(p0 - where[0]) - size[0], 0.0)
            e1 = max(abs(p1 - where[1]) - size[1], 0.0)
            e2 = max(abs(p2 - where[2]) - size[2], 0.0)
            d = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        else:
            d = np.sqrt((p0 - where[0]) ** 2 + (p1 - where[1]) ** 2 + (p2 - where[2]) ** 2) - size[0]
        best = min(best, d)
    return best


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _points_gap(bounds, inflate, kind, where, size, gap):  # type: ignore[no-untyped-def]
    """A lower bound of a shape's distance from an obstacle from its points' bounds (the larger of two)."""
    if kind == TABLE:
        tight = bounds[2] - inflate - where[2]  # exact: the lowest point
    elif kind == BOX:
        e0 = max(where[0] - size[0] - bounds[3], bounds[0] - where[0] - size[0], 0.0)
        e1 = max(where[1] - size[1] - bounds[4], bounds[1] - where[1] - size[1], 0.0)
        e2 = max(where[2] - size[2] - bounds[5], bounds[2] - where[2] - size[2], 0.0)
        tight = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2) - inflate
    else:
        return gap
    return max(gap, tight)


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _place_box(corners, j, rot_ws, pos_ws, out):  # type: ignore[no-untyped-def]
    """out (8, 3): the corners (joint frame) placed in the world by joint j (-1: the world itself)."""
    for c in range(8):
        x, y, z = corners[c, 0], corners[c, 1], corners[c, 2]
        if j < 0:
            out[c, 0], out[c, 1], out[c, 2] = x, y, z
        else:
            r = rot_ws[j]
            t = pos_ws[j]
            for axis in range(3):
                out[c, axis] = r[axis, 0] * x + r[axis, 1] * y + r[axis, 2] * z + t[axis]


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _box_gap(p, q):  # type: ignore[no-untyped-def]
    """A lower bound of the distance between two boxes given by their corners (8, 3) in the world.

    The largest gap between their projections on the boxes' own edge directions (a separating
    axis: the distance is at least the gap along any unit direction).
    """
    best = -np.inf
    for box in range(2):
        c = p if box == 0 else q
        for e in (1, 2, 4):  # corners 0 and 1, 2, 4 differ along one edge of the box
            u0 = c[e, 0] - c[0, 0]
            u1 = c[e, 1] - c[0, 1]
            u2 = c[e, 2] - c[0, 2]
            norm = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
            if norm < 1e-12:
                continue
            u0, u1, u2 = u0 / norm, u1 / norm, u2 / norm
            lo_p = hi_p = p[0, 0] * u0 + p[0, 1] * u1 + p[0, 2] * u2
            lo_q = hi_q = q[0, 0] * u0 + q[0, 1] * u1 + q[0, 2] * u2
            for k in range(1, 8):
                vp = p[k, 0] * u0 + p[k, 1] * u1 + p[k, 2] * u2
                vq = q[k, 0] * u0 + q[k, 1] * u1 + q[k, 2] * u2
                lo_p, hi_p = min(lo_p, vp), max(hi_p, vp)
                lo_q, hi_q = min(lo_q, vq), max(hi_q, vq)
            best = max(best, lo_q - hi_p, lo_p - hi_q)
    return best
