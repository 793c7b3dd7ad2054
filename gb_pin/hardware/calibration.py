"""LeRobot calibration files, read as they are: ``{motor: {id, drive_mode, homing_offset, range_min, ...}}``.

LeRobot writes them under ``~/.cache/huggingface/lerobot/calibration/robots/so_follower/<id>.json``
(``so101_follower`` / ``so100_follower`` in older versions) when ``lerobot-calibrate`` runs, and the
same values into the servos' EEPROM (Homing_Offset, Min/Max_Position_Limit). Radians of the
preset's URDF <-> ticks as :mod:`gb_pin.hardware.arms` says.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.hardware.arms import TICKS_PER_RAD, ArmKind

FIELDS = ("id", "drive_mode", "homing_offset", "range_min", "range_max")


@dataclass(frozen=True, eq=False)
class Calibration:
    """The six motors' calibration, in the order of :data:`~gb_pin.hardware.arms.MOTORS`.

    Attributes:
        ids, drive_modes, homing_offsets, range_min, range_max: (6,) integer arrays.
        source: the file read (or ``"<dict>"``).
    """

    ids: NDArray[np.int64]
    drive_modes: NDArray[np.int64]
    homing_offsets: NDArray[np.int64]
    range_min: NDArray[np.int64]
    range_max: NDArray[np.int64]
    source: str

    @property
    def mid(self) -> NDArray[np.float64]:
        """The middle of each calibrated range [ticks]."""
        return (self.range_min + self.range_max) / 2.0

    @property
    def sign(self) -> NDArray[np.float64]:
        """-1 for a motor of drive mode 1 (turning the other way), else 1."""
        return np.where(self.drive_modes == 1, -1.0, 1.0)

    def radians(self, kind: ArmKind, ticks: NDArray[Any]) -> NDArray[np.float64]:
        """Present_Position ticks (6,) -> radians of the URDF (6,)."""
        return kind.centre + self.sign * (np.asarray(ticks, dtype=float) - self.mid) / TICKS_PER_RAD

    def ticks(self, kind: ArmKind, q: NDArray[np.float64]) -> NDArray[np.int64]:
        """Radians of the URDF (6,) -> the nearest goal ticks (6,)."""
        return np.rint(self.mid + self.sign * (q - kind.centre) * TICKS_PER_RAD).astype(np.int64)

    def limits(self, kind: ArmKind) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The calibrated ranges in radians of the URDF (6,), (6,)."""
        a, b = self.radians(kind, self.range_min), self.radians(kind, self.range_max)
        return np.minimum(a, b), np.maximum(a, b)


def load_calibration(source: str | os.PathLike[str] | dict[str, Any], kind: ArmKind) -> Calibration:
    """A LeRobot calibration (a JSON file's path or its dict) for the arm ``kind``.

    Raises:
        InvalidArgumentError: no such file, not JSON, motors missing or of another arm, a field
            missing or out of range, ids repeated or not the arm's.
    """
    if not isinstance(source, (dict, str, os.PathLike)):
        raise InvalidArgumentError(
            f"calibration must be a LeRobot calibration file or its dict, expected "
            f"{{motor: {{{', '.join(FIELDS)}}}}}, got {source!r:.80}"
        )
    where = "<dict>" if isinstance(source, dict) else os.fspath(source)
    if isinstance(source, dict):
        data: Any = source
    else:
        try:
            with open(where, encoding="utf-8") as f:
                data = json.load(f)
        except OSError as exc:
            raise InvalidArgumentError(
                f"calibration {where!r}: cannot read it ({exc.strerror or exc})"
            ) from exc
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise InvalidArgumentError(
                f"calibration {where!r}: not a LeRobot calibration (JSON) file ({exc})"
            ) from exc
    if not isinstance(data, dict):
        raise InvalidArgumentError(f"calibration {where!r}: expected {{motor: {{{', '.join(FIELDS)}}}}}")
    missing = [m for m in kind.motors if m not in data]
    if missing:
        raise InvalidArgumentError(
            f"calibration {where!r}: motors {', '.join(missing)} missing; a {kind.robot} has "
            f"{', '.join(kind.motors)} (the file has {', '.join(map(str, data)) or 'none'})"
        )
    extra = [str(m) for m in data if m not in kind.motors]
    if extra:
        raise InvalidArgumentError(
            f"calibration {where!r}: motors {', '.join(extra)} are not a {kind.robot}'s "
            f"({', '.join(kind.motors)}): the file of another arm?"
        )
    rows = []
    for motor in kind.motors:
        entry = data[motor]
        if not isinstance(entry, dict) or any(key not in entry for key in FIELDS):
            raise InvalidArgumentError(
                f"calibration {where!r}: {motor} needs {', '.join(FIELDS)}, got {entry!r:.120}"
            )
        values = []
        for key in FIELDS:
            v = entry[key]
            if isinstance(v, bool) or not isinstance(v, int):
                raise InvalidArgumentError(
                    f"calibration {where!r}: {motor}.{key} must be an integer, got {v!r:.40}"
                )
            values.append(v)
        servo, mode, offset, lo, hi = values
        if not (0 <= servo <= 253 and mode in (0, 1) and abs(offset) < 2048 and 0 <= lo < hi <= 4095):
            raise InvalidArgumentError(
                f"calibration {where!r}: {motor} = {entry!r:.160} is out of range "
                "(id 0-253, drive_mode 0 or 1, "
                "|homing_offset| < 2048, 0 <= range_min < range_max <= 4095)"
            )
        rows.append(values)
    arr = np.array(rows, dtype=np.int64)
    if len(set(arr[:, 0].tolist())) != len(kind.motors):
        raise InvalidArgumentError(f"calibration {where!r}: servo ids repeated: {arr[:, 0].tolist()}")
    return Calibration(arr[:, 0], arr[:, 1], arr[:, 2], arr[:, 3], arr[:, 4], where)
