"""Command line: ``gb-pin babble | bench | trials | reproduce | replay | show | plot | robots``.

- :mod:`~gb_pin.cli.parser`: :func:`build_parser`, assembled from the commands' ``add_<command>``;
- :mod:`~gb_pin.cli.options`: option helpers, the learner's options from the hyperparameter table;
- :mod:`~gb_pin.cli.babble`: one run, resumed, recorded, checkpointed or watched live;
- :mod:`~gb_pin.cli.trials`, :mod:`~gb_pin.cli.bench`, :mod:`~gb_pin.cli.robots`,
  :mod:`~gb_pin.cli.reproduce`: trials, step timings, the presets, the paper's figures;
- :mod:`~gb_pin.cli.viewing`: ``replay`` and ``show``, a saved result in the browser;
- :mod:`~gb_pin.cli.plot`: ``plot``, the learning curves of a result or of trials.

Imports go one way: this module imports the parser, the parser the commands, the commands the
option helpers. Nothing is imported from here by the other modules, nor outside the command line.
Importing this package is cheap (no numba, no pinocchio): the commands import what they run
inside their functions, so that ``gb-pin --help`` is fast.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from gb_pin.cli.parser import build_parser
from gb_pin.exceptions import GbPinError

__all__ = ["build_parser", "main"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``gb-pin``: user mistakes print one line and exit with status 2."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except GbPinError as exc:
        print(f"gb-pin: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # Output piped into e.g. `head`: stop quietly, as Unix tools do.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except KeyboardInterrupt as exc:
        print(f"gb-pin: {exc or 'interrupted'}", file=sys.stderr)
        return 130
