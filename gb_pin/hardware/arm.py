"""``FeetechArm``: an SO-101 / SO-100 on its Feetech bus, moved posture by posture, settled, stopped safely.

>>> with FeetechArm("/dev/ttyACM0", "so101", "arm.json", max_joint_step=0.05) as arm:  # doctest: +SKIP
...     arm.move_to(arm.home)          # from wherever it is, in steps of max_joint_step
...     q = arm.move([0.1, -0.6, 0.6, 0.6])   # the posture the encoders read once it settled

Postures are the preset's four learned joints in radians of its URDF; wrist roll and gripper are
held at the preset's locked value (0). Nothing moves before every servo answered, its model is an
STS3215 and its registers hold the calibration given. ``close()`` (also on leaving the ``with``
block, on an exception, Ctrl-C or the ``stop`` event) holds the arm where it is (``on_stop="hold"``:
torque on) or parks it (``"park"``: home at ``park_speed``, then torque off).
"""

from __future__ import annotations

import contextlib
import math
import threading
import time
import warnings
from collections import Counter
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin.exceptions import EmergencyStopError, HardwareError, HardwareWarning, InvalidArgumentError
from gb_pin.hardware import protocol as p
from gb_pin.hardware.arms import TICKS_PER_RAD, arm_kind
from gb_pin.hardware.bus import FeetechBus
from gb_pin.hardware.calibration import load_calibration

POLL = p.GOAL_POSITION.address  # one poll reads Goal_Position (42) ... Moving (66)
POLL_SIZE = p.MOVING.address + 1 - POLL


