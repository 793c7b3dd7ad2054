"""gb_pin: Online Goal Babbling (Rolf, Steil & Gienger, ICDL 2011) on Pinocchio kinematic targets.

>>> import gb_pin
>>> result = gb_pin.babble(robot="planar5", movements=100, seed=0)
>>> result.inverse([0.5, 0.0]).shape
(5,)
"""

from gb_pin.api import BabbleResult, babble, resume
from gb_pin.babbling import (
    BabbleConfig,
    BabbleState,
    GoalBabbling,
    History,
    RecordedSteps,
    Recording,
    default_sigma,
)
from gb_pin.chain import KinematicChain
from gb_pin.exceptions import (
    DivergenceError,
    GbPinError,
    GbPinWarning,
    InvalidArgumentError,
    NotFittedError,
    ResultFileError,
    UnknownRobotError,
    UnreachableTargetWarning,
)
from gb_pin.io import load_result, save_result
from gb_pin.llm import LocalLinearMap
from gb_pin.metrics import evaluation_schedule, speed
from gb_pin.robots import RobotPreset, grid_targets, load_robot, planar_chain, planar_home, robots
from gb_pin.target import KinematicTarget
from gb_pin.trials import Condition, Sweep, TrialSet, conditions_grid, run_sweep, run_trials

__version__ = "0.1.0"

__all__ = [
    "BabbleConfig",
    "BabbleResult",
    "BabbleState",
    "Condition",
    "DivergenceError",
    "GbPinError",
    "GbPinWarning",
    "GoalBabbling",
    "History",
    "InvalidArgumentError",
    "KinematicChain",
    "KinematicTarget",
    "LocalLinearMap",
    "NotFittedError",
    "RecordedSteps",
    "Recording",
    "ResultFileError",
    "RobotPreset",
    "Sweep",
    "TrialSet",
    "UnknownRobotError",
    "UnreachableTargetWarning",
    "__version__",
    "babble",
    "conditions_grid",
    "default_sigma",
    "evaluation_schedule",
    "grid_targets",
    "load_result",
    "load_robot",
    "planar_chain",
    "planar_home",
    "resume",
    "robots",
    "run_sweep",
    "run_trials",
    "save_result",
    "speed",
]
