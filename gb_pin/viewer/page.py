"""A scene as one self-contained HTML page: meshcat's bundled viewer inlined, nothing from the network.

The scene's commands are embedded as base64 msgpack and replayed synchronously on
load, in order; a Content-Security-Policy forbids every fetch and connection, so the
page opens offline and cannot call home.
"""

from __future__ import annotations

import base64
import json
import os
from collections.abc import Iterable

from gb_pin._names import printable
from gb_pin.viewer.dependencies import viewer_assets

# The static page may run inline scripts and styles and read data: images (meshcat's
# textures); it may load, fetch and connect to nothing.
CONTENT_SECURITY_POLICY = (
    "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:"
)


def html_page(messages: Iterable[bytes], title: str = "gb_pin", overlay: str = "") -> str:
    """The page replaying ``messages`` (msgpack-encoded meshcat commands, in order) under ``title``.

    Args:
        messages: the scene's commands.
        title: the page's title (HTML-escaped; non-printable characters such as direction overrides
            written as escapes, e.g. U+202E as backslash-u-202e).
        overlay: HTML drawn over the view (the legend, :func:`gb_pin.viewer.legend.legend_html`:
            gb_pin's own markup with escaped text; static, no script).
    """
    with open(os.path.join(viewer_assets(), "main.min.js"), encoding="utf-8") as fh:
        script = fh.read().replace("</script", "<\\/script")
    commands = json.dumps([base64.b64encode(m).decode("ascii") for m in messages])
    # non-printable characters escaped (Unicode direction overrides would reorder the title shown)
    safe_title = printable(title, 200).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return f"""<!DOCTYPE html>
<html>
<head>
<meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="{CONTENT_SECURITY_POLICY}">
<title>{safe_title}</title>
<style>body {{ margin: 0; }} #meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}</style>
</head>
<body>
<div id="meshcat-pane"></div>
{overlay}
<script>
{script}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
var commands = {commands};
for (var i = 0; i < commands.length; i++) {{
  var raw = atob(commands[i]);
  var bytes = new Uint8Array(raw.length);
  for (var j = 0; j < raw.length; j++) {{ bytes[j] = raw.charCodeAt(j); }}
  viewer.handle_command_bytearray(bytes);
}}
</script>
</body>
</html>
"""
