"""``python -m gb_pin.cli``: the gb-pin command line."""

from gb_pin.cli import run

run()
