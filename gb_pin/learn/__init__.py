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
- :mod:`~gb_pin.learn.metrics`: E^X, D^home, S(Q, e) (Eqs. 9-11).
"""

from gb_pin.learn.body import FramePosition, KinematicChain, TaskMap
from gb_pin.learn.config import HYPERPARAMETERS, BabbleConfig, default_sigma
from gb_pin.learn.goals import CyclicGoals, GoalGenerator, PythonGoals, UniformGoals
from gb_pin.learn.history import History, RecordedSteps, Recording
from gb_pin.learn.learner import GoalBabbling
from gb_pin.learn.llm import LocalLinearMap
from gb_pin.learn.metrics import evaluation_schedule, speed
from gb_pin.learn.state import BabbleState, Kinematics

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
