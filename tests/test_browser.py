"""The exported replay renders in a real browser (headless Debian chromium), offline, and plays.

CI installs chromium (.ci/run); there these tests must run (CI=true makes a missing chromium a failure),
elsewhere they are skipped without it. The pixel thresholds are derived from the scene's geometry: the
camera looks straight down on the planar arm from ``Scene.camera_distance`` with meshcat's 75 degree
field of view, so a link of length l and radius r covers about (l - 2 r_joint) * 2 r * ppm^2 pixels,
ppm being pixels per metre in the arm's plane.
"""

from __future__ import annotations

import asyncio
import json
import math
import os
import shutil
import subprocess
import time
import urllib.request
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

import gb_pin
from gb_pin.viewer import Viewer, export_replay
from gb_pin.viewer.cache import OfflineWindow
from gb_pin.viewer.scene import Scene
from gb_pin.viewer.style import CAMERA_FOV, LINK_COLOR

WIDTH, HEIGHT = 800, 600
pytestmark = pytest.mark.slow  # chromium starts and renders: outside the quick subset (pytest -m "not slow")


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail("chromium is not installed; CI must install it (.ci/run) so that the browser tests run")
    pytest.skip("chromium is not installed (apt-get install chromium)")


def screenshot(page: Path, png: Path, tmp: Path, budget_ms: int) -> np.ndarray:
    """Render ``page`` headless after ``budget_ms`` of virtual time; returns the RGB pixels."""
    profile = tmp / f"profile-{png.stem}"  # a fresh profile: no state between runs
    cmd = [
        _chromium(),
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--enable-unsafe-swiftshader",
        "--disable-background-networking",
        "--disable-component-update",
        "--no-first-run",
        f"--user-data-dir={profile}",
        f"--screenshot={png}",
        f"--window-size={WIDTH},{HEIGHT}",
        f"--virtual-time-budget={budget_ms}",
        page.resolve().as_uri(),
    ]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert png.is_file(), f"chromium wrote no screenshot (exit {proc.returncode}): {proc.stderr[-2000:]}"
    return np.asarray(Image.open(png).convert("RGB")).astype(int)


def link_mask(rgb: np.ndarray) -> np.ndarray:
    """Pixels of the links' orange (LINK_COLOR under meshcat's lights): hue within 12 degrees, saturated."""
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    mx, mn = rgb.max(axis=-1), rgb.min(axis=-1)
    sat = (mx - mn) / np.maximum(mx, 1)
    hue = np.degrees(np.arctan2(math.sqrt(3) * (g - b), 2 * r - g - b)) % 360
    lr, lg, lb = (LINK_COLOR >> 16) & 255, (LINK_COLOR >> 8) & 255, LINK_COLOR & 255
    link_hue = math.degrees(math.atan2(math.sqrt(3) * (lg - lb), 2 * lr - lg - lb)) % 360
    return (np.abs(hue - link_hue) < 12) & (sat > 0.5) & (mx > 80)


@pytest.fixture(scope="module")
def replay(tmp_path_factory: Any) -> tuple[Path, Scene, gb_pin.BabbleResult]:
    """A short planar5 run with its first movements recorded, exported to one HTML file."""
    tmp = tmp_path_factory.mktemp("browser")
    result = gb_pin.babble(
        "planar5", movements=20, seed=0, record=gb_pin.Recording(every=1, first=0, last=10)
    )
    page = tmp / "replay.html"
    export_replay(result, page, speed=1.0)
    scene = Scene(OfflineWindow(), result.target, result.targets)
    scene.draw_static()  # the same camera as the page's
    return page, scene, result


def expected_link_pixels(scene: Scene) -> float:
    """Projected area of the links in pixels, from the camera distance and the field of view."""
    visible_height = 2.0 * scene.camera_distance * math.tan(math.radians(CAMERA_FOV / 2.0))  # [m]
    ppm = HEIGHT / visible_height
    fig = scene.figure
    area = sum(
        (float(np.linalg.norm(b - a)) - 2 * fig.joint_radius) * 2 * fig.link_radius for _, a, b in fig.links
    )
    return area * ppm**2


def test_replay_draws_the_chain_offline(
    replay: tuple[Path, Scene, gb_pin.BabbleResult], tmp_path: Path
) -> None:
    """The page, opened from disk with every network fetch forbidden, draws the arm's links.

    Half the derived link area is the lower bound (lighting darkens cylinder edges past the colour test,
    joints cover link ends); twice the area the upper one (a wrong camera or scale breaks it).
    """
    page, scene, _ = replay
    pixels = int(link_mask(screenshot(page, tmp_path / "early.png", tmp_path, 1500)).sum())
    expected = expected_link_pixels(scene)
    assert 0.5 * expected <= pixels <= 2.0 * expected, (pixels, expected)


