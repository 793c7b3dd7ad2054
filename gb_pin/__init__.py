"""gb_pin: Online Goal Babbling (Rolf, Steil & Gienger, ICDL 2011) on Pinocchio kinematic targets.

>>> import gb_pin
>>> result = gb_pin.babble(robot="planar5", movements=100, seed=0)
>>> result.inverse([0.5, 0.0]).shape
(5,)

The public names are exported lazily (PEP 562): ``import gb_pin`` loads nothing heavy,
and ``import gb_pin.learn`` (the robot-agnostic learner) loads neither pinocchio nor
meshcat. The layers are described in docs/ARCHITECTURE.md.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from gb_pin._lazy import lazy_exports

__version__ = "0.1.0"

# public name -> the module that defines it
_EXPORTS: dict[str, str] = {
    "BabbleConfig": "gb_pin.learn.config",
    "default_sigma": "gb_pin.learn.config",
    "History": "gb_pin.learn.history",
    "RecordedSteps": "gb_pin.learn.history",
    "Recording": "gb_pin.learn.history",
    "BabbleState": "gb_pin.learn.state",
    "GoalBabbling": "gb_pin.learn.learner",
    "KinematicChain": "gb_pin.learn.body.chain",
    "LocalLinearMap": "gb_pin.learn.llm",
    "evaluation_schedule": "gb_pin.learn.metrics",
    "speed": "gb_pin.learn.metrics",
    "DivergenceError": "gb_pin.exceptions",
    "GbPinError": "gb_pin.exceptions",
    "GbPinWarning": "gb_pin.exceptions",
    "InvalidArgumentError": "gb_pin.exceptions",
    "NotFittedError": "gb_pin.exceptions",
    "ResultFileError": "gb_pin.exceptions",
    "UnknownRobotError": "gb_pin.exceptions",
    "UnreachableTargetWarning": "gb_pin.exceptions",
    "ExtrapolationWarning": "gb_pin.exceptions",
    "KinematicTarget": "gb_pin.robot.target",
    "RobotPreset": "gb_pin.robot.presets",
    "load_robot": "gb_pin.robot.presets",
    "robots": "gb_pin.robot.presets",
    "planar_chain": "gb_pin.robot.planar",
    "planar_home": "gb_pin.robot.planar",
    "grid_targets": "gb_pin.robot.grids",
    "BabbleResult": "gb_pin.runs.result",
    "babble": "gb_pin.runs.api",
    "resume": "gb_pin.runs.api",
    "BabbleSession": "gb_pin.runs.session",
    "babble_session": "gb_pin.runs.session",
    "FunctionTarget": "gb_pin.robot.function",
    "ExternalRobot": "gb_pin.robot.external",
    "Plant": "gb_pin.robot.plant",
    "Sensor": "gb_pin.learn.sensor",
    "FeedbackReach": "gb_pin.learn.feedback",
    "RunSpec": "gb_pin.runs.spec",
    "resume_session": "gb_pin.runs.session",
    "ChangedBody": "gb_pin.robot.bodies",
    "load_result": "gb_pin.runs.result",
    "save_result": "gb_pin.runs.result",
    "Condition": "gb_pin.experiments.trials",
    "Sweep": "gb_pin.experiments.trials",
    "TrialSet": "gb_pin.experiments.trials",
    "conditions_grid": "gb_pin.experiments.trials",
    "run_sweep": "gb_pin.experiments.trials",
    "run_trials": "gb_pin.experiments.trials",
    "Table": "gb_pin.safety.obstacles",
    "Box": "gb_pin.safety.obstacles",
    "Sphere": "gb_pin.safety.obstacles",
    "CollisionChecker": "gb_pin.safety.checker",
    "UnsafeSetupError": "gb_pin.exceptions",
}

# the same names as _EXPORTS (a literal, for linters; tests/test_architecture.py checks it)
__all__ = [
    "BabbleConfig",
    "BabbleResult",
    "BabbleSession",
    "BabbleState",
    "Box",
    "ChangedBody",
    "CollisionChecker",
    "Condition",
    "DivergenceError",
    "ExternalRobot",
    "ExtrapolationWarning",
    "FeedbackReach",
    "FunctionTarget",
    "GbPinError",
    "GbPinWarning",
    "GoalBabbling",
    "History",
    "InvalidArgumentError",
    "KinematicChain",
    "KinematicTarget",
    "LocalLinearMap",
    "NotFittedError",
    "Plant",
    "RecordedSteps",
    "Recording",
    "ResultFileError",
    "RobotPreset",
    "RunSpec",
    "Sensor",
    "Sphere",
    "Sweep",
    "Table",
    "TrialSet",
    "UnknownRobotError",
    "UnreachableTargetWarning",
    "UnsafeSetupError",
    "__version__",
    "babble",
    "babble_session",
    "conditions_grid",
    "default_sigma",
    "evaluation_schedule",
    "grid_targets",
    "load_result",
    "load_robot",
    "planar_chain",
    "planar_home",
    "resume",
    "resume_session",
    "robots",
    "run_sweep",
    "run_trials",
    "save_result",
    "speed",
]


__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS, globals())


if TYPE_CHECKING:  # what the lazy exports resolve to, for type checkers
    from gb_pin.exceptions import (
        DivergenceError,
        ExtrapolationWarning,
        GbPinError,
        GbPinWarning,
        InvalidArgumentError,
        NotFittedError,
        ResultFileError,
        UnknownRobotError,
        UnreachableTargetWarning,
        UnsafeSetupError,
    )
    from gb_pin.experiments.trials import Condition, Sweep, TrialSet, conditions_grid, run_sweep, run_trials
    from gb_pin.learn.body.chain import KinematicChain
    from gb_pin.learn.config import BabbleConfig, default_sigma
    from gb_pin.learn.feedback import FeedbackReach
    from gb_pin.learn.history import History, RecordedSteps, Recording
    from gb_pin.learn.learner import GoalBabbling
    from gb_pin.learn.llm import LocalLinearMap
    from gb_pin.learn.metrics import evaluation_schedule, speed
    from gb_pin.learn.sensor import Sensor
    from gb_pin.learn.state import BabbleState
    from gb_pin.robot.bodies import ChangedBody
    from gb_pin.robot.external import ExternalRobot
    from gb_pin.robot.function import FunctionTarget
    from gb_pin.robot.grids import grid_targets
    from gb_pin.robot.planar import planar_chain, planar_home
    from gb_pin.robot.plant import Plant
    from gb_pin.robot.presets import RobotPreset, load_robot, robots
    from gb_pin.robot.target import KinematicTarget
    from gb_pin.runs.api import babble, resume
    from gb_pin.runs.result import BabbleResult, load_result, save_result
    from gb_pin.runs.session import BabbleSession, babble_session, resume_session
    from gb_pin.runs.spec import RunSpec
    from gb_pin.safety.checker import CollisionChecker
    from gb_pin.safety.obstacles import Box, Sphere, Table
