"""The legend over the 3-D views: robot, movement r, E^X, D^home, colours; static offline, evaluated live."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

import gb_pin
from gb_pin.viewer.cache import OfflineWindow, SceneCache
from gb_pin.viewer.commands import encode
from gb_pin.viewer.legend import CONTROL, ELEMENT_ID, Legend, legend_command, legend_html, status_line
from gb_pin.viewer.page import CONTENT_SECURITY_POLICY
from gb_pin.viewer.scene import Scene

pytest.importorskip("meshcat")
from test_viewer import Client, html_commands


@pytest.fixture(scope="module")
def run() -> gb_pin.BabbleResult:
    return gb_pin.babble("planar5", movements=30, seed=0, record=gb_pin.Recording(every=1, first=0, last=5))


def _legend_text(html: str) -> str:
    match = re.search(rf'<div id="{ELEMENT_ID}".*?</div></div>(?=\s*<script)', html, re.S)
    assert match, "no legend in the page"
    return re.sub(r"<[^>]+>", "", match.group(0)).replace("&middot;", "·")


def test_exported_model_page_is_labelled_and_keeps_its_policy(
    run: gb_pin.BabbleResult, tmp_path: Path
) -> None:
    """`show --html`: robot, movements, final E^X and D^home, every colour drawn; static, CSP intact, no eval.

    A model shown has no current goal nor trail (issue 25): the legend does not list them.
    """
    path = tmp_path / "model.html"
    gb_pin.viewer.export_model(run, path)
    html = path.read_text()
    assert CONTENT_SECURITY_POLICY in html and "unsafe-eval" not in html
    text = _legend_text(html)
    for word in (
        "planar5",
        "5 joints",
        "movement r = 30",
        f"EX = {run.error:.4g} m",
        "Dhome",
        "target set X*",
    ):
        assert word in text, (word, text)
    assert "learned postures g(x*)" in text and "current goal" not in text and "trail" not in text
    assert not [c for c in html_commands(html) if c["type"] in ("set_control", "delete_control")]


def test_exported_replay_says_what_is_replayed_and_why_the_overlay_is_hidden(
    run: gb_pin.BabbleResult, tmp_path: Path
) -> None:
    """`replay --html`: the replayed movements, the final E^X, and where the hidden overlay is."""
    path = tmp_path / "replay.html"
    gb_pin.viewer.export_replay(run, path)
    text = _legend_text(path.read_text())
    assert "replaying movements 0-4" in text and "movement r = 30" in text
    assert "hidden" in text and "Open Controls" in text


def test_legend_escapes_names_and_the_cache_keeps_the_last() -> None:
    """A robot name with markup is escaped; the cache keeps the last legend, live pages get it last."""
    box = legend_html(Legend("<script>x</script>", status=status_line(5, 0.1, 0.2, 4)))
    assert "<script>" not in box and "&lt;script&gt;" in box and "(at r = 4)" in box
    cache = SceneCache()
    for name in ("robot-alpha", "robot-beta"):
        cache.apply(*encode(legend_command(Legend(name))))
    assert "robot-beta" in cache.legend_html and "robot-alpha" not in cache.legend_html
    assert "robot-beta" in cache.html() and "robot-alpha" not in cache.html()
    last = [m for m in cache.messages() if CONTROL.encode() in m]
    assert len(last) == 2  # set_control, then delete_control (no button left in meshcat's panel)


def test_3d_scenes_hide_the_floor_grid_through_the_robot() -> None:
    """meshcat's grid (world z = 0, through a humanoid's pelvis) is hidden in 3-D scenes, kept in 2-D."""

    def grid_hidden(robot: str) -> bool:
        window = OfflineWindow()
        target = gb_pin.load_robot(robot)
        Scene(window, target, target.targets).draw_static()
        cmds = html_commands(window.scene.html())
        return any(c.get("path") == "/Grid" and c.get("property") == "visible" for c in cmds)

    assert grid_hidden("talos_left_arm") and not grid_hidden("planar5")


def test_live_viewer_updates_the_legend() -> None:
    """A live browser receives legend commands with the movement count and E^X while babbling."""
    viewer = gb_pin.viewer.Viewer()
    client = Client(viewer.url)
    assert viewer.wait_for_browser(5)
    gb_pin.babble("planar5", movements=20, seed=0, viewer=viewer, observe_every=1)
    viewer.finish()
    viewer.close()
    messages: list[dict[str, Any]] = client.stop()
    legends = [m["html"] for m in messages if m["type"] == "set_control" and m["name"] == CONTROL]
    assert legends and "movement r = 20" in legends[-1] and "E<sup>X</sup>" in legends[-1]
    assert any(m["type"] == "delete_control" for m in messages)
