"""The collision shapes of :mod:`gb_pin.safety` as MuJoCo geoms, with contacts on for the checked pairs.

:func:`contact_xml` writes, for a :class:`~gb_pin.safety.checker.CollisionChecker`, each robot shape
as a geom of the body its joint moves (convex hulls as meshes given by their vertices, boxes,
spheres, capsules, cylinders), the obstacles as world geoms (a table as a plane), and one explicit
``<pair>`` per pair the checker checks (self pairs of the collision matrix, every moving shape
against every obstacle). Every geom has ``contype = conaffinity = 0``, so MuJoCo makes contacts for
those pairs only, with no margin: a contact is a real touch. The plant counts them
(:attr:`gb_pin.sim.MujocoPlant.contacts`).
"""

from __future__ import annotations

from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

from gb_pin.exceptions import InvalidArgumentError


def _v(values: Any) -> str:
    return quoteattr(" ".join(repr(float(x)) for x in np.ravel(values)))


def _geom(name: str, obj_geometry: Any, placement: Any, meshes: list[str]) -> str:
    """One geom element (and its mesh asset, appended to ``meshes``) for a coal shape."""
    import coal
    import pinocchio as pin

    g = obj_geometry
    x, y, z, w = pin.Quaternion(np.asarray(placement.rotation)).coeffs()
    pos, quat = np.asarray(placement.translation), np.array([w, x, y, z])
    frame = f"pos={_v(pos)} quat={_v(quat)}"
    common = f'name={quoteattr(name)} contype="0" conaffinity="0" group="3"'
    if isinstance(g, coal.Box):
        return f'<geom {common} type="box" size={_v(np.asarray(g.halfSide))} {frame}/>'
    if isinstance(g, coal.Sphere):
        return f'<geom {common} type="sphere" size={_v([g.radius])} {frame}/>'
    if isinstance(g, coal.Capsule):
        return f'<geom {common} type="capsule" size={_v([g.radius, g.halfLength])} {frame}/>'
    if isinstance(g, coal.Cylinder):
        return f'<geom {common} type="cylinder" size={_v([g.radius, g.halfLength])} {frame}/>'
    if isinstance(g, coal.ConvexBase):
        points = np.asarray(g.points())
        meshes.append(f"    <mesh name={quoteattr('mesh_' + name)} vertex={_v(points)}/>")
        return f'<geom {common} type="mesh" mesh={quoteattr("mesh_" + name)} {frame}/>'
    raise InvalidArgumentError(f"the shape {name!r} ({type(g).__name__}) has no MuJoCo geom here")


def contact_xml(checker: Any) -> tuple[dict[int, list[str]], list[str], list[str]]:
    """({moved joint index or -1: geom lines}, mesh asset lines, pair lines) of ``checker``'s shapes."""
    from gb_pin.safety.obstacles import Table

    gm = checker.collision_model
    k = len(checker.geometry.body)
    geoms: dict[int, list[str]] = {}
    meshes: list[str] = []
    names = []
    for s, obj in enumerate(gm.geometryObjects):
        name = f"g{s}_{obj.name}"
        names.append(name)
        if s < k:
            body = int(checker.geometry.body[s])
            geoms.setdefault(body, []).append(_geom(name, obj.geometry, obj.placement, meshes))
            continue
        obstacle = checker.obstacles[s - k]
        if isinstance(obstacle, Table):
            line = (
                f'<geom name={quoteattr(name)} type="plane" size="0 0 1" contype="0" conaffinity="0" '
                f"pos={_v([0.0, 0.0, obstacle.height])}/>"
            )
        else:
            line = _geom(name, obj.geometry, obj.placement, meshes)
        geoms.setdefault(-1, []).append(line)
    pairs = [
        f"    <pair geom1={quoteattr(names[int(p.first)])} geom2={quoteattr(names[int(p.second)])}/>"
        for p in gm.collisionPairs
    ]
    return geoms, meshes, pairs


def named_pairs(mujoco: Any, model: Any, pairs: dict[tuple[int, int], Any]) -> dict[tuple[str, str], Any]:
    """``pairs`` keyed by geom ids, keyed by the geoms' names instead (the id where a geom has none)."""
    name, kind = mujoco.mj_id2name, mujoco.mjtObj.mjOBJ_GEOM
    return {
        (name(model, kind, a) or str(a), name(model, kind, b) or str(b)): value
        for (a, b), value in sorted(pairs.items())
    }


def counted(contacts: list[Any] | None) -> list[Any]:
    """A plant's contact counts ``[total, pairs]``; a plant without collision geometry is refused.

    Raises:
        InvalidArgumentError: contacts are off.
    """
    if contacts is None:
        raise InvalidArgumentError("contacts are off: build the plant with obstacles= or self_collision=True")
    return contacts
