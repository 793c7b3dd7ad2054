"""What a checked run costs in the MuJoCo plant: its checks, and the contact detection that verifies them.

Three runs of a safety scene (gb_pin/safety/scenarios.py), same seed, alternated ``--rounds`` times:

- ``free``: no obstacles, nothing checked, contacts off (the run without obstacles of docs/SAFETY.md);
- ``checked``: every ask checked, the plant with contacts off (what the checks cost the learning);
- ``verified``: the same checked run in a plant with contacts on for the checker's pairs, counted at
  every simulation step (the acceptance runs' plant: the same run bit for bit while nothing touches).

    python scripts/mujoco_contact_cost.py --movements 300 --rounds 3

Prints each run's wall time [s], MuJoCo steps, asks cut and contacts, and the medians' ratios to ``free``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import gb_pin
from gb_pin.safety.scenarios import panda_scene, so101_scene
from gb_pin.sim import MujocoPlant


def one(robot: str, mode: str, movements: int, seed: int) -> tuple[float, int, int, int | None, float]:
    """(wall [s], MuJoCo steps, asks cut, contacts (None: not counted), E^X [m]) of one run in ``mode``."""
    scene = {"so101": so101_scene, "panda": panda_scene}[robot]()
    checks: dict[str, Any] = {"obstacles": scene.obstacles, "self_collision": True}
    plant = MujocoPlant(robot, kp=scene.kp, speed=scene.speed, **(checks if mode == "verified" else {}))
    session = gb_pin.babble_session(
        plant, movements=movements, seed=seed, targets=scene.goals, **(checks if mode != "free" else {})
    )
    start = time.perf_counter()
    while not session.done:
        session.tell(plant.forward(session.ask()))
    wall = time.perf_counter() - start
    contacts = plant.contacts if mode == "verified" else None
    return wall, plant.steps, session.cuts, contacts, float(session.result().history.error[-1])


def main() -> None:
    """Alternate the three runs and print their times."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", default="so101", choices=["so101", "panda"])
    parser.add_argument("--movements", type=int, default=300)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    walls: dict[str, list[float]] = {"free": [], "checked": [], "verified": []}
    for _ in range(args.rounds):
        for mode in walls:
            wall, steps, cuts, contacts, error = one(args.robot, mode, args.movements, args.seed)
            walls[mode].append(wall)
            line = f"{mode:9s} {wall:7.2f} s  MuJoCo steps {steps:8d}  cut {cuts:6d}  contacts {contacts}"
            print(f"{line}  E^X {1000 * error:.3f} mm", flush=True)
    free = statistics.median(walls["free"])
    for mode, times in walls.items():
        print(f"{mode}: median {statistics.median(times):.2f} s, {statistics.median(times) / free:.2f}x free")


if __name__ == "__main__":
    main()
