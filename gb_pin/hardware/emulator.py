"""An emulated STS3215 bus on a pseudo-terminal, with a mis-calibrated arm behind it, for tests.

``python -m gb_pin.hardware.emulator --robot so101 --seed 3`` opens a pty (the emulator owns the
master side), prints one JSON line ``{"port": SLAVE_PATH, "control": SOCKET, "authkey": HEX,
"calibration": {...}}`` and serves the bus until stdin closes (``--serve``: from a shell, until
Ctrl-C, printing the ``gb-pin babble --arm`` command that drives it). The driver opens ``port`` with
pyserial as it would ``/dev/ttyACM0``. What the bus does:

- protocol 0 (:mod:`gb_pin.hardware.protocol`): PING, READ, WRITE, SYNC_READ, SYNC_WRITE,
  broadcast; a register file per servo with LeRobot's addresses and encodings; model 777;
- servos that move at a finite speed (``--speed`` ticks/s, or Goal_Velocity when set) toward
  Goal_Position + Homing_Offset, clamped to Min/Max_Position_Limit; Present_Position = actual -
  Homing_Offset; Moving while away from the goal;
- the calibration a LeRobot user would have made (homing offsets, ranges; the servo registers
  already hold it), and a body behind it: a :class:`~gb_pin.robot.plant.Plant` whose joint zeros
  are off the calibration's middles by N(0, offset_std) and links by N(0, length_std), watched
  by a tracker with noise and losses (asked over the control socket: :meth:`Emulator.tracker`);
- faults drawn from the seed: dropped replies, late replies (sent ``late_delay`` seconds after
  the request, holding the values of the request's time), a servo that stops answering, a
  stalled servo (``Emulator.set``);
- a log of every goal written (servo, raw value, the servo's limits): ``Emulator.stats()``.

:class:`Emulator` starts it in its own process and talks to its control socket.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
import tty
from multiprocessing.connection import Client, Connection, Listener
from typing import Any

import numpy as np

from gb_pin.hardware import protocol as p
from gb_pin.hardware.arms import TICKS_PER_RAD, arm_kind

EEPROM_END = 40  # registers below are EEPROM (calibration): written only with Lock = 0


class Servo:
    """One STS3215: its register file and the shaft's actual position (ticks, float)."""

    def __init__(self, servo: int, actual: float, speed: float) -> None:
        self.regs = bytearray(256)
        self.id = servo
        self.actual = actual
        self.speed = speed
        self.time = time.monotonic()
        self.silent = False
        self.stalled = False
        self.put(p.MODEL_NUMBER, p.MODEL_STS3215)
        self.put(p.ID, servo)
        self.put(p.MAX_POSITION_LIMIT, p.MAX_TICK)
        self.put(p.LOCK, 1)

    def get(self, reg: p.Register) -> int:
        """A register's value."""
        return p.decode(self.regs[reg.address : reg.address + reg.size], reg)

    def put(self, reg: p.Register, value: int) -> None:
        """Set a register."""
        self.regs[reg.address : reg.address + reg.size] = p.encode(value, reg)

    def goal(self) -> float:
        """The actual position the servo drives to (the goal clamped to the position limits)."""
        lo, hi = self.get(p.MIN_POSITION_LIMIT), self.get(p.MAX_POSITION_LIMIT)
        return min(max(self.get(p.GOAL_POSITION), lo), hi) + self.get(p.HOMING_OFFSET)

    def update(self, now: float) -> None:
        """Move toward the goal at the servo's speed for the time since the last update."""
        dt, self.time = now - self.time, now
        if self.get(p.TORQUE_ENABLE) and not self.stalled:
            velocity = self.get(p.GOAL_VELOCITY)
            speed = self.speed if velocity <= 0 else min(self.speed, float(velocity))
            delta = self.goal() - self.actual
            self.actual += max(-speed * dt, min(speed * dt, delta))
        present = round(self.actual) - self.get(p.HOMING_OFFSET)
        self.put(p.PRESENT_POSITION, present)
        moving = self.get(p.TORQUE_ENABLE) and abs(self.goal() - self.actual) > 0.5
        self.put(p.MOVING, int(moving))


