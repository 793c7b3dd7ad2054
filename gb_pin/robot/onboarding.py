"""Onboarding: the joints, home, goal grid and prototype radius of a robot, chosen by measurement.

A robot given as a model and a frame, without the joints the learner moves, a home posture, a goal
set or a radius, gets them here (``KinematicTarget(..., onboard=True)``, the default of
:meth:`~gb_pin.robot.target.KinematicTarget.from_urdf`, ``from_example_robot_data`` and
``gb-pin --robot FILE.urdf | erd:NAME``):

1. **joints**: the 1-DOF joints on the path from the model's root to the frame (a floating base
   and every other joint stay locked), less those that do not move the frame's position (measured
   on :data:`PROBES` seeded postures within the limits, e.g. a wrist roll about an axis through it);
2. **home**: among the reference posture, the middle of the limits and :data:`CANDIDATES` seeded
   postures within the central part of every joint's range, the :data:`SHORTLIST` best by
   ``min(margin / MARGIN_FULL, 1) * sigma_min`` (``margin``: the smallest distance of a joint from its
   limits, as a fraction of its range; ``sigma_min``: the smallest singular value of the task
   Jacobian, each column scaled by its joint's reach, zero at a singularity); each is probed by
   :data:`PROBE_SEEDS` runs of :data:`PROBE_MOVEMENTS` movements on its goal grid (steps 3-5), and
   the one with the largest reachable grid among those within :data:`PROBE_SLACK` of the best
   probe's E^X / E_0 is the home (the largest grid alone picked homes that learn badly: median
   0.085 E_0 for simple_humanoid's right wrist, 0.077 for G1's right hand, against 0.021 and 0.018);
3. **goal grid**: :data:`GRID_SCALE` of the largest reachable 3-per-axis grid around that home
   (:func:`~gb_pin.robot.targets_auto.auto_grid`; the largest reaches to the workspace's border, where
   learning is slow);
4. **radius**: :data:`RADIUS_FACTOR` times the grid's half-width (the spacing of its points);
5. **sigma**: Eq. 12's, unless the exploration it makes at home, ``sigma sqrt(1 + |x_home|^2) |J|_F``
   [m] (Eq. 8's noise A x + b on every joint, through the task Jacobian J), exceeds
   :data:`DEVIATION_SHARE` of the grid's half-width: then that much (a goal grid small for the arm,
   e.g. a 10 cm prismatic stroke across a 1 m arm, is otherwise drowned in exploration).

The constants were measured on the arms of example-robot-data (docs/ROBOTS.md, "Any robot": 5 seeds,
3000 movements): with the largest grid, Panda, TALOS and xArm7 ended at 19-30 % of E_0; with half of
it, this radius and the probed home, every arm's median is below 3 % (``gb-pin robots --erd``).
Every draw is seeded: the same model, the same choice. This module works on anything with a chain
and limits (no robot class); only :func:`path_joints` reads a ``pin.Model``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import GbPinError, InvalidArgumentError, OnboardingBudgetError
from gb_pin.robot.reachability import positions, sampling_bounds
from gb_pin.robot.targets_auto import AutoGrid, auto_grid

if TYPE_CHECKING:
    import pinocchio as pin

    from gb_pin.robot.reachability import Robot

CANDIDATES = 200  # seeded home candidates, besides the reference posture and the middle of the limits
BAND = 0.15  # candidates avoid this fraction of each joint's range at either end
MARGIN_FULL = 0.2  # a joint this far from its limits (fraction of its range) is not penalised
BUDGET_SECONDS = 30.0  # onboarding's time budget [s] (Budget), plus ...
BUDGET_PER_JOINT = 0.1  # ... this much a joint [s]
SHORTLIST = 6  # candidates whose reachable grid is measured
SHORTLIST_SAMPLES = 5000  # postures sampled for their grids (the final grid uses the default 20 000)
PROBE_MOVEMENTS = 300  # movements of each short run that probes how well a candidate home learns
PROBE_SEEDS = 2  # short runs per candidate (seeds PROBE_SEED, PROBE_SEED + 1)
PROBE_SEED = 1000
PROBE_SLACK = 1.5  # candidates within this factor of the best probe E^X / E_0 are kept
PROBES = 32  # seeded postures where each joint's effect on the frame is measured
MOVES = 1e-6  # a joint moves the frame if some probe's Jacobian column exceeds this [m/rad] or [m/m]
GRID_SCALE = 0.5  # the goal grid's half-width, a fraction of the largest reachable one
RADIUS_FACTOR = 0.8  # the prototype radius d, a multiple of the goal grid's half-width
DEVIATION_SHARE = 0.5  # the most exploration at home, a fraction of the goal grid's half-width
_STEP = 1e-7  # finite-difference step of the Jacobian [rad] or [m]
CHOSEN = ("joints", "home", "targets", "radius", "sigma")


@dataclass(frozen=True, eq=False)
class Onboarding:
    """What onboarding chose for a robot, and the measurements behind it.

    Attributes:
        chosen: which of ``"joints"``, ``"home"``, ``"targets"``, ``"radius"`` were chosen here
            (the others were given).
        dropped: joints on the frame's path left out because they do not move it.
        margin: the home's smallest distance from a joint limit, a fraction of that joint's range
            (0.5: every joint mid-range; unbounded joints count 0.5).
        sigma_min: the smallest singular value of the task Jacobian at home, each column scaled
            by its joint's reach (:func:`smallest_singular_value`) [m] (0: singular).
        half_width: the goal grid's half-width [m] (0 when the targets were given).
        largest_half_width: the largest reachable grid's half-width around home [m] (0: not measured).
        shape: points per task axis of the goal grid (empty when the targets were given).
        radius: the prototype radius d [m], or None when not chosen.
        sigma: the exploration noise [rad], or None (Eq. 12's, or not chosen).
        joints: the joints the robot moves (chosen or given), for :meth:`__str__`.
        home: the home posture over ``joints`` (chosen or given).
        n_targets: the goal set's size.

    ``print(record)`` shows what was chosen, as ``gb-pin babble`` does (:meth:`lines`), with the
    joints and home whether chosen or given.
    """

    chosen: tuple[str, ...]
    dropped: tuple[str, ...] = ()
    margin: float = math.nan
    sigma_min: float = math.nan
    half_width: float = 0.0
    largest_half_width: float = 0.0
    shape: tuple[int, ...] = ()
    radius: float | None = None
    sigma: float | None = None
    joints: tuple[str, ...] = ()
    home: tuple[float, ...] = ()
    n_targets: int = 0

    def __str__(self) -> str:
        """What was chosen and the robot it was chosen for: joints, home, goal grid, radius, sigma."""
        given = [c for c in CHOSEN if c not in self.chosen and not (c == "sigma" and self.sigma is None)]
        head = f"onboarding: chosen by measurement: {', '.join(self.chosen)}"
        head += f"; given: {', '.join(given)}" if given else ""
        lines = self.lines(self.joints, np.asarray(self.home, dtype=float), self.n_targets)
        if self.joints and "joints" not in self.chosen:
            lines.insert(0, f"joints    {','.join(self.joints)} (given)")
        if self.home and "home" not in self.chosen:
            at = 1 if self.joints else 0
            lines.insert(at, f"home      {','.join(f'{v:.3f}' for v in self.home)} (given)")
        return "\n".join([head, *(f"  {line}" for line in lines)])

    def to_json(self) -> dict[str, Any]:
        """A JSON-serialisable dict (the result file's ``robot_source.onboarding``).

        The robot's joints, home and goal set size are the file's own fields, not repeated here.
        """
        out = dataclasses.asdict(self)
        for key in ("joints", "home", "n_targets"):
            del out[key]
        out["chosen"], out["dropped"], out["shape"] = list(self.chosen), list(self.dropped), list(self.shape)
        for key in ("margin", "sigma_min"):
            if not math.isfinite(out[key]):
                out[key] = None
        return out

    @classmethod
    def from_json(cls, raw: dict[str, Any]) -> Onboarding:
        """The record :meth:`to_json` wrote (checked by :func:`gb_pin.runs.robot_source.check`)."""
        return cls(
            chosen=tuple(raw["chosen"]),
            dropped=tuple(raw["dropped"]),
            margin=math.nan if raw["margin"] is None else float(raw["margin"]),
            sigma_min=math.nan if raw["sigma_min"] is None else float(raw["sigma_min"]),
            half_width=float(raw["half_width"]),
            largest_half_width=float(raw["largest_half_width"]),
            shape=tuple(int(c) for c in raw["shape"]),
            radius=None if raw["radius"] is None else float(raw["radius"]),
            sigma=None if raw.get("sigma") is None else float(raw["sigma"]),
        )

    def lines(self, joints: Sequence[str], home: NDArray[np.float64], targets: int) -> list[str]:
        """What was chosen, one line each (the command line prints them), e.g. ``home  0.1,0.6 (...)``."""
        out = []
        if "joints" in self.chosen:
            left = f"; left out, they do not move it: {', '.join(self.dropped)}" if self.dropped else ""
            out.append(f"joints    {','.join(joints)} (the {len(joints)} that move the frame{left})")
        if "home" in self.chosen:
            out.append(
                f"home      {','.join(f'{v:.3f}' for v in home)} (joints >= {self.margin:.0%} of their "
                f"range from their limits, sigma_min {self.sigma_min:.3f} m)"
            )
        if "targets" in self.chosen:
            grid = " x ".join(str(c) for c in self.shape)
            out.append(
                f"targets   {targets} ({grid} grid, half-width {self.half_width:.3f} m around the home: "
                f"{GRID_SCALE:g} of the largest reachable, {self.largest_half_width:.3f} m)"
            )
        if self.radius is not None:
            out.append(f"radius    {self.radius:.3f} m ({RADIUS_FACTOR:g} x the grid's half-width)")
        if self.sigma is not None:
            out.append(
                f"sigma     {self.sigma:.3g} rad (less than Eq. 12's: the exploration at home within "
                f"{DEVIATION_SHARE:g} of the grid's half-width)"
            )
        return out


def path_joints(model: pin.Model, frame_id: int, name: str) -> list[str]:
    """The 1-DOF joints on the path from the root to frame ``frame_id``, root first.

    A floating base, spherical or planar joints on the path are left out (they stay locked).

    Raises:
        InvalidArgumentError: no such joint (the frame is fixed to the world or to a locked base).
    """
    from gb_pin.robot.chain_reader import joint_kind

    out = []
    jid = int(model.frames[frame_id].parentJoint)
    while jid > 0:
        try:
            joint_kind(model.joints[jid], model.names[jid])
        except InvalidArgumentError:
            pass  # a free flyer, a spherical joint...: locked
        else:
            out.append(model.names[jid])
        jid = int(model.parents[jid])
    if not out:
        frame = model.frames[frame_id].name
        raise InvalidArgumentError(
            f"no joint of {name!r} moves frame {frame!r} (it is fixed to the world or to a floating base): "
            "choose another frame"
        )
    return out[::-1]


JACOBIAN_ENTRIES = 4 * 10**6
"""Postures x joints^2 of the shifted postures built at once by :func:`_jacobians` (32 MB)."""


def _jacobians(robot: Robot, Q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Forward-difference task Jacobians (N, n, m) of the chain at postures Q (N, m).

    In chunks of postures whose shifted copies (m + 1 per posture) hold at most
    :data:`JACOBIAN_ENTRIES` numbers: all at once, 202 candidates of a 997-joint chain took 1.6 GB.
    """
    N, m = Q.shape
    chunk = max(1, JACOBIAN_ENTRIES // ((m + 1) * m))
    if chunk < N:
        return np.concatenate([_jacobians(robot, Q[i : i + chunk]) for i in range(0, N, chunk)])
    body = robot.chain.kernel()
    stacked = np.repeat(Q, m + 1, axis=0).reshape(N, m + 1, m)
    stacked[:, np.arange(1, m + 1), np.arange(m)] += _STEP
    X = np.empty((N * (m + 1), robot.chain.n_task))
    positions(np.ascontiguousarray(stacked.reshape(-1, m)), body, X)
    X3 = X.reshape(N, m + 1, -1)
    return np.transpose((X3[:, 1:, :] - X3[:, :1, :]) / _STEP, (0, 2, 1))


def moving_joints(robot: Robot, seed: int = 0) -> NDArray[np.bool_]:
    """(m,) whether each joint moves the frame at some of :data:`PROBES` seeded postures within the limits."""
    lo, hi = sampling_bounds(robot)
    Q = lo + (hi - lo) * np.random.default_rng(seed).random((PROBES, lo.shape[0]))
    columns = np.linalg.norm(_jacobians(robot, Q), axis=1)  # (N, m)
    return np.asarray(columns.max(axis=0) > MOVES)


def limit_margin(
    Q: NDArray[np.float64], lower: NDArray[np.float64], upper: NDArray[np.float64]
) -> NDArray[np.float64]:
    """(N,) the smallest distance of each posture's joints from their limits, as fractions of the ranges."""
    bounded = np.isfinite(lower) & np.isfinite(upper)
    span = np.where(bounded, upper - lower, 1.0)
    lo, hi = np.where(bounded, lower, -np.inf), np.where(bounded, upper, np.inf)
    margin = np.where(bounded, np.minimum(Q - lo, hi - Q) / span, 0.5)
    return np.asarray(margin.min(axis=1))


def smallest_singular_value(robot: Robot, Q: NDArray[np.float64]) -> NDArray[np.float64]:
    """(N,) the smallest singular value of the task Jacobian at each posture, columns in reach [m].

    Each joint's column is scaled by how far the joint can go, ``min(range / 2, 1)`` [rad] or [m]
    (1 where unbounded): a prismatic joint of 0.1 m stroke moves the frame by at most 5 cm, a
    revolute joint by its column's norm per radian.
    """
    lo, hi = sampling_bounds(robot)
    reach = np.minimum((hi - lo) / 2, 1.0)
    return np.asarray(np.linalg.svd(_jacobians(robot, Q) * reach, compute_uv=False)[:, -1])


@dataclass(frozen=True)
class _Candidate:
    """A robot seen with another home (what :func:`auto_grid` needs)."""

    chain: Any
    home: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class HomeChoice:
    """The home :func:`choose_home` chose: the posture, its margin, sigma_min and largest grid."""

    home: NDArray[np.float64]
    margin: float
    sigma_min: float
    largest_half_width: float


class Budget:
    """The time onboarding may take: :data:`BUDGET_SECONDS` plus :data:`BUDGET_PER_JOINT` a joint.

    The search measures grids of ever more candidates; a chain of 200 joints took 9 minutes and
    one of 998 ran on for more than 5: past the budget it stops with one line saying how to skip it.
    """

    def __init__(self, joints: int, name: str = "the robot") -> None:
        self.seconds = BUDGET_SECONDS + BUDGET_PER_JOINT * joints
        self.joints, self.name = joints, name
        self.end = time.monotonic() + self.seconds

    def check(self) -> None:
        """Raise once the budget is spent.

        Raises:
            OnboardingBudgetError: naming the budget and what to give instead.
        """
        if time.monotonic() > self.end:
            raise OnboardingBudgetError(
                f"onboarding {self.name!r} ({self.joints} joints) took more than its {self.seconds:.0f} s "
                f"({BUDGET_SECONDS:g} s + {BUDGET_PER_JOINT:g} s a joint): give a home (--home, home=) and "
                "a goal set (--targets, targets=), or fewer joints (--joints, joints=), to skip the search"
            )


def choose_home(robot: Robot, reference: NDArray[np.float64] | None = None, seed: int = 0) -> HomeChoice:
    """A home inside the limits, away from them and from singularities, with a large reachable grid.

    See the module docstring (step 2).

    Args:
        robot: chain and limits (its ``home`` is not read).
        reference: the model's reference posture over the joints, a candidate if within the limits.
        seed: seed of the candidates and of the reachability samples.

    Raises:
        InvalidArgumentError: fewer joints than task axes (no 3-D grid around any home), or no
            candidate has a reachable grid.
        OnboardingBudgetError: the search took longer than its :class:`Budget`.
    """
    lo, hi = sampling_bounds(robot)
    m, n = lo.shape[0], robot.chain.n_task
    budget = Budget(m, str(getattr(robot, "name", "the robot")))
    if m < n:
        raise InvalidArgumentError(
            f"the frame is moved by {m} joint(s): it cannot reach a {n}-D goal grid; choose at most "
            f"{m} task axes (--axes, axes=)"
        )
    span = hi - lo
    rng = np.random.default_rng(seed)
    fixed = [(lo + hi) / 2]
    if reference is not None and np.all((reference >= robot.lower) & (reference <= robot.upper)):
        fixed.insert(0, np.asarray(reference, dtype=float))
    Q = np.vstack([*fixed, lo + span * (BAND + (1 - 2 * BAND) * rng.random((CANDIDATES, m)))])
    margin = limit_margin(Q, robot.lower, robot.upper)
    sigma = smallest_singular_value(robot, Q)
    score = np.minimum(margin / MARGIN_FULL, 1.0) * sigma
    trials: list[tuple[float, float, float, int]] = []  # (probe E^X / E_0, largest width, score, index)
    for i in np.argsort(-score, kind="stable")[:SHORTLIST]:
        budget.check()
        view = _Candidate(robot.chain, Q[i], robot.lower, robot.upper)
        try:
            grid = auto_grid(view, seed=seed, samples=SHORTLIST_SAMPLES, scale=GRID_SCALE, deadline=budget)
        except OnboardingBudgetError:
            raise
        except GbPinError:
            continue
        trials.append((probe(view, grid), grid.largest_half_width, float(score[i]), int(i)))
    if not trials:
        raise InvalidArgumentError(
            "no home candidate has a reachable goal grid around it: give a home (--home, home=)"
        )
    best_probe = min(t[0] for t in trials)
    width, _, i = max(t[1:] for t in trials if t[0] <= PROBE_SLACK * best_probe)
    return HomeChoice(Q[i].copy(), float(margin[i]), float(sigma[i]), width)


def probe(robot: Robot, grid: AutoGrid) -> float:
    """Mean E^X / E_0 of :data:`PROBE_SEEDS` short runs (:data:`PROBE_MOVEMENTS`) on the goal grid.

    The learner is the onboarding's (radius and sigma of steps 4 and 5, the paper's otherwise).
    """
    from gb_pin.learn.learner import GoalBabbling

    learner = GoalBabbling(
        radius=RADIUS_FACTOR * grid.half_width, sigma=exploration_sigma(robot, grid.half_width)
    )
    ratios = []
    for seed in range(PROBE_SEEDS):
        learner.fit(
            robot, grid.targets, PROBE_MOVEMENTS, seed=PROBE_SEED + seed, schedule=[0, PROBE_MOVEMENTS]
        )
        ratios.append(learner.history_.error[-1] / learner.history_.error[0])
    return float(np.mean(ratios))


def goal_grid(robot: Robot, seed: int = 0) -> AutoGrid:
    """The onboarding's goal grid: :data:`GRID_SCALE` of the largest reachable grid around the home.

    Raises:
        OnboardingBudgetError: the search took longer than its :class:`Budget`.
    """
    budget = Budget(int(np.size(robot.lower)), str(getattr(robot, "name", "the robot")))
    return auto_grid(robot, seed=seed, scale=GRID_SCALE, deadline=budget)


def record(
    joints: bool, dropped: tuple[str, ...], home: HomeChoice | None, grid: AutoGrid | None, robot: Robot
) -> Onboarding | None:
    """The :class:`Onboarding` of a robot: what was chosen (joints, home, grid, radius); None: nothing.

    Args:
        joints: whether the joints were chosen.
        dropped: the path's joints left out.
        home: the home choice, or None if the home was given.
        grid: the goal grid, or None if the targets were given.
        robot: the robot with its home (for the margin and sigma_min of a given home).
    """
    q = np.asarray(robot.home, dtype=float)[None, :]
    sigma = None if grid is None else exploration_sigma(robot, grid.half_width)
    done = (joints, home is not None, grid is not None, grid is not None, sigma is not None)
    chosen = tuple(what for what, yes in zip(CHOSEN, done, strict=True) if yes)
    if not chosen:
        return None
    return Onboarding(
        chosen=chosen,
        dropped=dropped,
        margin=float(limit_margin(q, robot.lower, robot.upper)[0]),
        sigma_min=float(smallest_singular_value(robot, q)[0]),
        half_width=0.0 if grid is None else grid.half_width,
        largest_half_width=0.0 if grid is None else grid.largest_half_width,
        shape=() if grid is None else grid.shape,
        radius=None if grid is None else RADIUS_FACTOR * grid.half_width,
        sigma=sigma,
        joints=tuple(str(j) for j in getattr(robot, "joints", ()) or ()),
        home=tuple(float(v) for v in np.asarray(robot.home, dtype=float)),
        n_targets=0 if grid is None else int(np.prod(grid.shape)),
    )


def exploration_sigma(robot: Robot, half_width: float) -> float | None:
    """Eq. 12's sigma capped to keep the exploration at home within a share of the grid; None: no cap.

    Args:
        robot: chain, home and limits.
        half_width: the goal grid's half-width [m].
    """
    from gb_pin.learn.config import default_sigma

    home = np.asarray(robot.home, dtype=float)
    x = robot.chain.forward(home)
    per_sigma = math.sqrt(1.0 + float(x @ x)) * float(np.linalg.norm(_jacobians(robot, home[None, :])[0]))
    paper = default_sigma(home.shape[0])
    if per_sigma * paper <= DEVIATION_SHARE * half_width:
        return None
    return DEVIATION_SHARE * half_width / per_sigma
