"""Figs. 3 and 6: one trial's inverse estimate g(X*) after 10, 100, 1000 and 10000 movements.

One babble run with an observer that stores g(X*) at the snapshot counts; each panel shows
the target grid, the grid the estimate reaches, f(g(X*)), and the postures of a few targets.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin import _validation as check
from gb_pin._files import write_json
from gb_pin.learn.body.chain import body_forward
from gb_pin.reproduce.conditions import SNAPSHOTS, Settings
from gb_pin.reproduce.figures import Panel, draw_snapshots, grid_shape
from gb_pin.runs.api import babble


class _Snapshots:
    """A babble() observer that stores the inverse estimate g(X*) at given movement counts."""

    def __init__(self, at: Sequence[int]) -> None:
        self.at = set(at)
        self.postures: dict[int, NDArray[np.float64]] = {}
        self.targets: NDArray[np.float64] = np.empty((0, 2))

    def start(self, target: Any, targets: NDArray[np.float64]) -> None:
        self.targets = np.asarray(targets, dtype=float)

    def update(self, state: Any) -> None:
        if state.movements in self.at:
            self.postures[state.movements] = state.llm.predict(self.targets, warn=False)


def arm_points(chain: Any, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """Positions of every joint and of the effector on the task axes, (m + 1, n) [m].

    Computed by the compiled forward kinematics read from the Pinocchio model
    (:class:`~gb_pin.learn.body.chain.KinematicChain`): its workspace holds each joint's world position.
    """
    body = chain.kernel()
    tip = np.empty(chain.n_task)
    body_forward(np.ascontiguousarray(q, dtype=float), body, tip)
    pos_ws = body.pos_ws
    return np.vstack([pos_ws[:, chain.task_axes], tip])


def _shown_targets(X: NDArray[np.float64]) -> list[int]:
    """Indices of a 3 x 3 subset of the target grid whose postures are drawn (the paper shows "several")."""
    shape = grid_shape(X)
    rows, cols = shape if shape is not None else (1, X.shape[0])
    return [
        i * cols + j
        for i in sorted({0, rows // 2, rows - 1})
        for j in sorted({0, cols // 2, cols - 1})
        if i * cols + j < X.shape[0]
    ]


def snapshot_figure(
    figure: str,
    robot: str,
    st: Settings,
    formats: Sequence[str],
    at: Sequence[int] = SNAPSHOTS,
    learning_rate: float = 0.1,
) -> tuple[list[str], Any]:
    """Figs. 3 and 6: one trial after each count in ``at``: target grid, reached grid, postures.

    Args:
        figure: ``"fig3"`` or ``"fig6"`` (the file names).
        robot: the robot (the paper: planar5 for Fig. 3, planar20 for Fig. 6).
        st: seed of the trial and output folder.
        formats: figure file formats.
        at: the movement counts of the panels.
        learning_rate: eta.

    Returns:
        The files written (the figure and ``OUT/FIGURE.json`` with every posture), and the
        numbers for ``results.json`` (E^X and D^home at each count).
    """
    at = sorted(check.positive_int("snapshot", a) for a in at)
    snaps = _Snapshots(at)
    result = babble(
        robot,
        movements=at[-1],
        seed=st.seed,
        learning_rate=learning_rate,
        viewer=snaps,
        observe_every=math.gcd(*at),
        schedule=[0, *at],
    )
    target = result.target
    X = snaps.targets
    pick = _shown_targets(X)
    numbers: dict[str, Any] = {
        "settings": {**st.as_dict(), "trials": 1},
        "robot": robot,
        "learning_rate": learning_rate,
        "targets": X.tolist(),
        "snapshots": [],
    }
    panels = []
    for r in at:
        Q = snaps.postures[r]
        reached = target.forward(target.clip(Q))
        error, home_distance = result.history.at(r)
        arms = [arm_points(target.chain, target.clip(Q[i])) for i in pick]
        panels.append(Panel(movements=r, error=error, reached=reached, arms=arms))
        numbers["snapshots"].append(
            {
                "movements": r,
                "error": error,
                "home_distance": home_distance,
                "postures": Q.tolist(),
                "reached": reached.tolist(),
            }
        )
    title = (
        f"Fig. {figure[3:]}: one trial of {robot} (η = {learning_rate:g}, seed {st.seed})\n"
        "gray: targets X*, black: reached f(g(x*)), blue: postures g(x*), dashed: home posture"
    )
    files = draw_snapshots(panels, X, arm_points(target.chain, target.home), title, st.out, figure, formats)
    path = os.path.join(st.out, f"{figure}.json")
    write_json(path, numbers)
    summary = [{k: s[k] for k in ("movements", "error", "home_distance")} for s in numbers["snapshots"]]
    shown = {k: v for k, v in numbers.items() if k not in ("targets", "snapshots")}
    return [*files, path], shown | {"snapshots": summary}