class Bus:
    """The servos, the body and the faults; ``handle`` answers one instruction packet."""

    def __init__(self, options: argparse.Namespace) -> None:
        from gb_pin.robot.plant import Plant

        self.kind = arm_kind(options.robot)
        self.rng = np.random.default_rng(np.random.SeedSequence(options.seed).spawn(3)[2])
        draw = np.random.default_rng(np.random.SeedSequence(options.seed).spawn(3)[1])
        self.options = options
        self.calibration: dict[str, dict[str, int]] = {}
        self.servos: dict[int, Servo] = {}
        for i, (name, servo) in enumerate(zip(self.kind.motors, self.kind.ids, strict=True)):
            half = (self.kind.upper[i] - self.kind.lower[i]) / 2 * (1 - 0.05 * draw.random())
            lo = 2047 - int(half * TICKS_PER_RAD)
            hi = 2047 + int(half * TICKS_PER_RAD)  # mid = 2047: the URDF's centre
            homing = int(draw.integers(-600, 600))
            start = 2047 + homing + int(draw.integers(-40, 40))  # near the middle, torque off
            s = Servo(servo, float(start), options.speed)
            s.put(p.HOMING_OFFSET, homing)
            s.put(p.MIN_POSITION_LIMIT, lo)
            s.put(p.MAX_POSITION_LIMIT, hi)
            s.put(p.GOAL_POSITION, start - homing)
            s.update(s.time)
            self.servos[servo] = s
            self.calibration[name] = {
                "id": servo, "drive_mode": 0, "homing_offset": homing, "range_min": lo, "range_max": hi,
            }  # fmt: skip
        self.plant = Plant(
            options.robot, offset_std=math.radians(options.offset_deg), length_std=options.length,
            noise=options.noise, loss=options.loss, seed=options.seed,
        )  # fmt: skip
        self.lock = threading.Lock()
        self.write_lock = threading.Lock()
        self.goals: list[tuple[int, int, int, int]] = []  # (servo, goal, min limit, max limit)
        self.faults = {"dropped": 0, "late": 0, "silent": 0, "corrupt": 0}
        self.requests = 0
        self.master = -1

    # -- the body ---------------------------------------------------------------------------
    def joints(self) -> np.ndarray:
        """The six joints' positions [rad of the URDF] the encoders stand at (actual, unrounded)."""
        now = time.monotonic()
        q = np.empty(6)
        for i, servo in enumerate(self.kind.ids):
            s = self.servos[servo]
            s.update(now)
            c = self.calibration[self.kind.motors[i]]
            mid = (c["range_min"] + c["range_max"]) / 2
            q[i] = self.kind.centre[i] + (s.actual - c["homing_offset"] - mid) / TICKS_PER_RAD
        return q

    def arm(self) -> np.ndarray:
        """The learned joints' true angles as the encoders give them (the plant adds its offsets)."""
        q = self.joints()
        return np.array([q[self.kind.motors.index(j)] for j in self.kind.learned])

    # -- the bus ----------------------------------------------------------------------------
    def send(self, data: bytes, delay: float = 0.0) -> None:
        """Write bytes to the bus (after ``delay`` seconds, from a timer thread)."""
        if delay > 0:
            timer = threading.Timer(delay, self.send, (data,))
            timer.daemon = True
            timer.start()
            return
        with self.write_lock:
            os.write(self.master, data)

    def reply(self, servo: int, params: bytes = b"") -> None:
        """A status packet, unless this reply is dropped (or sent late), as drawn from the seed."""
        s = self.servos[servo]
        if s.silent:
            self.faults["silent"] += 1
            return
        u = self.rng.random()
        if u < self.options.drop:
            self.faults["dropped"] += 1
            return
        late = u < self.options.drop + self.options.late
        if late:
            self.faults["late"] += 1
        self.send(p.packet(servo, 0, params), self.options.late_delay if late else 0.0)

    def handle(self, servo: int, instruction: int, params: bytes) -> None:
        """Execute one instruction packet."""
        self.requests += 1
        now = time.monotonic()
        for s in self.servos.values():
            s.update(now)
        if instruction == p.SYNC_WRITE and servo == p.BROADCAST and len(params) >= 2:
            address, size = params[0], params[1]
            for k in range(2, len(params) - size, size + 1):
                if params[k] in self.servos:
                    self.write(self.servos[params[k]], address, params[k + 1 : k + 1 + size])
        elif instruction == p.SYNC_READ and servo == p.BROADCAST and len(params) >= 2:
            address, size = params[0], params[1]
            for target in params[2:]:
                if target in self.servos:
                    self.reply(target, bytes(self.servos[target].regs[address : address + size]))
        elif servo in self.servos:
            s = self.servos[servo]
            if instruction == p.PING:
                self.reply(servo)
            elif instruction == p.READ and len(params) == 2:
                self.reply(servo, bytes(s.regs[params[0] : params[0] + params[1]]))
            elif instruction == p.WRITE and len(params) >= 2:
                self.write(s, params[0], params[1:])
                self.reply(servo)
        elif servo == p.BROADCAST and instruction == p.WRITE and len(params) >= 2:
            for s in self.servos.values():
                self.write(s, params[0], params[1:])

    def write(self, s: Servo, address: int, data: bytes) -> None:
        """Write a servo's registers (EEPROM only when unlocked); goal writes are logged."""
        if s.silent:
            return
        if address < EEPROM_END and s.get(p.LOCK):
            return  # EEPROM is locked
        if address <= p.GOAL_POSITION.address < address + len(data):
            s.regs[address : address + len(data)] = data
            lo, hi = s.get(p.MIN_POSITION_LIMIT), s.get(p.MAX_POSITION_LIMIT)
            self.goals.append((s.id, s.get(p.GOAL_POSITION), lo, hi))
        else:
            s.regs[address : address + len(data)] = data

    def serve(self, master: int, stop: threading.Event) -> None:
        """Answer packets from the master side of the pty until ``stop``."""
        self.master = master
        buffer = bytearray()
        while not stop.is_set():
            ready, _, _ = select.select([master], [], [], 0.05)
            if not ready:
                continue
            try:
                buffer += os.read(master, 4096)
            except OSError:  # no slave open right now
                time.sleep(0.01)
                continue
            while True:
                packet, used = p.parse_status(buffer)
                del buffer[:used]
                if packet is None:
                    break
                if packet.error == 0x100:
                    self.faults["corrupt"] += 1
                    continue
                with self.lock:
                    self.handle(packet.servo, packet.error, packet.params)

    # -- the control socket -----------------------------------------------------------------
    def control(self, message: tuple[Any, ...]) -> Any:
        """Answer a message of the control socket (tracker, truth, statistics, faults)."""
        with self.lock:
            what = message[0]
            if what == "hand":  # the tracker: the hand's position [m] (noisy), or None
                return self.plant.observe(self.arm())
            if what == "truth":
                q = self.arm()
                servos = self.servos.items()
                return {"joints": self.joints(), "arm": q, "hand": self.plant.forward(q),
                        "torque": {sid: s.get(p.TORQUE_ENABLE) for sid, s in servos},
                        "present": {sid: s.get(p.PRESENT_POSITION) for sid, s in servos}}  # fmt: skip
            if what == "stats":
                return {"goals": list(self.goals), "faults": dict(self.faults), "requests": self.requests}
            if what == "set":  # ("set", servo id, attribute, value): silent, stalled
                setattr(self.servos[message[1]], message[2], message[3])
                return True
            if what == "faults":  # ("faults", drop, late)
                self.options.drop, self.options.late = message[1], message[2]
                return True
            if what == "plant":
                return {"offsets": self.plant.calibration.offsets, "scales": self.plant.calibration.scales}
            raise ValueError(f"unknown control message {message!r}")


