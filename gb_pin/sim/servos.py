"""Servos: the position controllers that hold each moved joint of a simulated arm.

A hobby servo (and, at joint level, most position-controlled arms) is a PD controller on the
joint angle, with no gravity compensation:

    tau = clip(kp (q_cmd - q) - kv dq/dt, -force_limit, force_limit),

so an arm under gravity settles where the servo torque balances the gravity torque, short of
the commanded posture by about tau_gravity / kp: the sag a learner sees and a kinematic model
does not. ``armature`` adds the reflected rotor inertia to each joint; it also keeps the
explicit position gain stable on light links (0.01 kg m^2 at a 2 ms step for the SO-101).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.exceptions import InvalidArgumentError

DAMPING_RATIO = 0.05
"""Default servo damping kv as a fraction of kp [s] (kv = 0.05 kp)."""


@dataclass(frozen=True, eq=False)
class Servos:
    """The servo of each moved joint.

    Attributes:
        kp: (m,) position gain [N m/rad] (prismatic joints: [N/m]).
        kv: (m,) damping gain [N m s/rad] (prismatic: [N s/m]).
        force_limit: (m,) largest torque [N m] (prismatic: [N]); inf: unlimited.
        armature: (m,) rotor inertia added to each joint [kg m^2] (prismatic: [kg]).
    """

    kp: NDArray[np.float64]
    kv: NDArray[np.float64]
    force_limit: NDArray[np.float64]
    armature: NDArray[np.float64]

    @classmethod
    def of(
        cls,
        m: int,
        kp: float | ArrayLike = 10.0,
        damping: float | ArrayLike | None = None,
        force_limit: float | ArrayLike | None = None,
        armature: float | ArrayLike = 0.01,
    ) -> Servos:
        """Servos of ``m`` joints from numbers (one for every joint) or vectors (one per joint).

        Args:
            m: number of moved joints.
            kp: position gain [N m/rad], > 0.
            damping: kv [N m s/rad], >= 0; None: ``DAMPING_RATIO * kp``.
            force_limit: largest torque [N m], > 0; None: unlimited.
            armature: rotor inertia [kg m^2], >= 0.

        Raises:
            InvalidArgumentError: a value of the wrong length, not finite, or out of range.
        """
        gains = _per_joint("kp", kp, m, positive=True)
        kv = DAMPING_RATIO * gains if damping is None else _per_joint("damping", damping, m)
        limit = (
            np.full(m, math.inf) if force_limit is None else _per_joint("force_limit", force_limit, m, True)
        )
        return cls(gains, kv, limit, _per_joint("armature", armature, m))

    @property
    def limited(self) -> bool:
        """Whether any servo has a force limit."""
        return bool(np.any(np.isfinite(self.force_limit)))

    def describe(self) -> str:
        """``kp 10, kv 0.5, armature 0.01`` (one number where all joints agree)."""
        parts = [f"kp {short(self.kp)}", f"kv {short(self.kv)}", f"armature {short(self.armature)}"]
        if self.limited:
            parts.append(f"force limit {short(self.force_limit)}")
        return ", ".join(parts)


def _per_joint(name: str, value: Any, m: int, positive: bool = False) -> NDArray[np.float64]:
    """``value`` as (m,) finite floats (>= 0, or > 0 with ``positive``), a number broadcast."""
    try:
        arr = np.array(np.broadcast_to(np.asarray(value, dtype=np.float64), (m,)))
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"{name} must be a number or one per joint ({m}), got {value!r}") from exc
    bad = ~np.isfinite(arr) | (arr <= 0 if positive else arr < 0)
    if np.any(bad) or isinstance(value, bool):
        bound = "> 0" if positive else ">= 0"
        raise InvalidArgumentError(f"{name} must be finite and {bound} (one or {m} numbers), got {value!r}")
    return arr


def short(values: NDArray[np.float64]) -> str:
    """``10`` where every joint has the value, else ``[10, 10, 5, 5]``."""
    if np.all(values == values[0]):
        return f"{values[0]:g}"
    return "[" + ", ".join(f"{v:g}" for v in values) + "]"
