"""A replay as one meshcat ``set_animation`` command: keyframe tracks per node, looping forever.

Every moving node gets a clip: the robot's nodes (position and quaternion tracks,
plus scale where a mesh is scaled), the current-target sphere (position, and
visibility: hidden during home returns) and each trail sphere (the reached positions,
lagging behind). Keyframe times are in frames; the browser plays ``fps`` of them per
second, and its animation panel pauses, scrubs and changes speed.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
import umsgpack
from numpy.typing import NDArray

from gb_pin.viewer.geometry import quaternions
from gb_pin.viewer.style import TARGET, TRAIL

if TYPE_CHECKING:
    from gb_pin.viewer.stick import StickFigure


def _f32(a: NDArray[Any]) -> umsgpack.Ext:
    """A Float32Array for the browser (msgpack extension 0x17)."""
    return umsgpack.Ext(0x17, np.ascontiguousarray(a, dtype=np.float32).tobytes())


def _track(name: str, kind: str, times: umsgpack.Ext, values: Any) -> dict[str, Any]:
    return {"name": name, "type": kind, "times": times, "values": values}


def rotation_and_scale(M: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(R, s): rotations (..., 3, 3) and per-axis scales (..., 3) with ``M[..., :3, :3] = R @ diag(s)``.

    A mesh's scale multiplies the columns of its placement's rotation (``MeshFigure``); a mirrored
    mesh (a negative scale, e.g. TALOS's right arm and leg, its left ones mirrored) makes the matrix a
    reflection, which no quaternion describes: its y scale is then negative and R a rotation again.
    """
    A = np.asarray(M, dtype=float)[..., :3, :3]
    s = np.linalg.norm(A, axis=-2)
    R = A / np.where(s > 0, s, 1.0)[..., None, :]
    mirrored = np.linalg.det(R) < 0
    s[mirrored, 1] *= -1.0
    R[mirrored, :, 1] *= -1.0
    return R, s


def _pose_tracks(M: NDArray[np.float64], times: umsgpack.Ext) -> list[dict[str, Any]]:
    """Position, quaternion (and scale, if not 1) tracks of (R, 4, 4) transforms."""
    R, scale = rotation_and_scale(M)
    tracks = [
        _track(".position", "vector3", times, _f32(M[:, :3, 3])),
        _track(".quaternion", "quaternion", times, _f32(quaternions(R))),
    ]
    if not np.allclose(scale, 1.0):
        tracks.append(_track(".scale", "vector3", times, _f32(scale)))
    return tracks


def animation_command(
    figure: StickFigure,
    postures: NDArray[np.float64],
    targets3: NDArray[np.float64],
    target_visible: NDArray[np.bool_],
    positions3: NDArray[np.float64],
    times: NDArray[np.float64],
    fps: float,
    *,
    trail: int,
    trail_stride: int = 1,
) -> dict[str, Any]:
    """The ``set_animation`` command replaying recorded steps (looping forever).

    Args:
        figure: the robot's figure (node transforms of each posture).
        postures: (R, m) executed postures.
        targets3: (R, 3) current-target positions [m] (any value where hidden).
        target_visible: (R,) whether there is a current target (False during home returns).
        positions3: (R, 3) reached positions [m].
        times: (R,) keyframe times in frames (e.g. time steps since the first recorded).
        fps: frames per second of playback.
        trail: number of trail spheres.
        trail_stride: recorded steps between trail spheres.
    """
    R = postures.shape[0]
    per_path: dict[str, list[NDArray[np.float64]]] = {}
    for q in postures:
        for p, T in figure.transforms(q):
            per_path.setdefault(p, []).append(T)
    t = _f32(np.asarray(times, dtype=np.float32))
    clips: list[dict[str, Any]] = []

    def clip(path: str, tracks: list[dict[str, Any]]) -> None:
        clips.append({"path": path, "clip": {"fps": float(fps), "name": "default", "tracks": tracks}})

    for p, Ts in per_path.items():
        clip(p, _pose_tracks(np.array(Ts), t))
    clip(
        TARGET,
        [
            _track(".position", "vector3", t, _f32(targets3)),
            _track(".visible", "boolean", t, np.asarray(target_visible, dtype=bool).tolist()),
        ],
    )
    for k in range(trail):
        lag = k * trail_stride
        idx = np.maximum(np.arange(R) - lag, 0)
        clip(
            f"{TRAIL}/t{k}",
            [
                _track(".position", "vector3", t, _f32(positions3[idx])),
                _track(".visible", "boolean", t, (np.arange(R) >= lag).tolist()),
            ],
        )
    return {
        "type": "set_animation",
        "path": "",
        "animations": clips,
        "options": {"play": True, "repetitions": math.inf},
    }
