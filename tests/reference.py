"""A slow, readable, pure-numpy reference of Online Goal Babbling (Rolf, Steil & Gienger, ICDL 2011).

Written from Sec. II and III of the paper, with the conventions that gb_pin documents where the
paper is silent (module docstrings of ``gb_pin.learn.llm_kernels``, ``gb_pin.learn.weighting``,
``gb_pin.learn.exploration``, ``gb_pin.learn.loop``). It shares no code with gb_pin: the forward
kinematics of the planar arm is the closed form, the local-linear map is a handful of vectorised
numpy expressions, and randomness is drawn with ordinary numpy ``Generator`` calls.

Conventions reproduced (paper silent or ambiguous):

* The run starts with the noise draw A_0 (row by row), then b_0, each entry ``sigma * N(0, 1)``.
* Movements r = 0, 1, ... are goal-directed or home returns; the movement count includes home returns.
  Before each movement: if the previous movement was goal-directed, ``rng.random() < p_home`` decides a
  home return (Eq. 7); otherwise (first movement, or after a home return) the movement is goal-directed
  and no number is drawn for that decision. A goal-directed movement draws its goal with
  ``rng.integers(0, N)``.
* Each step: q from Eq. 2 (goal) or Eq. 7 (home), x = f(q) (Eq. 1), weight (Eqs. 4-6; home steps
  w_eff only), learning, then one step of the noise random walk (Eq. 8) drawing the increments of A
  row by row, then of b. The walk advances on home steps too.
* Weights: w_eff = 0 if q did not move; the cosine of w_dir is 0 if either displacement is zero.
* Local-linear map: W_k acts on u_k = (x - p_k) / d; insertion when x is at distance >= d from all
  prototypes, with o = g(x) and W = d * dg/dx (derivative of the responsibilities included); the
  gradient's factor 2 is folded into eta: o_k += eta w beta_k e, W_k += eta w beta_k e u_k^T, e = q - g(x).
* After a home return the next goal path starts at f(q_home) (Sec. II-A).
* E^X and D^home (Eqs. 9-10) are measured before movement r, i.e. with theta_{rL}.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

GOAL = "goal"
HOME = "home"


# -- the robot: planar arm of Sec. III ---------------------------------------------------------
def planar_forward(q: np.ndarray, total_length: float = 1.0) -> np.ndarray:
    """Effector position of a planar arm of equal segments, closed form (Eq. 1).

    x = sum_i l cos(q_1 + ... + q_i), y = sum_i l sin(q_1 + ... + q_i), l = total_length / m.

    Args:
        q: posture (m,) or postures (N, m) [rad].
        total_length: length of the whole arm [m].

    Returns:
        (2,) or (N, 2) positions [m].
    """
    q = np.asarray(q, dtype=float)
    segment = total_length / q.shape[-1]
    angles = np.cumsum(q, axis=-1)
    return np.stack([segment * np.cos(angles).sum(axis=-1), segment * np.sin(angles).sum(axis=-1)], axis=-1)


def planar_home(m: int) -> np.ndarray:
    """Home posture of Sec. III: -pi/3 for the first joint, 2 pi / (3 (m - 1)) for the others [rad]."""
    home = np.full(m, 2.0 * math.pi / (3.0 * (m - 1)))
    home[0] = -math.pi / 3.0
    return home


def paper_sigma(m: int) -> float:
    """sigma with sigma * sqrt((m + 1) / 2) = 0.05 * sqrt(3) (Eq. 12, Sec. III-B): 0.05 at m = 5."""
    return 0.05 * math.sqrt(3.0 / ((m + 1) / 2.0))


# -- the inverse estimate: local-linear map of Sec. II-C ----------------------------------------
class ReferenceMap:
    """g(x) = sum_k beta_k(x) (W_k u_k + o_k), u_k = (x - p_k) / d, beta = soft-max of -||u_k||^2."""

    def __init__(self, x0: np.ndarray, q0: np.ndarray, radius: float) -> None:
        self.d = radius
        self.P = np.array([x0], dtype=float)  # (K, n)
        self.W = np.zeros((1, q0.size, x0.size))  # (K, m, n)
        self.O = np.array([q0], dtype=float)  # (K, m)

    def _parts(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(beta (K,), u (K, n), local outputs y_k (K, m)) at x."""
        u = (x - self.P) / self.d
        sq = np.sum(u * u, axis=1)
        # exp(-||u||^2) normalised; shifting by the smallest exponent cancels in the ratio.
        b = np.exp(-(sq - sq.min()))
        beta = b / b.sum()
        y = np.einsum("kij,kj->ki", self.W, u) + self.O
        return beta, u, y

    def predict(self, x: np.ndarray) -> np.ndarray:
        """g(x) for one input (n,) -> (m,)."""
        beta, _, y = self._parts(x)
        return beta @ y

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """dg/dx (m, n), by the product rule on beta_k(x) (W_k u_k + o_k).

        d beta_k / dx = -(2 / d) beta_k (u_k - sum_j beta_j u_j), d(W_k u_k + o_k)/dx = W_k / d.
        """
        beta, u, y = self._parts(x)
        ubar = beta @ u
        dbeta = -(2.0 / self.d) * beta[:, None] * (u - ubar)  # (K, n)
        return np.einsum("k,kij->ij", beta, self.W) / self.d + y.T @ dbeta

    def learn(self, x: np.ndarray, q: np.ndarray, w: float, eta: float) -> None:
        """Insert a prototype at x if needed, then one gradient step on w ||q - g(x)||^2."""
        if np.all(np.linalg.norm(x - self.P, axis=1) >= self.d):
            g, J = self.predict(x), self.jacobian(x)
            self.P = np.vstack([self.P, x])
            self.W = np.concatenate([self.W, (self.d * J)[None]])
            self.O = np.vstack([self.O, g])
        if w == 0.0:
            return
        beta, u, y = self._parts(x)
        e = q - beta @ y
        self.O += eta * w * beta[:, None] * e
        self.W += eta * w * beta[:, None, None] * e[None, :, None] * u[:, None, :]


