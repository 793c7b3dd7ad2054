"""The meshcat viewer: loopback-only server, live streaming, recording/replay, HTML export, Fig. 3 overlay.

Live streaming is checked as meshcat's own tests do: a websocket client connects to the server on
127.0.0.1 and decodes the scene commands it receives. Rendering in a real browser is in test_browser.py.
"""

from __future__ import annotations

import ast
import asyncio
import base64
import json
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import psutil
import pytest
import umsgpack

import gb_pin
import gb_pin.viewer
from gb_pin.cli import main
from gb_pin.viewer import (
    Viewer,
    ViewerError,
    ViewerWarning,
    export_model,
    export_replay,
    open_viewer,
    parse_range,
    select_movements,
)
from gb_pin.viewer.cache import OfflineWindow
from gb_pin.viewer.commands import transform_message
from gb_pin.viewer.geometry import grid_edges, grid_shape, quaternions
from gb_pin.viewer.page import CONTENT_SECURITY_POLICY
from gb_pin.viewer.scene import Scene
from gb_pin.viewer.server import LOOPBACK, LocalServer
from gb_pin.viewer.stick import StickFigure
from gb_pin.viewer.style import OVERLAY, ROBOT, TARGET

RECORDED = 10  # movements recorded in the fixture run


class Client:
    """A websocket client in a thread, like a browser: collects the decoded meshcat commands."""

    def __init__(self, url: str) -> None:
        self.url = url.replace("http://", "ws://").replace("/static/", "/")
        self.messages: list[dict[str, Any]] = []
        self.connected = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._run()), daemon=True)
        self._thread.start()
        assert self.connected.wait(10), "the websocket client could not connect"

    async def _run(self) -> None:
        from tornado.websocket import websocket_connect

        ws = await websocket_connect(self.url)
        self.connected.set()
        while not self._stop.is_set():
            try:
                msg = await asyncio.wait_for(ws.read_message(), 0.1)
            except TimeoutError:
                continue
            if msg is None:
                break
            self.messages.append(umsgpack.unpackb(msg))
        ws.close()

    def stop(self, settle: float = 0.3) -> list[dict[str, Any]]:
        """Wait ``settle`` seconds for messages in flight, disconnect, return all received."""
        time.sleep(settle)
        self._stop.set()
        self._thread.join(5)
        return self.messages


def last_transforms(messages: list[dict[str, Any]]) -> dict[str, np.ndarray]:
    """Path -> last 4x4 transform received."""
    out = {}
    for m in messages:
        if m["type"] == "set_transform":
            out[m["path"]] = np.array(m["matrix"], dtype=float).reshape(4, 4).T
    return out


def html_commands(html: str) -> list[dict[str, Any]]:
    """The meshcat commands embedded in an exported HTML page."""
    match = re.search(r"var commands = (\[.*?\]);", html, re.S)
    assert match is not None
    return [umsgpack.unpackb(base64.b64decode(c)) for c in json.loads(match.group(1))]


def float32s(ext: Any) -> np.ndarray:
    """A Float32Array sent as msgpack extension 0x17."""
    assert ext.type == 0x17
    return np.frombuffer(ext.data, dtype=np.float32)


@pytest.fixture(scope="module")
def run() -> gb_pin.BabbleResult:
    """A short planar5 run recording every step of its first movements."""
    return gb_pin.babble(
        "planar5", movements=30, seed=1, record=gb_pin.Recording(every=1, first=0, last=RECORDED)
    )


# -- server security -----------------------------------------------------------------------------
def test_server_listens_on_loopback_only() -> None:
    """The viewer's web server has a listening socket on 127.0.0.1 only, none on another address."""
    with LocalServer() as server:
        listening = [
            c for c in psutil.Process().net_connections(kind="inet") if c.status == psutil.CONN_LISTEN
        ]
        ours = [c for c in listening if c.laddr.port == server.port]
        assert ours, f"nothing listens on port {server.port}"
        assert all(c.laddr.ip == LOOPBACK for c in ours), ours
        assert server.web_url == f"http://127.0.0.1:{server.port}/static/"
    after = [
        c
        for c in psutil.Process().net_connections(kind="inet")
        if c.status == psutil.CONN_LISTEN and c.laddr.port == server.port
    ]
    assert not after, "close() must stop listening"


