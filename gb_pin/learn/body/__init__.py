"""The learner's body: compiled forward kinematics (joints) and the task map (what x is)."""

from gb_pin.learn.body.chain import Body, KinematicChain, body_forward
from gb_pin.learn.body.components import ORIENTATION, POINTING, POSITION, TaskComponents
from gb_pin.learn.body.joints import PRISMATIC, REVOLUTE, Joints, joints_forward
from gb_pin.learn.body.kinematics import Kinematics
from gb_pin.learn.body.task import (
    FRAME_POSITION,
    STACKED,
    FramePosition,
    StackedTask,
    StackedTaskArrays,
    TaskArrays,
    TaskMap,
    task_forward,
)

__all__ = [
    "FRAME_POSITION",
    "ORIENTATION",
    "POINTING",
    "POSITION",
    "PRISMATIC",
    "REVOLUTE",
    "STACKED",
    "Body",
    "FramePosition",
    "Joints",
    "KinematicChain",
    "Kinematics",
    "StackedTask",
    "StackedTaskArrays",
    "TaskArrays",
    "TaskComponents",
    "TaskMap",
    "body_forward",
    "joints_forward",
    "task_forward",
]
