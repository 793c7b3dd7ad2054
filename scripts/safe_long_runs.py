"""Does the checked learner catch up with more movements? E^X along a long run, checked and not.

On the kinematic robot (the checked run steps through the session; the run without obstacles is the
compiled loop, the same run bit for bit as its session), E^X on the scene's goals at 10^3, 3 x 10^3,
5 x 10^3, 10^4, 2 x 10^4, 3 x 10^4 movements (those within ``--movements``):

    python scripts/safe_long_runs.py --robot panda --movements 30000 --seed 0          # --stop: no slide
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import gb_pin
from gb_pin.safety.scenarios import panda_scene, so101_scene

POINTS = (1000, 3000, 5000, 10000, 20000, 30000, 50000)


def main() -> None:
    """One checked run and its run without obstacles; one JSON line of their E^X [mm] at each point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="panda", choices=["so101", "panda"])
    parser.add_argument("--movements", type=int, default=30000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--stop", action="store_true", help="a cut ask stops at its last safe posture")
    args = parser.parse_args()
    scene = {"so101": so101_scene, "panda": panda_scene}[args.robot]()
    target = gb_pin.load_robot(args.robot)
    schedule = [m for m in POINTS if m <= args.movements]
    run = {"movements": args.movements, "seed": args.seed, "targets": scene.goals, "schedule": schedule}
    checks: dict[str, Any] = {"obstacles": scene.obstacles, "self_collision": True, "slide": not args.stop}
    session = gb_pin.babble_session(target, **run, **checks)
    start = time.perf_counter()
    while not session.done:
        session.tell(target.forward(session.ask()))
    wall = time.perf_counter() - start
    checked = session.result()
    free = gb_pin.babble(target, **run)
    print(json.dumps({
        "robot": args.robot, "seed": args.seed, "movements": [int(m) for m in checked.history.movements],
        "checked_mm": [round(1000 * float(e), 2) for e in checked.history.error],
        "without_obstacles_mm": [round(1000 * float(e), 2) for e in free.history.error],
        "asks_cut": session.cuts, "checked_wall_s": round(wall, 1), "slide": not args.stop,
    }))  # fmt: skip


if __name__ == "__main__":
    main()
