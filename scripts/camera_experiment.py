"""The camera study of docs/CAMERA.md: learn a simulated SO-101 in a camera's own frame from a marker.

    python scripts/camera_experiment.py tracker --postures 200 --out docs/figures/camera
    python scripts/camera_experiment.py learn --seed 0 --movements 1000 --out docs/figures/camera
    python scripts/camera_experiment.py table --out docs/figures/camera

``tracker``: detection and error of the ArUco tracker (three corner refinements) at random
postures of the goal region, against the true marker centre. ``learn`` (one seed): the plant
(kp 10, rendered from the ``side`` camera, 3/255 pixel noise), goals taught by holding the arm
at the 8 corners of the preset's goal box (10 readings each), test targets taught at a 3 x 3 x
3 grid over 3/4 of the box; babbling on the tracker's readings and, for comparison, on perfect
readings (the true marker centre in the camera frame, no rendering); then the reach error,
true (MuJoCo's marker centre), open loop and with feedback (result.reach, 5 readings), and exact
IK on the URDF with the camera pose known exactly or off by 1 cm / 2 deg. ``table`` gathers
the JSON files into ``camera.md`` and a figure.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import gb_pin
from gb_pin.ik import solve
from gb_pin.sim import MujocoPlant
from gb_pin.vision import ArucoTracker, CameraSensor, WatchedRobot

SCHEDULE = [0, 100, 200, 300, 500, 700, 1000, 1500, 2000, 3000]


def box_corners(target) -> np.ndarray:
    """The 8 corners of the preset's goal box (x fastest)."""
    lo, hi = target.targets.min(axis=0), target.targets.max(axis=0)
    return np.array([[(hi if b else lo)[a] for a, b in enumerate((i, j, k))]
                     for k in (0, 1) for j in (0, 1) for i in (0, 1)])  # fmt: skip


def test_points(target, shrink: float = 0.75) -> np.ndarray:
    """A 3 x 3 x 3 grid over ``shrink`` of the goal box (none a goal)."""
    lo, hi = target.targets.min(axis=0), target.targets.max(axis=0)
    c, h = (lo + hi) / 2, shrink * (hi - lo) / 2
    axes = [np.linspace(c[a] - h[a], c[a] + h[a], 3) for a in range(3)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)


def urdf_postures(target, X: np.ndarray) -> np.ndarray:
    """Exact IK on the URDF (where a user would hold the arm)."""
    return solve(target, X, seed="home", tol=1e-9).postures


def tracker_study(args: argparse.Namespace) -> None:
    """Detection and error of three corner refinements at random postures."""
    plant = MujocoPlant("so101", kp=10.0, camera="side", seed=0)
    rng = np.random.default_rng(1)
    lo, hi = plant.target.targets.min(0), plant.target.targets.max(0)
    Q = urdf_postures(plant.target, rng.uniform(lo, hi, (args.postures, 3)))
    K = plant.camera.intrinsics()
    trackers = {r: ArucoTracker(K, 0.025, marker_id=7, refine=r) for r in ("apriltag", "subpix", "none")}
    rows = {r: {"err": [], "ms": []} for r in trackers}
    render = []
    for q in Q:
        plant.move(q)
        t0 = time.perf_counter()
        image = plant.read()
        render.append(time.perf_counter() - t0)
        truth = plant.camera.pose.to_camera(plant.marker_position())
        for r, tr in trackers.items():
            t0 = time.perf_counter()
            x = tr(image)
            rows[r]["ms"].append(1e3 * (time.perf_counter() - t0))
            rows[r]["err"].append(np.nan if x is None else 1e3 * float(np.linalg.norm(x - truth)))
    out = {"postures": len(Q), "render_ms": 1e3 * float(np.median(render)), "trackers": {}}
    for r, v in rows.items():
        e = np.array(v["err"])
        out["trackers"][r] = {
            "detected": int(np.isfinite(e).sum()),
            "median_mm": float(np.nanmedian(e)),
            "p90_mm": float(np.nanpercentile(e, 90)),
            "ms": float(np.median(v["ms"])),
        }
    print(json.dumps(out, indent=1))
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "tracker.json").write_text(json.dumps(out, indent=1))