def test_server_rejects_foreign_host_header() -> None:
    """A request naming another host (DNS rebinding) is refused; the bundled viewer page is served locally."""
    import http.client

    with LocalServer() as server:
        conn = http.client.HTTPConnection(LOOPBACK, server.port, timeout=5)
        conn.request("GET", "/static/", headers={"Host": "evil.example:80"})
        assert conn.getresponse().status == 403
        conn = http.client.HTTPConnection(LOOPBACK, server.port, timeout=5)
        conn.request("GET", "/static/")
        resp = conn.getresponse()
        body = resp.read().decode()
        assert resp.status == 200
        assert "main.min.js" in body and "MeshCat.Viewer" in body


def test_port_in_use_raises_viewer_error_and_open_viewer_warns() -> None:
    """A taken port raises ViewerError naming it; open_viewer() warns and returns None instead."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as blocker:
        blocker.bind((LOOPBACK, 0))
        blocker.listen()
        port = blocker.getsockname()[1]
        with pytest.raises(ViewerError, match=str(port)):
            Viewer(port)
        with pytest.warns(ViewerWarning, match="babbling goes on"):
            assert open_viewer(port) is None


def test_bad_viewer_arguments() -> None:
    """Bad viewer arguments raise InvalidArgumentError naming the value."""
    with pytest.raises(gb_pin.InvalidArgumentError, match="max_fps"):
        Viewer(max_fps=0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="port"):
        Viewer(port=70000)
    with pytest.raises(gb_pin.InvalidArgumentError, match="pace"):
        Viewer(pace=-1.0)


def test_missing_meshcat_is_a_viewer_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """Without meshcat, Viewer raises ViewerError with the install hint, and open_viewer warns."""
    monkeypatch.setitem(sys.modules, "meshcat", None)
    with pytest.raises(ViewerError, match=r"gb_pin\[viz\]"):
        Viewer()
    with pytest.warns(ViewerWarning, match="meshcat"):
        assert open_viewer() is None


VIEWER_PACKAGE_SCRIPT = """
import json, os, sys
import gb_pin.viewer as viewer
names = {n: getattr(viewer, n).__module__ if callable(getattr(viewer, n)) else None for n in viewer.__all__}
loaded = [m for m in ("meshcat", "tornado", "umsgpack", "pinocchio", "numba") if m in sys.modules]
import gb_pin
result = gb_pin.babble("planar3", movements=3, seed=0)
viewer.export_model(result, os.path.join(sys.argv[1], "m.html"))
print(json.dumps({"names": names, "loaded": loaded, "meshes": "gb_pin.viewer.meshes" in sys.modules}))
"""


def test_viewer_names_resolve_lazily_and_a_stick_figure_loads_no_mesh_code(tmp_path: Path) -> None:
    """Every public name resolves without loading meshcat, tornado or pinocchio.

    Drawing a robot without meshes never loads the mesh module (the viewer's only Pinocchio user).
    """
    out = subprocess.run(
        [sys.executable, "-c", VIEWER_PACKAGE_SCRIPT, str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout.splitlines()[-1])
    assert set(report["names"]) == set(gb_pin.viewer.__all__)
    assert report["names"]["Viewer"] == "gb_pin.viewer.live"
    assert report["loaded"] == []
    assert report["meshes"] is False
    assert set(gb_pin.viewer.__all__) <= set(dir(gb_pin.viewer))
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = gb_pin.viewer.nope  # type: ignore[attr-defined]


def _viewer_imports() -> dict[str, set[str]]:
    """Per module of gb_pin.viewer: every module it imports (at module level, in functions, for typing).

    The package itself counts as ``gb_pin.viewer.__init__``.
    """
    root = Path(gb_pin.viewer.__file__).parent
    modules = {p.stem for p in root.glob("*.py")}
    out: dict[str, set[str]] = {}
    for path in root.glob("*.py"):
        deps: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                deps.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module == "gb_pin.viewer":
                # a submodule (from gb_pin.viewer import shapes) or a name of the package itself
                deps.update(
                    f"gb_pin.viewer.{a.name if a.name in modules else '__init__'}" for a in node.names
                )
            elif isinstance(node, ast.ImportFrom) and node.module:
                deps.add(node.module)
        out[path.stem] = {"gb_pin.viewer.__init__" if d == "gb_pin.viewer" else d for d in deps}
    return out


def test_viewer_modules_import_acyclically_and_only_meshes_imports_pinocchio() -> None:
    """No module of the viewer imports one that imports it back, nor the package itself.

    Imports inside functions and for typing only count too. Pinocchio is imported by
    gb_pin.viewer.meshes only, tornado by the server (and the dependency check) only.
    """
    imports = _viewer_imports()
    graph = {
        m: {d.split(".")[2] for d in deps if d.startswith("gb_pin.viewer.")} - {m}
        for m, deps in imports.items()
    }
    done: set[str] = set()

    def visit(m: str, path: tuple[str, ...]) -> None:
        assert m not in path, f"import cycle: {' -> '.join((*path, m))}"
        if m not in done:
            for d in sorted(graph[m]):
                visit(d, (*path, m))
            done.add(m)

    for m in sorted(graph):
        visit(m, ())
    assert "__init__" not in set().union(*graph.values())  # nothing imports the package back

    def users(library: str) -> set[str]:
        return {m for m, deps in imports.items() if any(d.split(".")[0] == library for d in deps)}

    assert users("pinocchio") == {"meshes"}
    assert users("tornado") == {"server", "listener", "dependencies"}  # listener: the server's accept loop
    assert users("meshcat") == {"shapes", "meshes", "dependencies"}


def test_cli_view_without_meshcat_still_babbles(monkeypatch: pytest.MonkeyPatch, capsys: Any) -> None:
    """`gb-pin babble --view` without meshcat prints a warning and babbles to the end (exit 0)."""
    monkeypatch.setitem(sys.modules, "meshcat", None)
    code = main(["babble", "--robot", "planar5", "--movements", "5", "--view", "--view-wait", "0", "--quiet"])
    out = capsys.readouterr()
    assert code == 0
    assert "warning" in out.err and "meshcat" in out.err
    assert "E^X" in out.out


def test_cli_view_with_port_in_use_still_babbles(capsys: Any) -> None:
    """`gb-pin babble --view --view-port P` with P taken warns and babbles to the end."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as blocker:
        blocker.bind((LOOPBACK, 0))
        blocker.listen()
        port = blocker.getsockname()[1]
        code = main(
            [
                "babble",
                "--robot",
                "planar5",
                "--movements",
                "5",
                "--view",
                "--view-port",
                str(port),
                "--quiet",
            ]
        )
    out = capsys.readouterr()
    assert code == 0
    assert str(port) in out.err and "E^X" in out.out


# -- live streaming ----------------------------------------------------------------------------------
def test_live_streaming_sends_the_scene_and_final_state() -> None:
    """A browser on 127.0.0.1 receives the robot, the targets, the markers and the frames.

    The last frame places every joint and the effector where Pinocchio puts them at the final posture.
    """
    movements = 40
    viewer = Viewer()
    client = Client(viewer.url)
    assert viewer.wait_for_browser(5) and viewer.clients == 1
    result = gb_pin.babble(
        "planar5",
        movements=movements,
        seed=2,
        viewer=viewer,
        observe_every=1,
        record=gb_pin.Recording(every=1, first=movements - 1),
    )
    viewer.finish()
    viewer.close()
    messages = client.stop()
    kinds = {m["type"] for m in messages}
    assert {"set_object", "set_transform", "set_property"} <= kinds
    objects = {m["path"] for m in messages if m["type"] == "set_object"}
    for j in range(1, 6):
        assert f"{ROBOT}/j{j}/joint" in objects
    assert f"{TARGET}/sphere" in objects
    assert f"{OVERLAY}/reached_grid" in objects
    assert viewer.frames >= 2  # the first update and the final one
    # The final frame: joint placements and the effector at the final executed posture.
    assert result.recording is not None
    q_final = result.recording.posture[-1]
    target = result.target
    data = target.model.createData()
    pin.forwardKinematics(target.model, data, target.to_pinocchio(q_final))
    tf = last_transforms(messages)
    for j in range(1, 6):
        np.testing.assert_allclose(tf[f"{ROBOT}/j{j}"], data.oMi[j].homogeneous, atol=1e-12)
    effector = tf[f"{ROBOT}/effector"][:3, 3]
    np.testing.assert_allclose(effector[:2], target.forward(q_final), atol=1e-12)
    np.testing.assert_allclose(effector[2], 0.0, atol=1e-12)


def test_browser_connecting_late_gets_the_current_scene() -> None:
    """A browser that connects after the run still receives the geometry and the latest transforms."""
    with Viewer() as viewer:
        gb_pin.babble("planar5", movements=10, seed=0, viewer=viewer)
        viewer.finish()
        client = Client(viewer.url)
        messages = client.stop(settle=0.5)
    objects = {m["path"] for m in messages if m["type"] == "set_object"}
    assert f"{ROBOT}/j1/joint" in objects
    assert f"{ROBOT}/effector" in last_transforms(messages)


def test_viewer_does_not_change_learning() -> None:
    """A run watched by a viewer learns exactly what the same run learns unwatched."""
    plain = gb_pin.babble("planar5", movements=25, seed=4)
    with Viewer() as viewer:
        watched = gb_pin.babble("planar5", movements=25, seed=4, viewer=viewer, observe_every=1)
    np.testing.assert_array_equal(plain.history.error, watched.history.error)
    np.testing.assert_array_equal(plain.inverse(plain.targets), watched.inverse(watched.targets))


def test_updates_are_throttled_to_max_fps() -> None:
    """update() sends at most one frame per 1/max_fps seconds and drops the others (the throttle)."""
    target = gb_pin.load_robot("planar5")
    learner = gb_pin.GoalBabbling()
    learner.fit(target, target.targets, 1, seed=0)
    state = learner.state_
    with Viewer(max_fps=20.0, overlay=False) as viewer:
        viewer.start(target, target.targets)
        start = time.perf_counter()
        for _ in range(3000):
            viewer.update(state)
        elapsed = time.perf_counter() - start
        frames, dropped = viewer.frames, viewer.dropped
    assert frames + dropped == 3000
    assert 1 <= frames <= 1 + elapsed * 20.0
    assert viewer.frames == frames + 1  # leaving the block draws the last state


def test_pace_limits_movements_per_second() -> None:
    """With pace, babbling waits so that movements per second stay at most the pace."""
    with Viewer(pace=200.0, overlay=False) as viewer:
        start = time.perf_counter()
        gb_pin.babble("planar5", movements=40, seed=0, viewer=viewer, observe_every=1)
        elapsed = time.perf_counter() - start
    # 40 movements at <= 200 per second; the first update sets the clock after movement 1.
    assert elapsed >= 39 / 200.0


# -- scene geometry ------------------------------------------------------------------------------------
def test_transform_message_is_meshcat_encoding() -> None:
    """The fast set_transform encoder produces exactly umsgpack's bytes of meshcat's command."""
    T = np.random.default_rng(0).normal(size=(4, 4))
    path = "/meshcat/gb_pin/robot/j3"
    expected = umsgpack.packb({"type": "set_transform", "path": path, "matrix": list(T.T.flatten())})
    assert transform_message(path, T)[2] == expected


def test_quaternions_match_pinocchio() -> None:
    """Rotation matrices become the quaternions Pinocchio computes (three.js order x, y, z, w, up to sign)."""
    rng = np.random.default_rng(3)
    R = np.array([pin.Quaternion(*rng.normal(size=4)).normalized().matrix() for _ in range(200)])
    R = np.concatenate([R, [np.diag([1.0, -1.0, -1.0]), np.diag([-1.0, 1.0, -1.0]), np.eye(3)]])
    q = quaternions(R)
    for Ri, qi in zip(R, q, strict=True):
        ref = pin.Quaternion(Ri).coeffs()  # x, y, z, w
        assert min(np.abs(qi - ref).max(), np.abs(qi + ref).max()) < 1e-12


def test_grid_shape_and_edges() -> None:
    """The preset 5x5 target grid is recognised (40 neighbour edges); a shuffled set is not a grid."""
    X = gb_pin.load_robot("planar5").targets
    assert X is not None
    assert grid_shape(X) == (5, 5)
    edges = grid_edges((5, 5))
    assert edges.shape == (2 * 5 * 4, 2)
    assert np.allclose(np.linalg.norm(X[edges[:, 0]] - X[edges[:, 1]], axis=1).min(), 0.125)
    shuffled = X[np.random.default_rng(0).permutation(len(X))]
    assert grid_shape(shuffled) is None
    assert grid_shape(gb_pin.grid_targets([0, 0, 0], [1, 1, 1], [2, 3, 4])) == (2, 3, 4)


def test_overlay_draws_forward_kinematics_of_the_estimates(run: gb_pin.BabbleResult) -> None:
    """The Fig. 3 overlay's reached grid is f(g(x*)) (Pinocchio) and its postures are g(x*)."""
    window = OfflineWindow()
    scene = Scene(window, run.target, run.targets)
    scene.draw_static()
    postures = run.inverse(run.targets)
    drawn = scene.overlay(postures, few=3)
    np.testing.assert_allclose(drawn["reached"][:, :2], run.target.forward(postures), atol=1e-12)
    assert drawn["skeletons"].shape == (3, 2 * 5, 3)  # 5 links, 2 endpoints each
    # Each skeleton ends at the effector of its posture.
    ends = drawn["skeletons"][:, -1, :2]
    assert any(np.allclose(ends[0], p, atol=1e-12) for p in drawn["reached"][:, :2])
    cmds = html_commands(window.scene.html())
    assert f"{OVERLAY}/reached_grid" in {c["path"] for c in cmds if c["type"] == "set_object"}


def test_stick_figure_follows_any_model() -> None:
    """A stick figure of a branching model has one link per child joint and per operational frame."""
    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "j1")
    model.addJoint(j1, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0])), "j2")
    j3 = model.addJoint(j1, pin.JointModelRX(), pin.SE3(np.eye(3), np.array([0.0, 0.2, 0.0])), "j3")
    model.addFrame(
        pin.Frame("tip", j3, 0, pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1])), pin.FrameType.OP_FRAME)
    )
    target = gb_pin.KinematicTarget(model, "tip", axes="xyz")
    figure = StickFigure(target)
    assert len(figure.links) == 3
    q = np.array([0.3, -0.2, 0.5])
    bones = figure.skeleton(q)
    np.testing.assert_allclose(bones[-1], target.forward(q), atol=1e-12)


