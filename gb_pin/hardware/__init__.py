"""Real arms over a Feetech STS3215 bus: :class:`FeetechArm` (extra ``[hardware]``: pyserial).

Nothing else in gb_pin imports this package (the CLI does, for ``--arm feetech:...`` only).
:mod:`gb_pin.hardware.emulator` is an emulated bus on a pseudo-terminal, for tests.
"""

from gb_pin.hardware.arm import FeetechArm
from gb_pin.hardware.bus import FeetechBus
from gb_pin.hardware.calibration import Calibration, load_calibration

__all__ = ["Calibration", "FeetechArm", "FeetechBus", "load_calibration"]
