"""Safe babbling measured (issue 34): contacts in MuJoCo (contacts on), asks cut, reach error, wall time.

For each scene (gb_pin/safety/scenarios.py) and seed: a checked run in the MuJoCo plant with contacts
on (the checker's shapes, obstacles and pairs) and, as the baseline, the same plant without obstacles
(contacts off, nothing checked). Every posture the checked run sends is checked again by an
independent checker with no margin (an "unsafe ask sent" is one that touches there).

    nice -n 10 python scripts/safe_babbling.py --movements 1000 --seeds 0 1 2 --json out.json
"""

from __future__ import annotations

import argparse
import json
import time
from typing import Any

import numpy as np

import gb_pin
from gb_pin.safety.checker import CollisionChecker
from gb_pin.safety.scenarios import panda_scene, so101_scene
from gb_pin.sim import MujocoPlant


class KinematicPlant:
    """The kinematic robot as a plant (forward kinematics, counted asks), for runs without physics."""

    def __init__(self, robot: str) -> None:
        self.target = gb_pin.load_robot(robot)
        self.asks = 0

    def forward(self, q: Any) -> Any:
        """The hand's position at ``q`` [m]."""
        self.asks += 1
        return self.target.forward(q)


def run(scene, seed: int, movements: int, checked: bool, kinematic: bool = False) -> dict:  # type: ignore[no-untyped-def]
    """One run of a scene in the MuJoCo plant: checked (contacts on) or the baseline; its figures.

    ``kinematic``: on the kinematic robot instead (no physics, no contacts counted).
    """
    options = {"obstacles": scene.obstacles, "self_collision": True} if checked else {}
    plant: Any = (
        KinematicPlant(scene.robot) if kinematic else MujocoPlant(scene.robot, kp=scene.kp, **options)
    )
    robot = plant.target if kinematic else plant
    session = gb_pin.babble_session(robot, movements=movements, seed=seed, targets=scene.goals, **options)
    independent = None
    if checked:
        matrix = session.guard.matrix  # type: ignore[union-attr]
        independent = CollisionChecker(plant.target, scene.obstacles, self_collision=True, clearance=1e-6,
                                       matrix=matrix)  # fmt: skip
    unsafe = 0
    extra = 0.0  # the independent check's time, not counted in the run's wall time
    start = time.perf_counter()
    while not session.done:
        q = session.ask()
        if independent is not None:
            t0 = time.perf_counter()
            unsafe += not independent.is_safe(q)
            extra += time.perf_counter() - t0
        session.tell(plant.forward(q))
    wall = time.perf_counter() - start - extra
    result = session.result()
    return {
        "robot": scene.robot, "seed": seed, "movements": movements, "checked": checked,
        "error_mm": 1000 * float(result.history.error[-1]),
        "reach_mm": 1000 * float(result.history.reach[-1]),
        "asks": int(plant.asks), "cut": int(session.cuts), "unsafe_sent": unsafe,
        "contacts": int(plant.contacts) if checked and not kinematic else None, "wall_s": wall,
        "checks": None if not checked else int(session.guard.checks),  # type: ignore[union-attr]
    }  # fmt: skip


def main() -> None:
    """Run the scenes and seeds, printing one JSON line per run and a summary per robot."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=1000)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--robots", nargs="+", default=["so101", "panda"])
    parser.add_argument("--json", default=None)
    parser.add_argument("--kinematic", action="store_true", help="on the kinematic robot (no physics)")
    args = parser.parse_args()
    scenes = {"so101": so101_scene, "panda": panda_scene}
    rows = []
    for robot in args.robots:
        scene = scenes[robot]()
        for seed in args.seeds:
            for checked in (True, False):
                row = run(scene, seed, args.movements, checked, args.kinematic)
                rows.append(row)
                print(json.dumps(row), flush=True)
                if args.json:
                    with open(args.json, "w") as f:
                        json.dump(rows, f, indent=1)
    for robot in args.robots:
        on = [r for r in rows if r["robot"] == robot and r["checked"]]
        off = [r for r in rows if r["robot"] == robot and not r["checked"]]
        e_on, e_off = np.median([r["error_mm"] for r in on]), np.median([r["error_mm"] for r in off])
        total = {
            key: sum(r[key] or 0 for r in on) for key in ("contacts", "unsafe_sent", "cut", "asks", "wall_s")
        }
        print(
            f"{robot}: {len(on)} seeds x {args.movements} movements; contacts {total['contacts']}, "
            f"unsafe asks sent {total['unsafe_sent']}, cut {total['cut']} of {total['asks']} asks; "
            f"E^X {e_on:.2f} mm checked vs {e_off:.2f} mm without obstacles ({e_on / e_off:.2f}x); "
            f"wall {total['wall_s']:.0f} s vs {sum(r['wall_s'] for r in off):.0f} s"
        )


if __name__ == "__main__":
    main()
