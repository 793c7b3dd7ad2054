"""The compiled loop's arguments as named structures, and the indices of its counters.

:meth:`gb_pin.learn.state.BabbleState.kernel_args` is the one place on the Python side
that builds them; :func:`gb_pin.learn.loop.babble_loop` reads them by name, so that no
argument can be passed in the wrong order without numba refusing to compile.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from gb_pin.learn.body.chain import Body, PlanarBody
from gb_pin.learn.goals.base import GoalArrays
from gb_pin.learn.llm_kernels import MapArrays, Scratch
from gb_pin.learn.sensor import NoSensorArrays, SensorArrays

# Indices into the int64 counters (Run.counters), saved in checkpoints as "istate".
MOVEMENTS = 0  # r: completed movements, home returns included
STEP = 1  # l: steps done in the current movement (0..L)
KIND = 2  # kind of the current movement, NONE between movements
LAST_KIND = 3  # kind of the previous movement
PROTOTYPES = 4  # K
EVAL_CURSOR = 5  # next entry of the evaluation schedule
STEPS = 6  # total steps t
RECORDED = 7  # entries written to the recording buffers
REACHES = 8  # goal-directed movements whose end was observed (entries written to Run.reach)
MISSING = 9  # steps whose reading was missing (nothing learnt from them)
ISTATE_SIZE = 10
OLD_ISTATE_SIZE = 8  # files written before the reach ring and missing readings

# Movement kinds.
NONE = -1
GOAL = 0
HOME = 1
BABBLE = 2  # motor babbling: a joint-space movement to a random posture (gb_pin.learn.goals.motor)

# Status codes returned by babble_loop.
DONE = 0
NEED_CAPACITY = 1
NOT_FINITE = 2
NEED_RECORD_CAPACITY = 3
NEED_GOAL = 4  # a goal generator written in Python must write the next path end
MOVEMENT_DONE = 5  # an ask/tell step completed the movement (gb_pin.learn.session_kernels)
STEP_DONE = 6  # an ask/tell step ended, the movement goes on
REACHED = 7  # E^X reached the run's stopping level (until_error): the run is over
SLICE = 8  # the loop's time slice is up (Evaluation.seconds): Python looks for Ctrl-C and calls again

MAX_POSTURE = 1e6  # a posture beyond this (rad or m) means the estimate has exploded


class Hyper(NamedTuple):
    """The hyperparameters as the loop uses them (see :mod:`gb_pin.learn.config`)."""

    learning_rate: float
    sigma: float
    sigma_delta: float
    radius: float
    path_length: int
    p_home: float


class Limits(NamedTuple):
    """Home posture and joint limits, (m,) each ([rad] or [m]; +-inf where unbounded).

    ``max_step``: no step moves a joint farther than this from the last executed posture
    ([rad] or [m]; +inf: no limit).
    """

    home: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    max_step: float


class Noise(NamedTuple):
    """E_t(x) = A x + b of Eq. 8: A (m, n), b (m,)."""

    A: NDArray[np.float64]
    b: NDArray[np.float64]


class Learner(NamedTuple):
    """What learns: hyperparameters, the local-linear map (and its scratch buffers), the exploration noise."""

    hyper: Hyper
    lm: MapArrays
    scratch: Scratch
    noise: Noise


class Robot(NamedTuple):
    """What is learnt about: limits, the compiled forward kinematics and what observes it.

    ``sensor``: :data:`~gb_pin.learn.sensor.NO_SENSOR` (x = f(q) exactly, the paper's) or a
    :class:`~gb_pin.learn.sensor.SensorArrays` (noisy readings, some missing).
    """

    limits: Limits
    body: Body | PlanarBody
    sensor: NoSensorArrays | SensorArrays


class Motion(NamedTuple):
    """Where the run is: the previous step, the current path, and per-step scratch buffers.

    Attributes:
        q_prev: (m,) the posture of the last observed step (Eqs. 4, 5 compare with it).
        q_start: (m,) start of the current joint-space movement (home return, motor babbling).
        q_end: (m,) end of the current joint-space movement (q_home, or a random posture).
        x_prev: (n,) the last observed position.
        target_prev: (n,) the target of the last observed goal-directed step.
        path_start: (n,) start of the current target path (Eq. 3).
        path_end: (n,) end of the current target path (the goal).
        q: (m,) scratch: this step's posture.
        x: (n,) scratch: this step's position.
        target: (n,) scratch: this step's target.
        q_exec: (m,) the last executed posture (q_prev unless readings went missing since).
    """

    q_prev: NDArray[np.float64]
    q_start: NDArray[np.float64]
    q_end: NDArray[np.float64]
    x_prev: NDArray[np.float64]
    target_prev: NDArray[np.float64]
    path_start: NDArray[np.float64]
    path_end: NDArray[np.float64]
    q: NDArray[np.float64]
    x: NDArray[np.float64]
    target: NDArray[np.float64]
    q_exec: NDArray[np.float64]


class Run(NamedTuple):
    """The run's mutable state: the motion, the int64 counters (indices above), and ``reach``.

    ``reach`` (W,): a ring of the last W reach errors ||x_L - x*_L|| observed at the end of
    goal-directed movements [m] (entry ``counters[REACHES] % W`` is written next).
    """

    motion: Motion
    counters: NDArray[np.int64]
    reach: NDArray[np.float64]


class Evaluation(NamedTuple):
    """When and where E^X and D^home are measured, and the output arrays (one entry per count).

    ``components`` (T, C): E^X per task component of a stacked task (C = 0 for the paper's).
    ``until``: the run stops (REACHED) at the first evaluation with E^X <= until (-inf: never).
    ``reach`` (T,): the median of the run's reach ring (:class:`Run`) at each count [m].
    ``seconds``: the longest the loop runs before it returns ``SLICE`` (inf: it never does);
    ``progress`` (5,): an evaluation under way (:func:`~gb_pin.learn.metrics.evaluate_model`: next
    target, two sums), then when the call's slice ends and the movement count it began at;
    ``clock``: int64 (2,) scratch of :func:`~gb_pin.learn.clock.monotonic`.
    """

    at: NDArray[np.int64]
    targets: NDArray[np.float64]
    errors: NDArray[np.float64]
    distances: NDArray[np.float64]
    components: NDArray[np.float64]
    until: float
    reach: NDArray[np.float64]
    seconds: float
    progress: NDArray[np.float64]
    clock: NDArray[np.int64]


class Recorder(NamedTuple):
    """Every ``every``-th step of movements ``first <= r < last`` is written to the buffers."""

    every: int
    first: int
    last: int
    step: NDArray[np.int64]
    movement: NDArray[np.int64]
    posture: NDArray[np.float64]
    target: NDArray[np.float64]
    position: NDArray[np.float64]


class Monitor(NamedTuple):
    """What the loop measures and records, never what it learns."""

    evaluation: Evaluation
    recorder: Recorder


__all__ = [
    "Body",
    "Evaluation",
    "GoalArrays",
    "Hyper",
    "Learner",
    "Limits",
    "MapArrays",
    "Monitor",
    "Motion",
    "Noise",
    "Recorder",
    "Robot",
    "Run",
    "Scratch",
]