def test_stick_figure_places_nodes_where_pinocchio_does() -> None:
    """Each joint node and the effector node sit where Pinocchio puts them.

    The model has a locked joint, a rotated joint placement and a rotated frame; the figure evaluates
    the target's chain, not Pinocchio.
    """
    model = pin.Model()
    j1 = model.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.1])), "j1")
    rot = pin.utils.rotate("x", 0.4)
    j2 = model.addJoint(j1, pin.JointModelRY(), pin.SE3(rot, np.array([0.3, 0.0, 0.0])), "j2")
    j3 = model.addJoint(j2, pin.JointModelPX(), pin.SE3(np.eye(3), np.array([0.2, 0.1, 0.0])), "j3")
    j4 = model.addJoint(j3, pin.JointModelRX(), pin.SE3(np.eye(3), np.array([0.0, 0.2, 0.0])), "j4")
    for j in (j1, j2, j3, j4):
        model.addJointFrame(j)
    tip = pin.SE3(pin.utils.rotate("z", 0.7), np.array([0.0, 0.0, 0.15]))
    model.addFrame(pin.Frame("tip", j4, 0, tip, pin.FrameType.OP_FRAME))
    target = gb_pin.KinematicTarget(model, "tip", joints=["j1", "j2", "j4"], axes="xyz")  # j3 locked
    figure = StickFigure(target)
    data = target.model.createData()
    for q in np.random.default_rng(5).uniform(-2.0, 2.0, size=(5, 3)):
        pin.framesForwardKinematics(target.model, data, target.to_pinocchio(q))
        tf = dict(figure.transforms(q))
        assert len(tf) == target.model.njoints  # one node per joint, and the effector
        for j in range(1, target.model.njoints):
            np.testing.assert_allclose(tf[figure.joint_path(j)], data.oMi[j].homogeneous, atol=1e-12)
        np.testing.assert_allclose(
            tf[figure.effector_path], data.oMf[target.frame_id].homogeneous, atol=1e-12
        )
        np.testing.assert_allclose(figure.effector(q), target.forward(q), atol=1e-12)


