"""Stacked task maps: several components (positions, orientations, pointing directions) in one x.

A stacked task vector x is the concatenation of its components, each a function of one
frame (carried by a joint, at a fixed placement in it):

* ``POSITION``: the frame's position on chosen world axes [m] (1 to 3 rows), as the
  paper's task;
* ``ORIENTATION``: ``s * log(R_ref^T R)`` (3 rows), the rotation vector of the frame's
  world rotation R relative to a reference rotation R_ref (default the frame's rotation
  at home), scaled by s [m/rad], so that 1 rad of rotation counts like s metres of
  position in the learner's Euclidean task space (its radius, its E^X);
* ``POINTING``: one axis a of the frame (e.g. a gripper's approach axis), its world
  direction d = R a given by 2 tangent coordinates ``s * theta * (u . k, v . k)`` where
  theta is the angle between d and the reference direction d0 (default d at home), k
  the unit axis of the rotation taking d0 to d and (u, v) an orthonormal basis of the
  plane normal to d0 (the azimuthal equidistant chart of the sphere at d0: the distance
  of x to the reference is exactly s * theta).

:class:`TaskComponents` holds the components as arrays (one row per component);
:func:`components_forward` evaluates them in compiled code from the joint frames of
:func:`~gb_pin.learn.body.joints.joints_forward`, without allocating.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from gb_pin._jit import NO_REFCOUNT, njit

POSITION = 0
ORIENTATION = 1
POINTING = 2
COMPONENT_KINDS = {POSITION: "position", ORIENTATION: "orientation", POINTING: "pointing"}
"""Name of each component kind."""
COMPONENT_SIZES = {ORIENTATION: 3, POINTING: 2}
"""Rows of x of the rotational kinds (a position has one row per axis)."""

# Below this sin(theta) near theta = pi the rotation axis is read from the symmetric part of R.
_NEAR_PI_SIN = 1e-4


@dataclass(frozen=True, eq=False)
class TaskComponents:
    """The components of a stacked task map as arrays, one row per component (c components).

    Attributes:
        kinds: (c,) int64, ``POSITION``, ``ORIENTATION`` or ``POINTING``.
        parents: (c,) int64, index of the joint carrying the component's frame, -1 for the world.
        translations: (c, 3) position of the frame in its parent joint [m].
        rotations: (c, 3, 3) rotation of the frame in its parent joint.
        references: (c, 3, 3) ``ORIENTATION``: the reference rotation R_ref in the world;
            ``POINTING``: rows d0, u, v (the reference direction and the tangent basis, world).
        directions: (c, 3) ``POINTING``: the pointing axis in the parent joint's frame
            (the frame's axis rotated by the frame placement); zero otherwise.
        axes: (c, 3) int64, ``POSITION``: the world coordinates (0=x, 1=y, 2=z) of its rows,
            the first ``sizes[c]`` of them used; zero otherwise.
        sizes: (c,) int64, rows of x of each component.
        scales: (c,) float64, s [m/rad] of the rotational components, 1.0 for positions.
    """

    kinds: NDArray[np.int64]
    parents: NDArray[np.int64]
    translations: NDArray[np.float64]
    rotations: NDArray[np.float64]
    references: NDArray[np.float64]
    directions: NDArray[np.float64]
    axes: NDArray[np.int64]
    sizes: NDArray[np.int64]
    scales: NDArray[np.float64]

    FIELDS = ("kinds", "parents", "translations", "rotations", "references", "directions", "axes", "sizes",
              "scales")  # fmt: skip
    INTS = ("kinds", "parents", "axes", "sizes")

    def __eq__(self, other: object) -> bool:
        """Equal arrays, field by field (so that checks comparing two chains' fields hold)."""
        if not isinstance(other, TaskComponents):
            return NotImplemented
        return all(np.array_equal(getattr(self, k), getattr(other, k)) for k in self.FIELDS)

    __hash__ = None  # type: ignore[assignment]

    @property
    def count(self) -> int:
        """Number of components c."""
        return int(self.kinds.shape[0])

    @property
    def n_task(self) -> int:
        """Task dimension n: the rows of all components."""
        return int(np.sum(self.sizes))

    def rows(self, c: int) -> slice:
        """The rows of x of component ``c``."""
        start = int(np.sum(self.sizes[:c]))
        return slice(start, start + int(self.sizes[c]))

    @classmethod
    def empty(cls) -> TaskComponents:
        """No components (the arrays a plain frame-position task carries, for one compiled type)."""
        z = np.zeros
        return cls(z(0, np.int64), z(0, np.int64), z((0, 3)), z((0, 3, 3)), z((0, 3, 3)), z((0, 3)),
                   z((0, 3), np.int64), z(0, np.int64), z(0))  # fmt: skip

    def validate(self, n_joints: int) -> str | None:
        """What is wrong with the arrays for a chain of ``n_joints`` joints, None if nothing."""
        c = self.kinds.shape[0] if self.kinds.ndim == 1 else -1
        shapes = {"kinds": (c,), "parents": (c,), "translations": (c, 3), "rotations": (c, 3, 3),
                  "references": (c, 3, 3), "directions": (c, 3), "axes": (c, 3), "sizes": (c,),
                  "scales": (c,)}  # fmt: skip
        for name, shape in shapes.items():
            if np.shape(getattr(self, name)) != shape:
                return f"task {name} has shape {np.shape(getattr(self, name))}, expected {shape}"
        if c < 1:
            return "a stacked task needs at least one component"
        for k in range(c):
            kind, size = int(self.kinds[k]), int(self.sizes[k])
            if kind not in COMPONENT_KINDS:
                return f"task component {k} has kind {kind}; valid: {sorted(COMPONENT_KINDS)}"
            if not -1 <= int(self.parents[k]) < n_joints:
                return f"task component {k} hangs on joint {int(self.parents[k])} of {n_joints}"
            if kind == POSITION:
                axes = self.axes[k, :size].tolist() if 1 <= size <= 3 else []
                if not axes or len(set(axes)) != size or not all(0 <= a < 3 for a in axes):
                    return f"task component {k}: position axes {self.axes[k].tolist()} of size {size}"
            elif size != COMPONENT_SIZES[kind]:
                expected = COMPONENT_SIZES[kind]
                return f"task component {k}: a {COMPONENT_KINDS[kind]} has {expected} rows, got {size}"
        floats = (self.translations, self.rotations, self.references, self.directions, self.scales)
        if not all(np.all(np.isfinite(a)) for a in floats) or not np.all(self.scales > 0):
            return "task components: non-finite placements or references, or scales not > 0"
        return None


@njit(cache=True, nogil=True, error_model="numpy", **NO_REFCOUNT)  # the IK calls it without counting
def components_forward(task, rot_ws, pos_ws, out):  # type: ignore[no-untyped-def]
    """The stacked task vector into ``out`` (n,) from the joint frames (``task``: TaskArrays).

    One function with straight-line code per kind (numba's compile time grows with every
    function and every inlined call, the run time does not gain from them).
    """
    row = 0
    for c in range(task.component_kinds.shape[0]):
        kind = task.component_kinds[c]
        f = task.component_parents[c]
        s = task.component_scales[c]
        # R: the world rotation of the joint carrying the frame (identity for the world).
        if f >= 0:
            r = rot_ws[f]
            r00, r01, r02 = r[0, 0], r[0, 1], r[0, 2]
            r10, r11, r12 = r[1, 0], r[1, 1], r[1, 2]
            r20, r21, r22 = r[2, 0], r[2, 1], r[2, 2]
            p0, p1, p2 = pos_ws[f, 0], pos_ws[f, 1], pos_ws[f, 2]
        else:
            r00, r01, r02 = 1.0, 0.0, 0.0
            r10, r11, r12 = 0.0, 1.0, 0.0
            r20, r21, r22 = 0.0, 0.0, 1.0
            p0, p1, p2 = 0.0, 0.0, 0.0
        if kind == POSITION:
            t = task.component_translations[c]
            for a in range(task.component_sizes[c]):
                k = task.component_axes[c, a]
                if k == 0:
                    out[row + a] = p0 + r00 * t[0] + r01 * t[1] + r02 * t[2]
                elif k == 1:
                    out[row + a] = p1 + r10 * t[0] + r11 * t[1] + r12 * t[2]
                else:
                    out[row + a] = p2 + r20 * t[0] + r21 * t[1] + r22 * t[2]
        elif kind == ORIENTATION:
            b = task.component_rotations[c]
            ref = task.component_references[c]
            # W = R B (the frame's world rotation), E = R_ref^T W.
            w00 = r00 * b[0, 0] + r01 * b[1, 0] + r02 * b[2, 0]
            w01 = r00 * b[0, 1] + r01 * b[1, 1] + r02 * b[2, 1]
            w02 = r00 * b[0, 2] + r01 * b[1, 2] + r02 * b[2, 2]
            w10 = r10 * b[0, 0] + r11 * b[1, 0] + r12 * b[2, 0]
            w11 = r10 * b[0, 1] + r11 * b[1, 1] + r12 * b[2, 1]
            w12 = r10 * b[0, 2] + r11 * b[1, 2] + r12 * b[2, 2]
            w20 = r20 * b[0, 0] + r21 * b[1, 0] + r22 * b[2, 0]
            w21 = r20 * b[0, 1] + r21 * b[1, 1] + r22 * b[2, 1]
            w22 = r20 * b[0, 2] + r21 * b[1, 2] + r22 * b[2, 2]
            e00 = ref[0, 0] * w00 + ref[1, 0] * w10 + ref[2, 0] * w20
            e01 = ref[0, 0] * w01 + ref[1, 0] * w11 + ref[2, 0] * w21
            e02 = ref[0, 0] * w02 + ref[1, 0] * w12 + ref[2, 0] * w22
            e10 = ref[0, 1] * w00 + ref[1, 1] * w10 + ref[2, 1] * w20
            e11 = ref[0, 1] * w01 + ref[1, 1] * w11 + ref[2, 1] * w21
            e12 = ref[0, 1] * w02 + ref[1, 1] * w12 + ref[2, 1] * w22
            e20 = ref[0, 2] * w00 + ref[1, 2] * w10 + ref[2, 2] * w20
            e21 = ref[0, 2] * w01 + ref[1, 2] * w11 + ref[2, 2] * w21
            e22 = ref[0, 2] * w02 + ref[1, 2] * w12 + ref[2, 2] * w22
            # The antisymmetric part gives sin(theta) * axis, the trace cos(theta).
            wx = 0.5 * (e21 - e12)
            wy = 0.5 * (e02 - e20)
            wz = 0.5 * (e10 - e01)
            sn = math.sqrt(wx * wx + wy * wy + wz * wz)
            cs = 0.5 * (e00 + e11 + e22 - 1.0)
            theta = math.atan2(sn, cs)
            if sn >= _NEAR_PI_SIN or cs > 0.0:
                g = theta / sn if sn > 0.0 else 1.0
                ax, ay, az = g * wx, g * wy, g * wz
            else:
                # Near theta = pi: (E + E^T) / 2 = cos(theta) I + (1 - cos(theta)) a a^T; read a
                # from its largest diagonal entry, its sign from the antisymmetric part.
                v = 1.0 - cs
                d0 = (e00 - cs) / v
                d1 = (e11 - cs) / v
                d2 = (e22 - cs) / v
                if d0 >= d1 and d0 >= d2:
                    ax = math.sqrt(max(d0, 0.0))
                    ay = 0.5 * (e01 + e10) / (v * ax)
                    az = 0.5 * (e02 + e20) / (v * ax)
                elif d1 >= d2:
                    ay = math.sqrt(max(d1, 0.0))
                    ax = 0.5 * (e01 + e10) / (v * ay)
                    az = 0.5 * (e12 + e21) / (v * ay)
                else:
                    az = math.sqrt(max(d2, 0.0))
                    ax = 0.5 * (e02 + e20) / (v * az)
                    ay = 0.5 * (e12 + e21) / (v * az)
                if ax * wx + ay * wy + az * wz < 0.0:
                    ax, ay, az = -ax, -ay, -az
                ax, ay, az = theta * ax, theta * ay, theta * az
            out[row] = s * ax
            out[row + 1] = s * ay
            out[row + 2] = s * az
        else:
            # POINTING: d = R a; k sin(theta) = d0 x d; cos(theta) = d0 . d.
            a = task.component_directions[c]
            ref = task.component_references[c]
            dx = r00 * a[0] + r01 * a[1] + r02 * a[2]
            dy = r10 * a[0] + r11 * a[1] + r12 * a[2]
            dz = r20 * a[0] + r21 * a[1] + r22 * a[2]
            cx = ref[0, 1] * dz - ref[0, 2] * dy
            cy = ref[0, 2] * dx - ref[0, 0] * dz
            cz = ref[0, 0] * dy - ref[0, 1] * dx
            sn = math.sqrt(cx * cx + cy * cy + cz * cz)
            cs = ref[0, 0] * dx + ref[0, 1] * dy + ref[0, 2] * dz
            theta = math.atan2(sn, cs)
            if sn > 0.0:
                g = s * theta / sn
                out[row] = g * (ref[1, 0] * cx + ref[1, 1] * cy + ref[1, 2] * cz)
                out[row + 1] = g * (ref[2, 0] * cx + ref[2, 1] * cy + ref[2, 2] * cz)
            else:  # along d0 (theta = 0) or opposite it (theta = pi, any direction: take u)
                out[row] = s * theta
                out[row + 1] = 0.0
        row += task.component_sizes[c]


@njit(cache=True, nogil=True, error_model="numpy")
def component_errors_into(task, target, reached, acc):  # type: ignore[no-untyped-def]
    """Add ||x*[r_c] - x[r_c]|| / s_c of every component c to ``acc[c]`` ([m]; [deg] for rotations)."""
    row = 0
    for c in range(task.component_kinds.shape[0]):
        e = 0.0
        for j in range(row, row + task.component_sizes[c]):
            v = target[j] - reached[j]
            e += v * v
        e = math.sqrt(e) / task.component_scales[c]
        acc[c] += e if task.component_kinds[c] == POSITION else e * (180.0 / math.pi)
        row += task.component_sizes[c]