def test_replay_animation_plays(replay: tuple[Path, Scene, gb_pin.BabbleResult], tmp_path: Path) -> None:
    """Two screenshots 2 s apart in virtual time (two movements at speed 1) show the arm in other postures.

    The links' pixels must change by at least a fifth of the arm's area: the recorded postures 50 steps
    apart differ by far more than a link's width (checked on the recording).
    """
    page, scene, result = replay
    rec = result.recording
    assert rec is not None
    moved = np.linalg.norm(rec.position[50] - rec.position[0])
    assert moved > 4 * scene.figure.link_radius  # the recording itself moves visibly
    a = link_mask(screenshot(page, tmp_path / "t1.png", tmp_path, 1000))
    b = link_mask(screenshot(page, tmp_path / "t2.png", tmp_path, 3000))
    assert a.sum() > 0 and b.sum() > 0
    changed = int((a ^ b).sum())
    assert changed >= 0.2 * expected_link_pixels(scene), changed


class DevToolsPage:
    """Headless chromium showing ``url``, driven through the DevTools protocol (screenshots on demand).

    The debugging port is chosen by chromium (port 0) and read from the profile's DevToolsActivePort;
    chromium binds it to 127.0.0.1.
    """

    def __init__(self, url: str, tmp: Path) -> None:
        profile = tmp / "profile-live"
        self.proc = subprocess.Popen(
            [
                _chromium(),
                "--headless",
                "--no-sandbox",
                "--disable-gpu",
                "--enable-unsafe-swiftshader",
                "--disable-background-networking",
                "--disable-component-update",
                "--no-first-run",
                f"--user-data-dir={profile}",
                "--remote-debugging-port=0",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        port_file = profile / "DevToolsActivePort"
        deadline = time.monotonic() + 60
        while not (port_file.is_file() and port_file.read_text().strip()):
            assert time.monotonic() < deadline, "chromium did not open its DevTools port"
            time.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json") as resp:
            pages = json.load(resp)
        self.ws_url = next(p for p in pages if p["type"] == "page")["webSocketDebuggerUrl"]
        self.loop = asyncio.new_event_loop()
        self.ws: Any = self.loop.run_until_complete(self._connect())
        self._id = 0
        self.call(
            "Emulation.setDeviceMetricsOverride",
            width=WIDTH,
            height=HEIGHT,
            deviceScaleFactor=1,
            mobile=False,
        )
        self.call("Page.navigate", url=url)

    async def _connect(self) -> Any:
        from tornado.websocket import websocket_connect

        return await websocket_connect(self.ws_url, max_message_size=1 << 28)

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        """Send one DevTools command and return its result."""
        self._id += 1
        ident = self._id

        async def roundtrip() -> dict[str, Any]:
            await self.ws.write_message(json.dumps({"id": ident, "method": method, "params": params}))
            while True:
                msg = json.loads(await self.ws.read_message())
                if msg.get("id") == ident:
                    assert "error" not in msg, msg
                    return dict(msg["result"])

        return self.loop.run_until_complete(asyncio.wait_for(roundtrip(), 60))

    def screenshot(self, png: Path) -> np.ndarray:
        """The page's pixels now, as RGB."""
        import base64

        png.write_bytes(base64.b64decode(self.call("Page.captureScreenshot", format="png")["data"]))
        return np.asarray(Image.open(png).convert("RGB")).astype(int)

    def close(self) -> None:
        """Disconnect and end chromium."""
        self.ws.close()
        self.loop.close()
        self.proc.terminate()
        self.proc.wait(30)


def test_live_view_draws_the_chain_in_chromium(tmp_path: Path) -> None:
    """The live page served on 127.0.0.1 renders the streamed arm, and keeps it after the server closes.

    After a run watched by chromium, the page shows the links within the same derived bounds as the
    offline page.
    """
    viewer = Viewer()
    page = DevToolsPage(viewer.url, tmp_path)
    try:
        assert viewer.wait_for_browser(60), "chromium did not connect to the viewer"
        result = gb_pin.babble("planar5", movements=30, seed=0, viewer=viewer, observe_every=1)
        viewer.finish()
        viewer.close()
        scene = Scene(OfflineWindow(), result.target, result.targets)
        scene.draw_static()
        expected = expected_link_pixels(scene)
        # The page draws as messages arrive: poll until the links show (or give up).
        deadline = time.monotonic() + 30
        while True:
            pixels = int(link_mask(page.screenshot(tmp_path / "live.png")).sum())
            if pixels >= 0.5 * expected or time.monotonic() > deadline:
                break
            time.sleep(0.5)
        # The legend, put into meshcat's own page by an evaluated set_control (gb_pin.viewer.legend).
        legend = page.call(
            "Runtime.evaluate", expression="(document.getElementById('gb-pin-legend') || {}).innerText || ''"
        )["result"]["value"]
        controls = "Array.from(document.querySelectorAll('.dg .property-name')).map(e => e.innerText).join()"
        buttons = page.call("Runtime.evaluate", expression=controls)
    finally:
        viewer.close()
        page.close()
    assert 0.5 * expected <= pixels <= 2.0 * expected, (pixels, expected)
    assert "planar5" in legend and "movement r = 30" in legend and "target set X" in legend, legend
    assert "gb_pin_legend" not in buttons["result"]["value"]  # the control carrying it was removed again
