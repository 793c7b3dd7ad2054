"""Online goal babbling (paper Sec. II), robot-agnostic.

The learner sees forward kinematics (as a :class:`~gb_pin.chain.KinematicChain`),
a home posture, joint limits and a target set, nothing else. It imports neither
pinocchio nor meshcat. The step loop is compiled (:mod:`gb_pin._loop`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _loop
from gb_pin import _validation as check
from gb_pin.chain import KinematicChain
from gb_pin.exceptions import DivergenceError, InvalidArgumentError, NotFittedError
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

    def as_dict(self) -> dict[str, Any]:
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


@dataclass(frozen=True)
class Recording:
    """Which steps of a run to record (for replay and viewers).

    Attributes:
        every: record every ``every``-th time step.
        first: first movement recorded.
        last: movements ``first <= r < last`` are recorded; None for all.
    """

    every: int = 1
    first: int = 0
    last: int | None = None

    def __post_init__(self) -> None:
        check.positive_int("every", self.every)
        check.positive_int("first", self.first, minimum=0)
        if self.last is not None:
            check.positive_int("last", self.last, minimum=self.first)


@dataclass(frozen=True)
class RecordedSteps:
    """Recorded steps of a run.

    Attributes:
        step: (R,) time step t (1-based).
        movement: (R,) movement r the step belongs to.
        posture: (R, m) executed posture q_t.
        target: (R, n) target x*_t [m]; NaN during home returns.
        position: (R, n) reached position x_t = f(q_t) [m].
    """

    step: NDArray[np.int64]
    movement: NDArray[np.int64]
    posture: NDArray[np.float64]
    target: NDArray[np.float64]
    position: NDArray[np.float64]


class BabbleState:
    """The complete state of a goal-babbling run: everything the compiled loop reads and writes.

    Holding it in plain arrays makes a run resumable: :meth:`run` continues it, and
    :meth:`arrays` / :meth:`from_arrays` (used by checkpoints) rebuild it exactly.
    """

    def __init__(self) -> None:
        self.rng: np.random.Generator
        self.config: BabbleConfig
        self.chain: KinematicChain
        self.home: NDArray[np.float64]
        self.lower: NDArray[np.float64]
        self.upper: NDArray[np.float64]
        self.targets: NDArray[np.float64]
        self.eval_targets: NDArray[np.float64]
        self.schedule: NDArray[np.int64]
        self.errors: NDArray[np.float64]
        self.distances: NDArray[np.float64]
        self.llm: LocalLinearMap
        self.A: NDArray[np.float64]
        self.b: NDArray[np.float64]
        self.vectors: dict[str, NDArray[np.float64]]
        self.istate: NDArray[np.int64]
        self.record: tuple[int, int, int]
        self.rec: dict[str, NDArray[Any]]

    VECTORS = ("q_prev", "q_start", "x_prev", "target_prev", "path_start", "path_end")

    @classmethod
    def start(
        cls,
        kinematics: Kinematics,
        targets: ArrayLike,
        movements: int,
        config: BabbleConfig,
        *,
        seed: int | np.random.Generator = 0,
        eval_targets: ArrayLike | None = None,
        schedule: ArrayLike | None = None,
        record: Recording | None = None,
    ) -> BabbleState:
        """A fresh run at movement 0: the estimate is the constant q_home (paper Sec. II)."""
        movements = check.positive_int("movements", movements)
        st = cls()
        st.rng = check.generator(seed)
        st.config = config
        st.chain = kinematics.chain
        m, n = st.chain.n_joints, st.chain.n_task
        st.home = check.vector("home", kinematics.home, m)
        st.lower = np.ascontiguousarray(kinematics.lower, dtype=float)
        st.upper = np.ascontiguousarray(kinematics.upper, dtype=float)
        st.targets = check.points("targets", targets, n)
        st.eval_targets = (
            st.targets if eval_targets is None else check.points("eval_targets", eval_targets, n)
        )
        if schedule is None:
            st.schedule = evaluation_schedule(movements)
        else:
            try:
                at = np.unique(np.asarray(schedule, dtype=np.int64))
            except (TypeError, ValueError) as exc:
                raise InvalidArgumentError(f"schedule must be movement counts, got {schedule!r}") from exc
            if at.ndim != 1 or at.size == 0 or at[0] < 0 or at[-1] > movements:
                raise InvalidArgumentError(
                    f"schedule must hold movement counts in [0, {movements}], got {schedule!r}"
                )
            st.schedule = at
        st.errors = np.full(st.schedule.shape[0], np.nan)
        st.distances = np.full(st.schedule.shape[0], np.nan)

        x_home = st.chain.forward(st.home)
        st.llm = LocalLinearMap(radius=config.radius, learning_rate=config.learning_rate).initialize(
            x_home, st.home
        )
        st.A = np.empty((m, n))
        st.b = np.empty(m)
        noise_init(st.rng, config.sigma, st.A, st.b)
        # The robot starts at rest at home: previous posture, position and target are home's.
        st.vectors = {
            "q_prev": st.home.copy(),
            "q_start": st.home.copy(),
            "x_prev": x_home.copy(),
            "target_prev": x_home.copy(),
            "path_start": x_home.copy(),
            "path_end": x_home.copy(),
        }
        st.istate = np.zeros(_loop.ISTATE_SIZE, dtype=np.int64)
        st.istate[_loop.KIND] = _loop.NONE
        st.istate[_loop.LAST_KIND] = _loop.NONE
        st.istate[_loop.PROTOTYPES] = 1
        if record is None:
            st.record = (1, 0, 0)
            size = 0
        else:
            last = movements if record.last is None else min(record.last, movements)
            st.record = (record.every, record.first, last)
            size = max(0, (last - record.first) * config.path_length // record.every + 1)
        st.rec = {
            "step": np.zeros(size, dtype=np.int64),
            "movement": np.zeros(size, dtype=np.int64),
            "posture": np.zeros((size, m)),
            "target": np.zeros((size, n)),
            "position": np.zeros((size, n)),
        }
        return st

    @property
    def movements(self) -> int:
        """Completed movements r."""
        return int(self.istate[_loop.MOVEMENTS])

    @property
    def steps(self) -> int:
        """Completed time steps t."""
        return int(self.istate[_loop.STEPS])

    @property
    def posture(self) -> NDArray[np.float64]:
        """The last executed posture q_t."""
        return self.vectors["q_prev"]

    @property
    def position(self) -> NDArray[np.float64]:
        """The last reached position x_t [m]."""
        return self.vectors["x_prev"]

    @property
    def target(self) -> NDArray[np.float64]:
        """The last goal-directed target x*_t [m]."""
        return self.vectors["target_prev"]

    def run(self, stop: int) -> None:
        """Run the compiled loop until ``stop`` movements are complete.

        Raises:
            DivergenceError: a posture became non-finite.
        """
        cfg = self.config
        params = (
            cfg.learning_rate,
            cfg.sigma,
            cfg.sigma_delta,
            cfg.radius,
            float(cfg.path_length),
            cfg.p_home,
        )
        m, n = self.home.shape[0], self.targets.shape[1]
        rot_ws, pos_ws = self.chain.workspace()
        v = self.vectors
        fstate = (v["q_prev"], v["q_start"], v["x_prev"], v["target_prev"], v["path_start"], v["path_end"])
        while True:
            llm = self.llm
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
            r = self.rec
            record = (*self.record, r["step"], r["movement"], r["posture"], r["target"], r["position"])
            status = _loop.babble_loop(
                self.rng, stop, params, (self.home, self.lower, self.upper, self.targets),
                self.chain.as_tuple(), (llm._P, llm._W, llm._O), (self.A, self.b), fstate,
                self.istate, scratch, (self.schedule, self.eval_targets), (self.errors, self.distances),
                record,
            )  # fmt: skip
            llm._K = int(self.istate[_loop.PROTOTYPES])
            if status == _loop.NEED_CAPACITY:
                llm.reserve(2 * llm._P.shape[0])
            elif status == _loop.NEED_RECORD_CAPACITY:
                grow = max(16, 2 * self.rec["step"].shape[0])
                for key, arr in self.rec.items():
                    bigger = np.zeros((grow, *arr.shape[1:]), dtype=arr.dtype)
                    bigger[: arr.shape[0]] = arr
                    self.rec[key] = bigger
            elif status == _loop.NOT_FINITE:
                reach = float(np.max(np.abs(self.targets)))
                raise DivergenceError(
                    f"the inverse estimate diverged at movement {self.movements} (step {self.steps + 1}): "
                    f"a posture became non-finite or exceeded {_loop.MAX_POSTURE:g}. Likely causes: "
                    f"learning_rate={cfg.learning_rate!r} too high (the paper uses 0.001-0.5), "
                    f"sigma={cfg.sigma!r} too large, or targets far outside the robot's reach "
                    f"(largest |coordinate| {reach:.3g} m)"
                )
            else:
                return

    # -- checkpoints ------------------------------------------------------------
    def to_arrays(self) -> dict[str, NDArray[Any]]:
        """Every array of the state, trimmed to what is in use (for checkpoint files)."""
        K = self.llm.n_prototypes_
        c = int(self.istate[_loop.RECORDED])
        out: dict[str, NDArray[Any]] = {
            "home": self.home,
            "lower": self.lower,
            "upper": self.upper,
            "targets": self.targets,
            "eval_targets": self.eval_targets,
            "schedule": self.schedule,
            "errors": self.errors,
            "distances": self.distances,
            "prototypes": self.llm._P[:K],
            "matrices": self.llm._W[:K],
            "offsets": self.llm._O[:K],
            "noise_A": self.A,
            "noise_b": self.b,
            "istate": self.istate,
            "record": np.array(self.record, dtype=np.int64),
        }
        for key in self.VECTORS:
            out[key] = self.vectors[key]
        for key, arr in self.rec.items():
            out["rec_" + key] = arr[:c]
        for f in fields(self.chain):
            out["chain_" + f.name] = np.asarray(getattr(self.chain, f.name))
        return out

    def rng_state(self) -> dict[str, Any]:
        """The random generator's bit-generator state (JSON-serialisable)."""
        return dict(self.rng.bit_generator.state)

    @classmethod
    def from_arrays(
        cls, arrays: dict[str, NDArray[Any]], config: BabbleConfig, rng_state: dict[str, Any]
    ) -> BabbleState:
        """Rebuild a state written by :meth:`to_arrays` exactly (same numbers, same random stream).

        Raises:
            InvalidArgumentError: arrays missing or of inconsistent shapes.
        """
        try:
            st = cls()
            st.config = config
            bit_generator = getattr(np.random, str(rng_state["bit_generator"]))()
            bit_generator.state = rng_state
            st.rng = np.random.Generator(bit_generator)
            chain_fields: dict[str, Any] = {
                f.name: np.ascontiguousarray(arrays["chain_" + f.name])
                for f in fields(KinematicChain)
                if f.name != "frame_parent"
            }
            chain_fields["frame_parent"] = int(arrays["chain_frame_parent"])
            st.chain = KinematicChain(**chain_fields)
            m, n = st.chain.n_joints, st.chain.n_task
            st.home = check.vector("home", arrays["home"], m)
            st.lower = np.ascontiguousarray(arrays["lower"], dtype=float)
            st.upper = np.ascontiguousarray(arrays["upper"], dtype=float)
            st.targets = check.points("targets", arrays["targets"], n)
            st.eval_targets = check.points("eval_targets", arrays["eval_targets"], n)
            st.schedule = np.ascontiguousarray(arrays["schedule"], dtype=np.int64)
            st.errors = np.ascontiguousarray(arrays["errors"], dtype=float)
            st.distances = np.ascontiguousarray(arrays["distances"], dtype=float)
            P, W, O = arrays["prototypes"], arrays["matrices"], arrays["offsets"]
            K = P.shape[0]
            if K < 1 or P.shape != (K, n) or W.shape != (K, m, n) or O.shape != (K, m):
                raise InvalidArgumentError(
                    f"model arrays of inconsistent shapes {P.shape}, {W.shape}, {O.shape}"
                )
            st.llm = LocalLinearMap(radius=config.radius, learning_rate=config.learning_rate)
            st.llm.initialize(P[0], O[0], capacity=max(2 * K, 256))
            st.llm._P[:K], st.llm._W[:K], st.llm._O[:K] = P, W, O
            st.llm._K = K
            st.A = np.ascontiguousarray(arrays["noise_A"], dtype=float)
            st.b = np.ascontiguousarray(arrays["noise_b"], dtype=float)
            st.vectors = {k: np.ascontiguousarray(arrays[k], dtype=float) for k in cls.VECTORS}
            st.istate = np.ascontiguousarray(arrays["istate"], dtype=np.int64)
            every, first, last = (int(v) for v in arrays["record"])
            st.record = (every, first, last)
            st.rec = {}
            for key, dtype in (("step", np.int64), ("movement", np.int64), ("posture", float),
                               ("target", float), ("position", float)):  # fmt: skip
                arr = np.asarray(arrays["rec_" + key], dtype=dtype)
                grown = np.zeros((max(16, 2 * arr.shape[0]), *arr.shape[1:]), dtype=dtype)
                grown[: arr.shape[0]] = arr
                st.rec[key] = grown
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            if isinstance(exc, InvalidArgumentError):
                raise
            raise InvalidArgumentError(f"incomplete or inconsistent babbling state ({exc!r})") from exc
        shapes_ok = (
            st.A.shape == (m, n)
            and st.b.shape == (m,)
            and st.istate.shape == (_loop.ISTATE_SIZE,)
            and st.errors.shape == st.schedule.shape == st.distances.shape
            and all(st.vectors[k].shape == ((m,) if k.startswith("q") else (n,)) for k in cls.VECTORS)
            and int(st.istate[_loop.PROTOTYPES]) == K
        )
        if not shapes_ok:
            raise InvalidArgumentError("babbling state arrays of inconsistent shapes")
        return st

    def history(self) -> History:
        """E^X and D^home at the schedule's movement counts (NaN where not reached yet)."""
        return History(movements=self.schedule, error=self.errors, home_distance=self.distances)

    def recorded(self) -> RecordedSteps | None:
        """The recorded steps so far, or None if recording was not asked for."""
        if self.record[2] <= self.record[1]:
            return None
        c = int(self.istate[_loop.RECORDED])
        r = self.rec
        return RecordedSteps(
            step=r["step"][:c].copy(),
            movement=r["movement"][:c].copy(),
            posture=r["posture"][:c].copy(),
            target=r["target"][:c].copy(),
            position=r["position"][:c].copy(),
        )


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
        state_: the :class:`BabbleState` of the run (resumable with :meth:`resume`).
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

    @classmethod
    def from_config(cls, config: BabbleConfig) -> GoalBabbling:
        """A learner with the (resolved) hyperparameters of ``config``."""
        return cls(**config.as_dict())

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
        record: Recording | None = None,
        callback: Callable[[int], Any] | None = None,
        observer: Callable[[BabbleState], Any] | None = None,
        observe_every: int = 1,
        checkpoint: Callable[[BabbleState], Any] | None = None,
        checkpoint_every: int | None = None,
        should_stop: Callable[[], bool] | None = None,
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
            record: which steps to record (postures, targets, positions); default none.
            callback: called with the movement count after each chunk (progress bars).
            observer: called with the :class:`BabbleState` every ``observe_every``
                movements (live viewers); it must not modify the state.
            observe_every: movements between observer calls.
            checkpoint: called with the state every ``checkpoint_every`` movements and at the end.
            checkpoint_every: movements between checkpoints (default: a tenth of the run).
            should_stop: polled between chunks; True stops the run early, resumable.

        Raises:
            InvalidArgumentError: a bad argument.
            DivergenceError: a posture became non-finite or exploded.
        """
        self.state_ = BabbleState.start(
            kinematics,
            targets,
            movements,
            self._resolve(kinematics.chain.n_joints),
            seed=seed,
            eval_targets=eval_targets,
            schedule=schedule,
            record=record,
        )
        self.resume(
            movements,
            callback=callback,
            observer=observer,
            observe_every=observe_every,
            checkpoint=checkpoint,
            checkpoint_every=checkpoint_every,
            should_stop=should_stop,
        )
        return self

    def resume(
        self,
        until: int,
        *,
        callback: Callable[[int], Any] | None = None,
        observer: Callable[[BabbleState], Any] | None = None,
        observe_every: int = 1,
        checkpoint: Callable[[BabbleState], Any] | None = None,
        checkpoint_every: int | None = None,
        should_stop: Callable[[], bool] | None = None,
    ) -> GoalBabbling:
        """Continue the run held in ``state_`` until ``until`` movements are complete.

        Args:
            until: movement count to reach.
            callback: called with the movement count after each chunk.
            observer: called with the state every ``observe_every`` movements.
            observe_every: movements between observer calls.
            checkpoint: called with the state every ``checkpoint_every`` movements and at the end.
            checkpoint_every: movements between checkpoints.
            should_stop: polled between chunks; when it returns True the run stops early
                (after a checkpoint, if any), leaving a consistent, resumable state.
        """
        if not hasattr(self, "state_"):
            raise NotFittedError("this GoalBabbling learner has no run to resume: call fit() first")
        state = self.state_
        until = check.positive_int("until", until, minimum=0)
        observe_every = check.positive_int("observe_every", observe_every)
        total = int(state.schedule[-1])
        chunk = observe_every if observer is not None else max(1, min(total // 100, 1000))
        if checkpoint is not None:
            checkpoint_every = check.positive_int("checkpoint_every", checkpoint_every or max(1, total // 10))
            chunk = min(chunk, checkpoint_every)
        while state.movements < until:
            state.run(min(until, state.movements + chunk))
            # The checkpoint comes first, so that a failing observer or callback loses nothing.
            stopping = should_stop is not None and should_stop()
            if checkpoint is not None and (
                stopping or state.movements % checkpoint_every == 0 or state.movements >= until  # type: ignore[operator]
            ):
                checkpoint(state)
            if observer is not None:
                observer(state)
            if callback is not None:
                callback(state.movements)
            if stopping:
                break
        return self

    @property
    def model_(self) -> LocalLinearMap:
        """The learned local-linear map g."""
        return self._state().llm

    @property
    def config_(self) -> BabbleConfig:
        """The hyperparameters used."""
        return self._state().config

    @property
    def noise_(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(A, b) of Eq. 8 now."""
        st = self._state()
        return st.A, st.b

    @property
    def movements_(self) -> int:
        """Completed movements r (home returns included)."""
        return self._state().movements

    @property
    def steps_(self) -> int:
        """Completed time steps t."""
        return self._state().steps

    @property
    def history_(self) -> History:
        """E^X and D^home recorded so far (NaN where not reached yet)."""
        return self._state().history()

    @property
    def recording_(self) -> RecordedSteps | None:
        """The recorded steps, if recording was asked for."""
        return self._state().recorded()

    def _state(self) -> BabbleState:
        if not hasattr(self, "state_"):
            raise NotFittedError("this GoalBabbling learner is not fitted: call fit() first")
        return self.state_

    def predict(self, X: ArrayLike) -> NDArray[np.float64]:
        """The learned inverse estimate g(X): (N, n) -> (N, m), (n,) -> (m,)."""
        return self._state().llm.predict(X)
