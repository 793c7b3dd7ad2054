"""The collision geometry of a robot gb_pin loads, attached to the learner's reduced model.

From the URDF's ``<collision>`` elements (``pinocchio.buildGeomFromUrdf``, coal inside the ``pin``
wheel), each mesh replaced by its convex hull (contains the mesh: a check on the hull never misses a
contact of the mesh; GJK on a hull costs a fraction of a mesh test), or, on request, one capsule per
link from each moved joint to the next (and to the task frame). Each shape is re-attached to the
nearest moved joint above it, placed where the locked joints hold it, so the shapes move with the
reduced model the learner moves (the same as ``pinocchio.buildReducedModel(model, geom, ...)``).
"""

from __future__ import annotations

import os
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import UnsafeSetupError

GEOMETRY_KINDS = ("urdf", "capsules")
_HULLS: dict[tuple[Any, ...], Any] = {}  # the convex hulls of a URDF's meshes, by file, size, time, dirs


class RobotGeometry(NamedTuple):
    """Collision shapes on the reduced model: the GeometryModel, each shape's moved body, its radius.

    ``body[k]`` is the index (into ``target.joints``) of the moved joint the shape moves with, -1:
    fixed to the world. ``reach[k]`` bounds the distance [m] of the shape's points from the origin of
    its joint frame.
    """

    model: Any  # pin.GeometryModel
    body: NDArray[np.int64]
    reach: NDArray[np.float64]
    kind: str
    links: tuple[str, ...]  # each shape's link (URDF) or joint (capsules) name
    parents: NDArray[np.int64]  # each moved joint's moved parent (index into target.joints), -1: the world


def robot_geometry(target: Any, kind: str = "urdf", capsule_radius: float = 0.025) -> RobotGeometry:
    """The collision geometry of ``target`` (a KinematicTarget) on its reduced model.

    Raises:
        UnsafeSetupError: ``kind="urdf"`` and the robot has no URDF or no collision geometry.
    """
    if kind not in GEOMETRY_KINDS:
        raise UnsafeSetupError(
            f"self_collision must be one of {', '.join(GEOMETRY_KINDS)} (or True), got {kind!r}"
        )
    if kind == "capsules":
        return _capsules(target, capsule_radius)
    import coal
    import pinocchio as pin

    from gb_pin.robot.models import check_meshes, package_dirs_for

    urdf = getattr(target, "urdf", None)
    if urdf is None:
        raise UnsafeSetupError(
            f"{target.name!r} was not loaded from a URDF: it has no collision geometry; "
            "ask for self_collision='capsules' (simple capsules per link)"
        )
    dirs = getattr(target, "_package_dirs", None) or package_dirs_for(urdf)
    from pathlib import Path

    check_meshes(Path(os.fspath(urdf)), dirs)
    try:
        full = pin.buildGeomFromUrdf(
            target.full_model, os.fspath(urdf), pin.GeometryType.COLLISION, package_dirs=dirs
        )
    except (ValueError, RuntimeError, IndexError) as exc:
        raise UnsafeSetupError(f"cannot load the collision geometry of {os.fspath(urdf)!r}: {exc}") from exc
    if len(full.geometryObjects) == 0:
        raise UnsafeSetupError(
            f"the URDF of {target.name!r} has no <collision> geometry; "
            "ask for self_collision='capsules' (simple capsules per link) or add collision elements"
        )
    stat = os.stat(urdf)
    key = (os.path.realpath(urdf), stat.st_size, stat.st_mtime_ns, tuple(dirs))
    fm = target.full_model
    fdata = fm.createData()
    pin.forwardKinematics(fm, fdata, target.full_configuration(target.home))
    moved_full = {int(j): a for a, j in enumerate(target._full_ids)}
    reduced_ids = [int(target.model.getJointId(j)) for j in target.joints]
    out = pin.GeometryModel()
    body: list[int] = []
    reach: list[float] = []
    links: list[str] = []
    for obj in full.geometryObjects:
        j = int(obj.parentJoint)
        while j != 0 and j not in moved_full:
            j = int(fm.parents[j])
        a = moved_full.get(j, -1)
        rel = fdata.oMi[j].actInv(fdata.oMi[int(obj.parentJoint)]) * obj.placement
        geom = obj.geometry
        if isinstance(geom, coal.BVHModelBase):
            geom = _hull(key, obj.name, geom)
        new = pin.GeometryObject(obj.name, 0 if a < 0 else reduced_ids[a], rel, geom)
        if obj.meshScale is not None:
            new.meshScale = obj.meshScale
        out.addGeometryObject(new)
        links.append(str(fm.frames[int(obj.parentFrame)].name))
        body.append(a)
        reach.append(_reach(geom, rel))
    return RobotGeometry(
        out, np.array(body, dtype=np.int64), np.array(reach), "urdf", tuple(links), moved_parents(target)
    )


