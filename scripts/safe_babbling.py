"""Safe babbling measured (issue 34): contacts in MuJoCo (contacts on), asks cut, reach error, wall time.

For each scene (gb_pin/safety/scenarios.py) and seed: a checked run in the MuJoCo plant with contacts
on (the checker's shapes, obstacles and pairs) and, as the baseline, the same plant without obstacles
(contacts off, nothing checked). Every posture the checked run sends is checked again by an
independent checker with no margin (an "unsafe ask sent" is one that touches there).

    nice -n 10 python scripts/safe_babbling.py --movements 1000 --seeds 0 1 2 --json out.json

The reach error is measured twice on the learned inverse g, on the plant's resting arm (or the
kinematic robot): ``error_mm``, E^X over all the scene's goals (the run's own history), and
``safe_error_mm``, the mean error over the goals a safe posture can reach (``safe_goals``: an IK
search from 400 restarts finds a posture within 1 mm of the goal that keeps the clearance). The
second compares like with like: a goal only an arm through the table or the post reaches (1 cm above
the table at the far end of the SO-101's goals) counts for neither run.

``--cache DIR`` keeps each run's figures in DIR (one JSON file per run) and skips the runs already
there, so that a long sequence (the acceptance's 10^4 movements x 5 seeds) can be stopped and
started again. On the kinematic robot (``--kinematic``) the baseline is ``gb_pin.babble`` (compiled:
the same run as the stepped session, bit for bit, in a fraction of the time).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from typing import Any

import numpy as np

import gb_pin
from gb_pin.ik import solve
from gb_pin.safety.checker import CollisionChecker
from gb_pin.safety.scenarios import SCENES
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


_SAFE: dict[str, np.ndarray] = {}
_CACHE: list[str] = []  # the --cache folder, where the safe goals are kept too


def safe_goals(scene) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Which of the scene's goals some safe posture reaches (within 1 mm, keeping the 1 cm clearance)."""
    key = f"{scene.robot}_{len(scene.goals)}"
    if key in _SAFE:
        return _SAFE[key]
    stored = os.path.join(_CACHE[0], f"{key}_safe_goals.json") if _CACHE else None
    if stored and os.path.exists(stored):
        with open(stored) as f:
            mask = np.array(json.load(f), dtype=bool)
        if len(mask) == len(scene.goals):
            _SAFE[key] = mask
            return mask
    target = gb_pin.load_robot(scene.robot)
    checker = CollisionChecker(target, scene.obstacles, self_collision=True)
    found = solve(target, scene.goals, seed="middle", solutions=16, max_restarts=400, tol=1e-3, rng=0)
    postures = found.postures.reshape(len(scene.goals), -1, target.n_joints)
    mask = np.array([any(np.isfinite(q).all() and checker.is_safe(q) for q in P) for P in postures])
    _SAFE[key] = mask
    if stored and len(mask) == len(scene.goals) and not os.path.exists(stored):
        with open(stored, "w") as f:
            json.dump(mask.tolist(), f)
    return mask


def per_goal(result, forward, scene) -> dict:  # type: ignore[no-untyped-def]
    """Each goal's error [mm] of the learned inverse and whether its posture keeps the clearance."""
    target = gb_pin.load_robot(scene.robot)
    checker = CollisionChecker(target, scene.obstacles, self_collision=True)
    Q = np.clip(result.model.predict(scene.goals), target.lower, target.upper)
    errors = 1000 * np.linalg.norm(np.asarray(forward(Q)) - scene.goals, axis=1)
    return {"goal_error_mm": errors.tolist(), "goal_posture_safe": [checker.is_safe(q) for q in Q]}


def shared_error(on: dict, off: dict) -> tuple[float, float, int]:
    """(checked, unobstructed) mean error [mm] over the goals the unobstructed run reaches safely, count."""
    keep = np.array(off["goal_posture_safe"])
    e_on, e_off = np.array(on["goal_error_mm"]), np.array(off["goal_error_mm"])
    return float(e_on[keep].mean()), float(e_off[keep].mean()), int(keep.sum())


