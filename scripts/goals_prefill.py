"""Fill the trial cache of ``gb-pin reproduce goals`` in the order of issue 11's acceptance checks."""

import argparse
import time
import warnings

from gb_pin.reproduce.goals import ROBOTS, run_condition, study_conditions

FIRST = [
    ("planar5", "directions"),
    ("planar5", "uniform on O"),
    ("planar5", "progress on O"),
    ("planar20", "uniform on X*"),
    ("planar20", "motor"),
    ("talos_left_arm", "uniform on X*"),
    ("g1_left_arm", "uniform on X*"),
    ("g1_left_arm", "directions"),
    ("talos_left_arm", "directions"),
]

if __name__ == "__main__":
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", default="docs/figures/goals")
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--movements", type=int, default=10_000)
    p.add_argument("--workers", type=int, default=2)
    a = p.parse_args()
    warnings.simplefilter("ignore")
    todo = {(r, lab): (c, own) for r in ROBOTS for lab, c, own in study_conditions(r, a.movements)}
    order = FIRST + [k for k in todo if k not in FIRST]
    for key in order:
        cond, own = todo[key]
        t0 = time.perf_counter()
        ts = run_condition(a.out, key[1], cond, own or a.trials, 0, a.workers, False)
        print(key, f"{time.perf_counter() - t0:.0f} s", flush=True)