# -- recording, replay, export --------------------------------------------------------------------------
def test_parse_range() -> None:
    """Movement ranges FIRST:LAST parse; malformed or empty ones raise InvalidArgumentError naming them."""
    assert parse_range("0:50") == (0, 50)
    assert parse_range("10:") == (10, None)
    assert parse_range(":5") == (0, 5)
    for bad in ("5", "a:b", "5:5", "-1:3", "1:2:3"):
        with pytest.raises(gb_pin.InvalidArgumentError, match=re.escape(repr(bad))):
            parse_range(bad)


def test_select_movements(run: gb_pin.BabbleResult) -> None:
    """Selecting movements keeps exactly their steps; an empty selection names the recorded range."""
    assert run.recording is not None
    part = select_movements(run.recording, (2, 4))
    assert set(part.movement.tolist()) == {2, 3}
    assert part.step.shape[0] == 2 * run.config.path_length
    with pytest.raises(gb_pin.InvalidArgumentError, match=f"0..{RECORDED - 1}"):
        select_movements(run.recording, (50, 60))


def test_replay_html_is_self_contained_and_animates_the_recording(
    run: gb_pin.BabbleResult, tmp_path: Any
) -> None:
    """The exported page inlines meshcat's viewer, forbids every fetch, and animates the recording.

    The looping animation's effector keyframes are the recorded reached positions; the target marker is
    hidden during home returns.
    """
    path = tmp_path / "replay.html"
    export_replay(run, path, movements=(0, RECORDED), speed=4.0)
    html = path.read_text()
    assert CONTENT_SECURITY_POLICY in html and "default-src 'none'" in html
    assert not re.search(r"<script[^>]+src=|<link[^>]+href=|<iframe|<img[^>]+src=", html, re.I)
    assert "MeshCat.Viewer" in html
    cmds = html_commands(html)
    anims = [c for c in cmds if c["type"] == "set_animation"]
    assert len(anims) == 1 and anims[0]["options"]["repetitions"] == float("inf")
    clips = {a["path"]: a["clip"] for a in anims[0]["animations"]}
    assert run.recording is not None
    rec = run.recording
    L = run.config.path_length
    eff = clips[f"{ROBOT}/effector"]
    assert eff["fps"] == pytest.approx(4.0 * L)  # speed movements/s of L steps each
    tracks = {t["name"]: t for t in eff["tracks"]}
    times = float32s(tracks[".position"]["times"])
    np.testing.assert_array_equal(times, (rec.step - rec.step[0]).astype(np.float32))
    values = float32s(tracks[".position"]["values"]).reshape(-1, 3)
    np.testing.assert_allclose(values[:, :2], rec.position, atol=1e-6)  # float32
    target_tracks = {t["name"]: t for t in clips[TARGET]["tracks"]}
    visible = np.array(target_tracks[".visible"]["values"])
    np.testing.assert_array_equal(visible, np.all(np.isfinite(rec.target), axis=1))


