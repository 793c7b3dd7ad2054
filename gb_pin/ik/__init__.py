"""Inverse kinematics on the learned model: the learned estimate g(x*) refined on the robot's kinematics.

- :mod:`~gb_pin.ik.geometry`: goals from task vectors, geometric errors and their Jacobian (compiled);
- :mod:`~gb_pin.ik.jacobian`: the task-vector Jacobian dx/dq of every task map (compiled);
- :mod:`~gb_pin.ik.solver`: one damped least-squares attempt within the limits (compiled);
- :mod:`~gb_pin.ik.search`: seeds, restarts within a budget, several or the closest solutions (compiled);
- :mod:`~gb_pin.ik.clock`: the clock and random streams of compiled code;
- :mod:`~gb_pin.ik.robot`: the robot as the solver sees it (a preset name resolves here);
- :mod:`~gb_pin.ik.solution`: the typed results, :class:`IKSolution` and :class:`IKPath`;
- :mod:`~gb_pin.ik.pose`: :func:`pose_target`, a position and quaternion as a pose task's target;
- :mod:`~gb_pin.ik.api`: :func:`solve` and :func:`solve_path` (also ``BabbleResult.solve``).

This layer imports only gb_pin.learn and the shared modules (and the robot layer's presets for a
preset name): no Pinocchio call per iteration.
"""

from gb_pin.ik.api import (
    DEFAULT_ANGLE_TOL,
    DEFAULT_DAMPING,
    DEFAULT_MAX_ITERATIONS,
    DEFAULT_TOL,
    solve,
    solve_path,
)
from gb_pin.ik.jacobian import frame_jacobian
from gb_pin.ik.pose import pose_target
from gb_pin.ik.solution import IKPath, IKSolution

__all__ = [
    "DEFAULT_ANGLE_TOL",
    "DEFAULT_DAMPING",
    "DEFAULT_MAX_ITERATIONS",
    "DEFAULT_TOL",
    "IKPath",
    "IKSolution",
    "frame_jacobian",
    "pose_target",
    "solve",
    "solve_path",
]
