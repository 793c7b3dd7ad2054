"""Plants: the robot that is, not its model: a mis-calibrated body watched by a noisy, lossy sensor.

A low-cost arm is not its URDF: each servo's zero is off by a few degrees, each printed link by a
few per cent, and the camera that watches the hand adds millimetres of noise and sometimes loses
it. A :class:`Plant` is such an arm for rehearsal and tests: a true body (the model's kinematic
chain with joint zero offsets and scaled link translations, compiled as every chain is) and a
:class:`~gb_pin.learn.sensor.Sensor`. It is a robot wherever one is accepted: ``babble(plant)``
learns from the sensor's readings in compiled code, and E^X and every reported error are
measured on the true body. ``plant.target`` is the robot as its model says it is (for exact IK on
the URDF, which misses on the true body); ``plant.observe(q)`` reads the sensor from Python (a
stand-in for a camera in ask/tell sessions).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn.body.chain import PRISMATIC, REVOLUTE, KinematicChain
from gb_pin.learn.sensor import Sensor, observe_into
from gb_pin.robot.bodies import ChangedBody, _chain, _rotation


@dataclass(frozen=True, eq=False)
class Miscalibration:
    """How a body differs from its model.

    Attributes:
        offsets: (m,) joint zero offsets: the joint turns to q + offset when asked for q [rad]
            (prismatic joints: [m]).
        scales: (m + 1,) factors of each joint placement's translation (m) and of the frame's
            offset in its joint (last entry; every task component's frame for a stacked task).
    """

    offsets: NDArray[np.float64]
    scales: NDArray[np.float64]

    @classmethod
    def draw(cls, m: int, offset_std: float, length_std: float, seed: Any = 0) -> Miscalibration:
        """Offsets ~ N(0, offset_std^2) [rad] and scales ~ 1 + N(0, length_std^2), from ``seed``.

        Raises:
            InvalidArgumentError: a negative or non-finite spread, or scales that would not be > 0.
        """
        offset_std = check.nonnegative_float("offset_std", offset_std)
        length_std = check.nonnegative_float("length_std", length_std)
        if length_std >= 0.2:
            raise InvalidArgumentError(f"length_std must be < 0.2 (a few per cent), got {length_std!r}")
        rng = check.generator(seed)
        offsets = offset_std * rng.standard_normal(m)
        scales = 1.0 + length_std * rng.standard_normal(m + 1)
        return cls(offsets, np.clip(scales, 0.05, None))

    def apply(self, chain: KinematicChain) -> KinematicChain:
        """The true chain: offsets folded into the joint placements, translations scaled.

        Raises:
            InvalidArgumentError: arrays of the wrong length or non-finite, scales <= 0.
        """
        m = chain.n_joints
        offsets = check.vector("offsets", self.offsets, m)
        scales = check.vector("scales", self.scales, m + 1)
        if np.any(scales <= 0):
            raise InvalidArgumentError(f"scales must be > 0, got {scales.tolist()}")
        rotations = chain.rotations.copy()
        translations = chain.translations * scales[:m, None]
        for i in range(m):
            delta = offsets[chain.q_index[i]]
            if chain.kinds[i] == REVOLUTE:
                # R(axis, q + delta) = R(axis, delta) R(axis, q): the offset turns the placement.
                rotations[i] = rotations[i] @ _rotation(chain.axes[i], delta)
            elif chain.kinds[i] == PRISMATIC:
                translations[i] = translations[i] + rotations[i] @ (chain.axes[i] * delta)
        changes: dict[str, Any] = {
            "rotations": rotations,
            "translations": translations,
            "frame_translation": chain.frame_translation * scales[m],
        }
        if chain.components is not None:
            comps = chain.components
            changes["components"] = dataclasses.replace(comps, translations=comps.translations * scales[m])
        return dataclasses.replace(chain, **changes)


class Plant(ChangedBody):
    """A robot as it is: its model's body mis-calibrated, its hand seen through a sensor.

    Args:
        robot: the model (a preset name or a robot with a compiled chain, e.g. the SO-101's URDF).
        offset_std: joint zero offsets ~ N(0, offset_std^2) [rad] (ignored if ``offsets`` given).
        length_std: link translations scaled by 1 + N(0, length_std^2) (ignored if ``scales`` given).
        noise: the sensor's noise per axis [m] (one number or one per axis).
        loss: probability that a reading is missing.
        seed: draws the body and seeds the sensor (two independent streams).
        offsets: explicit joint offsets (m,) [rad] instead of drawn ones.
        scales: explicit translation factors (m + 1,) instead of drawn ones.
        name: a label; default derived from the model's.

    Attributes:
        target: the robot as its model says (the URDF's kinematics; also ``base``).
        preset: the model's preset name, when it was given by name (result files record it).
        calibration: the :class:`Miscalibration` of the true body.
        sensor: the :class:`~gb_pin.learn.sensor.Sensor` the learner observes through.
    """

    def __init__(
        self,
        robot: Any,
        *,
        offset_std: float = 0.0,
        length_std: float = 0.0,
        noise: float | ArrayLike = 0.0,
        loss: float = 0.0,
        seed: int = 0,
        offsets: ArrayLike | None = None,
        scales: ArrayLike | None = None,
        name: str | None = None,
    ) -> None:
        self.preset: str | None = robot if isinstance(robot, str) else None
        if isinstance(robot, str):
            from gb_pin.robot.presets import load_robot

            robot = load_robot(robot)
        chain = _chain(robot)
        seed = check.positive_int("seed", seed, 0, 2**63 - 1)
        body_seed, sensor_seed = np.random.SeedSequence(seed).spawn(2)
        m = chain.n_joints
        drawn = Miscalibration.draw(m, offset_std, length_std, np.random.default_rng(body_seed))
        calibration = Miscalibration(
            drawn.offsets if offsets is None else check.vector("offsets", offsets, m),
            drawn.scales if scales is None else check.vector("scales", scales, m + 1),
        )
        label = name or (
            f"{robot.name} mis-calibrated "
            f"({math.degrees(offset_std):g} deg, {100 * length_std:g} %, seed {seed})"
        )
        super().__init__(robot, calibration.apply(chain), label)
        self.target = robot
        self.calibration = calibration
        self.sensor = Sensor(noise, loss, np.random.default_rng(sensor_seed))
        self.sensor.std(chain.n_task)  # a per-axis noise of the wrong length is refused now
        self.seed = seed
        self._readings = self.sensor.start(chain.n_task)

    def observe(self, q: ArrayLike) -> NDArray[np.float64] | None:
        """The sensor's reading of the true position at posture ``q`` (m,), or None when it is lost.

        Draws from the plant's own stream of readings (independent of the runs made with it).
        """
        x = self.forward(check.vector("q", q, self.n_joints))
        return x if observe_into(self._readings, x) else None

    def __repr__(self) -> str:
        return f"Plant({self.name!r}, sensor={self.sensor!r})"
