"""Exceptions raised by gb_pin.

Every error a user can provoke with a bad argument, an unknown robot or a broken
file is a :class:`GbPinError`; argument errors also subclass :class:`ValueError`
so that generic ``except ValueError`` handlers keep working.
"""

from __future__ import annotations


class GbPinError(Exception):
    """Base class of every exception raised by gb_pin."""


class InvalidArgumentError(GbPinError, ValueError):
    """An argument has a wrong type, shape, range or value.

    The message names the parameter, the value received and what would be valid.
    """


class NotFittedError(InvalidArgumentError, AttributeError):
    """A learned attribute or prediction was asked of a learner that has not learned yet.

    Subclasses AttributeError too (as scikit-learn's does), so ``hasattr`` answers False.
    """


class UnknownRobotError(InvalidArgumentError):
    """A robot name, frame or joint name that gb_pin does not know."""


class ResultFileError(GbPinError):
    """A saved result file is missing, truncated, corrupted or not a gb_pin file."""


class DivergenceError(GbPinError):
    """The learner's state became non-finite (e.g. a far too high learning rate)."""


class ViewerError(GbPinError):
    """The viewer cannot start (meshcat missing, port taken, ...) or was asked for something impossible."""


class SimulationError(GbPinError):
    """The physics simulator cannot start (MuJoCo missing) or cannot simulate what was asked."""


class CameraError(GbPinError):
    """A camera cannot open or deliver a frame, OpenCV is missing, or no GL backend renders the plant."""


class FileWriteError(GbPinError, OSError):
    """A file could not be written (a full disk, a removed folder): the message names the file.

    Also an :class:`OSError`, so that code falling back to another place on a failed write
    (periodic checkpoints) catches it as before.
    """


class OnboardingBudgetError(InvalidArgumentError):
    """Onboarding a robot (choosing its home and goal grid) took longer than its chain's time budget."""


class GbPinWarning(UserWarning):
    """Base class of the warnings gb_pin emits."""


class UnreachableTargetWarning(GbPinWarning):
    """Targets that no posture within the joint limits can reach (detected cheaply: beyond the reach)."""


class ExtrapolationWarning(GbPinWarning):
    """Queries of the learned map far outside the learned region: its linear extrapolation may be far off."""


class ViewerWarning(GbPinWarning):
    """A viewer could not start; the run goes on without it."""


class HardwareError(GbPinError):
    """A real robot (or its bus) failed: a port that does not open, a servo that does not answer.

    Args:
        port: the bus's port (e.g. ``/dev/ttyACM0``).
        what: what went wrong.
        servo: the servo concerned (``"elbow_flex (id 3)"``), if one.
    """

    def __init__(self, port: str, what: str, servo: str | None = None) -> None:
        self.port, self.servo, self.what = port, servo, what
        where = f"{port}, servo {servo}" if servo else port
        super().__init__(f"Feetech bus {where}: {what}")


class EmergencyStopError(HardwareError):
    """The e-stop event was set: the arm stopped (and was held or parked as ``on_stop`` says)."""


class HardwareWarning(GbPinWarning):
    """A real robot did something worth knowing that is not an error (a joint stalled short of its goal)."""


class UnsafeSetupError(InvalidArgumentError):
    """A safe run cannot start (raised before anything moves).

    An obstacle touches the arm at home, goals lie inside an obstacle, the robot has no collision
    geometry, ...
    """