def _hull(key: tuple[Any, ...], name: str, mesh: Any) -> Any:
    """The convex hull of a mesh (qhull), computed once per URDF file and shape (read-only, shared)."""
    found = _HULLS.get((*key, name))
    if found is None:
        if len(_HULLS) > 10_000:
            _HULLS.clear()
        mesh.buildConvexHull(True, "Qt")
        found = _HULLS[(*key, name)] = mesh.convex
    return found


def _reach(geom: Any, placement: Any) -> float:
    """A bound on the distance of the shape's points from its joint frame's origin [m]."""
    geom.computeLocalAABB()
    return float(np.linalg.norm(placement.act(np.asarray(geom.aabb_center))) + geom.aabb_radius)


def _capsules(target: Any, radius: float) -> RobotGeometry:
    """One capsule per moved joint: from its origin to each child joint's origin (or the task frame)."""
    import coal
    import pinocchio as pin

    model = target.model
    ids = [int(model.getJointId(j)) for j in target.joints]
    index = {jid: a for a, jid in enumerate(ids)}
    out = pin.GeometryModel()
    body: list[int] = []
    reach: list[float] = []
    links: list[str] = []
    ends: dict[int, list[NDArray[np.float64]]] = {a: [] for a in range(len(ids))}
    for jid in range(1, model.njoints):
        parent = int(model.parents[jid])
        if parent in index and jid in index:
            ends[index[parent]].append(np.asarray(model.jointPlacements[jid].translation))
    frame = model.frames[target.frame_id]
    if int(frame.parentJoint) in index:
        ends[index[int(frame.parentJoint)]].append(np.asarray(frame.placement.translation))
    for a, points in ends.items():
        for k, p in enumerate(points):
            length = float(np.linalg.norm(p))
            if length < 1e-6:
                shape: Any = coal.Sphere(radius)
                placement = pin.SE3.Identity()
            else:
                shape = coal.Capsule(radius, length)  # along z, centred
                z = p / length
                x = np.cross(z, [1.0, 0, 0]) if abs(z[0]) < 0.9 else np.cross(z, [0, 1.0, 0])
                x /= np.linalg.norm(x)
                placement = pin.SE3(np.column_stack([x, np.cross(z, x), z]), p / 2)
            out.addGeometryObject(
                pin.GeometryObject(f"{target.joints[a]}_capsule_{k}", ids[a], placement, shape)
            )
            links.append(target.joints[a])
            body.append(a)
            reach.append(length + radius)
    if not body:
        raise UnsafeSetupError(f"{target.name!r}: no link long enough for a capsule")
    return RobotGeometry(
        out, np.array(body, dtype=np.int64), np.array(reach), "capsules", tuple(links), moved_parents(target)
    )


def moved_parents(target: Any) -> NDArray[np.int64]:
    """Each moved joint's parent among the moved joints of the reduced model (-1: the world)."""
    model = target.model
    ids = [int(model.getJointId(j)) for j in target.joints]
    index = {jid: a for a, jid in enumerate(ids)}
    return np.array([index.get(int(model.parents[jid]), -1) for jid in ids], dtype=np.int64)


def adjacent(geometry: RobotGeometry) -> NDArray[np.bool_]:
    """Pairs of shapes on the same body or on bodies joined by one joint (the world is a body)."""
    parents = geometry.parents
    b = geometry.body
    k = len(b)
    out = np.zeros((k, k), dtype=bool)
    for i in range(k):
        for j in range(k):
            bi, bj = int(b[i]), int(b[j])
            pi = -1 if bi < 0 else int(parents[bi])
            pj = -1 if bj < 0 else int(parents[bj])
            out[i, j] = bi == bj or (bi >= 0 and pi == bj) or (bj >= 0 and pj == bi)
    return out
