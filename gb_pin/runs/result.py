"""BabbleResult: what a goal-babbling run learned and measured."""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin.ik.api import DEFAULT_DAMPING, DEFAULT_MAX_ITERATIONS, DEFAULT_TOL, Seed, solve, solve_path
from gb_pin.ik.solution import IKPath, IKSolution
from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.feedback import DEFAULT_OBSERVATIONS, ReachResult, reach
from gb_pin.learn.history import History, RecordedSteps
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.state import BabbleState
from gb_pin.robot.target import KinematicTarget
from gb_pin.runs.plot import plot_result
from gb_pin.runs.results_file import read_result, write_result


@dataclass(frozen=True, eq=False)
class BabbleResult:
    """What a goal-babbling run learned and measured.

    Attributes:
        target: the robot (:class:`~gb_pin.robot.target.KinematicTarget`).
        targets: (N, n) evaluation target set X* [m].
        history: E^X and D^home over movements.
        model: the learned local-linear map g.
        config: hyperparameters used.
        seed: the integer seed, or None if a Generator was given.
        robot: the preset name, or None for a custom target.
        movements: movements run.
        steps: time steps run.
        wall_time: seconds spent babbling (compilation excluded after the first call).
        recording: the recorded steps, if ``record`` was given.
        state: the run's final :class:`~gb_pin.learn.state.BabbleState` (map, noise, random
            stream, posture), for ``babble(..., init=result)``; result files hold it, so that
            ``babble(init=load_result(path))`` continues a saved run (None for older files).
        goals: the goal generator, e.g. ``"DirectionGoals(distance=0.2, snap=0.05)"``; None for
            the paper's uniform choice.
        goal_targets: (M, n) the goal set X* the goals came from, when it is not ``targets``
            (the test set, ``eval_targets=``); None when they are the same set.
        missing: learning steps whose reading was missing (a sensor's losses, or ``tell(None)``).
        checked_asks: asks checked for collisions (safe babbling: ``obstacles``, ``self_collision``).
        cut_asks: of those, the asks cut short at the last safe posture.
        safety: a safe run's obstacles, collision settings and counts as plain values
            (:func:`gb_pin.safety.record.settings_of`; result files keep them); None: not checked.
        home_error: E_0 of the constant home estimate when this run continued another one
            (``babble(init=...)``, ``gb-pin babble --continue``), kept from the first run of the chain;
            None for a run from scratch, whose history starts with it (see :attr:`initial_error`).
    """

    target: KinematicTarget
    targets: NDArray[np.float64]
    history: History
    model: LocalLinearMap
    config: BabbleConfig
    seed: int | None
    robot: str | None
    movements: int
    steps: int
    wall_time: float
    recording: RecordedSteps | None = None
    state: BabbleState | None = field(default=None, repr=False)
    goals: str | None = None
    goal_targets: NDArray[np.float64] | None = field(default=None, repr=False)
    missing: int = 0
    checked_asks: int = 0
    cut_asks: int = 0
    safety: dict[str, Any] | None = field(default=None, repr=False)
    home_error: float | None = None

    def __repr__(self) -> str:
        """A summary in a few lines: robot, run, final errors, the arrays' shapes (not their values)."""
        e0 = self.initial_error
        share = f", {self.error / e0:.1%} of E_0" if e0 > 0 else ""
        recorded = "None" if self.recording is None else f"<{len(self.recording.step)} steps>"
        goal_set = "" if self.goal_targets is None else f", goal_targets=<{_shape(self.goal_targets)} array>"
        return "\n".join(
            [
                "BabbleResult(",
                f"  target={self.target!r}, robot={self.robot!r},",
                f"  movements={self.movements}, steps={self.steps}, seed={self.seed!r}, "
                f"wall_time={self.wall_time:.3g} s,",
                f"  error={self.error:.4g} m (E^X; E_0 = {e0:.4g} m{share}), "
                f"home_distance={self.home_distance:.4g} rad, n_prototypes={self.n_prototypes},",
                f"  targets=<{_shape(self.targets)} array>, history=<{len(self.history.movements)} records>, "
                f"recording={recorded}{goal_set},",
                f"  config={self.config!r},",
                f"  goals={self.goals!r},",
                ")",
            ]
        )

    def inverse(self, X: ArrayLike) -> NDArray[np.float64]:
        """Postures g(X) suggested by the inverse estimate: (N, n) -> (N, m), (n,) -> (m,)."""
        return self.model.predict(X)

    @property
    def error(self) -> float:
        """Final E^X [m]."""
        return float(self.history.error[-1])

    @property
    def initial_error(self) -> float:
        """E_0 [m]: E^X of the constant home estimate q_home, the paper's reference for E^X.

        A run from scratch measured it at movement 0; a continued run (``init=``) starts from the
        previous run's estimate, so its E_0 is the first run's (:attr:`home_error`), not its own
        movement 0. NaN when neither was recorded.
        """
        if self.home_error is not None:
            return float(self.home_error)
        return self.history.initial_error

    @property
    def home_distance(self) -> float:
        """Final D^home [rad]."""
        return float(self.history.home_distance[-1])

    @property
    def n_prototypes(self) -> int:
        """Number of local linear models K."""
        return self.model.n_prototypes_

    def diagnose(self) -> str | None:
        """Why the run stayed degenerate and what to try, in one line; None if it learned.

        Degenerate: E^X above half of E_0, or at most 5 local models, after 100 movements or more
        (:mod:`gb_pin.runs.diagnosis`); ``gb-pin babble`` ends such a run with this warning.
        """
        from gb_pin.runs.diagnosis import diagnose

        return diagnose(self)

    def task_errors(self) -> Any:
        """Final errors per task component over ``targets``: positions [m], rotations [deg] (docs/TASKS.md).

        Returns:
            A :class:`~gb_pin.learn.component_metrics.ComponentErrors` (``.mean``, ``.quantile(q)``,
            ``.summary(target.component_labels)``).
        """
        from gb_pin.learn.component_metrics import task_errors

        return task_errors(self.model, self.target, self.targets)

    def workspace_errors(self) -> Any:
        """The final reach error of every test point (``targets``), as median, 90 % and coverage.

        For ``targets="workspace:..."`` these are the region's test points, never learnt
        (docs/WORKSPACE.md). The error is over the whole task vector, on the robot's model.

        Returns:
            A :class:`~gb_pin.learn.reach_errors.ReachErrors` (``.median``, ``.p90``, ``.coverage``,
            ``.errors``, ``.summary()``).
        """
        from gb_pin.learn.reach_errors import ReachErrors

        if getattr(self.target, "chain", None) is not None:
            return ReachErrors.of(self.task_errors().total)
        # a robot given as a forward function: its own forward model, one posture at a time
        postures = np.clip(self.model.predict(self.targets, warn=False), self.target.lower, self.target.upper)
        reached = np.array([np.asarray(self.target.forward(q), dtype=float) for q in postures])
        return ReachErrors.of(np.linalg.norm(reached - self.targets, axis=1))

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the result to one ``.npz`` file (no pickle); see :func:`gb_pin.load_result`."""
        write_result(self, path)

    def plot(self, path: str | os.PathLike[str] | None = None, ax: Any = None) -> Any:
        """E^X and D^home over movements in the paper's style (:func:`gb_pin.runs.plot.plot_result`).

        Args:
            path: write the figure there (``.png``, ``.svg``, ``.pdf``), if given.
            ax: draw into these matplotlib axes (D^home on a twin axis); default: a new two-panel figure.

        Returns:
            The ``matplotlib.figure.Figure``.

        Raises:
            GbPinError: matplotlib is not installed (``pip install 'gb_pin[plots]'``).
        """
        return plot_result(self, path, ax)

    def export_inverse(self, path: str | os.PathLike[str]) -> str:
        """Write the learned inverse g to a plain ``.npz`` for use without gb_pin or numba.

        ``examples/numpy_inverse.py`` reads it in about 30 lines of numpy (:mod:`gb_pin.runs.export`).

        Returns:
            The path written.
        """
        from gb_pin.runs.export import export_inverse

        return export_inverse(self, path)

    @classmethod
    def load(cls, path: str | os.PathLike[str], target: KinematicTarget | None = None) -> BabbleResult:
        """Read a result written by :meth:`save` (see :func:`load_result`)."""
        return cls(**read_result(path, target))

    def solve(
        self,
        X: ArrayLike,
        tol: float = DEFAULT_TOL,
        max_iterations: int = DEFAULT_MAX_ITERATIONS,
        seed: Seed = "learned",
        damping: float = DEFAULT_DAMPING,
        **options: Any,
    ) -> IKSolution:
        """Exact postures for targets: g(x*) refined on the robot's kinematics (docs/IK.md).

        Args:
            X: (N, n) targets or one (n,) target, in the task vector (positions [m], poses, ...).
            tol: success when every position is within ``tol`` [m] (and rotations within ``angle_tol``).
            max_iterations: the most damped least-squares steps from one seed.
            seed: ``"learned"`` (g(x*)), ``"nearest"``, ``"home"``, ``"middle"``, or postures (m,) / (N, m).
            damping: lambda of the damped least squares [m].
            **options: the other settings of :func:`gb_pin.ik.solve` (``angle_tol``, ``timeout``,
                ``max_restarts``, ``solutions``, ``closest_to``, ``min_distance``, ``rng``, ...).

        Returns:
            An :class:`~gb_pin.ik.solution.IKSolution` (see :func:`gb_pin.ik.solve`).
        """
        model, seed = _seed_of(self.model, X, seed)
        return solve(
            self.target,
            X,
            model=model,
            seed=seed,
            tol=tol,
            max_iterations=max_iterations,
            damping=damping,
            **options,
        )

    def solve_path(
        self,
        start: ArrayLike,
        end: ArrayLike,
        steps: int = 50,
        tol: float = DEFAULT_TOL,
        seed: Seed = "learned",
        **options: Any,
    ) -> IKPath:
        """A joint path along the line from ``start`` to ``end`` (see :func:`gb_pin.ik.solve_path`).

        Args:
            start: (n,) first point (task vector).
            end: (n,) last point.
            steps: points on the line, ends included.
            tol: success when every position is within ``tol`` [m].
            seed: the first point's seed: ``"learned"``, ``"home"``, or postures (m,) / (steps, m).
            **options: ``follow`` and the settings of :func:`gb_pin.ik.solve`.

        Returns:
            An :class:`~gb_pin.ik.solution.IKPath` with its joint length and largest joint step [rad].
        """
        model: Any = self.model
        if isinstance(seed, str) and hasattr(model, "part_of"):  # a region in parts: seeds per point's part
            from gb_pin import _validation as check
            from gb_pin.ik.api import MAX_PATH_STEPS

            count = check.positive_int("steps", steps, minimum=2, maximum=MAX_PATH_STEPS)
            ends = [check.vector(name, v, self.target.n_task) for name, v in (("start", start), ("end", end))]
            model, seed = _seed_of(model, np.linspace(ends[0], ends[1], count), seed)
        return solve_path(self.target, start, end, steps, model=model, seed=seed, tol=tol, **options)

    def reach(
        self,
        X: ArrayLike,
        observe: Any,
        observations: Any = DEFAULT_OBSERVATIONS,
        **options: Any,
    ) -> ReachResult:
        """Reach targets by feedback on the learned model, the robot driven by ``observe(q) -> x or None``.

        g(x*) first, then corrections q += dg/dx (x* - mean of k readings) (:mod:`gb_pin.learn.feedback`):
        no kinematic model, sub-millimetre on a mis-modelled arm (docs/HARDWARE.md).

        Args:
            X: (N, n) targets or one (n,) target [m].
            observe: executes a posture (m,) and returns the reading (n,) [m], or None when it is lost.
            observations: readings averaged before each correction, e.g. (1, 1, 3).
            **options: ``gain``, ``max_joint_step`` with ``start``, ``retries``
                (:class:`~gb_pin.learn.feedback.FeedbackReach`).

        Returns:
            A :class:`~gb_pin.learn.feedback.ReachResult` (postures, initial, readings, reached).
        """
        lower, upper = self.target.lower, self.target.upper
        return reach(self.model, X, observe, lower, upper, observations=observations, **options)


def save_result(result: BabbleResult, path: str | os.PathLike[str]) -> None:
    """Write ``result`` to ``path`` (an ``.npz`` archive of plain arrays and a JSON header).

    The file is written to a temporary name, flushed and renamed, so a crash never leaves half a file.
    """
    write_result(result, path)


def load_result(path: str | os.PathLike[str], target: KinematicTarget | None = None) -> BabbleResult:
    """Read a result written by :func:`save_result`.

    Args:
        path: the ``.npz`` file.
        target: the robot; default the preset the file names, else the URDF or example-robot-data
            model it records (rebuilt and checked, :mod:`gb_pin.runs.robot_source`). Needed for a
            robot built in Python from a ``pin.Model`` or a function, or loaded by ``MODULE:NAME``.

    Raises:
        ResultFileError: missing, truncated, corrupted, foreign or newer-version file, or a recorded
            robot that cannot be rebuilt (the message says what was recorded and how to pass it).
    """
    return BabbleResult.load(path, target)


def state_fields(state: BabbleState) -> dict[str, Any]:
    """The fields of a result that its run's final state gives: goals, goal set, missing readings."""
    return {**goal_fields(state), "missing": state.missing}


