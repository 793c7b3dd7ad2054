"""The message of a run whose inverse estimate diverged: what caused it, in the order it is told apart.

A reading told far outside the goal set (a sensor outlier, a wrong unit), a forward model that
returned a non-finite position, else the learner's settings (learning rate, sigma, radius) or targets
beyond the robot's reach.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gb_pin.exceptions import DivergenceError
from gb_pin.learn import layout


def divergence_error(state: Any, outlier: float) -> DivergenceError:
    """The :class:`DivergenceError` of ``state`` (a :class:`~gb_pin.learn.state.BabbleState`) that diverged.

    ``outlier``: a reading beyond this many times the goal set's extent is named as the cause.
    """
    cfg = state.config
    x, q = state.vectors["x_prev"], state.vectors["q_prev"]
    if state.far_reading is not None:
        movement, step, reading = state.far_reading
        return DivergenceError(
            f"the reading {np.array2string(reading, precision=4)} told at movement {movement} "
            f"(step {step}) lies far outside the goal set (largest |coordinate| "
            f"{float(np.max(np.abs(state.targets))):.3g} m) and the inverse estimate diverged from it: "
            "a sensor outlier or a reading in the wrong unit, not the learner's settings; tell None "
            "for a reading that cannot be trusted"
        )
    if not np.all(np.isfinite(x)):  # the learner learned from a non-finite observation
        return DivergenceError(
            f"the forward model returned the non-finite position {np.array2string(x)} for the posture "
            f"{np.array2string(q, precision=4)} (movement {state.movements}, step {state.steps}): the "
            "robot's forward kinematics (its forward function or compiled kernel) is the cause, not "
            "the learner; it must return finite positions for every posture within the joint limits"
        )
    reach = float(np.max(np.abs(state.targets)))
    if float(np.max(np.abs(x))) > outlier * max(reach, 0.1):
        return DivergenceError(
            f"the reading {np.array2string(x, precision=4)} (movement {state.movements}, step "
            f"{state.steps}) lies far outside the goal set (largest |coordinate| {reach:.3g} m) and "
            "the inverse estimate diverged from it: a sensor outlier or a reading in the wrong unit, "
            "not the learner's settings; pass None for a reading that cannot be trusted"
        )
    return DivergenceError(
        f"the inverse estimate diverged at movement {state.movements} (step {state.steps + 1}): "
        f"a posture became non-finite or exceeded {layout.MAX_POSTURE:g}. Likely causes: "
        f"learning_rate={cfg.learning_rate!r} too high (the paper uses 0.001-0.5), "
        f"sigma={cfg.sigma!r} too large, radius={cfg.radius!r} far too small (the paper uses 0.1 m), "
        f"or targets far outside the robot's reach "
        f"(largest |coordinate| {reach:.3g} m)"
    )