class FeetechArm:
    """An SO-101 or SO-100 on a Feetech STS3215 bus.

    Args:
        port: the bus (``/dev/ttyACM0``).
        robot: ``"so101"`` or ``"so100"``.
        calibration: a LeRobot calibration file or its dict.
        baudrate: the bus's.
        max_joint_step: the most any joint's goal may change between two commands [rad] (None: no limit).
        tolerance: a joint has settled within this of its goal [rad] (and its Moving flag clear).
        timeout: seconds a move may take to settle; then it counts in ``stalls`` and the joints short
            of their goals are named in a :class:`~gb_pin.exceptions.HardwareWarning`.
        reply_timeout: seconds to wait for a reply; retries: attempts after the first.
        on_stop: ``"hold"`` (torque on, where it is) or ``"park"`` (home slowly, then torque off).
        stop: an e-stop (a ``threading.Event`` set from any thread): the arm stops at once.
        park_speed: the parking speed [rad/s].

    Attributes:
        lower, upper: (4,) the postures :meth:`move` accepts: the URDF's limits within the calibrated ranges.
        home: the preset's home (4,). command: the last posture commanded (4,).
        stalls: moves that did not settle in time; stalled: Counter of the joints named then.
        bus: the :class:`~gb_pin.hardware.bus.FeetechBus` (``bus.faults``: the faults recovered).

    Raises:
        InvalidArgumentError: bad arguments, a calibration of another arm or with motors missing.
        HardwareError: the port does not open, a servo does not answer or is not an STS3215, or its
            registers hold another calibration (nothing has moved then).
    """

    def __init__(
        self,
        port: str,
        robot: str = "so101",
        calibration: Any = None,
        *,
        baudrate: int = 1_000_000,
        max_joint_step: float | None = None,
        tolerance: float = math.radians(1.0),
        timeout: float = 2.0,
        reply_timeout: float = 0.02,
        retries: int = 8,
        on_stop: str = "hold",
        stop: threading.Event | None = None,
        park_speed: float = 0.5,
    ) -> None:
        if on_stop not in ("hold", "park"):
            raise InvalidArgumentError(f"on_stop must be 'hold' or 'park', got {on_stop!r}")
        if calibration is None:
            raise InvalidArgumentError("calibration= is needed: the LeRobot calibration file of this arm")
        self.kind = arm_kind(robot)
        self.calibration = load_calibration(calibration, self.kind)
        self.max_joint_step = (
            None if max_joint_step is None else check.positive_float("max_joint_step", max_joint_step)
        )
        self.tolerance = check.positive_float("tolerance", tolerance)
        self.timeout = check.positive_float("timeout", timeout)
        self.park_speed = check.positive_float("park_speed", park_speed)
        self.on_stop, self.stop = on_stop, stop
        from gb_pin.robot.presets import load_robot

        preset = load_robot(robot)
        self.learned = [self.kind.motors.index(j) for j in self.kind.learned]
        cal_lo, cal_hi = self.calibration.limits(self.kind)
        lo, hi = np.maximum(cal_lo, self.kind.lower), np.minimum(cal_hi, self.kind.upper)
        self.lower, self.upper = lo[self.learned], hi[self.learned]
        self.home = np.clip(np.asarray(preset.home, dtype=float), self.lower, self.upper)
        self.held = np.clip(np.zeros(6), lo, hi)  # wrist roll and gripper: the preset locks them at 0
        self.ids = [int(i) for i in self.calibration.ids]
        self.stalls = 0
        self.stalled: Counter[str] = Counter()
        self.moves = 0
        self._closed = True
        self.bus = FeetechBus(
            port, baudrate, reply_timeout=reply_timeout, retries=retries,
            names=dict(zip(self.ids, self.kind.motors, strict=True)),
        )  # fmt: skip
        try:
            self._connect()
        except BaseException:
            self.bus.close()
            raise
        self._closed = False

    # -- connection --------------------------------------------------------------------------
    def _connect(self) -> None:
        """Check every servo (answers, model, calibration), then hold where it stands, torque on."""
        cal = self.calibration
        for k, servo in enumerate(self.ids):
            label = self.bus.label(servo)
            try:
                self.bus.ping(servo)
            except HardwareError as exc:
                raise HardwareError(self.bus.port, "does not answer (powered? wired? id?)", label) from exc
            model = self.bus.read(servo, p.MODEL_NUMBER)
            if model != p.MODEL_STS3215:
                raise HardwareError(
                    self.bus.port, f"model number {model}, not an STS3215 ({p.MODEL_STS3215})", label
                )
            held = (self.bus.read(servo, p.HOMING_OFFSET), self.bus.read(servo, p.MIN_POSITION_LIMIT),
                    self.bus.read(servo, p.MAX_POSITION_LIMIT))  # fmt: skip
            given = (int(cal.homing_offsets[k]), int(cal.range_min[k]), int(cal.range_max[k]))
            if held != given:
                raise HardwareError(
                    self.bus.port,
                    f"holds homing offset {held[0]}, range {held[1]}-{held[2]}; the calibration {cal.source} "
                    f"says {given[0]}, {given[1]}-{given[2]}: the file of another arm? (calibrate this one "
                    "with lerobot-calibrate)",
                    label,
                )
        present = self._poll()[1]
        self.bus.sync_write(p.GOAL_POSITION, dict(zip(self.ids, present.tolist(), strict=True)))
        for servo in self.ids:
            self.bus.write(servo, p.TORQUE_ENABLE, 1)
        q = self.calibration.radians(self.kind, present)
        self.command = q[self.learned].copy()
        self._full = q.copy()  # all six joints' last command; wrist roll and gripper go to held in steps
        self._goal = present.copy()

    # -- reading -----------------------------------------------------------------------------
    def _poll(self) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.bool_]]:
        """Goal, present position and moving flag of each servo [ticks] (one SYNC_READ)."""
        data = self.bus.sync_read(self.ids, POLL, POLL_SIZE)
        goal = np.empty(6, dtype=np.int64)
        present = np.empty(6, dtype=np.int64)
        moving = np.empty(6, dtype=bool)
        for k, servo in enumerate(self.ids):
            d = data[servo]
            goal[k] = p.decode(d[0:2], p.GOAL_POSITION)
            at = p.PRESENT_POSITION.address - POLL
            present[k] = p.decode(d[at : at + 2], p.PRESENT_POSITION)
            moving[k] = bool(d[p.MOVING.address - POLL])
        return goal, present, moving

    def read(self) -> NDArray[np.float64]:
        """The posture the encoders read now (4,) [rad of the URDF]."""
        self._check_open()
        return self.calibration.radians(self.kind, self._poll()[1])[self.learned]

    # -- moving ------------------------------------------------------------------------------
    def check(self, q: ArrayLike) -> NDArray[np.float64]:
        """``q`` as :meth:`move` would send it, or InvalidArgumentError saying why not (nothing moves)."""
        arr = check.vector("q", q, 4)
        outside = (arr < self.lower - 1e-9) | (arr > self.upper + 1e-9)
        if outside.any():
            j = int(np.argmax(outside))
            raise InvalidArgumentError(
                f"q[{j}] ({self.kind.learned[j]}) = {arr[j]:.4f} rad is outside "
                f"[{self.lower[j]:.4f}, {self.upper[j]:.4f}] "
                "(the URDF's limits within the calibrated range); "
                "nothing moved"
            )
        if self.max_joint_step is not None:
            step = np.abs(arr - self.command)
            if step.max() > self.max_joint_step + 1e-9:
                j = int(np.argmax(step))
                raise InvalidArgumentError(
                    f"q[{j}] ({self.kind.learned[j]}) moves {step[j]:.4f} rad from the last command, "
                    "more than "
                    f"max_joint_step={self.max_joint_step:g}; nothing moved (move_to() goes in steps)"
                )
        return arr

    def move(self, q: ArrayLike) -> NDArray[np.float64]:
        """Send ``q`` (4,) [rad], wait until it settles (or ``timeout``), return the encoders' posture.

        Raises:
            InvalidArgumentError: q not finite, outside the limits or beyond max_joint_step (nothing moves).
            EmergencyStopError: the stop event is set (the arm is closed as ``on_stop`` says).
            HardwareError: the bus failed past its retries (the arm is closed as ``on_stop`` says).
        """
        self._check_open()
        arr = self.check(q)
        self._guard()
        full = self._full.copy()
        step = np.inf if self.max_joint_step is None else self.max_joint_step
        full = full + np.clip(
            self.held - full, -step, step
        )  # held joints: toward where the preset locks them
        full[self.learned] = arr
        goal = self.calibration.ticks(self.kind, full)
        lo, hi = self.calibration.range_min, self.calibration.range_max
        goal = np.clip(goal, lo, hi)  # rounding at a limit stays inside the calibrated range
        if self.max_joint_step is not None:  # rounding never makes a goal step a tick longer either
            most = math.floor(self.max_joint_step * TICKS_PER_RAD + 1e-9)
            goal = np.clip(goal, self._goal - most, self._goal + most)
        try:
            self.bus.sync_write(p.GOAL_POSITION, dict(zip(self.ids, goal.tolist(), strict=True)))
            self.command, self._goal, self._full = arr, goal, full
            present = self._settle(goal)
        except BaseException:
            self._stop_now()
            raise
        self.moves += 1
        return self.calibration.radians(self.kind, present)[self.learned]

    def move_to(self, q: ArrayLike, step: float | None = None) -> NDArray[np.float64]:
        """Go to ``q`` from the last command in straight steps of at most ``step`` [rad].

        ``step`` defaults to max_joint_step (or 0.05 rad without one).
        """
        self._check_open()
        target = check.vector("q", q, 4)
        step = step or self.max_joint_step or 0.05
        start = self.command.copy()
        held = [k for k in range(6) if k not in self.learned]
        distance = max(float(np.abs(target - start).max()), float(np.abs(self.held - self._full)[held].max()))
        n = max(1, math.ceil(distance / step - 1e-9))
        reached = start
        for i in range(1, n + 1):
            reached = self.move(start + (target - start) * (i / n))
        return reached

    def _settle(self, goal: NDArray[np.int64]) -> NDArray[np.int64]:
        """Poll until every joint is within tolerance of ``goal`` and not moving, or the timeout."""
        tol = self.tolerance * TICKS_PER_RAD
        deadline = time.monotonic() + self.timeout
        while True:
            self._guard()
            written, present, moving = self._poll()
            if (written != goal).any():  # the sync write was lost on the bus: write it again
                self.bus.faults["lost_write"] += 1
                self.bus.sync_write(p.GOAL_POSITION, dict(zip(self.ids, goal.tolist(), strict=True)))
            elif (np.abs(present - goal) <= tol).all() and not moving.any():
                return present
            if time.monotonic() > deadline:
                self.stalls += 1
                short = [self.kind.motors[k] for k in np.flatnonzero(np.abs(present - goal) > tol)]
                short = short or [self.kind.motors[k] for k in np.flatnonzero(moving)]
                self.stalled.update(short)
                warnings.warn(
                    f"{self.bus.port}: {', '.join(short)} did not settle within {self.timeout:g} s "
                    f"(goal {goal.tolist()}, at {present.tolist()} ticks): stalled or blocked?",
                    HardwareWarning,
                    stacklevel=3,
                )
                return present

    # -- stopping ----------------------------------------------------------------------------
    def _guard(self) -> None:
        if self.stop is not None and self.stop.is_set():
            raise EmergencyStopError(self.bus.port, "stopped by the e-stop event")

    def _check_open(self) -> None:
        if self._closed:
            raise InvalidArgumentError(f"the arm on {self.bus.port} is closed")

    def _stop_now(self) -> None:
        """After an exception (or the e-stop) in the middle of a move: close as on_stop says."""
        with contextlib.suppress(Exception):  # the first exception is the one to see
            self.close()

    def close(self) -> None:
        """Stop as ``on_stop`` says and close the port.

        ``"hold"``: where the arm is, torque on; ``"park"``: home at park_speed, then torque off.
        """
        if self._closed:
            return
        self._closed = True
        try:
            present = self._poll()[1]
            if self.on_stop == "hold":
                self.bus.sync_write(p.GOAL_POSITION, dict(zip(self.ids, present.tolist(), strict=True)))
            else:
                self._park(present)
        finally:
            self.bus.close()

    def _park(self, present: NDArray[np.int64]) -> None:
        full = self.held.copy()
        full[self.learned] = self.home
        goal = np.clip(
            self.calibration.ticks(self.kind, full), self.calibration.range_min, self.calibration.range_max
        )
        speed = max(1, round(self.park_speed * TICKS_PER_RAD))
        self.bus.sync_write(p.GOAL_VELOCITY, dict.fromkeys(self.ids, speed))
        self.bus.sync_write(p.GOAL_POSITION, dict(zip(self.ids, goal.tolist(), strict=True)))
        travel = float(np.abs(goal - present).max()) / speed
        deadline = time.monotonic() + travel + self.timeout
        while time.monotonic() < deadline:
            _, now, moving = self._poll()
            if (np.abs(now - goal) <= self.tolerance * TICKS_PER_RAD).all() and not moving.any():
                break
            time.sleep(0.01)
        for servo in self.ids:
            self.bus.write(servo, p.TORQUE_ENABLE, 0)
        self.bus.sync_write(p.GOAL_VELOCITY, dict.fromkeys(self.ids, 0))

    def __enter__(self) -> FeetechArm:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"FeetechArm({self.bus.port!r}, {self.kind.robot!r}, on_stop={self.on_stop!r})"
