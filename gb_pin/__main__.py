"""``python -m gb_pin``: the gb-pin command line, as ``gb-pin``."""

from gb_pin.cli import run

if __name__ == "__main__":
    run()