def _listen(bus: Bus, listener: Listener, stop: threading.Event) -> None:
    def serve(conn: Connection) -> None:
        with conn:
            while not stop.is_set():
                try:
                    message = conn.recv()
                except (EOFError, OSError):
                    return
                try:
                    conn.send(("ok", bus.control(message)))
                except Exception as exc:  # the caller sees it
                    conn.send(("error", repr(exc)))

    while not stop.is_set():
        try:
            conn = listener.accept()
        except OSError:
            return
        threading.Thread(target=serve, args=(conn,), daemon=True).start()


def options_parser() -> argparse.ArgumentParser:
    """The emulator's command-line options."""
    a = argparse.ArgumentParser(
        prog="python -m gb_pin.hardware.emulator", description=__doc__.splitlines()[0]
    )
    a.add_argument("--robot", default="so101", choices=("so101", "so100"))
    a.add_argument("--seed", type=int, default=0, help="calibration, body, tracker and faults")
    a.add_argument(
        "--speed", type=float, default=20000.0, help="servo speed [ticks/s] (STS3215 at 12 V: ~3400)"
    )
    a.add_argument("--offset-deg", type=float, default=3.0, help="joint zeros off the calibration, std [deg]")
    a.add_argument("--length", type=float, default=0.03, help="link lengths off the URDF, relative std")
    a.add_argument("--noise", type=float, default=0.0015, help="tracker noise per axis [m]")
    a.add_argument("--loss", type=float, default=0.1, help="probability that the tracker loses the hand")
    a.add_argument("--drop", type=float, default=0.0, help="probability that a reply is dropped")
    a.add_argument("--late", type=float, default=0.0, help="probability that a reply comes late")
    a.add_argument("--calibration-out", default=None, help="write the arm's LeRobot calibration file here")
    a.add_argument(
        "--serve", action="store_true", help="from a shell: print how to connect, serve until Ctrl-C"
    )
    a.add_argument("--late-delay", type=float, default=0.03, help="how late [s] (FeetechArm waits 0.02 s)")
    return a


