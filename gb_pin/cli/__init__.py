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

import argparse
import os
import sys
import warnings
from collections.abc import Sequence
from typing import Any, NoReturn

from gb_pin.cli.parser import build_parser
from gb_pin.exceptions import GbPinError, GbPinWarning

__all__ = ["build_parser", "main", "run"]


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``gb-pin``: user mistakes print one line and exit with status 2."""
    return _main(argv)[0]


def run() -> NoReturn:
    """``gb-pin`` and ``python -m gb_pin`` as a program: :func:`main`, then the process ends.

    A command that sets ``args.quick_exit`` (``babble`` without a viewer: it has written and
    closed everything it was asked for) ends the process with ``os._exit`` once the output is
    flushed, skipping the interpreter's teardown of numba's and LLVM's objects (0.2-0.3 s of a
    one-second run on the 2-core machine). Every other command exits as usual.
    """
    code, args = _main(None)
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (BrokenPipeError, OSError):
        pass
    if args is not None and getattr(args, "quick_exit", False):
        os._exit(code)
    sys.exit(code)


def _main(argv: Sequence[str] | None) -> tuple[int, argparse.Namespace | None]:
    args = build_parser().parse_args(argv)
    previous = warnings.showwarning

    def show(message: Warning | str, category: type[Warning], *rest: Any, **kw: Any) -> None:
        """gb_pin's warnings in one line, ``gb-pin: warning: ...`` (not a source line: the user's view)."""
        if issubclass(category, GbPinWarning):
            print(f"gb-pin: warning: {message}", file=sys.stderr)
        else:
            previous(message, category, *rest, **kw)

    warnings.showwarning = show
    try:
        return int(args.func(args)), args
    except GbPinError as exc:
        print(f"gb-pin: error: {exc}", file=sys.stderr)
        return 2, args
    except BrokenPipeError:
        # Output piped into e.g. `head`: stop quietly, as Unix tools do.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0, None
    except KeyboardInterrupt as exc:
        print(f"gb-pin: {exc or 'interrupted'}", file=sys.stderr)
        return 130, None
    finally:
        warnings.showwarning = previous