class Perfect(gb_pin.FunctionTarget):
    """The same plant read perfectly: the true marker centre in the camera frame after each settle."""

    def __init__(self, plant: MujocoPlant, targets: np.ndarray) -> None:
        self.plant = plant
        super().__init__(plant.true_marker, plant.home, lower=plant.lower, upper=plant.upper,
                         targets=targets, name="so101 perfect camera-frame readings")  # fmt: skip
        self.true_forward = plant.true_marker
        self.preset = "so101"

    def forward(self, q):  # type: ignore[override]
        """Move, read the true marker centre."""
        self.plant.move(q)
        return self.plant.camera.pose.to_camera(self.plant.marker_position())


def marker_ik(plant: MujocoPlant, world: np.ndarray) -> np.ndarray:
    """Exact IK of the marker point on the URDF's kinematics (no sag): damped Gauss-Newton from home."""
    out = []
    for x in world:
        q = plant.home.copy()
        for _ in range(100):
            p = plant.marker_position(q)
            e = x - p
            if np.linalg.norm(e) < 1e-10:
                break
            J = np.column_stack([(plant.marker_position(q + 1e-6 * d) - p) / 1e-6 for d in np.eye(len(q))])
            q = np.clip(q + J.T @ np.linalg.solve(J @ J.T + 1e-9 * np.eye(3), e), plant.lower, plant.upper)
        out.append(q)
    return np.array(out)


def turned(seed: int, degrees: float) -> np.ndarray:
    """A rotation of ``degrees`` about a random axis."""
    rng = np.random.default_rng(seed + 100)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    a = np.radians(degrees)
    Kx = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(a) * Kx + (1 - np.cos(a)) * Kx @ Kx


def learn_study(args: argparse.Namespace) -> None:
    """One seed: teach, babble (camera and perfect), reach, URDF IK."""
    seed, M = args.seed, args.movements
    plant = MujocoPlant("so101", kp=10.0, camera="side", seed=seed)
    tracker = ArucoTracker(plant.camera.intrinsics(), 0.025, marker_id=7)
    robot = WatchedRobot(plant, CameraSensor(plant, tracker))
    t0 = time.perf_counter()
    goals = robot.teach_box(urdf_postures(plant.target, box_corners(plant.target)), 4, readings=10)
    test_q = urdf_postures(plant.target, test_points(plant.target))
    taught = robot.teach_all(test_q, readings=10)
    truth = plant.true_marker(test_q)  # where the marker was when each test target was shown
    robot.targets = goals
    teach_s = time.perf_counter() - t0
    out = {"seed": seed, "movements": M, "teach_s": teach_s,
           "taught_error_mm": float(1e3 * np.median(np.linalg.norm(taught - truth, axis=1)))}  # fmt: skip

    def errors(result, observe) -> dict:
        q_open = result.inverse(taught)
        open_mm = 1e3 * np.linalg.norm(plant.true_marker(q_open) - truth, axis=1)
        reached = result.reach(taught, observe)
        fb_mm = 1e3 * np.linalg.norm(plant.true_marker(reached.postures) - truth, axis=1)
        return {
            "open_mm": float(np.median(open_mm)), "open_p90_mm": float(np.percentile(open_mm, 90)),
            "feedback_mm": float(np.median(fb_mm)), "feedback_p90_mm": float(np.percentile(fb_mm, 90)),
        }  # fmt: skip

    schedule = [m for m in SCHEDULE if m < M] + [M]
    runs = [("perfect", Perfect(plant, goals), None), ("camera", robot, robot.observe)]
    for name, body, observe in runs[: 1 if args.perfect_only else 2]:
        plant.reset()
        t0 = time.perf_counter()
        asks0, frames0 = plant.asks, plant.camera.frames
        result = gb_pin.babble(body, movements=M, seed=seed, schedule=schedule)
        wall = time.perf_counter() - t0
        obs = observe or (lambda q, b=body: b.forward(q))
        row = errors(result, obs)
        if name == "perfect":  # the same model, its feedback corrections read through the camera
            seen = errors(result, robot.observe)
            row["feedback_camera_mm"], row["feedback_camera_p90_mm"] = (
                seen["feedback_mm"],
                seen["feedback_p90_mm"],
            )
        row.update({
            "wall_s": wall, "asks": plant.asks - asks0, "frames": plant.camera.frames - frames0,
            "missing": int(result.missing), "prototypes": int(result.n_prototypes),
            "curve": {"movements": [int(v) for v in result.history.movements],
                      "error_mm": [1e3 * float(v) for v in result.history.error]},
        })  # fmt: skip
        out[name] = row
        print(name, {k: v for k, v in row.items() if k != "curve"}, flush=True)
    # exact IK on the URDF, targets taken to the world with the camera pose known or off by 1 cm / 2 deg
    pose = plant.camera.pose
    rng = np.random.default_rng(seed + 200)
    shift = rng.normal(size=3)
    shift *= 0.01 / np.linalg.norm(shift)
    for name, believed in (
        ("urdf_exact_pose", pose),
        ("urdf_pose_off", pose.moved(shift, turned(seed, 2.0))),
    ):
        world = taught @ believed.rotation.T + np.asarray(believed.position)
        q = marker_ik(plant, world)
        mm = 1e3 * np.linalg.norm(plant.true_marker(q) - truth, axis=1)
        out[name] = {"median_mm": float(np.median(mm)), "p90_mm": float(np.percentile(mm, 90))}
        print(name, out[name], flush=True)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    tag = "perfect" if args.perfect_only else "learn"
    (Path(args.out) / f"{tag}_seed{seed}_m{M}.json").write_text(json.dumps(out, indent=1))


