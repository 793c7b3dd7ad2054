"""Measure the paper's headline numbers (Sec. III) over independent trials of planar arms."""

from __future__ import annotations

import argparse
import time

import numpy as np

import gb_pin


def trials(robot: str, learning_rate: float, movements: int, count: int) -> tuple[np.ndarray, np.ndarray]:
    """E^X histories of ``count`` trials (seeds 0..count-1) and their movement counts."""
    runs = [
        gb_pin.babble(robot, movements=movements, seed=s, learning_rate=learning_rate) for s in range(count)
    ]
    return runs[0].history.movements, np.array([r.history.error for r in runs])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--trials", type=int, default=100)
    args = parser.parse_args()
    n = args.trials
    start = time.perf_counter()

    mv, err = trials("planar5", 0.1, 300, n)
    print(f"planar5 eta=0.1: median E^X after 100 movements = {np.median(err[:, 100]):.4f} m (paper: 0.04)")

    mv, err = trials("planar5", 0.01, 4000, n)
    med = np.median(err, axis=0)
    first = mv[np.flatnonzero(med <= 0.04)[0]] if np.any(med <= 0.04) else None
    print(f"planar5 eta=0.01: first movement count with median E^X <= 0.04 = {first} (paper: ~2000)")

    mv, err = trials("planar5", 0.5, 300, n)
    e0 = err[0, 0]
    print(f"planar5 eta=0.5: S(0.5, 0.1 E_0) = {gb_pin.speed(mv, err, 0.5, 0.1 * e0)} (paper: 34)")

    mv, err = trials("planar50", 0.1, 1000, n)
    e0 = err[0, 0]
    print(
        f"planar50 eta=0.1: S(0.5, 0.1 E_0) = {gb_pin.speed(mv, err, 0.5, 0.1 * e0)} (paper: 128), "
        f"S(0.9, 0.1 E_0) = {gb_pin.speed(mv, err, 0.9, 0.1 * e0)} (paper: 364)"
    )
    print(f"{n} trials per condition, {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
