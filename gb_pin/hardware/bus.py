"""The STS3215 bus over pyserial: every transaction checked, retried, counted; never a stale reading.

Written over pyserial rather than feetech-servo-sdk: the SDK's ``clearPort`` flushes only the
output, so after a timeout the late reply stays in the input buffer and the next read returns it
(a stale position that parses: the cause of the reference's "There is no status packet!" deaths
and of silently stale readings); its byte order is a process-wide global (``SCS_SETEND``); and its
receive loop cannot tell a reply to this request from one to the last.

Each transaction here: flush the input, write the request, read exactly the bytes the expected
replies take (one read with a deadline), and check each reply's header, id (in the order asked),
length and checksum. Any fault (timeout, wrong id, bad length or checksum) counts, and the
transaction is tried again after a back-off (``reply_timeout`` x 2, 4, 8 ..., at most 0.5 s) long enough for a
late reply to arrive and be flushed before the next request; a transaction that succeeded only on a
retry waits one more back-off and flushes what came meanwhile (the reply to its own last attempt,
when it read an earlier attempt's late one); after ``retries`` the bus gives up with a
:class:`~gb_pin.exceptions.HardwareError` naming the port and servo.
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Sequence

from gb_pin.exceptions import HardwareError
from gb_pin.hardware import protocol as p


class FeetechBus:
    """A serial port to STS3215 servos.

    Args:
        port: the device (``/dev/ttyACM0``, ``COM3``, a pty).
        baudrate: the bus's (LeRobot's arms: 1,000,000).
        reply_timeout: seconds to wait for the replies of one request (plus their transfer time).
        retries: attempts after the first before giving up.
        names: servo id -> name, for messages.

    Attributes:
        faults: counts of ``timeout``, ``wrong_id``, ``corrupt`` (header, length, checksum),
            ``status_error`` (a servo reported an error bit), ``retry``, ``extra_bytes`` and
            ``late_dropped`` (bytes that came after a recovered transaction, dropped).
        transactions: requests that got their replies.

    Raises:
        HardwareError: the port cannot be opened (pyserial missing, no such device, busy).
    """

    def __init__(
        self,
        port: str,
        baudrate: int = 1_000_000,
        *,
        reply_timeout: float = 0.02,
        retries: int = 8,
        names: dict[int, str] | None = None,
    ) -> None:
        self.port = str(port)
        self.reply_timeout = float(reply_timeout)
        self.retries = int(retries)
        self.names = dict(names or {})
        self.faults: Counter[str] = Counter()
        self.transactions = 0
        try:
            import serial
        except ImportError as exc:
            raise HardwareError(
                self.port, "pyserial is not installed: pip install 'gb_pin[hardware]'"
            ) from exc
        try:
            self.serial = serial.Serial(
                self.port, int(baudrate), timeout=self.reply_timeout, write_timeout=1.0
            )
        except (serial.SerialException, OSError, ValueError) as exc:
            raise HardwareError(self.port, f"cannot open the port ({exc})") from exc
        self.byte_time = 10.0 / int(baudrate)  # 8N1

    def label(self, servo: int) -> str:
        """``elbow_flex (id 3)``: a servo as messages name it."""
        name = self.names.get(servo)
        return f"{name} (id {servo})" if name else f"id {servo}"

    def close(self) -> None:
        """Close the port."""
        self.serial.close()

    # -- transactions ------------------------------------------------------------------------
    def _send(self, data: bytes) -> None:
        self.serial.reset_input_buffer()  # whatever came late belongs to an older request
        self.serial.write(data)

    def _receive(self, servos: Sequence[int], size: int) -> list[bytes] | int:
        """The parameters of one reply of ``size`` bytes from each servo in turn, or the first that failed."""
        total = (6 + size) * len(servos)
        self.serial.timeout = self.reply_timeout + total * self.byte_time
        data = self.serial.read(total)
        out = []
        for k, servo in enumerate(servos):
            chunk = data[k * (6 + size) : (k + 1) * (6 + size)]
            if len(chunk) < 6 + size:
                self.faults["timeout"] += 1
                return servo
            if chunk[:2] != b"\xff\xff" or chunk[3] != size + 2 or p.checksum(chunk[2:-1]) != chunk[-1]:
                self.faults["corrupt"] += 1
                return servo
            if chunk[2] != servo:
                self.faults["wrong_id"] += 1
                return servo
            if chunk[4]:
                self.faults["status_error"] += 1  # voltage, angle, overheat, overcurrent or overload
            out.append(bytes(chunk[5:-1]))
        if self.serial.in_waiting:  # more than the replies asked for: a late reply came first
            self.faults["extra_bytes"] += 1
            return servos[-1]
        return out

    def _transact(self, request: bytes, servos: Sequence[int], size: int, what: str) -> list[bytes]:
        failed = servos[0]
        for attempt in range(self.retries + 1):
            if attempt:
                self.faults["retry"] += 1
                time.sleep(
                    min(self.reply_timeout * 2**attempt, 0.5)
                )  # a late reply arrives now, and is flushed
            self._send(request)
            got = self._receive(servos, size)
            if not isinstance(got, int):
                self.transactions += 1
                if attempt:
                    self._let_late_replies_land(attempt)
                return got
            failed = got
        raise HardwareError(
            self.port, f"no valid reply to {what} after {self.retries + 1} attempts", self.label(failed)
        )

    def _let_late_replies_land(self, attempt: int) -> None:
        """After a transaction that needed ``attempt`` retries: wait a back-off, then drop what came.

        The reply just read may be a late one to an earlier attempt of the same request (the same
        register of the same servo: the right values, a few ms old); the reply to this attempt is
        then still on its way, and the next request's read would take it for its own (a reply of
        the same size from the same servo cannot be told from another). Measured before: under a
        load of 7 the fault test read a servo's range limits as each other's. Costs a back-off on
        the transactions that already failed once, nothing on the others.
        """
        time.sleep(min(self.reply_timeout * 2**attempt, 0.5))
        if self.serial.in_waiting:
            self.faults["late_dropped"] += 1
        self.serial.reset_input_buffer()

    # -- instructions ------------------------------------------------------------------------
    def ping(self, servo: int) -> None:
        """Check that ``servo`` answers (raises HardwareError if not)."""
        self._transact(p.packet(servo, p.PING), [servo], 0, "PING")

    def read(self, servo: int, register: p.Register) -> int:
        """One register of one servo."""
        request = p.packet(servo, p.READ, bytes((register.address, register.size)))
        (data,) = self._transact(request, [servo], register.size, f"READ of register {register.address}")
        return p.decode(data, register)

    def write(self, servo: int, register: p.Register, value: int) -> None:
        """One register of one servo, acknowledged."""
        params = bytes((register.address,)) + p.encode(value, register)
        self._transact(p.packet(servo, p.WRITE, params), [servo], 0, f"WRITE of register {register.address}")

    def sync_read(self, servos: Sequence[int], address: int, size: int) -> dict[int, bytes]:
        """``size`` bytes from ``address`` of each servo (one SYNC_READ; each answers in turn)."""
        request = p.packet(p.BROADCAST, p.SYNC_READ, bytes((address, size, *servos)))
        data = self._transact(request, list(servos), size, f"SYNC_READ of register {address}")
        return dict(zip(servos, data, strict=True))

    def sync_write(self, register: p.Register, values: dict[int, int]) -> None:
        """One register of several servos (one SYNC_WRITE; unacknowledged, verify by reading)."""
        params = bytearray((register.address, register.size))
        for servo, value in values.items():
            params += bytes((servo,)) + p.encode(value, register)
        self.serial.reset_input_buffer()
        self.serial.write(p.packet(p.BROADCAST, p.SYNC_WRITE, params))
