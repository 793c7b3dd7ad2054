"""Runs and their files: ``babble()`` / ``resume()``, :class:`BabbleResult`, result files and checkpoints.

- :mod:`~gb_pin.runs.api`: ``babble`` (a robot name or target in, a result out), ``resume``, ``warmup``;
- :mod:`~gb_pin.runs.result`: :class:`BabbleResult`, ``save_result``, ``load_result``;
- :mod:`~gb_pin.runs.results_file`, :mod:`~gb_pin.runs.checkpoint`, :mod:`~gb_pin.runs.archive`: the ``.npz``
  formats (JSON header, plain arrays, no pickle), written atomically.

Submodules are imported on use; this package module imports nothing.
"""
