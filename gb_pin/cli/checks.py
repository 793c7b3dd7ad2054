"""Checks of the command line's arguments, made before any work: each failure is one line, exit 2.

Output paths are checked to be writable (:func:`gb_pin._files.check_writable`) before a run
starts, so that a long run never ends in a traceback over a missing directory.
"""

from __future__ import annotations

import argparse
import math
import os
from typing import Any

from gb_pin import _validation as check
from gb_pin._files import check_directory, check_writable
from gb_pin.exceptions import InvalidArgumentError

BABBLE_DEFAULTS = {"robot": "planar20", "movements": 1000, "seed": 0}


def outputs(args: argparse.Namespace, **options: str) -> None:
    """Check each output option given (``attribute=option name``), e.g. ``out="--out"``."""
    for attribute, option in options.items():
        value = getattr(args, attribute, None)
        if value is not None:
            check_writable(value, option)


def no_clobber(path: Any, option: str, overwrite: bool) -> None:
    """Refuse an existing output file unless ``--overwrite`` was given: two runs never replace each other.

    Raises:
        InvalidArgumentError: one line naming the file and the option that allows replacing it.
    """
    if path is not None and not overwrite and os.path.lexists(path):
        raise InvalidArgumentError(
            f"{option} {path}: the file exists; give --overwrite (or --force) to replace it, "
            f"or another {option}"
        )


def fresh_outputs(args: argparse.Namespace, **options: str) -> None:
    """:func:`outputs`, and :func:`no_clobber` for each (``--overwrite`` lets them replace files)."""
    outputs(args, **options)
    for attribute, option in options.items():
        no_clobber(getattr(args, attribute, None), option, getattr(args, "overwrite", False))


def finite(option: str, value: Any, minimum: float = 0.0, strict: bool = False) -> None:
    """Raise unless ``value`` is None or a finite number >= ``minimum`` (> where ``strict``)."""
    if value is None:
        return
    if not math.isfinite(value) or value < minimum or (strict and value == minimum):
        relation = ">" if strict else ">="
        raise InvalidArgumentError(f"{option} must be a finite number {relation} {minimum:g}, got {value!r}")


def babble(args: argparse.Namespace) -> None:
    """``gb-pin babble``'s arguments: combinations, ranges and outputs; fills in the defaults.

    Raises:
        InvalidArgumentError: naming the option and what is valid.
    """
    if args.resume is not None and args.continue_from is not None:
        raise InvalidArgumentError(
            "--resume finishes a checkpoint's run, --continue extends a result: not both"
        )
    if args.continue_from is not None:
        if args.seed is not None:
            raise InvalidArgumentError("--continue goes on with the run's own random stream: drop --seed")
        args.movements = BABBLE_DEFAULTS["movements"] if args.movements is None else args.movements
        check.movements("--movements", args.movements, minimum=1)
    elif args.resume is not None:
        given = [f"--{k}" for k in BABBLE_DEFAULTS if getattr(args, k) is not None]
        if given:
            raise InvalidArgumentError(
                f"--resume continues the checkpoint's run with its own robot, movements and seed: "
                f"drop {', '.join(given)}"
            )
        if args.checkpoint is not None:
            raise InvalidArgumentError("--resume keeps writing the checkpoint it resumes: drop --checkpoint")
        check_writable(args.resume, "--resume")
    else:
        for key, default in BABBLE_DEFAULTS.items():
            if getattr(args, key) is None:
                setattr(args, key, default)
        check.movements("--movements", args.movements, minimum=1)
        check.positive_int("--seed", args.seed, minimum=0)
    if args.checkpoint_every is not None:
        if args.checkpoint is None and args.resume is None:
            raise InvalidArgumentError("--checkpoint-every needs --checkpoint FILE (or --resume FILE)")
        check.positive_int("--checkpoint-every", args.checkpoint_every)
    if getattr(args, "sigma", None) == 0:
        raise InvalidArgumentError(
            "--sigma 0 means no exploration: goal babbling would learn nothing; give a value > 0"
        )
    if args.record_every is not None:
        check.positive_int("--record-every", args.record_every)
    finite("--view-wait", args.view_wait)
    finite("--view-pace", args.view_pace, strict=True)
    outputs(args, out="--out", checkpoint="--checkpoint")
    no_clobber(args.out, "--out", getattr(args, "overwrite", False))
    if (
        args.checkpoint is not None
        and not getattr(args, "overwrite", False)
        and os.path.lexists(args.checkpoint)
    ):
        raise InvalidArgumentError(  # another run's checkpoint: the run it holds is not lost
            f"--checkpoint {args.checkpoint}: the file exists (another run's checkpoint?); --resume "
            f"{args.checkpoint} continues its run, --overwrite starts this one over it, "
            "or give another --checkpoint"
        )


def directory(path: Any, option: str) -> None:
    """Raise unless ``path`` is a writable directory or can be created (its parent is one)."""
    check_directory(path, option)
