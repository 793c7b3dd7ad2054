"""The Feetech STS3215 serial-bus protocol (protocol 0), as the servos and LeRobot's tables speak it.

A packet is ``0xFF 0xFF id length instruction params... checksum`` with ``length = len(params) + 2``
and ``checksum = ~(id + length + instruction + sum(params)) & 0xFF``. A servo answers with a status
packet ``0xFF 0xFF id length error params... checksum``. Words are little-endian. Broadcast id 0xFE
gets no answer, except SYNC_READ, which every listed servo answers in turn. Both the driver
(:mod:`gb_pin.hardware.bus`) and the emulated bus (:mod:`gb_pin.hardware.emulator`) use this module.
"""

from __future__ import annotations

from typing import NamedTuple

PING, READ, WRITE, SYNC_READ, SYNC_WRITE = 0x01, 0x02, 0x03, 0x82, 0x83
BROADCAST = 0xFE
MODEL_STS3215 = 777
RESOLUTION = 4096  # ticks per turn; LeRobot's degrees use 4095: (raw - mid) * 360 / 4095
MAX_TICK = 4095


class Register(NamedTuple):
    """A control-table entry: address, size in bytes, sign-magnitude bit (None: unsigned)."""

    address: int
    size: int
    sign_bit: int | None = None


# LeRobot's STS/SMS series table (the registers gb_pin uses).
MODEL_NUMBER = Register(3, 2)
ID = Register(5, 1)
MIN_POSITION_LIMIT = Register(9, 2)
MAX_POSITION_LIMIT = Register(11, 2)
HOMING_OFFSET = Register(31, 2, 11)
OPERATING_MODE = Register(33, 1)
TORQUE_ENABLE = Register(40, 1)
ACCELERATION = Register(41, 1)
GOAL_POSITION = Register(42, 2, 15)
GOAL_TIME = Register(44, 2)
GOAL_VELOCITY = Register(46, 2, 15)
LOCK = Register(55, 1)
PRESENT_POSITION = Register(56, 2, 15)
PRESENT_VELOCITY = Register(58, 2, 15)
MOVING = Register(66, 1)


def checksum(body: bytes | bytearray) -> int:
    """``~sum & 0xFF`` over id, length, instruction/error and parameters."""
    return ~sum(body) & 0xFF


def packet(servo: int, instruction: int, params: bytes | bytearray = b"") -> bytes:
    """An instruction (or, with ``instruction`` the error byte, a status) packet."""
    body = bytes((servo, len(params) + 2, instruction)) + bytes(params)
    return b"\xff\xff" + body + bytes((checksum(body),))


def encode(value: int, register: Register) -> bytes:
    """``value`` in the register's encoding (sign-magnitude where it has a sign bit), little-endian.

    Raises:
        ValueError: a value the register cannot hold.
    """
    raw = int(value)
    if register.sign_bit is not None:
        limit = 1 << register.sign_bit
        if abs(raw) >= limit:
            raise ValueError(f"{value} does not fit {register.sign_bit} bits of magnitude")
        raw = -raw | limit if raw < 0 else raw
    if not 0 <= raw < 1 << (8 * register.size):
        raise ValueError(f"{value} does not fit {register.size} byte(s)")
    return raw.to_bytes(register.size, "little")


def decode(data: bytes | bytearray, register: Register) -> int:
    """The value of a register's bytes (little-endian; sign-magnitude where it has a sign bit)."""
    raw = int.from_bytes(bytes(data[: register.size]), "little")
    if register.sign_bit is not None and raw & (1 << register.sign_bit):
        return -(raw & ((1 << register.sign_bit) - 1))
    return raw


class Status(NamedTuple):
    """A parsed status packet: servo id, error byte, parameters."""

    servo: int
    error: int
    params: bytes


def parse_status(buffer: bytes | bytearray) -> tuple[Status | None, int]:
    """The first complete packet in ``buffer`` and the bytes it used (leading garbage included).

    Returns ``(None, used)`` when no complete packet is there yet (``used`` bytes of garbage
    before a header can be dropped). A packet with a bad checksum is returned with error 0x100.
    """
    start = buffer.find(b"\xff\xff")
    while start >= 0 and start + 2 < len(buffer) and buffer[start + 2] == 0xFF:
        start += 1  # 0xFF 0xFF 0xFF: the header is the last two
    if start < 0:
        return None, max(0, len(buffer) - 1)
    if len(buffer) < start + 4:
        return None, start
    length = buffer[start + 3]
    end = start + 4 + length
    if length < 2 or len(buffer) < end:
        return (None, start + 2) if length < 2 else (None, start)
    body = bytes(buffer[start + 2 : end - 1])
    bad = checksum(body) != buffer[end - 1]
    return Status(body[0], 0x100 if bad else body[2], body[3:]), end
