"""``python -m gb_pin``: the gb-pin command line, as ``gb-pin``."""

import sys

from gb_pin.cli import main

if __name__ == "__main__":
    sys.exit(main())
