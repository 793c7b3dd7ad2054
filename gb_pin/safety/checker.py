"""Is a posture safe, and how far along a joint-space segment can the arm go safely?

:class:`CollisionChecker` holds the robot's collision shapes (:mod:`gb_pin.safety.geometry`), the
pairs of them its collision matrix keeps (:mod:`gb_pin.safety.matrix`) and the obstacles
(:mod:`gb_pin.safety.obstacles`, checked against every shape that moves: the links fixed to the world,
a base standing on the table, are not). A posture is safe when no checked pair comes within the
clearance (coal's security margin); coal sees only the pairs whose bounding spheres come that close
(:mod:`gb_pin.safety.broadphase`, compiled, all of a segment's samples at once). A straight
joint-space segment is checked at postures so close that no point of the arm moves more than the
clearance between two of them (a bound from the joints' lever arms), so a segment whose samples are
safe never touches (each pair's bound counts only the joints that move its two shapes apart).
Called as ``checker(q_from, q_to)`` it is the guard of an ask/tell run
(:class:`gb_pin.learn.asktell.AskTell`): None when the segment is safe, else the last safe posture,
where the movement is cut short.
"""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError, UnsafeSetupError
from gb_pin.safety.broadphase import BOX, SLACK, SPHERE, TABLE, Spheres, first_candidate, scratch
from gb_pin.safety.geometry import RobotGeometry, robot_geometry
from gb_pin.safety.matrix import DEFAULT_SAMPLES, CollisionMatrix, apply_srdf, cached_matrix
from gb_pin.safety.obstacles import Box, Obstacle, Sphere, Table, check_obstacles

DEFAULT_CLEARANCE = 0.01
"""The default clearance [m] between checked shapes."""
MAX_SEGMENT_SAMPLES = 10**5
COARSE_POINTS = 32
"""Points per shape in the prefilter's middle test (:class:`~gb_pin.safety.broadphase.Spheres`)."""


def _coal_shape(obstacle: Obstacle) -> tuple[Any, Any]:
    import coal
    import pinocchio as pin

    if isinstance(obstacle, Table):
        return coal.Halfspace(np.array([0.0, 0.0, 1.0]), obstacle.height), pin.SE3.Identity()
    if isinstance(obstacle, Box):
        half = np.asarray(obstacle.half_extents)
        return coal.Box(*(2 * half)), pin.SE3(np.eye(3), np.asarray(obstacle.center))
    return coal.Sphere(obstacle.radius), pin.SE3(np.eye(3), np.asarray(obstacle.center))


