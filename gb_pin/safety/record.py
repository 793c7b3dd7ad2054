"""A safe run's settings as plain values: what checkpoints and result files record, read back checked.

``{"obstacles": [{"kind": "table", "height": 0.0}, ...], "self_collision": True,
"collision_geometry": "urdf", "clearance": 0.01, "checked_asks": 7501, "cut_asks": 4188}``: the
obstacles as :func:`gb_pin.safety.obstacles.plain` writes them, the check's settings, and its counts
so far (``"slide": False`` too for a checker that stops at a cut instead of sliding: absent, it
slides, so the files of sliding runs are as before). :func:`gb_pin.runs.session.resume_session` and
:func:`gb_pin.resume` build the same
:class:`~gb_pin.safety.checker.CollisionChecker` from it (the collision matrix is regenerated the
same way, or read from its cache), so a resumed run is checked as it was before it stopped
(:func:`gb_pin.runs.setup.recorded_guard`).
"""

from __future__ import annotations

import math
from typing import Any

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.safety.obstacles import MAX_OBSTACLES, check_obstacles, plain

GEOMETRIES = ("urdf", "capsules")
KEYS = ("obstacles", "self_collision", "collision_geometry", "clearance", "checked_asks", "cut_asks")


def settings_of(guard: Any, cuts: int | None = None) -> dict[str, Any] | None:
    """The settings and counts of ``guard`` (a CollisionChecker), or None for no guard or another callable.

    Args:
        guard: the session's guard.
        cuts: asks cut short (a session counts every kind of ask; default the checker's own count).
    """
    from gb_pin.safety.checker import CollisionChecker

    if not isinstance(guard, CollisionChecker):
        return None
    settings: dict[str, Any] = {
        "obstacles": [plain(o) for o in guard.obstacles],
        "self_collision": guard.self_collision,
        "collision_geometry": guard.geometry.kind,
        "clearance": guard.clearance,
        "checked_asks": int(guard.asks),
        "cut_asks": int(guard.cuts if cuts is None else cuts),
    }
    if not guard.slide:
        settings["slide"] = False
    return settings


def result_fields(guard: Any, cuts: int) -> dict[str, Any]:
    """A session's result fields of its guard: settings and counts (none without a guard)."""
    if guard is None:
        return {}
    return {
        "safety": settings_of(guard, cuts),
        "checked_asks": int(getattr(guard, "asks", 0)),
        "cut_asks": cuts,
    }


def read_settings(value: Any) -> dict[str, Any] | None:
    """The settings a file recorded, checked (None: the run was not checked).

    Raises:
        InvalidArgumentError: anything but what :func:`settings_of` writes (the caller names the file).
    """
    if value is None:
        return None
    if not isinstance(value, dict) or sorted(set(value) - {"slide"}) != sorted(KEYS):
        raise InvalidArgumentError(f"corrupted safety entry {str(value)[:120]!r}: expected the keys {KEYS}")
    slide = value.get("slide", True)
    if not isinstance(slide, bool):
        raise InvalidArgumentError(f"corrupted slide entry {str(slide)[:40]!r}: expected true or false")
    raw = value["obstacles"]
    if not isinstance(raw, list) or len(raw) > MAX_OBSTACLES or not all(isinstance(o, dict) for o in raw):
        raise InvalidArgumentError(f"corrupted obstacles entry {str(raw)[:120]!r}")
    obstacles = check_obstacles(raw)
    self_collision = value["self_collision"]
    geometry = value["collision_geometry"]
    clearance = value["clearance"]
    if not isinstance(self_collision, bool) or (not obstacles and not self_collision):
        raise InvalidArgumentError(f"corrupted self_collision entry {self_collision!r}")
    if geometry not in GEOMETRIES:
        raise InvalidArgumentError(
            f"collision_geometry must be one of {GEOMETRIES}, got {str(geometry)[:40]!r}"
        )
    if (
        isinstance(clearance, bool)
        or not isinstance(clearance, int | float)
        or not (math.isfinite(clearance) and 0 < clearance <= 1.0)
    ):
        raise InvalidArgumentError(f"clearance must be a number in (0, 1] m, got {str(clearance)[:40]!r}")
    counts = {}
    for key in ("checked_asks", "cut_asks"):
        n = value[key]
        if isinstance(n, bool) or not isinstance(n, int) or not 0 <= n <= 2**62:
            raise InvalidArgumentError(f"{key} must be a count >= 0, got {str(n)[:40]!r}")
        counts[key] = n
    return {
        "obstacles": [plain(o) for o in obstacles], "self_collision": self_collision,
        "collision_geometry": geometry, "clearance": float(clearance), **counts,
        **({} if slide else {"slide": False}),
    }  # fmt: skip
