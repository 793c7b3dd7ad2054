"""Where a cold start's compile time goes: CPU seconds per numba kernel for the README's first command.

Runs ``gb-pin babble --robot planar20 --movements 1000 --seed 0`` in this process with numba's
compile events timed in this process's CPU time (a kernel's own time, "exclusive", and with the
kernels it compiled on the way, "inclusive"). Give it an empty cache to see a cold start:

    NUMBA_CACHE_DIR=$(mktemp -d) GB_PIN_PARALLEL_COMPILE=0 python scripts/compile_profile.py

(``GB_PIN_PARALLEL_COMPILE=1``: with the cold-start helper, whose kernels this process then loads;
the helper's own CPU time is not counted here.) ``PYTHONPATH=OTHER_TREE`` profiles another checkout.
"""

from __future__ import annotations

import collections
import contextlib
import sys
import time
from typing import Any

from numba.core import event

_stack: list[list[float]] = []
_rows: dict[str, list[float]] = collections.defaultdict(lambda: [0.0, 0.0])


class _Timer(event.Listener):
    def on_start(self, ev: Any) -> None:
        _stack.append([time.process_time(), 0.0])

    def on_end(self, ev: Any) -> None:
        start, children = _stack.pop()
        spent = time.process_time() - start
        func = ev.data["dispatcher"].py_func
        row = _rows[f"{func.__module__}.{func.__qualname__}"]
        row[0] += spent
        row[1] += spent - children
        if _stack:
            _stack[-1][1] += spent


def main() -> int:
    """Run the command with the compile timer, print the table."""
    event.register("numba:compile", _Timer())
    import gb_pin.cli

    with contextlib.suppress(SystemExit):
        gb_pin.cli.main(["babble", "--robot", "planar20", "--movements", "1000", "--seed", "0", "--quiet"])
    total = time.process_time()
    ours = {k: v for k, v in _rows.items() if k.startswith("gb_pin.")}
    print(f"process CPU time {total:.2f} s, of which compiling {sum(r[1] for r in _rows.values()):.2f} s")
    print("exclusive  inclusive  kernel [CPU s]")
    for name, (inclusive, exclusive) in sorted(ours.items(), key=lambda kv: -kv[1][1]):
        print(f"{exclusive:9.2f}  {inclusive:9.2f}  {name.removeprefix('gb_pin.')}")
    numba_own = sum(r[1] for k, r in _rows.items() if k not in ours)
    print(f"{numba_own:9.2f}             numba's own overloads (random draws, np.empty, min, max, ...)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
