"""The checker of an earlier revision against this one, alternated in one run (issue 34's speed-up).

The earlier ``gb_pin/safety/checker.py`` and its ``broadphase.py`` (``git show REV:...``; default
ba45acc: spheres in compiled code, 32 samples at a time; 438f5b7: bounding spheres in numpy per
posture) are loaded beside the current ones; each guards the same stepped session of
``scripts/bench_safety.py`` in turn, ``--repeat`` times; the best of each is shown, with the asks
cut and the postures checked (the same for both: the same answers).

    nice -n 10 python scripts/bench_safety_prefilter.py --movements 100 --repeat 3 --against 438f5b7 ba45acc
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


def _load(rev: str, name: str, source: str, replace: tuple[str, str] | None = None) -> Any:
    """``rev``'s file ``source`` as the module ``name`` (its import of ``replace[0]`` made ``replace[1]``)."""
    root = Path(__file__).resolve().parent.parent
    text = subprocess.run(["git", "show", f"{rev}:{source}"], cwd=root, check=True,
                          capture_output=True, text=True).stdout  # fmt: skip
    if replace is not None:
        text = text.replace(*replace)
    path = Path(tempfile.mkdtemp()) / f"{name}.py"
    path.write_text(text)
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def earlier_checker(rev: str) -> Any:
    """The CollisionChecker class of ``rev``'s gb_pin/safety/checker.py (with that revision's broadphase)."""
    try:
        _load(rev, f"earlier_broadphase_{rev}", "gb_pin/safety/broadphase.py")
    except subprocess.CalledProcessError:  # a revision before the compiled prefilter
        return _load(rev, f"earlier_checker_{rev}", "gb_pin/safety/checker.py").CollisionChecker
    replace = ("from gb_pin.safety.broadphase import", f"from earlier_broadphase_{rev} import")
    return _load(rev, f"earlier_checker_{rev}", "gb_pin/safety/checker.py", replace).CollisionChecker


def main() -> None:
    """Print one line per scene and checker."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--against", nargs="+", default=["ba45acc"])
    args = parser.parse_args()
    checkers = {rev: earlier_checker(rev) for rev in args.against}
    checkers["current"] = CollisionChecker
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
