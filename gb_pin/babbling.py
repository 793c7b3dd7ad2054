"""Online goal babbling (paper Sec. II), robot-agnostic.

The learner sees forward kinematics (as a :class:`~gb_pin.chain.KinematicChain`),
a home posture, joint limits and a target set, nothing else. It imports neither
pinocchio nor meshcat. The step loop is compiled (:mod:`gb_pin._loop`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _loop
from gb_pin import _validation as check
from gb_pin.chain import KinematicChain, chain_position
from gb_pin.exceptions import DivergenceError, InvalidArgumentError
from gb_pin.exploration import noise_init
from gb_pin.llm import LocalLinearMap
from gb_pin.metrics import evaluation_schedule


class Kinematics(Protocol):
    """What the learner needs from a robot (a :class:`~gb_pin.target.KinematicTarget` is one)."""

    @property
    def chain(self) -> KinematicChain:
        """Compiled forward kinematics of the operational frame."""

    @property
    def home(self) -> NDArray[np.float64]:
        """Home posture q_home, (m,)."""

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower joint limits (m,), -inf where unbounded."""

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper joint limits (m,), +inf where unbounded."""


def default_sigma(n_joints: int) -> float:
    """Exploration noise per joint keeping the effector deviation at 0.05 sqrt(3) (Eq. 12).

    sigma^X = sigma sqrt((m + 1) / 2) = 0.05 sqrt(3), i.e. sigma = 0.05 at m = 5 (Sec. III-A/B).
    """
    return 0.05 * math.sqrt(3.0) / math.sqrt((n_joints + 1) / 2.0)


@dataclass(frozen=True)
class BabbleConfig:
    """Hyperparameters of one run, as used (defaults resolved).

    Attributes:
        learning_rate: eta of the online gradient descent.
        sigma: standard deviation of the exploration noise entries (Eq. 8) [rad].
        sigma_delta: standard deviation of the noise's random-walk increments [rad].
        radius: radius d of the local-linear map's prototypes [m].
        path_length: L, steps per movement (Eq. 3).
        p_home: probability of a home return after a goal-directed movement (Eq. 7).
    """

    learning_rate: float = 0.1
    sigma: float = 0.05
    sigma_delta: float = 0.005
    radius: float = 0.1
    path_length: int = 25
    p_home: float = 0.1

    def __post_init__(self) -> None:
        check.positive_float("learning_rate", self.learning_rate)
        check.nonnegative_float("sigma", self.sigma)
        check.nonnegative_float("sigma_delta", self.sigma_delta)
        check.positive_float("radius", self.radius)
        check.positive_int("path_length", self.path_length)
        check.probability("p_home", self.p_home)

    def as_dict(self) -> dict[str, float]:
        """The parameters as a plain dict."""
        return asdict(self)


@dataclass(frozen=True)
class History:
    """E^X and D^home recorded during a run.

    Attributes:
        movements: (T,) movement counts r at which the model was evaluated (starts at 0).
        error: (T,) E^X (Eq. 9) [m].
        home_distance: (T,) D^home (Eq. 10) [rad].
    """

    movements: NDArray[np.int64]
    error: NDArray[np.float64]
    home_distance: NDArray[np.float64]

    def at(self, movements: int) -> tuple[float, float]:
        """(E^X, D^home) at a recorded movement count."""
        idx = np.flatnonzero(self.movements == movements)
        if not idx.size:
            raise InvalidArgumentError(
                f"movements={movements!r} was not recorded; recorded: "
                f"{self.movements[0]}..{self.movements[-1]} (see History.movements)"
            )
        return float(self.error[idx[0]]), float(self.home_distance[idx[0]])


class GoalBabbling:
    """Online goal babbling learner (paper Sec. II) with a local-linear map inverse estimate.

    ``__init__`` only stores hyperparameters (scikit-learn convention); ``fit`` runs.

    Args:
        learning_rate: eta.
        sigma: exploration noise [rad]; None: Eq. 12 from the number of joints.
        sigma_delta: random-walk step [rad]; None: 0.1 * sigma (Sec. III-B).
        radius: d [m].
        path_length: L (Eq. 3).
        p_home: home-return probability (Eq. 7).

    Attributes:
        model_: the learned :class:`~gb_pin.llm.LocalLinearMap`.
        config_: the :class:`BabbleConfig` used.
        history_: the :class:`History` of the last ``fit``.
        movements_: completed movements r (home returns included).
        steps_: completed time steps t.
        noise_: (A, b) of Eq. 8 at the end of the run.
    """

    def __init__(
        self,
        learning_rate: float = 0.1,
        sigma: float | None = None,
        sigma_delta: float | None = None,
        radius: float = 0.1,
        path_length: int = 25,
        p_home: float = 0.1,
    ) -> None:
        self.learning_rate = learning_rate
        self.sigma = sigma
        self.sigma_delta = sigma_delta
        self.radius = radius
        self.path_length = path_length
        self.p_home = p_home

    def _resolve(self, n_joints: int) -> BabbleConfig:
        sigma = default_sigma(n_joints) if self.sigma is None else self.sigma
        check.nonnegative_float("sigma", sigma)
        sigma_delta = 0.1 * sigma if self.sigma_delta is None else self.sigma_delta
        return BabbleConfig(
            learning_rate=self.learning_rate,
            sigma=float(sigma),
            sigma_delta=sigma_delta,
            radius=self.radius,
            path_length=self.path_length,
            p_home=self.p_home,
        )

    def fit(
        self,
        kinematics: Kinematics,
        targets: ArrayLike,
        movements: int,
        *,
        seed: int | np.random.Generator = 0,
        eval_targets: ArrayLike | None = None,
        schedule: ArrayLike | None = None,
        callback: Callable[[int], Any] | None = None,
    ) -> GoalBabbling:
        """Bootstrap an inverse estimate from scratch by goal babbling.

        Args:
            kinematics: the robot (chain, home, lower, upper).
            targets: target set X*, (N, n) [m]; goals are drawn uniformly from it.
            movements: number of movements r to run (home returns included).
            seed: an int seed or a numpy Generator (advanced in place).
            eval_targets: where E^X and D^home are measured; default ``targets``.
            schedule: movement counts to evaluate at; default
                :func:`~gb_pin.metrics.evaluation_schedule`.
            callback: called with the movement count after each chunk (progress bars).

        Raises:
            InvalidArgumentError: a bad argument.
            DivergenceError: a posture became non-finite.
        """
        movements = check.positive_int("movements", movements)
        rng = check.generator(seed)
        chain = kinematics.chain
        m, n = chain.n_joints, chain.n_task
        home = check.vector("home", kinematics.home, m)
        lower = np.ascontiguousarray(kinematics.lower, dtype=float)
        upper = np.ascontiguousarray(kinematics.upper, dtype=float)
        X = check.points("targets", targets, n)
        Xe = X if eval_targets is None else check.points("eval_targets", eval_targets, n)
        if schedule is None:
            at = evaluation_schedule(movements)
        else:
            at = np.unique(np.asarray(schedule, dtype=np.int64))
            if at.size == 0 or at[0] < 0 or at[-1] > movements:
                raise InvalidArgumentError(
                    f"schedule must hold movement counts in [0, {movements}], got {schedule!r}"
                )
        config = self._resolve(m)

        chain_args = chain.as_tuple()
        rot_ws, pos_ws = chain.workspace()
        x_home = np.empty(n)
        chain_position(home, chain_args, rot_ws, pos_ws, x_home)
        llm = LocalLinearMap(radius=config.radius, learning_rate=config.learning_rate).initialize(
            x_home, home
        )
        A = np.empty((m, n))
        b = np.empty(m)
        noise_init(rng, config.sigma, A, b)

        q_prev = home.copy()
        fstate = (q_prev, home.copy(), x_home.copy(), x_home.copy(), x_home.copy(), x_home.copy())
        istate = np.zeros(_loop.ISTATE_SIZE, dtype=np.int64)
        istate[_loop.KIND] = _loop.NONE
        istate[_loop.LAST_KIND] = _loop.NONE
        istate[_loop.PROTOTYPES] = 1
        errors = np.full(at.shape[0], np.nan)
        distances = np.full(at.shape[0], np.nan)
        params = (
            config.learning_rate,
            config.sigma,
            config.sigma_delta,
            config.radius,
            float(config.path_length),
            config.p_home,
        )
        problem = (home, lower, upper, X)
        chunk = max(1, min(movements // 100, 1000))
        stop = 0
        while stop < movements:
            stop = min(movements, stop + chunk)
            while True:
                scratch = (
                    np.empty(m),
                    np.empty(n),
                    np.empty(n),
                    llm._act,
                    llm._g,
                    llm._y,
                    llm._J,
                    rot_ws,
                    pos_ws,
                )
                status = _loop.babble_loop(
                    rng, stop, params, problem, chain_args, (llm._P, llm._W, llm._O), (A, b),
                    fstate, istate, scratch, (at, Xe), (errors, distances),
                )  # fmt: skip
                llm._K = int(istate[_loop.PROTOTYPES])
                if status == _loop.NEED_CAPACITY:
                    llm.reserve(2 * llm._P.shape[0])
                    continue
                if status == _loop.NOT_FINITE:
                    raise DivergenceError(
                        f"the posture became non-finite at movement {int(istate[_loop.MOVEMENTS])} "
                        f"(step {int(istate[_loop.STEPS])}); the learning rate "
                        f"{config.learning_rate!r} is likely too high for this robot"
                    )
                break
            if callback is not None:
                callback(stop)
        self.model_ = llm
        self.config_ = config
        self.noise_ = (A, b)
        self.movements_ = int(istate[_loop.MOVEMENTS])
        self.steps_ = int(istate[_loop.STEPS])
        self.history_ = History(movements=at, error=errors, home_distance=distances)
        return self

    def predict(self, X: ArrayLike) -> NDArray[np.float64]:
        """The learned inverse estimate g(X): (N, n) -> (N, m), (n,) -> (m,)."""
        if not hasattr(self, "model_"):
            raise InvalidArgumentError("this GoalBabbling learner is not fitted: call fit() first")
        return self.model_.predict(X)