def stream_study(args: argparse.Namespace) -> None:
    """Streaming: one reading per 30 fps frame (each ask held 1/30 s) against waiting for rest.

    The lag of a streamed reading is its distance to where the marker comes to rest under the
    same command (perfect readings: the physics, not the tracker); E^X of the run on the true body.
    """
    out = {}
    for name, options in (("stream_30fps", {"period": 1 / 30}), ("at_rest", {})):
        plant = MujocoPlant("so101", kp=10.0, camera="side", meshes=False, seed=args.seed, **options)
        goals = plant.true_marker(urdf_postures(plant.target, plant.target.targets))
        lags: list[float] = []

        class Streamed(Perfect):
            def forward(self, q, lags=lags):  # type: ignore[override]
                x = super().forward(q)
                lags.append(float(np.linalg.norm(x - self.plant.true_marker(q))))
                return x

        t0 = time.perf_counter()
        result = gb_pin.babble(Streamed(plant, goals), movements=args.movements, seed=args.seed)
        lag = 1e3 * np.array(lags)
        out[name] = {"lag_median_mm": float(np.median(lag)), "lag_p90_mm": float(np.percentile(lag, 90)),
                     "error_mm": 1e3 * float(result.error), "robot_s": plant.steps * plant.timestep,
                     "wall_s": time.perf_counter() - t0, "movements": args.movements}  # fmt: skip
        print(name, out[name], flush=True)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / f"stream_seed{args.seed}_m{args.movements}.json").write_text(json.dumps(out, indent=1))


def main() -> None:
    """Command line."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("what", choices=["tracker", "learn", "stream", "table"])
    p.add_argument("--out", default="docs/figures/camera")
    p.add_argument("--postures", type=int, default=200)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--movements", type=int, default=1000)
    p.add_argument(
        "--perfect-only", action="store_true", help="babble on perfect readings only (no rendering)"
    )
    args = p.parse_args()
    {"tracker": tracker_study, "learn": learn_study, "stream": stream_study, "table": table}[args.what](args)


def table(args: argparse.Namespace) -> None:
    """Markdown rows of docs/CAMERA.md's table: one per seed and kind of run, then the medians."""

    def cell(values: list[float]) -> str:
        return f"{np.median(values):.2f}" + (
            f" ({min(values):.2f}-{max(values):.2f})" if len(values) > 1 else ""
        )

    for kind, key in (("perfect", "perfect"), ("learn", "camera")):
        groups: dict[int, list[dict]] = {}
        for f in sorted(Path(args.out).glob(f"{kind}_seed*_m*.json")):
            row = json.loads(f.read_text())
            groups.setdefault(row["movements"], []).append(row)
        for movements, rows in sorted(groups.items()):
            runs = [r[key] for r in rows]
            fb_cam = [r.get("feedback_camera_mm", r["feedback_mm"]) for r in runs] if key == "perfect" else [
                r["feedback_mm"] for r in runs]  # fmt: skip
            fb_perfect = [r["feedback_mm"] for r in runs] if key == "perfect" else []
            print(
                f"| {'perfect readings' if key == 'perfect' else 'the tracker'} | "
                f"{', '.join(str(r['seed']) for r in rows)} | {movements} | "
                f"{cell([r['open_mm'] for r in runs])} | {cell(fb_perfect) if fb_perfect else '-'} | "
                f"{cell(fb_cam)} | "
                f"{cell([r['urdf_exact_pose']['median_mm'] for r in rows])} | "
                f"{cell([r['urdf_pose_off']['median_mm'] for r in rows])} |"
            )


if __name__ == "__main__":
    main()
