"""The study behind ``parts`` (docs/WORKSPACE.md, "A region in parts"): variants on 3 seeds.

    python scripts/workspace_parts_sweep.py panda 10000 "parts=1;parts=2,mode='yaw',first_scale=0.5" 3

Each variant (keyword arguments of :func:`run`, separated by ``;``) learns the region f = 0.5 with
P learners run one after the other (independent learners: the same maps as in turns), each from
its part's home (the median of its postures), its goals the region's goal postures of its part
drawn towards that home per curriculum stage; the test points (300, seed 1) are answered by the map
of their part. ``mode``: ``"yaw"`` (sectors of the angle around the first joint's axis, as
``targets="workspace:...,parts=P"``) or ``"kmeans"`` (nearest of P k-means centres of the goal
points). ``first_scale``: the curriculum's first stage scaled (0.5: at the run's movement 1000 with
two learners), ``rshare``: radius / L, ``lr``: learning rate, ``lr_end``: the rate decayed
geometrically to this over the run, ``points``: goal points, ``sgain``: sigma / Eq. 12's,
``overlap``: each sector's goals reach this far [rad] beyond its inner edges, ``home_mode``:
``"median"``, ``"medoid"`` or ``"home"``. Prints each seed's median and 90 % [mm], K and CPU s,
then the medians over the seeds. This is the prototype the measurements were taken with; its
random streams differ from ``babble``'s.
"""

import sys
import time
import types

import numpy as np

import gb_pin
from gb_pin.learn.learner import GoalBabbling
from gb_pin.learn.reach_errors import ReachErrors
from gb_pin.robot.workspace import WorkspaceRegion, extent, region_postures
from gb_pin.runs.scaling import RADIUS_SHARE, REGION_LEARNING_RATE, REGION_SIGMA_GAIN, scaled_sigma


def kmeans(X, k, iters=50):
    """(centres, labels) of k-means with a farthest-point start."""
    # deterministic: farthest-point init from the point nearest the mean
    c = [X[np.argmin(np.linalg.norm(X - X.mean(0), axis=1))]]
    for _ in range(k - 1):
        d = np.min([np.linalg.norm(X - ci, axis=1) for ci in c], axis=0)
        c.append(X[np.argmax(d)])
    C = np.array(c)
    for _ in range(iters):
        lab = np.argmin(((X[:, None] - C[None]) ** 2).sum(-1), axis=1)
        C = np.array([X[lab == j].mean(0) for j in range(k)])
    return C, lab