class CollisionChecker:
    """Self-collision and obstacles of a :class:`~gb_pin.robot.target.KinematicTarget`.

    Args:
        target: the robot (its reduced model moves the shapes).
        obstacles: Table, Box, Sphere (world frame [m]).
        self_collision: check the robot's own shapes against each other (through the matrix).
        geometry: ``"urdf"`` (the URDF's collision shapes, meshes as convex hulls) or ``"capsules"``.
        clearance: the margin [m] every checked pair keeps.
        capsule_radius: the capsules' radius [m] (``geometry="capsules"``).
        srdf: an SRDF whose ``<disable_collisions>`` pairs are not checked.
        samples: postures sampled to generate the collision matrix.
        matrix: a matrix to use instead of the cached/generated one.
        slide: an unsafe ask goes to the last safe posture of its straight move, then slides joint by
            joint along what it touched (:meth:`slide_posture`); False: it stops at the last safe one.

    Raises:
        UnsafeSetupError: no collision geometry (and no capsules asked), or nothing to check.
        InvalidArgumentError: a bad argument.
    """

    def __init__(
        self,
        target: Any,
        obstacles: Any = (),
        *,
        self_collision: bool = False,
        geometry: str = "urdf",
        clearance: float = DEFAULT_CLEARANCE,
        capsule_radius: float = 0.025,
        srdf: str | os.PathLike[str] | None = None,
        samples: int = DEFAULT_SAMPLES,
        matrix: CollisionMatrix | None = None,
        slide: bool = True,
    ) -> None:
        import pinocchio as pin

        self.target = target
        self.obstacles = check_obstacles(obstacles)
        self.clearance = check.positive_float("clearance", clearance)
        self.self_collision = bool(self_collision)
        if not self.obstacles and not self_collision:
            raise UnsafeSetupError("nothing to check: give obstacles or self_collision=True")
        self.geometry: RobotGeometry = robot_geometry(
            target, geometry, check.positive_float("capsule_radius", capsule_radius)
        )
        self.matrix: CollisionMatrix | None = None
        k = len(self.geometry.body)
        gm = self.geometry.model.copy()
        gm.removeAllCollisionPairs()
        if self_collision:
            samples = check.positive_int("samples", samples, 1, 10**7)
            self.matrix = (
                matrix
                if matrix is not None
                else cached_matrix(target, self.geometry, self.clearance, samples)
            )
            if srdf is not None:
                self.matrix = apply_srdf(self.matrix, self.geometry, srdf)
            for i, j in self.matrix.pairs:
                gm.addCollisionPair(pin.CollisionPair(i, j))
        moving = [s for s in range(k) if self.geometry.body[s] >= 0]
        for o, obstacle in enumerate(self.obstacles):
            shape, placement = _coal_shape(obstacle)
            oid = gm.addGeometryObject(pin.GeometryObject(f"obstacle_{o}", 0, placement, shape))
            for s in moving:
                gm.addCollisionPair(pin.CollisionPair(s, oid))
        self.collision_model = gm
        self._gdata = gm.createData()
        for request in self._gdata.collisionRequests:
            request.security_margin = self.clearance
        self._model = target.model
        self._data = self._model.createData()
        self._broadphase()
        self._lever = self._levers()
        self._pair_lever = self._pair_levers()
        self.slide = bool(slide)  # after a cut, slide joint by joint along the obstacle (slide_posture)
        self.checks = 0  # postures checked
        self.asks = 0  # segments checked
        self.cuts = 0  # segments cut short

    def _broadphase(self) -> None:
        """Bounding spheres of the shapes, the checked pairs and the obstacles, as the prefilter's arrays.

        Only the pairs whose spheres come within the clearance go to coal
        (:func:`gb_pin.safety.broadphase.first_candidate`).
        """
        gm = self.collision_model
        k = len(self.geometry.body)
        self._centres = np.zeros((k, 3))
        self._radii = np.zeros(k)
        model = self._model
        moved = sorted(int(model.getJointId(j)) for j in self.target.joints)  # the chain's joint order
        self._chain_of = np.full(k, -1, dtype=np.int64)
        for s, obj in enumerate(gm.geometryObjects):
            geom = obj.geometry
            geom.computeLocalAABB()
            if s >= k:
                continue
            self._centres[s] = obj.placement.act(np.asarray(geom.aabb_center))
            self._radii[s] = float(geom.aabb_radius)
            if int(obj.parentJoint) != 0:
                self._chain_of[s] = moved.index(int(obj.parentJoint))
        pairs = [(int(p.first), int(p.second)) for p in gm.collisionPairs]
        self._pair_a = np.array([a for a, _ in pairs], dtype=np.int64)
        self._pair_b = np.array([b for _, b in pairs], dtype=np.int64)
        n = len(self.obstacles)
        self._kind = np.zeros(n, dtype=np.int64)
        self._where = np.zeros((n, 3))
        self._size = np.zeros((n, 3))
        for o, obstacle in enumerate(self.obstacles):
            if isinstance(obstacle, Table):
                self._kind[o] = TABLE
                self._where[o, 2] = obstacle.height
            elif isinstance(obstacle, Box):
                self._kind[o] = BOX
                self._where[o] = obstacle.center
                self._size[o] = obstacle.half_extents
            else:
                self._kind[o] = SPHERE
                self._where[o] = obstacle.center
                self._size[o, 0] = obstacle.radius
        points, first, inflate = _shape_points(gm, k)
        corners = np.zeros((k, 8, 3))
        signs = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)])
        coarse: list[NDArray[np.float64]] = []
        coarse_first = np.zeros(k + 1, dtype=np.int64)
        coarse_inflate = inflate.copy()
        for s in range(k):
            mine = points[first[s] : first[s + 1]]
            if len(mine):
                corners[s] = mine.min(axis=0) + signs * (mine.max(axis=0) - mine.min(axis=0))
                few, spread = _farthest_points(mine, COARSE_POINTS)
                coarse.append(few)
                coarse_inflate[s] += spread
            coarse_first[s + 1] = coarse_first[s] + (len(coarse[-1]) if len(mine) else 0)
        few_points = np.ascontiguousarray(np.concatenate(coarse) if coarse else np.zeros((0, 3)))
        self._spheres = Spheres(
            self._chain_of, self._centres, self._radii, self._pair_a, self._pair_b, self._kind, self._where,
            self._size, points, first, inflate, corners, few_points, coarse_first, coarse_inflate,
        )  # fmt: skip
        self._ws = scratch(self.target.n_joints, self._pair_a.shape[0], k)
        self._entry: Any = None  # first_candidate compiled for these arrays (see _first)
        self._mask = self._ws.mask
        # the Pinocchio configuration of a posture: a scatter into the home configuration when every
        # joint takes one entry (no continuous joint, written as cos and sin), else target.to_pinocchio
        jids = [int(model.getJointId(j)) for j in self.target.joints]
        self._base: NDArray[np.float64] | None = None
        if all(int(model.joints[j].nq) == 1 for j in jids):
            self._base = np.array(self.target.to_pinocchio(self.target.home), dtype=float)
            self._idx_q = np.array([int(model.joints[j].idx_q) for j in jids], dtype=np.int64)
        self._joints = self.target.chain.joints

    def _first(self, a: NDArray[np.float64], b: NDArray[np.float64], n: int, k0: int) -> int:
        """The first sample k >= k0 of the segment with a pair not proven clear (its pairs in ``_mask``).

        After the first call, the compiled version for these argument types is called directly
        (numba's dispatch types each of the two dozen arrays on every call: 11 us of 15).
        """
        args = (a, b, n, k0, self._joints, self._spheres, self.clearance + SLACK, self._ws)
        if self._entry is None:
            k = first_candidate(*args)
            signature = tuple(first_candidate.typeof_pyval(x) for x in args)
            self._entry = first_candidate.overloads[signature].entry_point
            return int(k)
        return int(self._entry(*args))

    def _configuration(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """``target.to_pinocchio(q)``, without its Python loop where the joints allow."""
        if self._base is None:
            return np.asarray(self.target.to_pinocchio(q))
        out = self._base.copy()
        out[self._idx_q] = q
        return out

    def _coal_safe(self, q: NDArray[np.float64], candidates: NDArray[np.bool_]) -> bool:
        """Whether coal finds none of ``candidates`` (a mask of the pairs) within the clearance at ``q``."""
        import pinocchio as pin

        (pairs,) = np.nonzero(candidates)
        if pairs.shape[0] == 0:
            return True
        pin.forwardKinematics(self._model, self._data, self._configuration(q))
        pin.updateGeometryPlacements(self._model, self._data, self.collision_model, self._gdata)
        gm, gd = self.collision_model, self._gdata
        return not any(pin.computeCollision(gm, gd, int(p)) for p in pairs)

    def _levers(self) -> NDArray[np.float64]:
        """Per joint: how far [m] a point of any shape it moves travels per unit of that joint's motion."""
        g = self.geometry
        model = self._model
        ids = [int(model.getJointId(j)) for j in self.target.joints]
        m = len(ids)
        link = np.array([float(np.linalg.norm(model.jointPlacements[jid].translation)) for jid in ids])
        span = np.where(
            np.isfinite(self.target.upper - self.target.lower), self.target.upper - self.target.lower, 0.0
        )
        prismatic = np.array(["P" in model.joints[jid].shortname() for jid in ids])
        lever = np.zeros(m)
        for s, b in enumerate(g.body):
            if b < 0:
                continue
            dist = float(g.reach[s])
            a = int(b)
            while a >= 0:
                lever[a] = max(lever[a], 1.0 if prismatic[a] else dist)
                dist += link[a] + (abs(span[a]) if prismatic[a] else 0.0)
                a = int(g.parents[a])
        return lever

    def _pair_levers(self) -> NDArray[np.float64]:
        """(P, m): per checked pair, how far its shapes move relative to each other per unit of each joint.

        A shape's points move at most ``lever[s, j]`` (its distance from joint j's origin, bounded
        along the chain) per unit of joint j above it. Against an obstacle: its own joints. Two of
        the arm's shapes: only the joints between them (those above both move them together),
        each shape's own lever.
        """
        g = self.geometry
        model = self._model
        ids = [int(model.getJointId(j)) for j in self.target.joints]
        link = np.array([float(np.linalg.norm(model.jointPlacements[jid].translation)) for jid in ids])
        span = np.where(
            np.isfinite(self.target.upper - self.target.lower), self.target.upper - self.target.lower, 0.0
        )
        prismatic = np.array(["P" in model.joints[jid].shortname() for jid in ids])
        k, m = len(g.body), len(ids)
        lever = np.zeros((k, m))
        above = np.zeros((k, m), dtype=bool)
        for s in range(k):
            dist = float(g.reach[s])
            a = int(g.body[s])
            while a >= 0:
                lever[s, a] = 1.0 if prismatic[a] else dist
                above[s, a] = True
                dist += link[a] + (abs(span[a]) if prismatic[a] else 0.0)
                a = int(g.parents[a])
        out = np.zeros((self._pair_a.shape[0], m))
        for p, (a, b) in enumerate(zip(self._pair_a, self._pair_b, strict=True)):
            if b >= k:  # an obstacle
                out[p] = lever[a]
            else:
                out[p] = np.where(above[a] & ~above[b], lever[a], 0.0) + np.where(
                    above[b] & ~above[a], lever[b], 0.0
                )
        return out

    def same_setup(self, obstacles: Any, self_collision: bool, geometry: str, clearance: float) -> bool:
        """Whether this checker checks exactly these (so that a plant's checker can serve a run)."""
        return (
            self.obstacles == check_obstacles(obstacles)
            and self.self_collision == bool(self_collision)
            and self.geometry.kind == geometry
            and self.clearance == clearance
        )

    # -- checks ------------------------------------------------------------------------------
    def is_safe(self, q: ArrayLike) -> bool:
        """Whether posture ``q`` (m,) keeps every checked pair at least the clearance apart."""
        self.checks += 1
        q = np.ascontiguousarray(q, dtype=float)
        return self._first(q, q, 1, 1) > 1 or self._coal_safe(q, self._mask)

    def contacts(self, q: ArrayLike) -> list[tuple[str, str]]:
        """The checked pairs within the clearance at posture ``q``, by their shapes' names."""
        import pinocchio as pin

        gm, gd = self.collision_model, self._gdata
        pin.computeCollisions(self._model, self._data, gm, gd, self.target.to_pinocchio(q), False)
        out = []
        for p, pair in enumerate(gm.collisionPairs):
            if gd.collisionResults[p].isCollision():
                out.append((gm.geometryObjects[pair.first].name, gm.geometryObjects[pair.second].name))
        return out

    def samples(self, q_from: NDArray[np.float64], q_to: NDArray[np.float64]) -> int:
        """Postures checked on the segment: no pair's shapes move more than the clearance between two.

        (Relative to each other: :meth:`_pair_levers`.)
        """
        if self._pair_lever.shape[0] == 0:
            return 1
        travel = float(np.max(self._pair_lever @ np.abs(q_to - q_from)))
        return min(MAX_SEGMENT_SAMPLES, max(1, math.ceil(travel / self.clearance)))

    def cut(self, q_from: ArrayLike, q_to: ArrayLike) -> tuple[NDArray[np.float64], bool]:
        """The last safe posture on the straight segment from ``q_from`` (safe) to ``q_to``.

        Its :meth:`samples` are walked in compiled code (:func:`~gb_pin.safety.broadphase.first_candidate`);
        only those with a pair not proven clear go to coal, on those pairs.

        Returns (posture, whether the whole segment is safe: then the posture is ``q_to``).
        """
        a = np.ascontiguousarray(q_from, dtype=float)
        b = np.ascontiguousarray(q_to, dtype=float)
        n = self.samples(a, b)
        k = self._first(a, b, n, 1)
        while k <= n:
            if not self._coal_safe(b if k == n else a + (k / n) * (b - a), self._mask):
                self.checks += k
                return (a + ((k - 1) / n) * (b - a) if k > 1 else a.copy()), False
            k = self._first(a, b, n, k + 1)
        self.checks += n
        return b.copy(), True

    def __call__(self, q_from: NDArray[np.float64], q_to: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The guard of an ask/tell run: None (the segment is safe) or the posture to go to instead."""
        self.asks += 1
        q, ok = self.cut(q_from, q_to)
        if ok:
            return None
        self.cuts += 1
        return self.slide_posture(q_from, q, q_to) if self.slide else q

    def slide_posture(self, q_from: ArrayLike, q_cut: ArrayLike, q_to: ArrayLike) -> NDArray[np.float64]:
        """The cut posture, then each joint's remaining move added alone where it stays safe.

        Largest first, each kept where the straight move from ``q_from`` stays safe: the arm slides
        along the obstacle, as a posture clipped to its joint limits slides along them, instead of
        stopping where it first touched.
        """
        a = np.asarray(q_from, dtype=float)
        q = np.asarray(q_cut, dtype=float).copy()
        rest = np.asarray(q_to, dtype=float) - q
        for i in np.argsort(-np.abs(rest) * self._lever):
            if rest[i] == 0.0:
                continue
            trial = q.copy()
            trial[i] += rest[i]
            if self.cut(a, trial)[1]:
                q = trial
        return q

    # -- bad input, before anything moves ---------------------------------------------------
    def check_setup(self, targets: ArrayLike | None = None) -> None:
        """Refuse a run that cannot be safe.

        Home within the clearance of an obstacle or of itself; goals inside an obstacle (a table
        above them).

        Raises:
            UnsafeSetupError: naming the obstacle or pair and what to change.
        """
        home = np.asarray(self.target.home, dtype=float)
        touching = self.contacts(home)
        if touching:
            a, b = touching[0]
            what = self._describe(b) if b.startswith("obstacle_") else f"its own shape {b!r}"
            raise UnsafeSetupError(
                f"at home the arm ({a!r}) is within the clearance {self.clearance} m of {what}: "
                "move the obstacle or choose another home"
            )
        if targets is None or getattr(self.target, "task", None) is not None:
            return
        axes = str(getattr(self.target, "axes", ""))
        if sorted(axes) != ["x", "y", "z"] or len(axes) != 3:
            return
        X = check.points("targets", targets, 3)[:, [axes.index("x"), axes.index("y"), axes.index("z")]]
        for o, obstacle in enumerate(self.obstacles):
            inside = obstacle.contains(X)
            if inside.any():
                raise UnsafeSetupError(
                    f"{int(inside.sum())} of {len(X)} goals lie inside {self._describe(f'obstacle_{o}')} "
                    f"(e.g. {np.round(X[inside][0], 4).tolist()}): no safe posture reaches them"
                )

    def _describe(self, name: str) -> str:
        o = self.obstacles[int(name.removeprefix("obstacle_"))]
        if isinstance(o, Table):
            return f"the table (z <= {o.height} m)"
        return repr(o)


def _shape_points(gm: Any, k: int) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """The robot shapes' points in their joint frames, where they start, and the radius around them.

    A convex hull: its vertices; a box: its corners; a capsule: its two ends and radius; a sphere:
    its centre and radius; any other shape: none (its bounding sphere alone is tested).
    """
    import coal

    chunks: list[NDArray[np.float64]] = []
    first = np.zeros(k + 1, dtype=np.int64)
    inflate = np.zeros(k)
    for s in range(k):
        obj = gm.geometryObjects[s]
        g = obj.geometry
        local: NDArray[np.float64] | None = None
        if isinstance(g, coal.Box):
            h = np.asarray(g.halfSide)
            local = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * h
        elif isinstance(g, coal.Capsule):
            local = np.array([[0.0, 0.0, -g.halfLength], [0.0, 0.0, g.halfLength]])
            inflate[s] = g.radius
        elif isinstance(g, coal.Sphere):
            local = np.zeros((1, 3))
            inflate[s] = g.radius
        elif isinstance(g, coal.ConvexBase):
            local = np.asarray(g.points(), dtype=float).reshape(-1, 3)
        if local is not None and len(local):
            R = np.asarray(obj.placement.rotation)
            chunks.append(local @ R.T + np.asarray(obj.placement.translation))
        first[s + 1] = first[s] + (len(chunks[-1]) if local is not None and len(local) else 0)
    points = np.ascontiguousarray(np.concatenate(chunks) if chunks else np.zeros((0, 3)))
    return points, first, inflate


def _farthest_points(points: NDArray[np.float64], count: int) -> tuple[NDArray[np.float64], float]:
    """``count`` of ``points`` spread by farthest-point sampling, and how far any point is from them [m]."""
    if len(points) <= count:
        return points.copy(), 0.0
    chosen = [int(np.argmax(np.linalg.norm(points - points.mean(axis=0), axis=1)))]
    gap = np.linalg.norm(points - points[chosen[0]], axis=1)
    for _ in range(count - 1):
        chosen.append(int(np.argmax(gap)))
        gap = np.minimum(gap, np.linalg.norm(points - points[chosen[-1]], axis=1))
    return points[chosen].copy(), float(gap.max()) + SLACK


def describe_obstacles(obstacles: Any) -> str:
    """One line: the obstacles as given."""
    return ", ".join(repr(o) for o in check_obstacles(obstacles)) or "none"


__all__ = ["DEFAULT_CLEARANCE", "Box", "CollisionChecker", "InvalidArgumentError", "Sphere", "Table"]