def main(argv: list[str] | None = None) -> int:
    """Serve an emulated bus until stdin closes (the parent process ended)."""
    options = options_parser().parse_args(argv)
    bus = Bus(options)
    master, slave = os.openpty()
    tty.setraw(slave)
    stop = threading.Event()
    folder = tempfile.mkdtemp(prefix="gb_pin_bus_")
    authkey = os.urandom(16)
    listener = Listener(os.path.join(folder, "control"), family="AF_UNIX", authkey=authkey)
    threading.Thread(target=_listen, args=(bus, listener, stop), daemon=True).start()
    threading.Thread(target=bus.serve, args=(master, stop), daemon=True).start()
    info = {"port": os.ttyname(slave), "control": listener.address, "authkey": authkey.hex()}
    if options.calibration_out:
        with open(options.calibration_out, "w", encoding="utf-8") as f:
            json.dump(bus.calibration, f, indent=1)
    if options.serve:  # from a shell: say how to use it, serve until Ctrl-C
        print(f"emulated {options.robot} bus on {info['port']} (Ctrl-C ends it); in another shell:\n"
              f"export {ENVIRONMENT}='{json.dumps({k: info[k] for k in ('control', 'authkey')})}'\n"
              f"gb-pin babble --robot {options.robot} --arm feetech:port={info['port']},calibration="
              f"{options.calibration_out or 'FILE'} --tracker gb_pin.hardware.emulator:tracker "
              "--movements 300",
              flush=True)  # fmt: skip
        signal.signal(signal.SIGTERM, lambda *_: stop.set())
        with contextlib.suppress(KeyboardInterrupt):
            while not stop.wait(0.2):
                pass
    else:
        print(json.dumps({**info, "calibration": bus.calibration, "pid": os.getpid()}), flush=True)
        with contextlib.suppress(KeyboardInterrupt):
            sys.stdin.read()  # until the parent closes our stdin (or dies)
    stop.set()
    listener.close()
    os.close(slave)
    return 0


