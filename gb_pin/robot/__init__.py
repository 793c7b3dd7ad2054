"""The robot side: Pinocchio models as the learner's kinematic targets (the layer that imports pinocchio).

- :mod:`~gb_pin.robot.target`: :class:`KinematicTarget`, one frame of a ``pin.Model`` over joints and axes;
- :mod:`~gb_pin.robot.chain_reader`, :mod:`~gb_pin.robot.reduction`, :mod:`~gb_pin.robot.postures`: reading a
  model into the learner's arrays, locking joints, reference postures;
- :mod:`~gb_pin.robot.presets`, :mod:`~gb_pin.robot.models`, :mod:`~gb_pin.robot.planar`: robots as
  data (``robots/*.toml``, example-robot-data, URDF, procedural planar chains);
- :mod:`~gb_pin.robot.grids`, :mod:`~gb_pin.robot.reachability`, :mod:`~gb_pin.robot.targets_auto`: target
  sets (regular grids, reachability checks, the "auto" grid).

Submodules are imported on use; this package module imports nothing.
"""