def test_export_model_html(run: gb_pin.BabbleResult, tmp_path: Any) -> None:
    """The model page holds the target grid, the reached grid and the postures, and no animation."""
    path = tmp_path / "model.html"
    export_model(run, path, few=4)
    cmds = html_commands(path.read_text())
    paths = {c["path"] for c in cmds if c["type"] == "set_object"}
    assert {f"{OVERLAY}/reached_grid", f"{OVERLAY}/postures", "/meshcat/gb_pin/targets/grid"} <= paths
    assert not any(c["type"] == "set_animation" for c in cmds)


def test_export_errors(tmp_path: Any) -> None:
    """Replaying a run without recording, or writing to a missing folder, raise InvalidArgumentError."""
    plain = gb_pin.babble("planar3", movements=3, seed=0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="--record-every"):
        export_replay(plain, tmp_path / "x.html")
    with pytest.raises(gb_pin.InvalidArgumentError, match=r"cannot write .*missing"):
        export_model(plain, tmp_path / "missing" / "x.html")


def test_export_replaces_the_file_atomically(run: gb_pin.BabbleResult, tmp_path: Any) -> None:
    """An export replaces an existing page whole and leaves no temporary file.

    A failed one leaves the previous page untouched.
    """
    path = tmp_path / "page.html"
    path.write_text("old page")
    export_model(run, path)
    assert "MeshCat.Viewer" in path.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["page.html"]
    before = path.read_text()
    with pytest.raises(gb_pin.InvalidArgumentError, match="speed"):
        export_replay(run, path, speed=0.0)
    assert path.read_text() == before
    blocked = tmp_path / "dir.html"
    blocked.mkdir()
    with pytest.raises(gb_pin.InvalidArgumentError, match=re.escape(repr(str(blocked)))):
        export_model(run, blocked)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir.html", "page.html"]