def reach_mm(result) -> float | None:  # type: ignore[no-untyped-def]
    """The run's last reach error [mm] (None: no goal-directed movement ended observed)."""
    reach = result.history.reach
    return None if reach is None else 1000 * float(reach[-1])


def safe_error(result, forward, scene) -> float:  # type: ignore[no-untyped-def]
    """The learned inverse's mean error [mm] over the safely reachable goals (``forward``: the arm)."""
    target = gb_pin.load_robot(scene.robot)
    X = scene.goals[safe_goals(scene)]
    Q = np.clip(result.model.predict(X), target.lower, target.upper)
    return 1000 * float(np.mean(np.linalg.norm(np.asarray(forward(Q)) - X, axis=1)))


def run(
    scene: Any,
    seed: int,
    movements: int,
    checked: bool,
    kinematic: bool = False,
    contacts: bool = True,
    slide: bool = True,
) -> dict:
    """One run of a scene in the MuJoCo plant: checked (contacts on) or the baseline; its figures.

    ``kinematic``: on the kinematic robot instead (no physics, no contacts counted). ``contacts``
    False: the checked run in the baseline's plant (contacts off, none counted): what the checks
    cost the learning, without MuJoCo's collision detection that verifies them. ``slide`` False: a
    cut ask stops at the last safe posture of its move (``babble_session(..., slide=False)``).
    """
    if kinematic and not checked:
        target = gb_pin.load_robot(scene.robot)
        start = time.perf_counter()  # the preset by name: its learner settings (radius 0.04 m on the SO-101)
        result = gb_pin.babble(scene.robot, movements=movements, seed=seed, targets=scene.goals)
        wall = time.perf_counter() - start
        return {
            "robot": scene.robot, "seed": seed, "movements": movements, "checked": False,
            "error_mm": 1000 * float(result.history.error[-1]),
            "safe_error_mm": safe_error(result, target.forward, scene),
            **per_goal(result, target.forward, scene),
            "reach_mm": reach_mm(result), "asks": int(result.steps), "cut": 0,
            "unsafe_sent": None, "contacts": None, "wall_s": wall, "checks": None,
        }  # fmt: skip
    options = {"obstacles": scene.obstacles, "self_collision": True} if checked else {}
    plant: Any = (
        KinematicPlant(scene.robot)
        if kinematic
        else MujocoPlant(scene.robot, kp=scene.kp, speed=scene.speed, **(options if contacts else {}))
    )
    robot = scene.robot if kinematic else plant  # the preset by name, or its plant: the preset's learner
    checks = {**options, "slide": slide} if checked else {}
    session = gb_pin.babble_session(robot, movements=movements, seed=seed, targets=scene.goals, **checks)
    independent = None
    if checked:
        matrix = session.guard.matrix
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
        "safe_error_mm": safe_error(result, plant.target.forward if kinematic else plant.true_forward, scene),
        **per_goal(result, plant.target.forward if kinematic else plant.true_forward, scene),
        "reach_mm": reach_mm(result),
        "asks": int(plant.asks), "cut": int(session.cuts), "unsafe_sent": unsafe,
        "contacts": int(plant.contacts) if checked and not kinematic and contacts else None,
        "wall_s": wall, "contacts_on": checked and not kinematic and contacts,
        "contact_pairs": None if not checked or kinematic or not contacts else
            [[a, b, steps, deepest] for (a, b), (steps, deepest) in plant.contact_pairs.items()],
        "checks": None if not checked else int(session.guard.checks),
        "slide": slide,
    }  # fmt: skip


