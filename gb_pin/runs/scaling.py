"""Learner settings that follow the target set in use: radius, sigma and direction step scale with L.

A preset's radius and sigma (and onboarding's) were chosen for its own goal grid, a few
centimetres around home. A run given another target set (an array at ``babble`` time, or a
workspace region: ``targets="workspace:fraction=0.5"``) takes, for each setting not given:

- radius d = :data:`RADIUS_SHARE` L, L the extent of the goals (the diagonal of their 5-95 %
  percentile box, :func:`gb_pin.robot.workspace.extent`): 0.05-0.12 L was the useful band in
  the reference measurements, 0.08 L the best single value at the paper's learning rate; for a
  workspace region :data:`REGION_RADIUS_SHARE` L (with its learning rate 0.5 and 1000 goal
  points, 10^4 movements, 3 seeds, median / 90 %: SO-101 1.15 / 5.9 mm at 0.06 L against 1.73 /
  6.6 at 0.08 L and 300 points; Panda in two parts 5.1 / 24 against 7.8 / 24; docs/WORKSPACE.md);
- sigma: Eq. 12's, capped as onboarding caps it (:func:`gb_pin.robot.onboarding.exploration_sigma`:
  the exploration at home within half the half-width L / (2 sqrt(n)) of the set); for a workspace
  region :data:`REGION_SIGMA_GAIN` times that (measured: fewer misses near the joint limits);
- for a workspace region, the learning rate :data:`REGION_LEARNING_RATE` (the paper's 0.1 was
  chosen for 25 targets and about 50 prototypes; a region's 300-600 prototypes are each updated
  less often: at 10^4 movements, 3 seeds, SO-101 median / 90 % 3.10 / 19.1 mm at 0.1, 1.74 / 8.5 at
  0.3, 1.73 / 6.6 at 0.5, 1.90 / 5.7 at 1.0; Panda 6.76 / 151 at 0.1, 6.29 / 84 at 0.3, 7.34 / 85
  at 0.5);
- for a workspace region, the map's cutoff :data:`REGION_CUTOFF` (c = 3 radii: prototypes whose
  activation is below exp(-9) = 1.2e-4 of the nearest one's are left out of its sums; of a
  region's 800 prototypes about 55 remain; the errors those of c = 4 and of the whole sums, 10
  seeds, docs/WORKSPACE.md; a step costs 0.3-0.4 of the whole sums');
- for a workspace region, the noise's random-walk step sigma_delta: :func:`noise_walk_share` sigma,
  0.1 sigma (the paper's, Sec. III-B) per redundant joint, at most 0.3 sigma: over a region, an arm
  with several redundant joints learns better from a walk that turns faster (f = 0.5, 10^4
  movements, 6 seeds, median / 90 %: Panda 3.5 / 18 mm at 0.3 against 5.1 / 23 at 0.1, TALOS left
  arm 4.0 / 8.7 against 4.9 / 10.5, UR5 7.3 / 35 against 8.1 / 36), the SO-101 (one redundant
  joint) worse (f = 0.25: 0.32 / 0.85 mm at 0.1, 0.43 / 1.4 at 0.2, 0.58 / 2.3 at 0.3);
- the direction step of ``goals="directions"`` (when its ``distance`` is not given):
  :data:`DIRECTION_SHARE` L.

For a workspace region these values are taken as they are. For a target array given at ``babble``
time they only grow: each setting is the larger of the robot's own (its preset's, onboarding's,
else the paper's) and the scaled one, since the robot's were measured for its own goal set and
still serve a smaller one (the paper's planar arms learn 4 targets with radius 0.1 as well as 25),
while a larger set drowns in a radius chosen for a few centimetres (the human arm of
example-robot-data onboarded with radius 0.028 m for its 7 cm grid, given targets 40 cm across:
E^X / E_0 0.047-0.15 against 0.026-0.028 with the scaled radius, docs/WORKSPACE.md).

A run with the robot's own targets (a preset's default run) is left as it was: its fingerprint is
unchanged. Explicit values always win.
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.config import default_sigma
from gb_pin.learn.goals import CurriculumGoals, DirectionGoals, make_goals
from gb_pin.learn.metrics import evaluation_schedule
from gb_pin.robot.workspace import WorkspaceRegion, extent, is_workspace_spec
from gb_pin.runs.spec import RunSpec

RADIUS_SHARE = 0.08  # prototype radius d, a share of the goal set's extent L
REGION_RADIUS_SHARE = 0.06  # the same for a workspace region (measured, docs/WORKSPACE.md)
REGION_SIGMA_GAIN = 2.0  # sigma of a workspace region: this times Eq. 12's (capped)
DIRECTION_SHARE = 0.1  # direction sampling's step D, a share of L
REGION_DENSE = 100  # a region's E^X is recorded after every movement up to this count, then 20 per decade
REGION_LEARNING_RATE = 0.5  # eta of a workspace region (measured, docs/WORKSPACE.md)
REGION_CUTOFF = 3.0  # c of a workspace region's map: its sums over ~1/14 of the prototypes
REGION_NOISE_WALK = 0.1  # sigma_delta / sigma of a region, per redundant joint (docs/WORKSPACE.md)
REGION_NOISE_WALK_MAX = 0.3  # ... at most (measured on arms of 3 and 4 redundant joints)


def scaled_spec(spec: RunSpec, target: Any, defaults: dict[str, Any] | None = None) -> RunSpec:
    """``spec`` with a workspace region turned into point sets and the settings scaled to the goals.

    Unchanged when the run learns the robot's own targets (or continues a run: ``init``).
    ``defaults``: the robot's learner defaults (a preset's, onboarding's), the floor of the
    settings scaled to a given target array.

    Raises:
        InvalidArgumentError: a malformed workspace spec, or a robot without forward kinematics.
    """
    region = WorkspaceRegion.parse(str(spec.targets)) if is_workspace_spec(spec.targets) else None
    changes: dict[str, Any] = {}
    if region is not None and region.parts > 1:
        raise InvalidArgumentError(
            f"a workspace region in parts (parts={region.parts}) is learnt by babble() alone (one learner "
            "per part, gb_pin.runs.parted); a session or a continued run learns it with parts=1"
        )
    if region is not None:
        generator = make_goals(spec.goals) if spec.goals is not None else None
        blocks = region.stages > 1 and (
            generator is None
            or (isinstance(generator, CurriculumGoals) and generator.stages == region.stages)
        )
        goals = region.goal_points(target) if blocks else region.final_goals(target)
        changes["targets"] = goals
        if spec.goals is None and blocks:
            changes["goals"] = f"curriculum:stages={region.stages}"
        if spec.eval_targets is None:
            changes["eval_targets"] = region.test_set(target)
        if spec.schedule is None:  # 300 test points over a large map: the paper's dense schedule costs 3x
            changes["schedule"] = evaluation_schedule(
                int(spec.movements), dense_until=REGION_DENSE, per_decade=20
            )
        L = extent(goals[-region.points :])
    elif spec.targets is None or spec.init is not None or _same(spec.targets, _own_targets(target)):
        return spec
    else:
        with warnings.catch_warnings():  # checked here for their extent; target_set warns once after
            warnings.simplefilter("ignore")
            L = extent(target.check_targets(spec.targets))
        if not math.isfinite(L):
            return spec
    if not L > 0.0:
        return spec.replace(**changes)
    floor = _floors(target, defaults or {}) if region is None else {}
    if region is not None and spec.learning_rate is None:
        changes["learning_rate"] = REGION_LEARNING_RATE
    if region is not None and spec.cutoff is None:
        changes["cutoff"] = REGION_CUTOFF
    if spec.radius is None:
        share = REGION_RADIUS_SHARE if region is not None else RADIUS_SHARE
        changes["radius"] = max(share * L, floor.get("radius", 0.0))
    if spec.sigma is None:
        sigma = scaled_sigma(target, L, REGION_SIGMA_GAIN if region is not None else 1.0)
        if sigma is not None:
            changes["sigma"] = max(sigma, floor.get("sigma", 0.0))
    sigma_in_use = changes.get("sigma", spec.sigma)
    if region is not None and spec.sigma_delta is None and sigma_in_use is not None:
        changes["sigma_delta"] = noise_walk_share(target) * float(sigma_in_use)
    goals_name = changes.get("goals", spec.goals)
    if (
        isinstance(goals_name, str)
        and isinstance(make_goals(goals_name), DirectionGoals)
        and ("distance=" not in goals_name)
    ):
        sep = "," if ":" in goals_name else ":"
        distance = max(DIRECTION_SHARE * L, floor.get("distance", 0.0))
        changes["goals"] = f"{goals_name}{sep}distance={distance!r}"
    return spec.replace(**changes)


def noise_walk_share(target: Any) -> float:
    """sigma_delta / sigma of a workspace region: :data:`REGION_NOISE_WALK` per redundant joint, capped.

    Redundant joints: the learner's joints less the task's dimensions (at least one counted). The
    paper's 0.1 (Sec. III-B) for one, as the SO-101's 4 joints for a 3-D position; 0.3 for the UR5's
    6 joints and the 7 of the Panda and the TALOS arm.
    """
    joints = int(getattr(target, "n_joints", 0) or 0)
    task = int(getattr(target, "n_task", 0) or 0)
    redundant = max(1, joints - task)
    return min(REGION_NOISE_WALK * redundant, REGION_NOISE_WALK_MAX)


def _floors(target: Any, defaults: dict[str, Any]) -> dict[str, float]:
    """The robot's own radius, sigma and direction step: what a given target array scales up from."""
    from gb_pin.learn.config import BY_NAME

    home = getattr(target, "home", getattr(getattr(target, "target", None), "home", None))
    radius: Any = defaults.get("radius", BY_NAME["radius"].default)
    out = {"radius": float(radius),
           "distance": DirectionGoals().distance}  # fmt: skip
    sigma: Any = defaults.get("sigma")
    if sigma is None and home is not None:
        sigma = default_sigma(int(np.asarray(home).shape[0]))
    if sigma is not None:
        out["sigma"] = float(sigma)
    return out