# -- command line ----------------------------------------------------------------------------------------
def test_cli_record_replay_show(tmp_path: Any, capsys: Any) -> None:
    """babble --record-every/--record-movements saves the steps; replay --html and show --html write pages."""
    out = tmp_path / "run.npz"
    assert (
        main(
            [
                "babble",
                "--robot",
                "planar5",
                "--movements",
                "12",
                "--record-every",
                "2",
                "--record-movements",
                "0:6",
                "--out",
                str(out),
                "--quiet",
            ]
        )
        == 0
    )
    loaded = gb_pin.load_result(out)
    assert loaded.recording is not None
    assert set(loaded.recording.movement.tolist()) == set(range(6))
    assert np.all(np.diff(loaded.recording.step) == 2)
    assert main(["replay", str(out), "--html", str(tmp_path / "r.html"), "--movements", "1:3"]) == 0
    cmds = html_commands((tmp_path / "r.html").read_text())
    (anim,) = [c for c in cmds if c["type"] == "set_animation"]
    assert anim["animations"]
    assert main(["show", str(out), "--html", str(tmp_path / "s.html")]) == 0
    assert "wrote" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["replay", "{plain}", "--html", "{tmp}/x.html"], "no recorded steps"),
        (["replay", "{rec}", "--html", "{tmp}/x.html", "--movements", "70:80"], "70"),
        (["replay", "{rec}", "--html", "{tmp}/x.html", "--movements", "oops"], "oops"),
        (["replay", "{rec}", "--html", "{tmp}/x.html", "--speed", "0"], "speed"),
        (["replay", "{tmp}/missing.npz"], "missing.npz"),
        (["show", "{tmp}/missing.npz"], "missing.npz"),
        (["babble", "--robot", "planar3", "--movements", "2", "--record-movements", "9"], "record-movements"),
        (["babble", "--robot", "planar3", "--movements", "2", "--record-every", "0"], "every"),
    ],
)
def test_cli_errors_exit_2(argv: list[str], needle: str, tmp_path: Any, capsys: Any) -> None:
    """Bad replay/show/record input exits with status 2 and one line naming the bad value."""
    plain, rec = tmp_path / "plain.npz", tmp_path / "rec.npz"
    gb_pin.babble("planar3", movements=3, seed=0).save(str(plain))
    gb_pin.babble("planar3", movements=3, seed=0, record=gb_pin.Recording(first=0, last=2)).save(str(rec))
    args = [a.format(plain=plain, rec=rec, tmp=tmp_path) for a in argv]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err


