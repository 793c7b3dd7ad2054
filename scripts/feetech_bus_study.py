"""The acceptance study of gb_pin.hardware: goal babbling on emulated SO-101s through the real byte protocol.

Each arm is an emulated STS3215 bus in its own process on a pseudo-terminal (gb_pin.hardware.emulator):
calibration middles off the URDF zero by N(0, 3 deg), links off by N(0, 3 %), a tracker with 1.5 mm
noise per axis losing 10 % of its readings. FeetechArm drives it (max_joint_step 0.05 rad); the
session learns from the executed postures. After the run, a 3 x 3 x 3 test grid over the goal box
shrunk to 2/3 is reached twice on the emulated arm, by the learned inverse and by exact IK on the
URDF, and the error measured on the emulator's true body. With --faults the bus drops 1 % of the
replies and sends 0.5 % late (after the host's timeout).

    nice -n 10 python scripts/feetech_bus_study.py --arms 1 2 3 --movements 3000 --out study.json
    nice -n 10 python scripts/feetech_bus_study.py --arms 1 2 3 --movements 3000 --faults --out faults.json
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import gb_pin
from gb_pin.hardware import FeetechArm
from gb_pin.hardware.arms import TICKS_PER_RAD
from gb_pin.hardware.babbling import babble_on_arm
from gb_pin.hardware.emulator import Emulator


def grid(robot: str) -> np.ndarray:
    """3 x 3 x 3 points over the preset's goal box shrunk to 2/3 about its centre."""
    model = gb_pin.load_robot(robot)
    lo, hi = model.targets.min(axis=0), model.targets.max(axis=0)
    c, h = (lo + hi) / 2, (hi - lo) / 3
    axes = [np.linspace(c[i] - h[i], c[i] + h[i], 3) for i in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


def reach(arm: FeetechArm, bus: Emulator, postures: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Execute each posture on the arm (in steps), the true hand's distance to its target [m]."""
    errors = []
    for q, x in zip(postures, X, strict=True):
        arm.move_to(np.clip(q, arm.lower, arm.upper))
        errors.append(float(np.linalg.norm(bus.truth()["hand"] - x)))
    return np.array(errors)


def goal_writes(stats: dict, arm: FeetechArm) -> dict:
    """Goals written outside the servo's limits, and the largest change between two goals [ticks]."""
    outside = 0
    last: dict[int, int] = {}
    largest: dict[int, int] = {}
    for servo, goal, lo, hi in stats["goals"]:
        outside += not lo <= goal <= hi
        if servo in last:
            largest[servo] = max(largest.get(servo, 0), abs(goal - last[servo]))
        last[servo] = goal
    return {"writes": len(stats["goals"]), "outside_limits": outside, "largest_step_ticks": largest}


def one_arm(seed: int, args: argparse.Namespace) -> dict:
    """Learn on one emulated arm, then reach the test grid by the learned inverse and by URDF IK."""
    faults = {"drop": 0.01, "late": 0.005, "late_delay": 1.6 * args.reply_timeout} if args.faults else {}
    with (
        Emulator(robot=args.robot, seed=seed, speed=args.speed, **faults) as bus,
        FeetechArm(bus.port, args.robot, bus.calibration, max_joint_step=args.step,
                   reply_timeout=args.reply_timeout) as arm,
    ):  # fmt: skip
        start = time.perf_counter()

        def progress(r: int) -> None:
            if r % 250 == 0:
                print(f"arm {seed}: {r} movements, {time.perf_counter() - start:.0f} s", flush=True)

        stale = [0, 0]
        if args.check_stale:  # every reading compared with the emulator's encoders
            move = arm.move

            def checked(q: np.ndarray) -> np.ndarray:
                got = move(q)
                stale[0] += 1
                stale[1] += bool(np.abs(got - bus.truth()["arm"]).max() > 0.5 / TICKS_PER_RAD)
                return got

            arm.move = checked  # type: ignore[method-assign,assignment]
        result = babble_on_arm(arm, bus.tracker, movements=args.movements, seed=seed, callback=progress)
        wall = time.perf_counter() - start
        moves = arm.moves
        X = grid(args.robot)
        learned = reach(arm, bus, result.inverse(X), X)
        urdf = gb_pin.ik.solve(gb_pin.load_robot(args.robot), X, seed="home", tol=1e-9).postures
        exact = reach(arm, bus, urdf, X)
        stats = bus.stats()
        row = {
                "seed": seed, "movements": result.movements, "steps": result.steps, "missing": result.missing,
                "wall_s": wall, "ms_per_step": 1e3 * wall / result.steps, "moves": moves,
                "learned_mm": 1e3 * float(np.median(learned)),
                "learned_p90_mm": 1e3 * float(np.quantile(learned, 0.9)),
                "urdf_mm": 1e3 * float(np.median(exact)), "urdf_p90_mm": 1e3 * float(np.quantile(exact, 0.9)),
                "stalls": arm.stalls, "bus_faults": dict(arm.bus.faults), "injected": stats["faults"],
                "requests": stats["requests"], "goal_writes": goal_writes(stats, arm),
                "step_ticks": args.step * 4095 / (2 * np.pi),
            "readings_checked": stale[0], "stale_readings": stale[1],
            }  # fmt: skip
    print(json.dumps(row), flush=True)
    return row


def main() -> int:
    """Run the arms, print a line each, write --out."""
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("--robot", default="so101", choices=("so101", "so100"))
    a.add_argument("--arms", type=int, nargs="+", default=[1, 2, 3], help="emulator seeds")
    a.add_argument("--movements", type=int, default=3000)
    a.add_argument("--faults", action="store_true", help="1 %% dropped, 0.5 %% late replies")
    a.add_argument("--speed", type=float, default=60000.0, help="emulated servo speed [ticks/s]")
    a.add_argument("--step", type=float, default=0.05, help="max_joint_step [rad]")
    a.add_argument("--reply-timeout", type=float, default=0.01, help="the host's reply timeout [s]")
    a.add_argument("--check-stale", action="store_true", help="compare every reading with the emulator's")
    a.add_argument("--out", default=None)
    a.add_argument("--overwrite", "--force", action="store_true", help="let --out replace an existing file")
    args = a.parse_args()
    if args.out is not None:
        from gb_pin._files import check_writable
        from gb_pin.cli.checks import no_clobber
        from gb_pin.exceptions import GbPinError

        try:  # before any work: another study's file is never replaced by accident
            check_writable(args.out, "--out")
            no_clobber(args.out, "--out", args.overwrite)
        except GbPinError as exc:
            a.exit(2, f"feetech_bus_study.py: error: {exc}\n")
    rows = [one_arm(seed, args) for seed in args.arms]
    for r in rows:
        ratio = r["urdf_mm"] / r["learned_mm"]
        print(f"arm {r['seed']}: learned {r['learned_mm']:.2f} mm, URDF IK {r['urdf_mm']:.2f} mm "
              f"({ratio:.1f}x); "
              f"{r['ms_per_step']:.2f} ms/step; bus faults {r['bus_faults']}; injected {r['injected']}; "
              f"goals outside limits {r['goal_writes']['outside_limits']}; "
              f"stale readings {r['stale_readings']} of {r['readings_checked']} checked")  # fmt: skip
    if args.out:
        with open(args.out, "w") as f:
            json.dump({"args": vars(args), "arms": rows}, f, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
