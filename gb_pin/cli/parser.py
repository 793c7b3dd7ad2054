"""The ``gb-pin`` argument parser, assembled from the commands' ``add_<command>`` functions.

Each command module's ``add_<command>(sub)`` registers its sub-command with the function adding
its options and ``func`` (what :func:`gb_pin.cli.main` calls with the parsed arguments), through
:class:`~gb_pin.cli.options.CommandParser`; this module only orders them.
The commands import what they run inside their functions, so building the parser stays cheap.
"""

from __future__ import annotations

import argparse

from gb_pin.cli.babble import add_babble
from gb_pin.cli.bench import add_bench
from gb_pin.cli.ik import add_ik
from gb_pin.cli.options import CommandParser
from gb_pin.cli.plot import add_plot
from gb_pin.cli.reproduce import add_reproduce
from gb_pin.cli.robots import add_robots
from gb_pin.cli.trials import add_trials
from gb_pin.cli.viewing import add_replay_and_show

PROG = "gb-pin"
DESCRIPTION = "Online Goal Babbling (Rolf, Steil & Gienger 2011) on Pinocchio robots."


def build_parser() -> argparse.ArgumentParser:
    """The ``gb-pin`` argument parser; each sub-command sets ``func``, the function running it."""
    from gb_pin import __version__

    parser = argparse.ArgumentParser(prog=PROG, description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=CommandParser)
    # The order of ``gb-pin --help``.
    add_babble(sub)
    add_bench(sub)
    add_trials(sub)
    add_ik(sub)
    add_reproduce(sub)
    add_replay_and_show(sub)
    add_plot(sub)
    add_robots(sub)
    return parser
