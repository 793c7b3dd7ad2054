"""The cost of the ask/tell stepping per step: what a robot's controller pays to drive gb_pin.

    python scripts/bench_session.py                # planar5, so101, talos_left_arm; about a minute
    python scripts/bench_session.py --robots so101 --movements 2000 --rounds 5

For each robot, a session (``babble_session``) is driven by the robot's compiled forward kinematics
(``chain.forward``, whose own cost is timed apart and subtracted), and an external robot's session
(``ExternalRobot``, no model, ``evaluate="none"``) by the same readings. Printed: microseconds per
ask + tell (median and range over rounds), the forward call's cost, and babble()'s compiled loop per
step for comparison. A 1 kHz controller has 1000 us per step.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import gb_pin


def _drive(session: gb_pin.BabbleSession, forward) -> float:  # type: ignore[no-untyped-def]
    """Seconds of the loop; forward() is called inside it."""
    start = time.perf_counter()
    while not session.done:
        session.tell(forward(session.ask()))
    return time.perf_counter() - start


def measure(robot: str, movements: int, rounds: int) -> dict[str, list[float]]:
    """us per step of each way, ``rounds`` times."""
    target = gb_pin.load_robot(robot)
    external = gb_pin.ExternalRobot.from_preset(robot)
    forward = target.chain.forward
    out: dict[str, list[float]] = {"session": [], "external": [], "forward": [], "babble": []}
    gb_pin.babble(robot, movements=5, seed=0)  # compile and load
    for r in range(rounds):
        s = gb_pin.babble_session(robot, movements=movements, seed=r)
        wall = _drive(s, forward)
        steps = s.steps
        qs = np.array([target.home + 0.01 * i for i in range(1000)])
        start = time.perf_counter()
        for q in qs:
            forward(q)
        per_forward = (time.perf_counter() - start) / len(qs)
        out["forward"].append(1e6 * per_forward)
        out["session"].append(1e6 * (wall / steps - per_forward))
        e = gb_pin.babble_session(external, movements=movements, seed=r)
        wall = _drive(e, forward)
        out["external"].append(1e6 * (wall / e.steps - per_forward))
        result = gb_pin.babble(robot, movements=movements, seed=r)
        out["babble"].append(1e6 * result.wall_time / result.steps)
    return out


def main() -> None:
    """Print one line per robot and way."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--robots", default="planar5,so101,talos_left_arm")
    p.add_argument("--movements", type=int, default=1000)
    p.add_argument("--rounds", type=int, default=5)
    args = p.parse_args()
    head = ("ask + tell, session", "ask + tell, external robot", "forward", "babble() loop")
    print("| robot | " + " | ".join(f"{h} (us/step)" for h in head) + " |")
    print("|---|---|---|---|---|")
    for robot in args.robots.split(","):
        t = measure(robot, args.movements, args.rounds)
        cells = " | ".join(
            f"{statistics.median(v):.1f} ({min(v):.1f}-{max(v):.1f})"
            for v in (t["session"], t["external"], t["forward"], t["babble"])
        )
        print(f"| {robot} | {cells} |")


if __name__ == "__main__":
    main()