# -- weights, Eqs. 4-6 ---------------------------------------------------------------------------
def efficiency_weight(x: np.ndarray, x_prev: np.ndarray, q: np.ndarray, q_prev: np.ndarray) -> float:
    """w_eff = ||x_t - x_{t-1}|| / ||q_t - q_{t-1}|| (Eq. 5); 0 if q did not move."""
    dq = np.linalg.norm(q - q_prev)
    return 0.0 if dq == 0.0 else float(np.linalg.norm(x - x_prev) / dq)


def direction_weight(target: np.ndarray, target_prev: np.ndarray, x: np.ndarray, x_prev: np.ndarray) -> float:
    """w_dir = (1 + cos angle(x*_t - x*_{t-1}, x_t - x_{t-1})) / 2 (Eq. 4); cos = 0 for a zero move."""
    a, b = target - target_prev, x - x_prev
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0.0 or nb == 0.0:
        return 0.5
    return 0.5 * (1.0 + float(np.clip(a @ b / (na * nb), -1.0, 1.0)))


# -- the run ---------------------------------------------------------------------------------------
@dataclass
class Step:
    """One example of the run, for tests that inspect paths."""

    movement: int
    kind: str
    l: int  # substep 1..L
    target: np.ndarray | None  # x*_t (goal steps), None on home steps
    q: np.ndarray
    x: np.ndarray
    w: float


@dataclass
class ReferenceRun:
    """What :func:`reference_babble` returns.

    Attributes:
        errors: (R + 1,) E^X before movements 0..R (Eq. 9) [m].
        home_distances: (R + 1,) D^home before movements 0..R (Eq. 10) [rad].
        kinds: kind of every movement.
        goals: index of the goal of every movement (-1 for home returns).
        prototypes, matrices, offsets: the final map (K, n), (K, m, n), (K, m).
        A, b: the final noise (Eq. 8).
        snapshots: per completed movement r (1..R), (P, W, O, A, b) after it, if requested.
        steps: every example, if requested.
    """

    errors: np.ndarray
    home_distances: np.ndarray
    kinds: list[str]
    goals: list[int]
    prototypes: np.ndarray
    matrices: np.ndarray
    offsets: np.ndarray
    A: np.ndarray
    b: np.ndarray
    x_home: np.ndarray
    snapshots: list[tuple[np.ndarray, ...]] = field(default_factory=list)
    steps: list[Step] = field(default_factory=list)


def evaluate(g: ReferenceMap, targets: np.ndarray, home: np.ndarray) -> tuple[float, float]:
    """(E^X, D^home) of Eqs. 9-10 over the target set."""
    Q = np.array([g.predict(t) for t in targets])
    error = np.mean(np.linalg.norm(targets - planar_forward(Q), axis=1))
    distance = np.mean(np.linalg.norm(home - Q, axis=1))
    return float(error), float(distance)


