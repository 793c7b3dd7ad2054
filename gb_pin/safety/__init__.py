"""Safe babbling: the robot's collision shapes, its collision matrix, obstacles, and the check of each ask.

:class:`~gb_pin.safety.checker.CollisionChecker` is built by ``babble(obstacles=..., self_collision=...)``
and sessions; it imports pinocchio (the learner, :mod:`gb_pin.learn`, sees it only as a guard function).
"""

from gb_pin.safety.obstacles import Box, Sphere, Table, check_obstacles, parse_obstacle

__all__ = ["Box", "Sphere", "Table", "check_obstacles", "parse_obstacle"]
