"""Record the behaviour fingerprint of fixed-seed runs (tests/test_fingerprint.py compares with it).

The fingerprint is what a run's user sees: E^X and D^home histories, the number of prototypes,
the learned map's arrays, predictions at the targets and off them, and a recording. Regenerate it
only on purpose (a change of behaviour an issue asks for), and say why in the commit:

    python scripts/fingerprint.py --out tests/data/fingerprint.npz

``--check`` compares the current code with the stored file instead (exit 1 on any difference).
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

import numpy as np

import gb_pin

# (name, babble keyword arguments). Short runs (CI-sized), every path of the loop covered:
# presets of 2-D and 3-D task spaces, joint limits (panda, talos), a Generator seed, given
# targets with a separate evaluation set, recording, and every hyperparameter off its default.
RUNS: dict[str, dict[str, Any]] = {
    "planar5": {"robot": "planar5", "movements": 400, "seed": 0},
    "planar7": {"robot": "planar7", "movements": 300, "seed": 1},
    "planar20": {"robot": "planar20", "movements": 300, "seed": 2},
    "planar50": {"robot": "planar50", "movements": 200, "seed": 3},
    "talos_left_arm": {"robot": "talos_left_arm", "movements": 300, "seed": 4},
    "panda": {"robot": "panda", "movements": 300, "seed": 5},
    "planar7_all_params": {
        "robot": "planar7",
        "movements": 300,
        "seed": 6,
        "learning_rate": 0.3,
        "sigma": 0.03,
        "sigma_delta": 0.01,
        "radius": 0.15,
        "path_length": 15,
        "p_home": 0.2,
    },
    "planar5_eval_record": {
        "robot": "planar5",
        "movements": 150,
        "seed": 7,
        "targets": [[0.5, 0.0], [0.6, 0.2], [0.4, -0.2], [0.7, -0.1]],
        "eval_targets": [[0.45, 0.05], [0.55, -0.15], [0.65, 0.1]],
        "record": gb_pin.Recording(every=3, first=10, last=40),
    },
}


def _probe_points(targets: np.ndarray) -> np.ndarray:
    """Points off the target set (fixed, from the targets themselves): between and beyond them."""
    centre = targets.mean(axis=0)
    return np.concatenate([0.5 * (targets + centre), centre + 1.1 * (targets - centre)])


def fingerprint() -> dict[str, np.ndarray]:
    """The fingerprint arrays of every run in RUNS."""
    out: dict[str, np.ndarray] = {}
    for name, kwargs in RUNS.items():
        args = dict(kwargs)
        if name == "planar5_eval_record":
            args["seed"] = np.random.default_rng(args["seed"])
        res = gb_pin.babble(**args)
        h = res.history
        out[f"{name}/movements"] = h.movements
        out[f"{name}/error"] = h.error
        out[f"{name}/home_distance"] = h.home_distance
        out[f"{name}/prototypes"] = res.model.prototypes_
        out[f"{name}/matrices"] = res.model.matrices_
        out[f"{name}/offsets"] = res.model.offsets_
        out[f"{name}/predict_targets"] = res.inverse(res.targets)
        out[f"{name}/predict_probe"] = res.inverse(_probe_points(res.targets))
        out[f"{name}/steps"] = np.array(res.steps)
        if res.recording is not None:
            rec = res.recording
            for key in ("step", "movement", "posture", "target", "position"):
                out[f"{name}/rec_{key}"] = getattr(rec, key)
    return out


def compare(stored: dict[str, np.ndarray], now: dict[str, np.ndarray]) -> list[str]:
    """Names of the arrays that differ (bit for bit, NaNs equal) or are missing on either side."""
    bad = sorted(set(stored) ^ set(now))
    for key in sorted(set(stored) & set(now)):
        a, b = stored[key], now[key]
        if a.shape != b.shape or a.dtype != b.dtype or not np.array_equal(a, b, equal_nan=True):
            bad.append(key)
    return bad


def main(argv: list[str] | None = None) -> int:
    """Write or check the fingerprint file."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="tests/data/fingerprint.npz")
    parser.add_argument("--check", action="store_true", help="compare with --out instead of writing")
    parser.add_argument(
        "--overwrite", action="store_true", help="replace an existing --out: regenerate on purpose only"
    )
    args = parser.parse_args(argv)
    if not args.check and os.path.exists(args.out) and not args.overwrite:
        parser.exit(
            2, f"fingerprint.py: {args.out} exists: --check compares with it, --overwrite replaces it\n"
        )
    now = fingerprint()
    if args.check:
        with np.load(args.out, allow_pickle=False) as f:
            stored = {k: f[k] for k in f.files}
        bad = compare(stored, now)
        print("identical" if not bad else f"{len(bad)} arrays differ: {bad}")
        return 1 if bad else 0
    np.savez_compressed(args.out, **now)
    print(f"wrote {len(now)} arrays to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