def run(
    robot,
    movements,
    seed,
    parts=2,
    mode="kmeans",
    home_mode="median",
    f=0.5,
    first_scale=1.0,
    lr=None,
    lr_end=None,
    rshare=None,
    chunk=100,
    points=300,
    sgain=None,
    overlap=0.0,
):
    """(ReachErrors on the test points, K of all parts, CPU s) of one variant and seed."""
    arm = gb_pin.load_robot(robot)
    reg = WorkspaceRegion(f, points=points)
    m = arm.home.shape[0]
    u = np.random.default_rng(reg.seed).random((reg.points, m))
    Q = region_postures(arm, f, u)
    X = arm.forward(Q)
    L = extent(X)
    T = reg.test_set(arm)
    if parts == 1:
        C, lab = X.mean(0)[None], np.zeros(len(X), int)
    elif mode == "kmeans":
        C, lab = kmeans(X, parts)
    elif mode == "yaw":  # azimuth about joint 1's axis (circle fit), relative to home direction
        q = np.tile(arm.home, (3, 1))
        q[0, 0] -= 0.3
        q[2, 0] += 0.3
        p = arm.forward(q)
        a, b = p[0] - p[1], p[2] - p[1]
        nrm = np.cross(a, b)
        nrm /= np.linalg.norm(nrm)
        # circumcentre
        ab = np.cross(a, b)
        c = p[1] + (np.dot(a, a) * np.cross(b, ab) + np.dot(b, b) * np.cross(ab, a)) / (2 * np.dot(ab, ab))
        u = p[1] - c
        u -= np.dot(u, nrm) * nrm
        u /= np.linalg.norm(u)
        v = np.cross(nrm, u)
        az = np.arctan2((X - c) @ v, (X - c) @ u)
        edges = np.quantile(az, np.linspace(0, 1, parts + 1))
        lab = np.clip(np.searchsorted(edges, az, side="right") - 1, 0, parts - 1)
        inner = edges[1:-1]
        lo = np.r_[-np.inf, inner - overlap]
        hi = np.r_[inner + overlap, np.inf]
        members = [(az >= lo[j]) & (az <= hi[j]) for j in range(parts)]
        C = np.array([X[lab == j].mean(0) for j in range(parts)])
    radius = (rshare or RADIUS_SHARE) * L
    sigma = scaled_sigma(arm, L, sgain or REGION_SIGMA_GAIN)
    maps = []
    per = movements // parts
    t0 = time.process_time()
    K = 0
    for j in range(parts):
        Qj = Q[members[j]] if mode == "yaw" and parts > 1 else Q[lab == j]
        if home_mode == "median":
            hj = np.median(Qj, axis=0)
        elif home_mode == "home":
            hj = arm.home.copy()
        elif home_mode == "medoid":
            D = np.abs(Qj[:, None] - Qj[None]).sum(-1)
            hj = Qj[np.argmin(D.sum(1))]
        if parts == 1:
            hj = arm.home.copy()
        hj = np.clip(hj, arm.lower, arm.upper)
        blocks = []
        for fs in reg.stage_fractions():
            blocks.append(arm.forward(hj + (fs / f) * (Qj - hj)))
        goals = np.vstack(blocks)
        kin = types.SimpleNamespace(chain=arm.chain, home=hj, lower=arm.lower, upper=arm.upper)
        gbl = GoalBabbling(learning_rate=lr or REGION_LEARNING_RATE, sigma=sigma, radius=radius)
        first = max(1, int(900 * first_scale))
        if lr_end is None:
            gbl.fit(
                kin,
                goals,
                per,
                seed=np.random.default_rng([seed, j]),
                schedule=[0, per],
                goals=f"curriculum:stages=3,first={first}",
            )
        else:
            import dataclasses

            from gb_pin.learn.state import BabbleState

            lr0 = lr or REGION_LEARNING_RATE
            st = BabbleState.start(
                kin,
                goals,
                per,
                gbl._resolve(m),
                seed=np.random.default_rng([seed, j]),
                schedule=[0, per],
                goals=f"curriculum:stages=3,first={first}",
            )
            gbl.state_ = st
            base = st.config
            while st.movements < per:
                frac = st.movements / per
                st.config = dataclasses.replace(base, learning_rate=float(lr0 * (lr_end / lr0) ** frac))
                st.run(min(per, st.movements + chunk))
        maps.append(gbl.model_)
        K += gbl.model_.n_prototypes_
    cpu = time.process_time() - t0
    lab_t = np.argmin(((T[:, None] - C[None]) ** 2).sum(-1), axis=1)
    if mode == "yaw" and parts > 1:
        azt = np.arctan2((T - c) @ v, (T - c) @ u)
        lab_t = np.clip(np.searchsorted(edges, azt, side="right") - 1, 0, parts - 1)
    P = np.empty((len(T), m))
    for j in range(parts):
        if np.any(lab_t == j):
            P[lab_t == j] = maps[j].predict(T[lab_t == j], warn=False)
    P = np.clip(P, arm.lower, arm.upper)
    e = ReachErrors.of(np.linalg.norm(arm.forward(P) - T, axis=1))
    return e, K, cpu


if __name__ == "__main__":
    robot, movements = sys.argv[1], int(sys.argv[2])
    seeds = int(sys.argv[4]) if len(sys.argv) > 4 else 3
    for variant in sys.argv[3].split(";"):
        kw = dict(eval(f"dict({variant})"))
        rows = []
        for s in range(seeds):
            e, K, cpu = run(robot, movements, s, **kw)
            rows.append((e.median * 1000, e.p90 * 1000, K, cpu))
        a = np.array(rows)
        med, p90 = np.round(a[:, 0], 2), np.round(a[:, 1], 1)
        head = f"{robot} {movements} {variant:40s} med {med} p90 {p90} K {a[:, 2].astype(int)}"
        tail = f"cpu {a[:, 3].mean():.1f} | {np.median(a[:, 0]):.2f} / {np.median(a[:, 1]):.1f}"
        print(head, tail, flush=True)
