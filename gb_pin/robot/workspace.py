"""Goal regions at the scale of the arm's own reach: ``targets="workspace:fraction=0.5"``.

A preset's goal grid covers 1-5 % of the volume its arm reaches; a user wants the arm to reach
the table in front of it. A *workspace region* is the set of hand positions of postures drawn
uniformly within a fraction ``f`` of every joint's range around home:

    q = low + f (upper - lower) u,   u ~ U(0, 1)^m,

low centring the window on home, shifted inside the limits where it would cross one,

and its points are f(q) (forward kinematics): reachable by construction, shaped like the arm's
own workspace (a shell around the base for a turning arm, not a box). The goal points and the
test points come from two seeds, so that E^X is measured on points never learnt.

With a curriculum (``stages`` > 1, the default) the goal set holds ``stages`` blocks of
``points`` goals each, the same draws u scaled to ``f / 2^(stages - 1)``, ..., ``f / 2``, ``f``
(from home outwards); :class:`~gb_pin.learn.goals.CurriculumGoals` draws from one block after
the other (docs/WORKSPACE.md measures why: 10^4 movements of the Panda, 90 % error 84 mm with it
against 108 mm without, in the reference measurements).

This module imports no pinocchio: it needs a robot's home, limits and forward function.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError

PREFIX = "workspace"
MAX_POINTS = 100_000  # goal or test points of one region (arrays of a few MB)
_UNBOUNDED = math.pi  # half-width of the sampling interval of an unbounded joint [rad] or [m]
EXTENT_LOW, EXTENT_HIGH = 5.0, 95.0  # the percentiles of the box whose diagonal is a set's extent L
AUTO = 0  # parts=auto: chosen by gb_pin.robot.workspace_parts.auto_parts
MAX_PARTS = 8  # gb_pin.learn.parts.MAX_PARTS (not imported: the CLI's help loads no numba)


def is_workspace_spec(value: Any) -> bool:
    """True for ``"workspace"`` or ``"workspace:..."`` (a :class:`WorkspaceRegion` spec string)."""
    return isinstance(value, str) and (value == PREFIX or value.startswith(PREFIX + ":"))


@dataclass(frozen=True)
class WorkspaceRegion:
    """A region of the arm's reach: FK of postures within ``fraction`` of every joint's range.

    Attributes:
        fraction: f, the share of each joint's range (centred on home, within the limits), in (0, 1].
        points: goal points per curriculum stage.
        seed: seed of the goal postures.
        test_points: test points (where E^X is measured).
        test_seed: seed of the test postures (another than ``seed``: points never learnt).
        stages: curriculum stages (1: none); stage s draws from ``fraction / 2^(stages - s)``.
        parts: learners, one per sector around the first joint's axis, each with its own home and
            map (:mod:`gb_pin.robot.workspace_parts`); 1: one learner for the whole region; 0
            (``parts=auto``, the default): 2 where the region wraps around that axis (its goal
            points span more than half a turn around it, :data:`AUTO_SPAN`), else 1.
    """

    fraction: float = 0.5
    points: int = 1000
    seed: int = 0
    test_points: int = 300
    test_seed: int = 1
    stages: int = 3
    parts: int = AUTO

    def __post_init__(self) -> None:
        f = self.fraction
        if isinstance(f, bool) or not isinstance(f, int | float) or not 0.0 < float(f) <= 1.0:
            raise InvalidArgumentError(
                f"workspace fraction must be in (0, 1] (the share of each joint's range), got {f!r}"
            )
        bounds = (("points", 1, MAX_POINTS), ("test_points", 1, MAX_POINTS), ("stages", 1, 8),
                  ("parts", AUTO, MAX_PARTS))  # fmt: skip
        for name, low, high in bounds:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
                auto = " or 'auto' (0)" if name == "parts" else ""
                raise InvalidArgumentError(
                    f"workspace {name} must be an integer in [{max(low, 1)}, {high}]{auto}, got {value!r}"
                )
        for name in ("seed", "test_seed"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InvalidArgumentError(f"workspace {name} must be an integer >= 0, got {value!r}")

    @classmethod
    def parse(cls, text: str) -> WorkspaceRegion:
        """``"workspace:fraction=0.5,points=1000,seed=0,test_points=300,test_seed=1,stages=3,parts=2"``.

        ``parts=auto`` (the default) reads as 0.

        Raises:
            InvalidArgumentError: not a workspace spec, an unknown key or a bad value.
        """
        if not is_workspace_spec(text):
            raise InvalidArgumentError(f"a workspace region is 'workspace:fraction=F,...', got {text!r}")
        names = [f.name for f in dataclasses.fields(cls)]
        values: dict[str, Any] = {}
        for item in filter(None, (part.strip() for part in text[len(PREFIX) + 1 :].split(","))):
            key, sep, value = (s.strip() for s in item.partition("="))
            if not sep or key not in names:
                raise InvalidArgumentError(
                    f"targets={text!r}: expected key=value with a key of {', '.join(names)}, got {item!r}"
                )
            if key == "parts" and value == "auto":
                values[key] = AUTO
                continue
            try:
                values[key] = float(value) if key == "fraction" else int(value)
            except ValueError as exc:
                raise InvalidArgumentError(f"targets={text!r}: {key}={value!r} is not a number") from exc
        return cls(**values)

    def spec(self) -> str:
        """The spec string that :meth:`parse` reads back to this region."""
        return (
            PREFIX
            + ":"
            + ",".join(
                f"{f.name}={getattr(self, f.name)!r}"
                for f in dataclasses.fields(self)
                if f.name != "parts" or self.parts != AUTO  # the default's spec reads as before
            )
        )

    def stage_fractions(self) -> list[float]:
        """The fraction of every curriculum stage, from home outwards (the last is ``fraction``)."""
        return [self.fraction / 2.0 ** (self.stages - 1 - s) for s in range(self.stages)]

    def goal_points(self, robot: Any) -> NDArray[np.float64]:
        """(stages * points, n) goals: the curriculum's blocks one after the other [m]."""
        u = np.random.default_rng(self.seed).random((self.points, _model(robot).home.shape[0]))
        return np.vstack([region_points(robot, f, u) for f in self.stage_fractions()])

    def final_goals(self, robot: Any) -> NDArray[np.float64]:
        """(points, n) the goals of the whole region (the last stage's block) [m]."""
        u = np.random.default_rng(self.seed).random((self.points, _model(robot).home.shape[0]))
        return region_points(robot, self.fraction, u)

    def test_set(self, robot: Any) -> NDArray[np.float64]:
        """(test_points, n) test points of the whole region, from ``test_seed`` [m]."""
        u = np.random.default_rng(self.test_seed).random((self.test_points, _model(robot).home.shape[0]))
        return region_points(robot, self.fraction, u)


