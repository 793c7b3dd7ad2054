"""The checker of an earlier revision against this one, alternated in one run (issue 34's speed-up).

The earlier ``gb_pin/safety/checker.py`` (``git show REV:...``, default 438f5b7: bounding spheres in
numpy per posture) is loaded beside the current one; each guards the same stepped session of
``scripts/bench_safety.py`` in turn, ``--repeat`` times; the best of each is shown, with the asks
cut and the postures checked (the same for both: the same answers).

    nice -n 10 python scripts/bench_safety_prefilter.py --movements 200 --repeat 3
"""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import gb_pin
from gb_pin.safety.checker import CollisionChecker
from gb_pin.safety.scenarios import panda_scene, so101_scene

sys.path.insert(0, str(Path(__file__).parent))
from bench_safety import stepped


def earlier_checker(rev: str) -> Any:
    """The CollisionChecker class of ``rev``'s gb_pin/safety/checker.py."""
    root = Path(__file__).resolve().parent.parent
    text = subprocess.run(["git", "show", f"{rev}:gb_pin/safety/checker.py"], cwd=root, check=True,
                          capture_output=True, text=True).stdout  # fmt: skip
    path = Path(tempfile.mkdtemp()) / "earlier_checker.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location("earlier_checker", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.CollisionChecker


def main() -> None:
    """Print one line per scene and checker."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--against", default="438f5b7")
    args = parser.parse_args()
    checkers = {args.against: earlier_checker(args.against), "current": CollisionChecker}
    for scene in (so101_scene(), panda_scene()):
        target = gb_pin.load_robot(scene.robot)
        gb_pin.babble(target, movements=2, targets=scene.goals)  # compiled once
        plain, runs = [], {name: [] for name in checkers}  # type: ignore[var-annotated]
        for _ in range(args.repeat):
            plain.append(stepped(scene, args.movements, None)[0])
            for name, cls in checkers.items():
                checker = cls(target, scene.obstacles, self_collision=True)
                wall, inside = stepped(scene, args.movements, checker)
                runs[name].append((wall, inside, checker.asks, checker.checks, checker.cuts))
        for name, rows in runs.items():
            wall, inside = min(r[0] for r in rows), min(r[1] for r in rows)
            _, _, asks, checks, cuts = rows[0]
            print(
                f"{scene.robot} {name}: {asks} asks ({cuts} cut), {checks / asks:.2f} postures checked per "
                f"ask; stepped {min(plain):.2f} s, checked {wall:.2f} s ({wall / min(plain):.2f}x); check "
                f"{1e6 * inside / asks:.0f} us per ask, {1e6 * inside / checks:.1f} us per posture",
                flush=True,
            )


if __name__ == "__main__":
    main()