def main() -> None:
    """Run the scenes and seeds, printing one JSON line per run and a summary per robot."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=1000)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--robots", nargs="+", choices=sorted(SCENES), default=["so101", "panda"])
    parser.add_argument("--json", default=None)
    parser.add_argument("--kinematic", action="store_true", help="on the kinematic robot (no physics)")
    parser.add_argument("--cache", default=None, help="a folder: one JSON file per run, runs there skipped")
    parser.add_argument(
        "--no-contacts",
        action="store_true",
        help="the checked run in the baseline's plant, contacts off: the checks' own cost",
    )
    parser.add_argument("--stop", action="store_true", help="a cut ask stops at its last safe posture")
    parser.add_argument("--reachable-goals", action="store_true",
                        help="babble (both runs) toward the goals a safe posture reaches only")  # fmt: skip
    args = parser.parse_args()
    if args.cache:
        os.makedirs(args.cache, exist_ok=True)
        _CACHE.append(args.cache)
    rows = []
    for robot in args.robots:
        scene = SCENES[robot]()
        if args.reachable_goals:
            scene = scene._replace(goals=scene.goals[safe_goals(scene)])
            _SAFE[f"{scene.robot}_{len(scene.goals)}"] = np.ones(len(scene.goals), dtype=bool)
        for seed in args.seeds:
            for checked in (True, False):
                kind = "kinematic" if args.kinematic else "mujoco"
                if checked and args.no_contacts and not args.kinematic:
                    kind = "mujoco_nocontacts"
                if checked and args.stop:
                    kind += "_stop"
                goals = "_reachable" if args.reachable_goals else ""
                name = (
                    f"{robot}{goals}_{kind}_{args.movements}_{seed}_{'checked' if checked else 'free'}.json"
                )
                cached = os.path.join(args.cache, name) if args.cache else None
                if cached and os.path.exists(cached):
                    with open(cached) as f:
                        row = json.load(f)
                else:
                    contacts, slide = not args.no_contacts, not args.stop
                    row = run(scene, seed, args.movements, checked, args.kinematic, contacts, slide)
                    if cached:
                        with open(cached + ".tmp", "w") as f:
                            json.dump(row, f)
                        os.replace(cached + ".tmp", cached)
                rows.append({**row, "scene": robot})
                print(json.dumps(row), flush=True)
                if args.json:
                    with open(args.json, "w") as f:
                        json.dump(rows, f, indent=1)
    for robot in args.robots:
        on = [r for r in rows if r["scene"] == robot and r["checked"]]
        off = [r for r in rows if r["scene"] == robot and not r["checked"]]
        e_on, e_off = np.median([r["error_mm"] for r in on]), np.median([r["error_mm"] for r in off])
        s_on, s_off = (
            np.median([r["safe_error_mm"] for r in on]),
            np.median([r["safe_error_mm"] for r in off]),
        )
        shared = [shared_error(a, b) for a, b in zip(on, off, strict=True) if "goal_error_mm" in a]
        if shared:
            ratios = [a / b for a, b, _ in shared]
            counts = [n for *_, n in shared]
            print(f"{robot}: on the goals the unobstructed run reaches safely ({counts} per seed): checked / "
                  f"unobstructed {np.round(ratios, 2).tolist()}, median {np.median(ratios):.2f}")  # fmt: skip
        total = {
            key: sum(r[key] or 0 for r in on) for key in ("contacts", "unsafe_sent", "cut", "asks", "wall_s")
        }
        print(
            f"{robot}: {len(on)} seeds x {args.movements} movements; contacts {total['contacts']}, "
            f"unsafe asks sent {total['unsafe_sent']}, cut {total['cut']} of {total['asks']} asks; "
            f"E^X {e_on:.2f} mm checked vs {e_off:.2f} mm without obstacles ({e_on / e_off:.2f}x), on the "
            f"safely reachable goals {s_on:.2f} vs {s_off:.2f} mm ({s_on / s_off:.2f}x); "
            f"wall {total['wall_s']:.0f} s vs {sum(r['wall_s'] for r in off):.0f} s"
        )


if __name__ == "__main__":
    main()