def _model(robot: Any) -> Any:
    """What has the home, limits and forward kinematics of ``robot`` (a plant's or changed body's model)."""
    model = robot
    for _ in range(3):
        if all(hasattr(model, a) for a in ("home", "lower", "upper", "forward")):
            return model
        model = getattr(model, "target", None)
    raise InvalidArgumentError(
        f"a workspace region needs a robot's home, joint limits and forward kinematics; {robot!r} has none "
        "(a robot known only from outside: give its targets as points)"
    )


def region_postures(robot: Any, fraction: float, u: NDArray[np.float64]) -> NDArray[np.float64]:
    """Postures uniform within a window of ``fraction`` of every joint's range around home (N, m).

    Joint i's window has width w_i = fraction (upper_i - lower_i), centred on home_i and shifted
    inside the limits where it would cross one (so that no posture piles up at a limit); an
    unbounded joint, or one whose range exceeds a turn (xArm7's +-2 pi), counts as a range of 2 pi
    there. q_i = low_i + w_i u_i.
    """
    model = _model(robot)
    low, width = window(robot, fraction)
    lower, upper = np.asarray(model.lower, dtype=float), np.asarray(model.upper, dtype=float)
    return np.clip(low + width * u, lower, upper)


def window(robot: Any, fraction: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """(low, width) (m,) each: the window of :func:`region_postures`, [low, low + width] per joint."""
    model = _model(robot)
    home = np.asarray(model.home, dtype=float)
    lower = np.asarray(model.lower, dtype=float)
    upper = np.asarray(model.upper, dtype=float)
    span = np.where(np.isfinite(upper - lower), upper - lower, 2.0 * _UNBOUNDED)
    width = fraction * np.minimum(span, 2.0 * _UNBOUNDED)  # a range beyond one turn adds no postures
    low = np.maximum(np.minimum(home - width / 2.0, upper - width), lower)
    low = np.where(np.isfinite(low), low, home - width / 2.0)
    return low, width


def region_points(robot: Any, fraction: float, u: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hand positions of :func:`region_postures` (N, n) [m]: reachable by construction."""
    return forward_all(robot, region_postures(robot, fraction, u))


def forward_all(robot: Any, Q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hand positions of postures Q (N, m) -> (N, n) [m], checked finite."""
    model = _model(robot)
    if getattr(model, "chain", None) is not None:  # compiled kinematics: all postures at once
        X = np.asarray(model.forward(Q), dtype=float)
    else:  # a forward model given as a function: one posture at a time, as babble() calls it
        X = np.array([np.asarray(model.forward(q), dtype=float) for q in Q])
    if X.ndim != 2 or X.shape[0] != Q.shape[0]:
        raise InvalidArgumentError(
            f"the forward kinematics gave positions of shape {X.shape} for {Q.shape[0]} postures"
        )
    if not np.all(np.isfinite(X)):
        raise InvalidArgumentError("the forward kinematics gave non-finite positions in the workspace region")
    return X


def extent(points: Any) -> float:
    """L, the diagonal of the 5-95 % percentile box of a point set (N, n) [m]."""
    X = np.asarray(points, dtype=float)
    if X.ndim != 2 or X.shape[0] == 0:
        raise InvalidArgumentError(f"extent needs a point set (N, n), got shape {X.shape}")
    low, high = np.percentile(X, [EXTENT_LOW, EXTENT_HIGH], axis=0)
    return float(np.linalg.norm(high - low))