class Emulator:
    """An emulated bus in its own process: ``with Emulator(seed=3) as bus: FeetechArm(bus.port, ...)``.

    Keyword arguments are the command line's options (``speed=``, ``drop=``, ``late=``, ...).
    Attributes: ``port`` (the pty to open), ``calibration`` (the LeRobot calibration dict).
    """

    def __init__(self, **options: Any) -> None:
        argv = [sys.executable, "-m", "gb_pin.hardware.emulator"]
        for key, value in options.items():
            argv += [f"--{key.replace('_', '-')}", str(value)]
        self.process = subprocess.Popen(argv, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        assert self.process.stdout is not None
        line = self.process.stdout.readline()
        if not line:
            self.process.wait()
            raise RuntimeError(f"the emulator did not start ({' '.join(argv)})")
        info = json.loads(line)
        self.control = {"control": info["control"], "authkey": info["authkey"]}
        self.port: str = info["port"]
        self.calibration: dict[str, dict[str, int]] = info["calibration"]
        self._conn = Client(info["control"], family="AF_UNIX", authkey=bytes.fromhex(info["authkey"]))
        self._lock = threading.Lock()

    def ask(self, *message: Any) -> Any:
        """Send a control message, return the answer."""
        with self._lock:
            self._conn.send(message)
            status, value = self._conn.recv()
        if status != "ok":
            raise RuntimeError(value)
        return value

    def tracker(self) -> np.ndarray | None:
        """The tracker's reading of the hand [m] (noise and losses as configured), or None."""
        return self.ask("hand")

    def truth(self) -> dict[str, Any]:
        """What only the emulator knows: joints, true hand, torque and present registers."""
        return self.ask("truth")

    def stats(self) -> dict[str, Any]:
        """Every goal written (servo, value, min limit, max limit), faults injected, requests."""
        return self.ask("stats")

    def environment(self) -> dict[str, str]:
        """The environment variable pointing :func:`tracker` at this bus."""
        return {ENVIRONMENT: json.dumps(self.control)}

    def set(self, servo: int, attribute: str, value: Any) -> None:
        """A servo fault: ``set(3, "silent", True)`` (stops answering), ``set(2, "stalled", True)``."""
        self.ask("set", servo, attribute, value)

    def close(self) -> None:
        """End the emulator's process."""
        if self.process.poll() is None:
            self._conn.close()
            assert self.process.stdin is not None
            self.process.stdin.close()
            try:
                self.process.wait(5)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        if self.process.stdout is not None:
            self.process.stdout.close()

    def __enter__(self) -> Emulator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


ENVIRONMENT = "GB_PIN_EMULATOR"
_TRACKER: list[Connection] = []


def tracker() -> np.ndarray | None:
    """The emulated tracker of the bus that ``$GB_PIN_EMULATOR`` names (``Emulator.environment()``).

    For ``gb-pin babble --arm feetech:port=PTY,... --tracker gb_pin.hardware.emulator:tracker``.
    """
    if not _TRACKER:
        info = json.loads(os.environ[ENVIRONMENT])
        _TRACKER.append(Client(info["control"], family="AF_UNIX", authkey=bytes.fromhex(info["authkey"])))
    conn = _TRACKER[0]
    conn.send(("hand",))
    status, value = conn.recv()
    if status != "ok":
        raise RuntimeError(value)
    return value


if __name__ == "__main__":
    raise SystemExit(main())
