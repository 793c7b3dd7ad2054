"""What the learner observes of Eq. 1: x_t = f(q_t) through a sensor with noise and losses.

The paper observes x_t = f(q_t) exactly. A real arm is watched by a tracker: every reading
carries noise, and some are lost (the camera lost the hand). :class:`Sensor` models both:
each axis gets Gaussian noise N(0, std_j^2), and with probability ``loss`` the whole reading is
missing. A missing reading teaches nothing: the learner skips the step's update (the
movement goes on, t advances) and keeps the last observed posture and position as the
"previous" ones of Eqs. 4-5, so weights always compare two observations.

The compiled loop calls :func:`observe` right after the forward kinematics; numba picks the
implementation by the class of its argument, so a run without a sensor (:data:`NO_SENSOR`, the
paper's) compiles to exactly the loop it was: ``observe`` is the constant True there.

The sensor draws from its own ``numpy.random.Generator`` (not the learner's), so that the same
body and sensor seed give the same readings whatever the learner does.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import types
from numba.extending import overload
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._jit import njit
from gb_pin.exceptions import InvalidArgumentError


class NoSensorArrays(NamedTuple):
    """No sensor: the learner observes f(q) exactly (the paper's Eq. 1)."""

    kind: int


MAX_NOISE = 1e6
"""The largest sensor noise [m]: readings scattered farther make the learner's sums overflow."""


class SensorArrays(NamedTuple):
    """A sensor as the compiled :func:`observe` takes it.

    Attributes:
        std: (n,) standard deviation of the noise on each task axis [m].
        loss: probability that a reading is missing.
        rng: the sensor's own generator (advanced in place).
    """

    std: NDArray[np.float64]
    loss: float
    rng: np.random.Generator


NO_SENSOR = NoSensorArrays(0)


def observe(sensor: Any, x: Any) -> bool:
    """Turn the true x (n,) into the reading in place; False when the reading is missing.

    Called from compiled code only (numba picks the implementation by the class of ``sensor``);
    from Python use :func:`observe_into`.
    """
    raise TypeError("observe runs inside compiled code (see observe_into)")


@overload(observe, jit_options={"nogil": True, "error_model": "numpy"}, inline="always")
def _observe(sensor, x):  # type: ignore[no-untyped-def]
    if isinstance(sensor, types.BaseNamedTuple) and sensor.instance_class is SensorArrays:
        return lambda sensor, x: _noisy_reading(sensor, x)
    return lambda sensor, x: True


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _noisy_reading(sensor, x):  # type: ignore[no-untyped-def]
    rng = sensor.rng
    if sensor.loss > 0.0 and rng.random() < sensor.loss:
        return False
    std = sensor.std
    for j in range(x.shape[0]):
        if std[j] > 0.0:
            x[j] += std[j] * rng.standard_normal()
    return True


@njit(cache=True, nogil=True, error_model="numpy")
def observe_into(sensor, x):  # type: ignore[no-untyped-def]
    """:func:`observe` called from Python (the same draws as in the compiled loop)."""
    return observe(sensor, x)


class Sensor:
    """Gaussian noise per task axis and lost readings, drawn from the sensor's own seed.

    Args:
        noise: standard deviation of the noise [m]: one number for every axis, or one per axis.
        loss: probability in [0, 1) that a reading is missing.
        seed: an int seed or a ``numpy.random.Generator`` for the sensor's own draws.

    Raises:
        InvalidArgumentError: a negative or non-finite noise, a loss outside [0, 1), a bad seed.
    """

    def __init__(self, noise: float | ArrayLike = 0.0, loss: float = 0.0, seed: Any = 0) -> None:
        arr = np.asarray(noise, dtype=object)
        try:
            values = np.asarray(noise, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise InvalidArgumentError(f"noise must be a number or one per axis [m], got {noise!r}") from exc
        if arr.ndim > 1 or values.size == 0 or not np.all(np.isfinite(values)) or np.any(values < 0):
            raise InvalidArgumentError(
                f"noise must be >= 0 and finite [m] (one number or one per axis), got {noise!r}"
            )
        if np.any(values > MAX_NOISE):
            raise InvalidArgumentError(
                f"noise must be at most {MAX_NOISE:g} m (readings beyond overflow the learner), got {noise!r}"
            )
        self.noise = values.copy()
        self.loss = check.probability("loss", loss)
        if self.loss >= 1.0:
            raise InvalidArgumentError(f"loss must be < 1 (some readings must arrive), got {loss!r}")
        check.generator(seed)  # validates an int seed (a Generator is copied at each start)
        self.seed = seed

    def std(self, n: int) -> NDArray[np.float64]:
        """The noise per axis for a task of n axes (n,) [m].

        Raises:
            InvalidArgumentError: a per-axis noise of another length.
        """
        if self.noise.ndim == 0:
            return np.full(n, float(self.noise))
        if self.noise.shape != (n,):
            raise InvalidArgumentError(f"noise has {self.noise.shape[0]} axes, the task has {n}")
        return self.noise.copy()

    def start(self, n: int) -> SensorArrays:
        """The sensor's arrays with a fresh generator from its seed (a Generator given is copied)."""
        if isinstance(self.seed, np.random.Generator):
            rng = np.random.Generator(type(self.seed.bit_generator)())
            rng.bit_generator.state = self.seed.bit_generator.state
        else:
            rng = check.generator(self.seed)
        return SensorArrays(self.std(n), float(self.loss), rng)

    @property
    def ideal(self) -> bool:
        """True for a sensor that neither adds noise nor loses readings."""
        return self.loss == 0.0 and not np.any(self.noise > 0)

    def __repr__(self) -> str:
        noise = float(self.noise) if self.noise.ndim == 0 else self.noise.tolist()
        return f"Sensor(noise={noise!r}, loss={self.loss!r})"
