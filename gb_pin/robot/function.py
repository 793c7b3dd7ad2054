"""FunctionTarget: a robot given as a forward model ``forward(q) -> x``, with home, limits and targets.

Goal babbling needs nothing of a robot but its forward function (Eq. 1), a home posture and
joint limits. A :class:`FunctionTarget` is such a robot written as any Python callable (a
simulator, a learned model, a numba-compiled function, a continuum arm): ``babble`` runs it
step by step through the ask/tell stepping (:mod:`gb_pin.learn.asktell`), calling ``forward``
once per step. This module does not import pinocchio.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError

ForwardFunction = Callable[[NDArray[np.float64]], ArrayLike]


class BlackBox:
    """What robots known only from outside share: a home, joint limits, a task dimension and a name."""

    home: NDArray[np.float64]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    name: str
    _n: int

    @property
    def n_joints(self) -> int:
        """Number of joints m."""
        return int(self.home.shape[0])

    @property
    def n_task(self) -> int:
        """Task dimension n."""
        return self._n

    def clip(self, q: ArrayLike) -> NDArray[np.float64]:
        """Posture(s) clipped to the joint limits: what the robot executes."""
        return np.clip(np.asarray(q, dtype=float), self.lower, self.upper)

    def check_targets(self, targets: ArrayLike, what: str = "targets") -> NDArray[np.float64]:
        """Validate targets: (N, n) finite points [m] (no reach check: the robot is a black box)."""
        return check.points(what, targets, self._n)


class FunctionTarget(BlackBox):
    """A robot given by its forward model.

    Args:
        forward: ``forward(q) -> x``: posture (m,) ([rad] or [m]) to task-space position (n,) [m].
            It receives a fresh array it may keep; it must be deterministic for a run to be
            reproducible.
        home: home posture q_home (m,), within the limits.
        lower: lower joint limits (m,); default -inf (unbounded).
        upper: upper joint limits (m,); default +inf.
        targets: target set X* (N, n) [m] (required by ``babble``: there is no "auto" grid).
        name: a label for messages and saved files.

    Raises:
        InvalidArgumentError: ``forward`` not callable, bad home, limits or targets, or a
            ``forward(home)`` that is not a finite vector.
    """

    chain = None  # no compiled kinematic chain: the learner calls forward() step by step
    kernel: Any = None  # a numba-compiled kernel(q, x), run inside compiled code (see from_kernel)

    def __init__(
        self,
        forward: ForwardFunction,
        home: ArrayLike,
        *,
        lower: ArrayLike | None = None,
        upper: ArrayLike | None = None,
        targets: ArrayLike | None = None,
        name: str = "function",
    ) -> None:
        if not callable(forward):
            raise InvalidArgumentError(f"forward must be a callable forward(q) -> x, got {forward!r}")
        self.function = forward
        self.name = str(name)
        self.home, self.lower, self.upper = home_and_limits(home, lower, upper)
        x_home = np.asarray(self._call(self.home), dtype=np.float64)
        if x_home.ndim != 1 or x_home.size == 0:
            raise InvalidArgumentError(f"forward(home) must be a vector (n,), got shape {x_home.shape}")
        self._n = int(x_home.shape[0])
        self.targets: NDArray[np.float64] | None = (
            None if targets is None else check.points("targets", targets, self._n)
        )

    @classmethod
    def from_kernel(
        cls,
        kernel: Any,
        home: ArrayLike,
        n_task: int,
        *,
        lower: ArrayLike | None = None,
        upper: ArrayLike | None = None,
        targets: ArrayLike | None = None,
        name: str = "kernel",
    ) -> FunctionTarget:
        """A robot whose forward model is a numba-compiled ``kernel(q, x)`` writing x (n_task,) [m] in place.

        ``babble`` then runs every step in compiled code, calling the kernel directly (compiled
        once per process and kernel, not cached on disk).

        Raises:
            InvalidArgumentError: ``kernel`` is not a numba ``@njit`` function, or a bad ``n_task``.
        """
        if not hasattr(kernel, "py_func"):
            raise InvalidArgumentError(f"kernel must be a numba @njit function kernel(q, x), got {kernel!r}")
        n = check.positive_int("n_task", n_task)

        def forward(q: NDArray[np.float64]) -> NDArray[np.float64]:
            out = np.zeros(n)
            kernel(np.ascontiguousarray(q, dtype=np.float64), out)
            return out

        target = cls(forward, home, lower=lower, upper=upper, targets=targets, name=name)
        target.kernel = kernel
        return target

    @property
    def home_position(self) -> NDArray[np.float64]:
        """f(q_home) [m]."""
        return self.forward(self.home)

    def _call(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        try:
            raw = self.function(q.copy())
            if raw is None:
                raise InvalidArgumentError(
                    f"forward model {self.name!r} returned None at q = {q.tolist()}: a forward model returns "
                    "a position; a robot whose readings go missing runs in a session (tell(None))"
                )
            if check.is_complex(raw):
                raise InvalidArgumentError(
                    f"forward model {self.name!r} returned complex values {raw!r:.200} at q = {q.tolist()}: "
                    "a position is real (the imaginary part would be dropped)"
                )
            x = np.asarray(raw, dtype=np.float64)
        except InvalidArgumentError:
            raise
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(f"forward({q.tolist()}) did not return a position: {exc}") from exc
        if not np.all(np.isfinite(x)):
            raise InvalidArgumentError(f"forward({q.tolist()}) returned a non-finite position {x.tolist()}")
        return x

    def forward(self, q: ArrayLike) -> NDArray[np.float64]:
        """Task-space position(s): (m,) -> (n,), (N, m) -> (N, n) [m], executed as given (not clipped).

        Raises:
            InvalidArgumentError: a posture of the wrong shape, or a forward model returning
                something other than a finite (n,) vector.
        """
        try:
            arr = np.asarray(q, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(f"q must be a posture ({self.n_joints},), got {q!r}") from exc
        single = arr.ndim == 1
        arr2 = np.atleast_2d(arr)
        if arr2.ndim != 2 or arr2.shape[1] != self.n_joints:
            raise InvalidArgumentError(
                f"q must have shape ({self.n_joints},) or (N, {self.n_joints}), got shape {arr.shape}"
            )
        out = np.empty((arr2.shape[0], self._n))
        for i, qi in enumerate(arr2):
            x = self._call(qi)
            if x.shape != (self._n,):
                raise InvalidArgumentError(f"forward(q) must return shape ({self._n},), got {x.shape}")
            out[i] = x
        return out[0] if single else out

    def auto_targets(self) -> NDArray[np.float64]:
        """There is no "auto" grid for a black box.

        Raises:
            InvalidArgumentError: always; pass ``targets=``.
        """
        raise InvalidArgumentError(f"FunctionTarget {self.name!r} has no target set: pass targets=")

    def __repr__(self) -> str:
        return f"FunctionTarget({self.name!r}, {self.n_joints} joints, {self.n_task} task axes)"


def home_and_limits(
    home: ArrayLike, lower: ArrayLike | None, upper: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """(home, lower, upper) checked: a finite non-empty posture, limits (-+inf where None) around it.

    Raises:
        InvalidArgumentError: a bad home or limits, or lower <= home <= upper violated.
    """
    try:
        home_arr = np.asarray(home, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(f"home must be a posture vector, got {home!r}") from exc
    if home_arr.ndim != 1 or home_arr.size == 0:
        raise InvalidArgumentError(f"home must be a non-empty vector (m,), got shape {home_arr.shape}")
    m = home_arr.shape[0]
    q = check.vector("home", home_arr, m)
    lo, up = _limit("lower", lower, m, -np.inf), _limit("upper", upper, m, np.inf)
    if np.any(lo > up) or np.any(q < lo) or np.any(q > up):
        raise InvalidArgumentError(f"need lower <= home <= upper, got lower={lo}, home={q}, upper={up}")
    return q, lo, up


def _limit(name: str, value: ArrayLike | None, m: int, default: float) -> NDArray[np.float64]:
    if value is None:
        return np.full(m, default)
    try:
        arr = np.array(np.broadcast_to(np.asarray(value, dtype=np.float64), (m,)))
    except (TypeError, ValueError) as exc:
        raise InvalidArgumentError(
            f"{name} must be a number or a vector of {m} limits, got {value!r}"
        ) from exc
    if np.any(np.isnan(arr)):
        raise InvalidArgumentError(f"{name} limits must not be NaN, got {arr.tolist()}")
    return arr