def reference_babble(
    m: int,
    targets: np.ndarray,
    movements: int,
    seed: int | np.random.Generator,
    *,
    learning_rate: float = 0.1,
    sigma: float | None = None,
    sigma_delta: float | None = None,
    radius: float = 0.1,
    path_length: int = 25,
    p_home: float = 0.1,
    record: bool = False,
) -> ReferenceRun:
    """Online goal babbling on the planar arm with m joints, straight from paper Sec. II.

    Args:
        m: number of joints of the 1 m planar arm.
        targets: target set X* (N, 2) [m].
        movements: movements R to run (home returns included).
        seed: int seed (``np.random.default_rng(seed)``) or a Generator.
        learning_rate: eta of the gradient step.
        sigma: standard deviation of the noise entries (Eq. 8) [rad]; default Eq. 12.
        sigma_delta: standard deviation of the random-walk increments [rad]; default 0.1 sigma.
        radius: d of the local-linear map [m].
        path_length: L, steps per movement (Eq. 3).
        p_home: probability of a home return after a goal-directed movement (Eq. 7).
        record: keep every step and a snapshot of the model after every movement.
    """
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    targets = np.asarray(targets, dtype=float)
    sigma = paper_sigma(m) if sigma is None else sigma
    sigma_delta = 0.1 * sigma if sigma_delta is None else sigma_delta
    L = path_length
    home = planar_home(m)
    x_home = planar_forward(home)
    n = x_home.size

    g = ReferenceMap(x_home, home, radius)  # g(x, theta_0) = q_home, p_1 = f(q_home)
    # Eq. 8: e_0 ~ N(0, sigma^2), A row by row, then b.
    A = sigma * rng.standard_normal((m, n))
    b = sigma * rng.standard_normal(m)
    shrink = math.sqrt(sigma**2 / (sigma**2 + sigma_delta**2)) if sigma > 0 else 0.0

    q_prev, x_prev = home.copy(), x_home.copy()
    path_end = x_home.copy()  # x*_0 = f(q_home)
    target_prev = x_home.copy()
    errors, distances, kinds, goals = [], [], [], []
    snapshots: list[tuple[np.ndarray, ...]] = []
    steps: list[Step] = []
    last_kind = None
    for r in range(movements):
        e, dist = evaluate(g, targets, home)
        errors.append(e)
        distances.append(dist)
        if last_kind == GOAL and rng.random() < p_home:
            kind, goal = HOME, -1
            q_start = q_prev.copy()
        else:
            kind, goal = GOAL, int(rng.integers(0, targets.shape[0]))
            path_start, path_end = path_end, targets[goal]
        kinds.append(kind)
        goals.append(goal)
        for l in range(1, L + 1):
            if kind == GOAL:
                target = (L - l) / L * path_start + l / L * path_end  # Eq. 3
                q = g.predict(target) + A @ target + b  # Eq. 2 with E_t of Eq. 8
            else:
                target = None
                q = (L - l) / L * q_start + l / L * home  # Eq. 7
            x = planar_forward(q)  # Eq. 1
            w = efficiency_weight(x, x_prev, q, q_prev)  # Eq. 5
            if kind == GOAL:
                w *= direction_weight(target, target_prev, x, x_prev)  # Eqs. 4, 6
                target_prev = target
            g.learn(x, q, w, learning_rate)
            delta = sigma_delta * rng.standard_normal(m * n + m)  # A row by row, then b
            A = shrink * (A + delta[: m * n].reshape(m, n))
            b = shrink * (b + delta[m * n :])
            if record:
                steps.append(Step(r, kind, l, target, q.copy(), x.copy(), w))
            q_prev, x_prev = q, x
        if kind == HOME:
            # The next goal path starts where the arm is: f(q_home).
            path_end = x_prev.copy()
            target_prev = x_prev.copy()
        last_kind = kind
        if record:
            snapshots.append((g.P.copy(), g.W.copy(), g.O.copy(), A.copy(), b.copy()))
    e, dist = evaluate(g, targets, home)
    errors.append(e)
    distances.append(dist)
    return ReferenceRun(
        errors=np.array(errors),
        home_distances=np.array(distances),
        kinds=kinds,
        goals=goals,
        prototypes=g.P,
        matrices=g.W,
        offsets=g.O,
        A=A,
        b=b,
        x_home=x_home,
        snapshots=snapshots,
        steps=steps,
    )
