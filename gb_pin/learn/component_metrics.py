"""E^X split by task component: position errors [m] and orientation errors [deg], per frame.

For a stacked task (:mod:`gb_pin.learn.body.components`) the overall E^X (Eq. 9) is the
mean Euclidean norm over the whole task vector, in task units. :func:`component_errors`
splits it: for each target x*_i and each component c with rows r_c,

    e_ic = ||x*_i[r_c] - f(g(x*_i))[r_c]|| / s_c

in [m] for a position (s_c = 1) and in [deg] for an orientation or a pointing direction
(the distance of the rotation vectors, resp. of the tangent coordinates, divided by the
scale s_c [m/rad]; to first order the angle between the reached and the target rotation,
resp. direction, and exactly that angle when one of them is the reference). The posture
is g(x*) clipped to the limits, as for E^X.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._jit import njit
from gb_pin.learn.body.chain import KinematicChain, body_forward
from gb_pin.learn.body.components import COMPONENT_KINDS, POSITION
from gb_pin.learn.body.kinematics import Kinematics
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.llm_kernels import llm_predict
from gb_pin.learn.parts import PartedMap

QUANTILES = (0.5, 0.9)
"""The quantiles :class:`ComponentErrors` reports."""


class ComponentErrors(NamedTuple):
    """Final errors of a learned inverse estimate, per task component.

    Attributes:
        kinds: (C,) ``"position"``, ``"orientation"`` or ``"pointing"``.
        units: (C,) ``"m"`` or ``"deg"``.
        errors: (N, C) error of each target, each component (see the module docstring).
        total: (N,) ||x*_i - f(g(x*_i))|| over the whole task vector (its mean is E^X).
    """

    kinds: tuple[str, ...]
    units: tuple[str, ...]
    errors: NDArray[np.float64]
    total: NDArray[np.float64]

    @property
    def mean(self) -> NDArray[np.float64]:
        """(C,) mean error of each component over the targets."""
        return np.asarray(self.errors.mean(axis=0))

    def quantile(self, q: float) -> NDArray[np.float64]:
        """(C,) the q-quantile of each component's errors over the targets."""
        return np.asarray(np.quantile(self.errors, q, axis=0))

    def summary(self, labels: tuple[str, ...] | None = None) -> str:
        """One line per component: mean, median and 90 % quantile with units."""
        labels = labels or self.kinds
        lines = []
        for c, label in enumerate(labels):
            unit = self.units[c]
            digits = 4 if unit == "m" else 2
            m, q50, q90 = self.mean[c], self.quantile(0.5)[c], self.quantile(0.9)[c]
            lines.append(
                f"{label}: mean {m:.{digits}f} {unit}, median {q50:.{digits}f}, 90% {q90:.{digits}f}"
            )
        return "\n".join(lines)


@njit(cache=True, nogil=True, error_model="numpy")
def reached(targets, limits, body, lm, K, out):  # type: ignore[no-untyped-def]
    """f(clip(g(x*))) of every target row into ``out`` (N, n), as in E^X (Eq. 9)."""
    home, lower, upper = limits
    m = home.shape[0]
    q = np.empty(m)
    for r in range(targets.shape[0]):
        llm_predict(targets[r], lm, K, q)
        for i in range(m):
            q[i] = min(max(q[i], lower[i]), upper[i])
        body_forward(q, body, out[r])


def component_errors(
    model: LocalLinearMap | PartedMap,
    chain: KinematicChain,
    limits: tuple[ArrayLike, ArrayLike, ArrayLike],
    targets: ArrayLike,
) -> ComponentErrors:
    """Per-component final errors of ``model`` over ``targets`` (see the module docstring).

    Args:
        model: the learned inverse estimate g.
        chain: the robot's forward kinematics (a plain position task is one component).
        limits: (home, lower, upper) postures (m,) each.
        targets: (N, n) targets.
    """
    X = check.points("targets", targets, chain.n_task)
    home, lower, upper = (np.ascontiguousarray(a, dtype=float) for a in limits)
    out = np.empty_like(X)
    if isinstance(model, PartedMap):  # each target reached by the map of its part
        part = model.part_of(X)
        for p, lm in enumerate(model.maps):
            rows = np.flatnonzero(part == p)
            if rows.size:
                sub = np.empty((rows.size, X.shape[1]))
                reached(np.ascontiguousarray(X[rows]), (home, lower, upper), chain.kernel(), lm.kernel(),
                        lm.n_prototypes_, sub)  # fmt: skip
                out[rows] = sub
    else:
        reached(X, (home, lower, upper), chain.kernel(), model.kernel(), model.n_prototypes_, out)
    diff = X - out
    total = np.sqrt(np.sum(diff * diff, axis=1))
    comps = chain.components
    if comps is None:
        return ComponentErrors(("position",), ("m",), total[:, None].copy(), total)
    errors = np.empty((X.shape[0], comps.count))
    kinds, units = [], []
    for c in range(comps.count):
        d = diff[:, comps.rows(c)]
        e = np.sqrt(np.sum(d * d, axis=1)) / comps.scales[c]
        position = comps.kinds[c] == POSITION
        errors[:, c] = e if position else e * (180.0 / math.pi)
        kinds.append(COMPONENT_KINDS[int(comps.kinds[c])])
        units.append("m" if position else "deg")
    return ComponentErrors(tuple(kinds), tuple(units), errors, total)


def task_errors(model: LocalLinearMap | PartedMap, robot: Kinematics, targets: ArrayLike) -> ComponentErrors:
    """:func:`component_errors` of ``model`` on a robot (chain, home, limits), e.g. a ``KinematicTarget``.

    Example::

        result = gb_pin.babble(robot="talos_left_arm_pose", movements=10_000)
        errors = task_errors(result.model, result.target, result.targets)
        print(errors.summary(result.target.component_labels))  # position [m], orientation [deg]
    """
    return component_errors(model, robot.chain, (robot.home, robot.lower, robot.upper), targets)


class ComponentHistory:
    """Component errors over a run: an observer for ``GoalBabbling.fit(observer=..., observe_every=k)``.

    The compiled loop records the overall E^X (Eq. 9) on its schedule; this records the
    mean error of each component every ``k`` movements, from Python between the loop's
    chunks (which leaves the run bit for bit the same).

    Example::

        history = ComponentHistory(robot, targets)
        GoalBabbling().fit(robot, targets, 10_000, observer=history, observe_every=250)
        history.movements, history.errors  # (T,), (T, C): [m] for positions, [deg] for rotations
    """

    def __init__(self, robot: Kinematics, targets: ArrayLike) -> None:
        self.robot = robot
        self.targets = check.points("targets", targets, robot.chain.n_task)
        self._movements: list[int] = []
        self._errors: list[NDArray[np.float64]] = []
        self.kinds: tuple[str, ...] = ()
        self.units: tuple[str, ...] = ()

    def __call__(self, state: Any) -> None:
        """Measure the state's current estimate (``state.llm``) at ``state.movements``."""
        errors = task_errors(state.llm, self.robot, self.targets)
        self.kinds, self.units = errors.kinds, errors.units
        self._movements.append(int(state.movements))
        self._errors.append(errors.mean)

    @property
    def movements(self) -> NDArray[np.int64]:
        """(T,) the movement counts measured at."""
        return np.array(self._movements, dtype=np.int64)

    @property
    def errors(self) -> NDArray[np.float64]:
        """(T, C) mean error of each component at each of :attr:`movements`."""
        return np.array(self._errors).reshape(len(self._errors), -1)