def scaled_sigma(target: Any, L: float, gain: float = 1.0) -> float | None:
    """``gain`` times Eq. 12's sigma, capped to keep the exploration at home within the set (None: no model).

    The cap is onboarding's (:func:`~gb_pin.robot.onboarding.exploration_sigma`) for a goal set of
    half-width L / (2 sqrt(n)); a robot without a compiled chain gets ``gain`` times Eq. 12's.
    """
    model = target if getattr(target, "chain", None) is not None else getattr(target, "target", None)
    home = getattr(model, "home", getattr(target, "home", None))
    if home is None:
        return None
    m = int(np.asarray(home).shape[0])
    paper = gain * default_sigma(m)
    if (
        model is None
        or getattr(model, "chain", None) is None
        or getattr(model.chain, "components", None) is not None
    ):
        return paper  # no compiled chain (a function), or a stacked task: Eq. 12's
    from gb_pin.robot.onboarding import exploration_sigma

    n = int(model.n_task)
    half_width = L / (2.0 * math.sqrt(n)) / gain
    capped = exploration_sigma(model, half_width)
    return paper if capped is None else gain * capped


def _own_targets(target: Any) -> Any:
    own = getattr(target, "targets", None)
    if own is None and hasattr(target, "target"):
        own = getattr(target.target, "targets", None)
    return own


def _same(given: Any, own: Any) -> bool:
    if own is None:
        return False
    try:
        a = np.asarray(given, dtype=float)
    except (TypeError, ValueError):
        return False
    return a.shape == np.shape(own) and bool(np.array_equal(a, own))
