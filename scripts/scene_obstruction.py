"""How obstructed an SO-101 scene is: the issue's two figures for a run without obstacles.

Issue 34 describes its SO-101 scene by what a session of 1000 movements without obstacles asks:
"25,000 postures: 2,834 (11 %) put the arm through the post and 62 below the table". This script
measures the same for our scenes (the preset's learner, the kinematic robot, no check): the asks
whose posture puts the arm's collision shapes (convex hulls) through the post, or into the table,
and those whose hand point alone is inside them. One JSON line per scene and seed::

    python scripts/scene_obstruction.py --scene so101 --seeds 0 1 2
    python scripts/scene_obstruction.py --scene so101-issue --half-widths 0.07 0.09 0.11 0.13 0.15 0.17
"""

from __future__ import annotations

import argparse
import json

import numpy as np

import gb_pin
from gb_pin.safety.checker import CollisionChecker
from gb_pin.safety.obstacles import Box, Table
from gb_pin.safety.scenarios import SCENES, Scene, so101_issue_scene


def obstruction(scene: Scene, movements: int = 1000, seed: int = 0) -> dict[str, int]:
    """Asks of a run without obstacles through the scene's post and table (shapes, hand point)."""
    post = next(o for o in scene.obstacles if isinstance(o, Box))
    table = next(o for o in scene.obstacles if isinstance(o, Table))
    target = gb_pin.load_robot(scene.robot)
    through_post = CollisionChecker(target, [post], clearance=1e-6)
    into_table = CollisionChecker(target, [table], clearance=1e-6)
    session = gb_pin.babble_session(scene.robot, movements=movements, seed=seed, targets=scene.goals)
    counts = {"asks": 0, "post": 0, "table": 0, "hand_in_post": 0, "hand_below_table": 0}
    while not session.done:
        q = session.ask()
        x = np.asarray(target.forward(q), dtype=float)
        counts["asks"] += 1
        counts["post"] += not through_post.is_safe(q)
        counts["table"] += not into_table.is_safe(q)
        counts["hand_in_post"] += bool(post.contains(x[None])[0])
        counts["hand_below_table"] += bool(x[2] < table.height)
        session.tell(x)
    return counts


def main() -> None:
    """Print one JSON line per scene (grid half-width) and seed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=["so101", "so101-issue"], default="so101-issue")
    parser.add_argument("--half-widths", type=float, nargs="+", default=[0.15],
                        help="so101-issue: the goal grid's half-width [m] around the post")  # fmt: skip
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--movements", type=int, default=1000)
    args = parser.parse_args()
    widths = args.half_widths if args.scene == "so101-issue" else [None]
    for width in widths:
        scene = SCENES[args.scene]() if width is None else so101_issue_scene(width)
        for seed in args.seeds:
            counts = obstruction(scene, args.movements, seed)
            share = round(100 * counts["post"] / counts["asks"], 1)
            row = {"scene": args.scene, "half_width": width, "seed": seed, "goals": len(scene.goals)}
            print(json.dumps({**row, **counts, "post_percent": share}), flush=True)


if __name__ == "__main__":
    main()
