"""The learner: online goal babbling (paper Sec. II), robot-agnostic.

It sees forward kinematics (a :class:`KinematicChain` of plain arrays), a home posture,
joint limits and a target set, never a robot type, and imports neither pinocchio,
meshcat, matplotlib nor dask:

- :mod:`~gb_pin.learn.config`: the hyperparameters, defined once;
- :mod:`~gb_pin.learn.llm` / :mod:`~gb_pin.learn.llm_kernels`: the local-linear map (Sec. II-C);
- :mod:`~gb_pin.learn.exploration`: the structured noise (Eq. 8);
- :mod:`~gb_pin.learn.weighting`: the example weights (Eqs. 4-6);
- :mod:`~gb_pin.learn.goals`: who chooses each movement's goal (the paper: uniform over X*);
- :mod:`~gb_pin.learn.body`: compiled forward kinematics and the task map;
- :mod:`~gb_pin.learn.loop`: the compiled loop (Eqs. 1-3, 7), its arguments in :mod:`~gb_pin.learn.layout`;
- :mod:`~gb_pin.learn.state`, :mod:`~gb_pin.learn.learner`: the resumable state and :class:`GoalBabbling`;
- :mod:`~gb_pin.learn.snapshot`: the state as validated plain arrays (checkpoints);
- :mod:`~gb_pin.learn.metrics`: E^X, D^home, S(Q, e) (Eqs. 9-11).

The names below are exported lazily (PEP 562): ``gb_pin.learn.config`` alone loads no compiler.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gb_pin._lazy import lazy_exports

_EXPORTS: dict[str, str] = {
    "FramePosition": "gb_pin.learn.body",
    "KinematicChain": "gb_pin.learn.body",
    "TaskMap": "gb_pin.learn.body",
    "HYPERPARAMETERS": "gb_pin.learn.config",
    "BabbleConfig": "gb_pin.learn.config",
    "default_sigma": "gb_pin.learn.config",
    "CyclicGoals": "gb_pin.learn.goals",
    "GoalGenerator": "gb_pin.learn.goals",
    "PythonGoals": "gb_pin.learn.goals",
    "UniformGoals": "gb_pin.learn.goals",
    "History": "gb_pin.learn.history",
    "RecordedSteps": "gb_pin.learn.history",
    "Recording": "gb_pin.learn.history",
    "GoalBabbling": "gb_pin.learn.learner",
    "LocalLinearMap": "gb_pin.learn.llm",
    "evaluation_schedule": "gb_pin.learn.metrics",
    "speed": "gb_pin.learn.metrics",
    "BabbleState": "gb_pin.learn.state",
    "Kinematics": "gb_pin.learn.body.kinematics",
}

# the same names as _EXPORTS (a literal, for linters; tests/test_architecture.py checks it)
__all__ = [
    "HYPERPARAMETERS",
    "BabbleConfig",
    "BabbleState",
    "CyclicGoals",
    "FramePosition",
    "GoalBabbling",
    "GoalGenerator",
    "History",
    "KinematicChain",
    "Kinematics",
    "LocalLinearMap",
    "PythonGoals",
    "RecordedSteps",
    "Recording",
    "TaskMap",
    "UniformGoals",
    "default_sigma",
    "evaluation_schedule",
    "speed",
]


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:
    from gb_pin.learn.body import FramePosition, KinematicChain, TaskMap
    from gb_pin.learn.body.kinematics import Kinematics
    from gb_pin.learn.config import HYPERPARAMETERS, BabbleConfig, default_sigma
    from gb_pin.learn.goals import CyclicGoals, GoalGenerator, PythonGoals, UniformGoals
    from gb_pin.learn.history import History, RecordedSteps, Recording
    from gb_pin.learn.learner import GoalBabbling
    from gb_pin.learn.llm import LocalLinearMap
    from gb_pin.learn.metrics import evaluation_schedule, speed
    from gb_pin.learn.state import BabbleState
