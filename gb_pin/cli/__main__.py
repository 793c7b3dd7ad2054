"""``python -m gb_pin.cli``: the gb-pin command line."""

import sys

from gb_pin.cli import main

sys.exit(main())
