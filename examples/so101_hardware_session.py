"""The whole hardware loop on a stand-in SO-101: a session that asks, checkpoints, survives a crash, reaches.

The learner knows the arm by its home, joint limits and goal box only (``ExternalRobot.from_preset``):
no URDF, no forward model. Each posture ``ask()`` returns goes to the "robot" (here a stand-in: a
mis-calibrated SO-101 that takes a control period per command and a camera with 1.5 mm of noise
that loses 10 % of its readings), and the reading (or None) goes back with ``tell()``. Joint steps
are limited (``max_joint_step``), E^X comes from evaluation movements the arm executes, the state is
checkpointed; kill it (or ``--crash-at``) and run again with ``--resume``. At the end the arm reaches
a few new targets by feedback on the learned model, compared with exact IK on the URDF.

    python examples/so101_hardware_session.py --checkpoint so101.ckpt --crash-at 300
    python examples/so101_hardware_session.py --checkpoint so101.ckpt --resume
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

import gb_pin


class StandInArm:
    """What a driver for a real SO-101 would do: execute a posture, wait a control period, read the camera."""

    def __init__(self, period: float, seed: int) -> None:
        self.plant = gb_pin.Plant("so101", offset_std=math.radians(3), length_std=0.03, noise=0.0015,
                                  loss=0.1, seed=seed)  # fmt: skip
        self.period = period
        self.commands = 0

    def move_and_read(self, q: np.ndarray) -> np.ndarray | None:
        """Command the servos, wait, return the camera's hand position [m] (None: the hand was not seen)."""
        self.commands += 1
        if self.period > 0:
            time.sleep(self.period)
        return self.plant.observe(q)


def session_for(args: argparse.Namespace, robot: gb_pin.ExternalRobot) -> gb_pin.BabbleSession:
    """A new session, or the one the checkpoint holds."""
    if args.resume:
        session = gb_pin.resume_session(args.checkpoint, robot=robot)
        print(f"resumed at movement {session.movements} from {args.checkpoint}")
        return session
    return gb_pin.babble_session(
        robot, movements=args.movements, seed=args.seed, evaluate="movements", max_joint_step=0.05,
        checkpoint=args.checkpoint, checkpoint_every=max(1, args.movements // 20),
    )  # fmt: skip


def main() -> int:
    """Learn, checkpoint, (crash,) reach; print what a user of a real arm would see."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--movements", type=int, default=1000, help="movements to learn (default 1000)")
    p.add_argument("--period", type=float, default=0.0, help="control period [s] per command (a bus: 0.02)")
    p.add_argument("--seed", type=int, default=0, help="learner seed; the stand-in arm is drawn from it too")
    p.add_argument("--checkpoint", default=None, help="checkpoint file (needed for --crash-at and --resume)")
    p.add_argument("--crash-at", type=int, default=None, help="simulate a crash at this movement")
    p.add_argument("--resume", action="store_true", help="continue the run of --checkpoint")
    args = p.parse_args()
    if (args.crash_at is not None or args.resume) and args.checkpoint is None:
        p.error("--crash-at and --resume need --checkpoint FILE")
    # The learner gets the preset's home, limits, goal box and learner settings: no kinematics.
    robot = gb_pin.ExternalRobot.from_preset("so101")
    model = gb_pin.load_robot("so101")  # the URDF, for the comparison with exact IK at the end
    arm = StandInArm(args.period, args.seed)
    session = session_for(args, robot)
    start = time.perf_counter()
    while not session.done:
        q = session.ask()
        session.tell(arm.move_and_read(q))
        if args.crash_at is not None and session.movements >= args.crash_at and session.ask_kind is None:
            saved = session.movements // session.every * session.every
            print(f"crashed at movement {session.movements}; the checkpoint {args.checkpoint} holds "
                  f"movement {saved}: run again with --resume")  # fmt: skip
            sys.stdout.flush()
            os._exit(3)  # no cleanup, as a crash
    wall = time.perf_counter() - start
    result = session.result()
    session.close()
    steps = max(result.steps, 1)
    print(f"learnt {result.movements} movements ({result.steps} steps, {arm.commands} commands this run, "
          f"{1e6 * wall / max(arm.commands, 1):.0f} us per command), {result.missing} readings missing "
          f"({result.missing / steps:.1%})")  # fmt: skip
    e0, reach = 1000 * result.history.error[0], 1000 * result.history.reach[-1]
    print(f"E^X by evaluation movements: {1000 * result.error:.2f} mm (E_0 {e0:.1f} mm; the tracker's noise "
          f"included); observed reach median {reach:.1f} mm (exploration noise included)")  # fmt: skip
    rng = np.random.default_rng(1)
    lo, hi = model.targets.min(axis=0), model.targets.max(axis=0)
    X = lo + (hi - lo) * (0.2 + 0.6 * rng.random((5, 3)))  # new targets inside the goal box
    truth = arm.plant.forward  # what only the stand-in knows: the true arm
    urdf = gb_pin.ik.solve(model, X, seed="home", tol=1e-9).postures
    learned = np.clip(result.inverse(X), model.lower, model.upper)
    reached = result.reach(X, arm.move_and_read, observations=(1, 1, 3))
    for name, Q in (("exact IK on the URDF", urdf), ("learned, open loop", learned),
                    ("learned + feedback", reached.postures)):  # fmt: skip
        errors = 1000 * np.linalg.norm(truth(Q) - X, axis=1)
        print(f"{name:22s} median {np.median(errors):5.2f} mm, worst {errors.max():5.2f} mm on 5 new targets")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
