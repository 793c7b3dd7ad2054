"""Several local inverses over one goal region: a map per part, and the rule for which one answers.

One single-valued inverse g cannot cover a region where the posture that reaches a point must
switch branches (a turning arm's points behind it: one side is reached turning one way, the other
the other way). A *parted* estimate splits the region into P sectors around an axis, each learnt
by its own goal-babbling learner (its own home and its own local-linear map), and answers a query
x* with the map of the sector x* falls in::

    g(x*) = g_p(x*),   p = #{edges e_j < phi(x*)},
    phi(x) = atan2(<x - o, v>, <x - o, u>)   in (-pi, pi],

o a point of the axis and u, v orthonormal directions across it (task space): phi is the
angle of x around the axis, measured from u, and the P - 1 sorted edges cut (-pi, pi] into the
P sectors (the last one ends where the first begins, behind: at phi = +-pi).

The learner layer sees only points, directions and postures: which axis, edges and homes a region
has is decided on the robot side (:func:`gb_pin.robot.workspace_parts.region_parts`, docs/WORKSPACE.md).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.llm import LocalLinearMap

MAX_PARTS = 8


class Sectors(NamedTuple):
    """The rule that routes a query to a part: sectors of the angle around an axis.

    Attributes:
        origin: (n,) a point o of the axis [m].
        u: (n,) the direction angle 0 points to (unit, across the axis).
        v: (n,) the direction of angle pi / 2 (unit, orthogonal to u).
        edges: (P - 1,) sorted angles in (-pi, pi] where one part ends and the next begins [rad].
    """

    origin: NDArray[np.float64]
    u: NDArray[np.float64]
    v: NDArray[np.float64]
    edges: NDArray[np.float64]

    @property
    def parts(self) -> int:
        """P."""
        return int(self.edges.shape[0]) + 1

    def angle(self, X: NDArray[np.float64]) -> NDArray[np.float64]:
        """phi of every row of ``X`` (N, n) [rad]."""
        d = X - self.origin
        return np.arctan2(d @ self.v, d @ self.u)

    def part_of(self, X: NDArray[np.float64]) -> NDArray[np.int64]:
        """The part of every row of ``X`` (N, n)."""
        return np.searchsorted(self.edges, self.angle(X), side="right").astype(np.int64)

    @classmethod
    def checked(cls, origin: Any, u: Any, v: Any, edges: Any, n: int) -> Sectors:
        """The rule from arrays, checked (unit, orthogonal directions; sorted edges in (-pi, pi]).

        Raises:
            InvalidArgumentError: naming the bad array.
        """
        o, uu, vv = (check.vector(name, a, n) for name, a in (("origin", origin), ("u", u), ("v", v)))
        e = np.asarray(edges, dtype=float).reshape(-1)
        if abs(np.linalg.norm(uu) - 1) > 1e-6 or abs(np.linalg.norm(vv) - 1) > 1e-6 or abs(uu @ vv) > 1e-6:
            raise InvalidArgumentError("a parted map's directions u, v must be orthonormal")
        if (
            e.shape[0] + 1 > MAX_PARTS
            or not np.all(np.isfinite(e))
            or np.any(np.diff(e) <= 0)
            or np.any(np.abs(e) > np.pi)
        ):
            raise InvalidArgumentError(
                f"a parted map's edges must be at most {MAX_PARTS - 1} increasing angles in [-pi, pi], "
                f"got {e.tolist()[:MAX_PARTS]}"
            )
        return cls(o, uu, vv, e)


class PartedMap:
    """Local-linear maps g_p, one per part of a region, and the sectors that route a query.

    It answers as a :class:`~gb_pin.learn.llm.LocalLinearMap` does (``predict``, ``jacobian``,
    ``n_prototypes_``, ``to_arrays``), so that a result, its file and feedback reaching take it
    in its place.

    Args:
        maps: the P maps (same input and output dimensions).
        sectors: the rule choosing the map of a query (:class:`Sectors` of P parts).
    """

    ARRAY_NAMES = LocalLinearMap.ARRAY_NAMES
    PART_KEYS = ("part_sizes", "part_origin", "part_u", "part_v", "part_edges")

    def __init__(self, maps: list[LocalLinearMap], sectors: Sectors) -> None:
        if not maps or not all(isinstance(m, LocalLinearMap) for m in maps):
            raise InvalidArgumentError(f"a parted map needs one or more LocalLinearMaps, got {maps!r}")
        dims = {(m.n_inputs_, m.n_outputs_) for m in maps}
        if len(dims) != 1:
            raise InvalidArgumentError(f"the maps of a parted map differ in dimensions: {sorted(dims)}")
        if sectors.parts != len(maps):
            raise InvalidArgumentError(f"{len(maps)} maps but sectors of {sectors.parts} parts")
        self.maps = list(maps)
        self.sectors = Sectors.checked(sectors.origin, sectors.u, sectors.v, sectors.edges, maps[0].n_inputs_)
        self.radius = maps[0].radius
        self.learning_rate = maps[0].learning_rate
        self.cutoff = maps[0].cutoff

    @property
    def n_parts(self) -> int:
        """P."""
        return len(self.maps)

    @property
    def n_prototypes_(self) -> int:
        """K: the prototypes of all maps together."""
        return sum(m.n_prototypes_ for m in self.maps)

    @property
    def n_inputs_(self) -> int:
        """Input (task) dimension n."""
        return self.maps[0].n_inputs_

    @property
    def n_outputs_(self) -> int:
        """Output (posture) dimension m."""
        return self.maps[0].n_outputs_

    def part_of(self, X: ArrayLike) -> NDArray[np.int64]:
        """The part answering each input: (N, n) -> (N,)."""
        return self.sectors.part_of(check.points("X", X, self.n_inputs_, allow_single=True))

    def predict(self, X: ArrayLike, *, warn: bool = True) -> NDArray[np.float64]:
        """g(x) = g_p(x) of the part p of every input: (N, n) -> (N, m), (n,) -> (m,)."""
        pts = check.points("X", X, self.n_inputs_, allow_single=True)
        part = self.sectors.part_of(pts)
        out = np.empty((pts.shape[0], self.n_outputs_))
        for p, model in enumerate(self.maps):
            rows = np.flatnonzero(part == p)
            if rows.size:
                out[rows] = model.predict(pts[rows], warn=warn)
        return out[0] if np.ndim(X) == 1 else out

    def jacobian(self, x: ArrayLike) -> NDArray[np.float64]:
        """dg_p/dx at one input (n,) -> (m, n), of the part it falls in."""
        xv = check.vector("x", x, self.n_inputs_)
        return self.maps[int(self.sectors.part_of(xv[None, :])[0])].jacobian(xv)

    def to_arrays(self) -> dict[str, NDArray[Any]]:
        """The maps' arrays one after the other, with ``part_sizes`` (P,) and the sectors' arrays."""
        arrays = [m.to_arrays() for m in self.maps]
        out: dict[str, NDArray[Any]] = {k: np.concatenate([a[k] for a in arrays]) for k in self.ARRAY_NAMES}
        out["part_sizes"] = np.array([m.n_prototypes_ for m in self.maps], dtype=np.int64)
        for key, value in zip(self.PART_KEYS[1:], self.sectors, strict=True):
            out[key] = np.array(value, dtype=np.float64)
        return out

    @classmethod
    def from_arrays(
        cls, arrays: dict[str, Any], radius: float, learning_rate: float = 0.1, cutoff: float | None = None
    ) -> PartedMap:
        """The parted map stored by :meth:`to_arrays`, exactly.

        Raises:
            InvalidArgumentError: missing or inconsistent arrays.
        """
        missing = [k for k in (*cls.ARRAY_NAMES, *cls.PART_KEYS) if k not in arrays]
        if missing:
            raise InvalidArgumentError(f"a parted map without {', '.join(missing)}")
        sizes = np.asarray(arrays["part_sizes"])
        P = np.asarray(arrays["prototypes"])
        if (
            sizes.ndim != 1
            or sizes.dtype.kind not in "iu"
            or not 1 <= sizes.shape[0] <= MAX_PARTS
            or np.any(sizes < 1)
            or P.ndim != 2
            or int(sizes.sum()) != P.shape[0]
        ):
            raise InvalidArgumentError(
                f"a parted map's part_sizes {sizes.reshape(-1).tolist()[:MAX_PARTS]} do not add up to "
                f"its {P.shape[0] if P.ndim else 0} prototypes"
            )
        ends = np.cumsum(sizes)
        maps = []
        for start, end in zip(ends - sizes, ends, strict=True):
            part = {k: np.asarray(arrays[k])[start:end] for k in cls.ARRAY_NAMES}
            maps.append(LocalLinearMap.from_arrays(part, radius, learning_rate, cutoff=cutoff))
        n = maps[0].n_inputs_
        sectors = Sectors.checked(
            arrays["part_origin"], arrays["part_u"], arrays["part_v"], arrays["part_edges"], n
        )
        return cls(maps, sectors)

    def copy(self) -> PartedMap:
        """An independent copy (the maps' arrays copied)."""
        maps = [
            LocalLinearMap.from_arrays(m.to_arrays(), m.radius, m.learning_rate, cutoff=m.cutoff)
            for m in self.maps
        ]
        return PartedMap(maps, self.sectors)

    def __repr__(self) -> str:
        sizes = ", ".join(str(m.n_prototypes_) for m in self.maps)
        return f"PartedMap({self.n_parts} parts of {sizes} prototypes, radius={self.radius:g})"
