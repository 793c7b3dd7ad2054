"""The URDF's visual meshes on the plant's bodies, decimated for fast offscreen rendering.

A rendering plant (:class:`~gb_pin.sim.plant.MujocoPlant` with ``camera=``) draws the robot as a
camera sees it: the URDF's visual meshes (Pinocchio's visual ``GeometryModel`` of the full
model) hung on the moved body they ride on (a mesh on a locked joint rides on its moved
ancestor, placed at the reference posture, as the reduced model welds it). Each mesh is
decimated by vertex clustering: vertices snapped to a grid (1.5 mm by default) and merged,
triangles that collapsed dropped: the SO-101's 323k triangles become ~31k, and a 640 x 480
frame renders in 20-35 ms on Mesa's llvmpipe instead of hundreds. Meshes are handed to MuJoCo
as in-memory binary STL assets. A robot without meshes (no URDF, or unreadable files) is drawn
with capsules between its joints instead.
"""

from __future__ import annotations

import struct
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

GRID = 0.0015
"""Vertex clustering grid of the decimation [m]."""
MAX_TRIANGLES = 2_000_000
"""The most triangles read from one mesh file (a larger one is drawn as a capsule instead)."""


class Visual(NamedTuple):
    """One mesh: its STL bytes, the moved joint it rides on (q index, -1: the world), its placement there."""

    name: str
    stl: bytes
    parent: int
    position: NDArray[np.float64]
    rotation: NDArray[np.float64]
    triangles: int


def read_stl(path: str | Path) -> NDArray[np.float64]:
    """The triangles (T, 3, 3) [file units] of a binary or ASCII STL file.

    Raises:
        ValueError: not an STL file, or larger than :data:`MAX_TRIANGLES`.
    """
    data = Path(path).read_bytes()
    if len(data) >= 84:
        (count,) = struct.unpack_from("<I", data, 80)
        if count <= MAX_TRIANGLES and len(data) == 84 + 50 * count:
            rec = np.frombuffer(data, dtype=np.uint8, count=50 * count, offset=84).reshape(count, 50)
            return rec[:, 12:48].copy().view("<f4").reshape(count, 3, 3).astype(np.float64)
    text = data.decode("ascii", errors="replace")
    if not text.lstrip().startswith("solid"):
        raise ValueError(f"{path}: not an STL file")
    values = [line.split()[1:4] for line in text.splitlines() if line.strip().startswith("vertex")]
    if not values or len(values) % 3 or len(values) > 3 * MAX_TRIANGLES:
        raise ValueError(f"{path}: malformed or too large STL")
    return np.asarray(values, dtype=np.float64).reshape(-1, 3, 3)


def decimate(
    triangles: NDArray[np.float64], grid: float = GRID
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Vertex clustering: (vertices (V, 3), faces (F, 3)) with vertices merged on a ``grid`` [m] lattice."""
    points = triangles.reshape(-1, 3)
    cells = np.floor(points / grid).astype(np.int64)
    cells -= cells.min(axis=0)
    span = cells.max(axis=0) + 1
    keys, inverse = np.unique(
        (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2], return_inverse=True
    )
    inverse = inverse.ravel()
    count = np.bincount(inverse, minlength=len(keys)).astype(float)[:, None]
    vertices = np.column_stack([np.bincount(inverse, points[:, a], len(keys)) for a in range(3)]) / count
    faces = inverse.reshape(-1, 3)
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])]
    s = np.sort(faces, axis=1)
    n = len(keys)
    _, first = np.unique((s[:, 0] * n + s[:, 1]) * n + s[:, 2], return_index=True)  # one of each triangle
    return vertices, faces[np.sort(first)].astype(np.int64)


def stl_bytes(vertices: NDArray[np.float64], faces: NDArray[np.int64]) -> bytes:
    """A binary STL of a mesh (normals left zero: MuJoCo computes its own)."""
    tri = vertices[faces].astype("<f4")
    rec = np.zeros(len(faces), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")])
    rec["v"] = tri
    return b"gb_pin decimated mesh".ljust(80, b" ") + struct.pack("<I", len(faces)) + rec.tobytes()


_CACHE: dict[tuple[Any, ...], list[Visual]] = {}


def visuals(target: Any, grid: float = GRID) -> list[Visual]:
    """The decimated visual meshes of ``target`` on its moved bodies; [] when it has none.

    Loading the meshes through Pinocchio builds their collision trees (seconds): the result is
    kept per process for the same URDF, joints, reference posture and grid.

    Args:
        target: a :class:`~gb_pin.robot.target.KinematicTarget` built from a URDF.
        grid: the decimation grid [m].
    """
    urdf = getattr(target, "urdf", None)
    key = (urdf, tuple(target.joints), np.asarray(target.reference, float).tobytes(), float(grid))
    if urdf is not None and key in _CACHE:
        return _CACHE[key]
    out = _visuals(target, grid)
    if urdf is not None:
        _CACHE[key] = out
    return out


def _visuals(target: Any, grid: float) -> list[Visual]:
    import pinocchio as pin

    try:
        geometry = target.visual_model()
    except Exception:  # no URDF, missing mesh files: the plant draws capsules instead
        return []
    model = target.full_model
    data = model.createData()
    pin.forwardKinematics(model, data, target.full_configuration(target.home))
    moved = {name: a for a, name in enumerate(target.joints)}
    out: list[Visual] = []
    for g in geometry.geometryObjects:
        path = getattr(g, "meshPath", "")
        if not path or not Path(path).is_file() or Path(path).suffix.lower() != ".stl":
            continue
        j = int(g.parentJoint)
        while j > 0 and model.names[j] not in moved:
            j = int(model.parents[j])
        parent = moved[model.names[j]] if j > 0 else -1
        world = data.oMi[int(g.parentJoint)] * g.placement
        local = world if j == 0 else data.oMi[j].actInv(world)
        try:
            triangles = read_stl(path) * np.asarray(g.meshScale, dtype=float)
        except (OSError, ValueError):
            continue
        vertices, faces = decimate(triangles, grid)
        if len(faces) == 0:
            continue
        out.append(Visual(f"mesh{len(out)}", stl_bytes(vertices, faces), parent,
                          np.array(local.translation), np.array(local.rotation), len(faces)))  # fmt: skip
    return out
