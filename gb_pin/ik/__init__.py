"""Inverse kinematics on the learned model: the learned estimate g(x*) refined on the robot's kinematics.

- :mod:`~gb_pin.ik.jacobian`: the compiled task Jacobian from the learner's joint frames;
- :mod:`~gb_pin.ik.solver`: the compiled damped least-squares refinement within the limits;
- :mod:`~gb_pin.ik.solution`: the typed results, :class:`IKSolution` and :class:`IKPath`;
- :mod:`~gb_pin.ik.api`: :func:`solve` and :func:`solve_path` (also ``BabbleResult.solve``).

This layer imports only gb_pin.learn and the shared modules: no Pinocchio call per iteration.
"""

from gb_pin.ik.api import DEFAULT_DAMPING, DEFAULT_MAX_ITERATIONS, DEFAULT_TOL, solve, solve_path
from gb_pin.ik.jacobian import frame_jacobian
from gb_pin.ik.solution import IKPath, IKSolution

__all__ = [
    "DEFAULT_DAMPING",
    "DEFAULT_MAX_ITERATIONS",
    "DEFAULT_TOL",
    "IKPath",
    "IKSolution",
    "frame_jacobian",
    "solve",
    "solve_path",
]
