r"""How long a command takes to answer Ctrl-C: SIGINT after a delay, then to its "interrupted" line and exit.

    python scripts/ctrl_c_latency.py 15 gb-pin babble --movements 1000000 --eval-targets t.csv \
        --checkpoint c.npz

Prints the exit status, the seconds from SIGINT to the first stderr line saying "interrupted" and to
the exit, and the load average (measurements on a shared machine need it).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time


def main() -> None:
    """Run the command, interrupt it, print the times."""
    delay, cmd = float(sys.argv[1]), sys.argv[2:]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    marks: dict[str, float] = {}

    def read() -> None:
        assert proc.stderr is not None
        for line in proc.stderr:
            if b"interrupted" in line and "line" not in marks:
                marks["line"] = time.perf_counter()

    threading.Thread(target=read, daemon=True).start()
    time.sleep(delay)
    start = time.perf_counter()
    proc.send_signal(signal.SIGINT)
    proc.wait()
    end = time.perf_counter()
    line = marks.get("line", float("nan")) - start
    print(f"rc {proc.returncode}: line {line:.2f} s, exit {end - start:.2f} s after SIGINT; "
          f"load {os.getloadavg()[0]:.1f}")  # fmt: skip


if __name__ == "__main__":
    main()
