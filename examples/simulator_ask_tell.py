"""Goal babbling with a robot in another process: the ask/tell loop of ``gb_pin.babble_session``.

A stand-in for a simulator or a hardware driver runs in a child process and answers each
posture with the position the arm reached (here planar5's forward kinematics plus nothing
else; a real simulator would step its physics). The learner never calls the robot: it asks
for the next posture, sends it over the pipe, and tells the session what came back.

    python examples/simulator_ask_tell.py
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import time
from multiprocessing.connection import Connection

import numpy as np

import gb_pin


def simulator(conn: Connection) -> None:
    """The other process: receive a posture, reply with the reached tip position; None ends it."""
    lengths = np.full(5, 0.2)  # planar5: five 0.2 m links
    while (q := conn.recv()) is not None:
        angles = np.cumsum(q)
        conn.send(np.array([lengths @ np.cos(angles), lengths @ np.sin(angles)]))
    conn.close()


def main(movements: int = 1000) -> None:
    """Babble ``movements`` movements of planar5 through the pipe; print E^X and the cost per step."""
    ours, theirs = mp.Pipe()
    sim = mp.Process(target=simulator, args=(theirs,), daemon=True)
    sim.start()
    session = gb_pin.babble_session("planar5", movements=movements, seed=0)
    start = time.perf_counter()
    try:
        while not session.done:
            ours.send(session.ask())  # execute this posture ...
            session.tell(ours.recv())  # ... and learn from where the arm went
    finally:
        ours.send(None)
        sim.join(timeout=5)
    wall = time.perf_counter() - start
    result = session.result()
    print(f"planar5 through a pipe: E^X {result.history.error[0]:.4f} m -> {result.error:.4f} m "
          f"after {result.movements} movements")  # fmt: skip
    print(f"{1e6 * wall / result.steps:.1f} us per step (a round trip to the other process included)")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=1000, help="movements (default 1000)")
    main(parser.parse_args().movements)
