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


def _pose_tracks(M: NDArray[np.float64], times: umsgpack.Ext) -> list[dict[str, Any]]:
    """Position, quaternion (and scale, if not 1) tracks of (R, 4, 4) transforms."""
    tracks = [
        _track(".position", "vector3", times, _f32(M[:, :3, 3])),
        _track(".quaternion", "quaternion", times, _f32(quaternions(M[:, :3, :3]))),
    ]
    scale = np.linalg.norm(M[:, :3, :3], axis=1)
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