def test_cli_live_replay_serves_animation_until_ctrl_c(run: gb_pin.BabbleResult, tmp_path: Any) -> None:
    """`gb-pin replay FILE` prints a 127.0.0.1 URL, sends the animation to a browser, exits 0 on Ctrl-C.

    Robust under load: the URL is awaited up to 120 s (not a blocking readline), Ctrl-C is sent with
    SIGINT ignored by the parent (as in a background job: the command restores its handler), and the
    process is killed in any case, so that no server is ever left on 127.0.0.1.
    """
    import selectors

    path = tmp_path / "run.npz"
    run.save(str(path))
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # inherited by the child, as from `cmd &`
    try:
        proc = subprocess.Popen(
            [sys.executable, "-m", "gb_pin.cli", "replay", str(path), "--speed", "3"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
    finally:
        signal.signal(signal.SIGINT, previous)
    code = None
    try:
        assert proc.stdout is not None
        selector = selectors.DefaultSelector()
        selector.register(proc.stdout, selectors.EVENT_READ)
        assert selector.select(timeout=120), "no URL printed within 120 s"
        line = proc.stdout.readline()
        match = re.search(r"(http://127\.0\.0\.1:\d+/static/)", line)
        assert match, line
        client = Client(match.group(1))
        messages = client.stop(settle=1.0)
        anims = [m for m in messages if m["type"] == "set_animation"]
        assert anims and anims[0]["animations"]
        proc.send_signal(signal.SIGINT)
        code = proc.wait(timeout=60)
    finally:
        if proc.poll() is None:  # never leave a server behind
            proc.kill()
            proc.wait(timeout=60)
    assert code == 0, proc.stderr.read() if proc.stderr else ""


def test_mesh_robot_is_drawn_with_its_meshes() -> None:
    """A robot with a visual model is drawn with its meshes (pinocchio's MeshcatVisualizer).

    Each mesh is placed where pinocchio.updateGeometryPlacements puts it.
    """
    from gb_pin.robot.models import example_robot_data_dir

    target = gb_pin.KinematicTarget.from_example_robot_data("ur5", "tool0", onboard=False)
    share = str(example_robot_data_dir().parent.parent)
    visual = pin.buildGeomFromUrdf(
        target.full_model, target.urdf, pin.GeometryType.VISUAL, package_dirs=[share]
    )
    window = OfflineWindow()
    with warnings.catch_warnings():
        warnings.simplefilter("error", ViewerWarning)
        scene = Scene(window, target, np.zeros((1, 3)), visual_model=visual)
        scene.draw_static()
    cmds = html_commands(window.scene.html())
    objects = {c["path"] for c in cmds if c["type"] == "set_object"}
    for obj in visual.geometryObjects:
        assert f"{ROBOT}/visuals/{obj.name}" in objects
    data, gdata = target.full_model.createData(), visual.createData()
    pin.forwardKinematics(target.full_model, data, target.full_configuration(target.home))
    pin.updateGeometryPlacements(target.full_model, data, visual, gdata)
    tf = last_transforms(cmds)
    for gid, obj in enumerate(visual.geometryObjects):
        T = tf[f"{ROBOT}/visuals/{obj.name}"]
        np.testing.assert_allclose(T[:3, 3], gdata.oMg[gid].translation, atol=1e-9)
