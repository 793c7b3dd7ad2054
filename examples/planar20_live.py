"""Watch a 20-joint planar arm learn its inverse kinematics live in the browser (meshcat, 127.0.0.1 only).

    python examples/planar20_live.py                  # prints the URL, waits for a browser, babbles
    python examples/planar20_live.py --pace 30        # slow motion: 30 movements per second
    python examples/planar20_live.py --measure        # how much the viewer slows learning down

``--measure`` runs the same seeded run with and without the viewer, alternately, with a client
connected (headless chromium if installed, else a websocket client process), and prints the median
slowdown of the learning's wall time.
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import gb_pin
from gb_pin.viewer import Viewer, serve_until_interrupted

_WS_CLIENT = """
import asyncio, sys
from tornado.websocket import websocket_connect
async def main():
    ws = await websocket_connect(sys.argv[1])
    while await ws.read_message() is not None:
        pass
asyncio.run(main())
"""


def watch(args: argparse.Namespace) -> None:
    """Babble with a live viewer, then keep serving the final state until Ctrl-C."""
    viewer = Viewer(args.port, pace=args.pace)
    print(f"open {viewer.url} in a browser (waiting up to {args.wait:g} s)")
    viewer.wait_for_browser(args.wait)
    result = gb_pin.babble(
        "planar20",
        movements=args.movements,
        seed=args.seed,
        viewer=viewer,
        observe_every=1 if args.pace else 10,
    )
    viewer.finish()
    print(f"E^X = {result.error:.4f} m after {result.movements} movements; Ctrl-C to quit")
    serve_until_interrupted(viewer, seconds=args.hold)


def _client(url: str, kind: str) -> subprocess.Popen[bytes]:
    if kind == "chromium" and shutil.which("chromium"):
        profile = tempfile.mkdtemp(prefix="gb_pin-chromium-")
        return subprocess.Popen(
            ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader",
             "--disable-background-networking", "--no-first-run", f"--user-data-dir={profile}",
             "--remote-debugging-port=0", url],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
    ws = url.replace("http://", "ws://").replace("/static/", "/")
    return subprocess.Popen([sys.executable, "-c", _WS_CLIENT, ws])


def measure(args: argparse.Namespace) -> None:
    """Median slowdown of learning (BabbleResult.wall_time) with a live viewer and a connected client."""
    gb_pin.babble("planar20", movements=2, seed=0)  # compile the kernels first
    viewer = Viewer(args.port)
    client = _client(viewer.url, args.client)
    try:
        if not viewer.wait_for_browser(30):
            raise SystemExit("no client connected")
        time.sleep(1.0)  # let the page settle
        for every in (10, 1):
            plain, watched = [], []
            for i in range(args.repeat):
                runs = [False, True] if i % 2 == 0 else [True, False]
                for with_viewer in runs:
                    res = gb_pin.babble(
                        "planar20",
                        movements=args.movements,
                        seed=args.seed,
                        viewer=viewer if with_viewer else None,
                        observe_every=every,
                    )
                    (watched if with_viewer else plain).append(res.wall_time)
            ratios = [w / p for w, p in zip(watched, plain, strict=True)]
            slowdown = statistics.median(ratios) - 1
            print(
                f"observe_every={every:<3} without {statistics.median(plain):.3f} s, "
                f"with viewer {statistics.median(watched):.3f} s: slowdown {slowdown:+.1%} "
                f"(median of {args.repeat} pairs; min {min(ratios) - 1:+.1%}, max {max(ratios) - 1:+.1%}); "
                f"{viewer.frames} frames sent so far"
            )
    finally:
        viewer.close()
        client.terminate()
        client.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--movements", type=int, default=1000, help="movements (default 1000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument(
        "--port", type=int, default=None, help="port on 127.0.0.1 (default first free from 7000)"
    )
    parser.add_argument("--pace", type=float, default=None, help="at most this many movements per second")
    parser.add_argument("--wait", type=float, default=60.0, help="seconds to wait for a browser (default 60)")
    parser.add_argument(
        "--hold", type=float, default=None, help="serve this long after the run (default: Ctrl-C)"
    )
    parser.add_argument("--measure", action="store_true", help="measure the viewer's slowdown instead")
    parser.add_argument("--repeat", type=int, default=7, help="--measure: pairs of runs (default 7)")
    parser.add_argument(
        "--client", choices=["chromium", "websocket"], default="chromium", help="--measure client"
    )
    args = parser.parse_args()
    if args.measure:
        measure(args)
    else:
        watch(args)


if __name__ == "__main__":
    main()
