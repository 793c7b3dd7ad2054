"""Cost of safe babbling per ask (issue 34): the checker's time per checked ask, and whole runs.

On the kinematic robot (no physics), for each scene (gb_pin/safety/scenarios.py): babble() in compiled
code (no check), the same run stepped in Python (a session driven by the chain's forward kinematics, no
check), and checked (the scene's obstacles and self-collision; the guard's own time measured around
each call). The three alternate, ``--repeat`` times; the best of each is shown.

    nice -n 10 python scripts/bench_safety.py --movements 200 --repeat 3
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import gb_pin
from gb_pin.safety.checker import CollisionChecker
from gb_pin.safety.scenarios import panda_scene, so101_scene


def stepped(scene: Any, movements: int, checker: CollisionChecker | None) -> tuple[float, float]:
    """(wall time of a session stepped by the chain's forward kinematics, time inside the checker)."""
    target = gb_pin.load_robot(scene.robot)
    session = gb_pin.babble_session(target, movements=movements, seed=0, targets=scene.goals)
    inside = [0.0]
    if checker is not None:

        def guard(q_from: Any, q_to: Any) -> Any:
            t0 = time.perf_counter()
            out = checker(q_from, q_to)
            inside[0] += time.perf_counter() - t0
            return out

        session.guard = guard
        assert session.state is not None
        session._attach(session.state)
    start = time.perf_counter()
    while not session.done:
        session.tell(target.forward(session.ask()))
    return time.perf_counter() - start, inside[0]


def main() -> None:
    """Print one line per scene."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    for scene in (so101_scene(), panda_scene()):
        target = gb_pin.load_robot(scene.robot)
        gb_pin.babble(target, movements=2, targets=scene.goals)  # compiled once
        compiled, plain, checked, inside = [], [], [], []
        for _ in range(args.repeat):
            start = time.perf_counter()
            gb_pin.babble(target, movements=args.movements, seed=0, targets=scene.goals)
            compiled.append(time.perf_counter() - start)
            plain.append(stepped(scene, args.movements, None)[0])
            checker = CollisionChecker(target, scene.obstacles, self_collision=True)
            wall, guard = stepped(scene, args.movements, checker)
            checked.append(wall)
            inside.append(guard)
        asks = checker.asks
        best = min(inside)
        print(
            f"{scene.robot}: {args.movements} movements, {asks} asks ({checker.cuts} cut), "
            f"{checker.checks / asks:.2f} postures checked per ask; compiled {min(compiled):.2f} s, "
            f"stepped {min(plain):.2f} s, checked {min(checked):.2f} s ({min(checked) / min(plain):.2f}x "
            f"stepped, {min(checked) / min(compiled):.0f}x compiled); the check {1e6 * best / asks:.0f} us "
            f"per ask, {1e6 * best / checker.checks:.0f} us per posture",
            flush=True,
        )


if __name__ == "__main__":
    main()