def goal_fields(state: BabbleState) -> dict[str, Any]:
    """``goals`` and ``goal_targets`` of a result from its run's state (None for the paper's defaults)."""
    from gb_pin.learn.goals import UniformGoals

    default = (
        isinstance(state.goals, UniformGoals) and state.goals.get_params() == UniformGoals().get_params()
    )
    same = state.targets is state.eval_targets or np.array_equal(state.targets, state.eval_targets)
    return {
        "goals": None if default else repr(state.goals),
        "goal_targets": None if same or not state.goals.needs_targets else state.targets,
    }


def _seed_of(model: Any, X: ArrayLike, seed: Seed) -> tuple[Any, Seed]:
    """(model, seed) for the IK solver: a parted map's learned seed is its prediction, given as postures.

    The compiled solver reads one local-linear map; a region learnt in parts
    (:class:`~gb_pin.learn.parts.PartedMap`) gives ``g(x*)`` of each target's part instead (also for
    ``"nearest"``).
    """
    from gb_pin.learn.parts import PartedMap

    if not isinstance(model, PartedMap) or not isinstance(seed, str) or seed not in ("learned", "nearest"):
        return model, seed
    return None, model.predict(X, warn=False)


def _shape(array: NDArray[np.float64]) -> str:
    """``27 x 3``: an array's shape for :meth:`BabbleResult.__repr__`."""
    return " x ".join(str(s) for s in np.shape(array))
