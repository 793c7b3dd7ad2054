"""The text layer over the 3-D view: robot, movement r, E^X, D^home, and what each colour means.

An HTML box in the page's top-left corner (meshcat's controls are top right). An exported page
(:mod:`~gb_pin.viewer.page`) carries it as static HTML, under its Content-Security-Policy (no script
is evaluated, nothing is fetched). A live page is meshcat's own: there the box is created and updated
by a meshcat ``set_control`` command, whose callback meshcat evaluates in the page (the only way
meshcat 0.3.2 runs page code), followed by ``delete_control`` so that no button is left in its panel.
:class:`~gb_pin.viewer.cache.SceneCache` keeps the last box: for browsers that connect later and for
the page exported from a live viewer. The text is escaped (robot names come from files).
"""

from __future__ import annotations

import html
import json
from dataclasses import dataclass
from typing import Any

from gb_pin.viewer.style import (
    EFFECTOR_COLOR,
    GOAL_SET_COLOR,
    LINK_COLOR,
    POSTURE_COLOR,
    REACHED_COLOR,
    TARGET_COLOR,
    TARGET_SET_COLOR,
)

#: The name of the meshcat control carrying the box (removed right after it ran).
CONTROL = "gb_pin_legend"
#: The id of the box in the page.
ELEMENT_ID = "gb-pin-legend"

BOX_STYLE = (
    "position:fixed;top:6px;left:6px;z-index:10;max-width:300px;padding:5px 8px;"
    "background:rgba(255,255,255,0.78);border:1px solid #bbb;border-radius:4px;"
    "font:11px/1.3 sans-serif;color:#222;pointer-events:none"
)


@dataclass(frozen=True)
class Legend:
    """What the box says.

    Attributes:
        robot: the robot's name.
        details: a line under the name (joints, task axes).
        status: the run's state (``movement r 300 | E^X 0.0123 m | D^home 0.45 rad``), "" if none yet.
        overlay_note: why the learned model's overlay is shown or hidden (e.g. in a replay).
        meshes: the robot is drawn by its meshes (else a stick figure).
        goal_set: a goal set other than the test set is drawn too.
        moving: a run (live or replayed: a current goal and a trail); False for a learned model shown.
        effector_only: the robot is drawn as its effector only (a robot given as a function).
    """

    robot: str
    details: str = ""
    status: str = ""
    overlay_note: str = ""
    meshes: bool = False
    goal_set: bool = False
    moving: bool = True
    effector_only: bool = False


def status_line(
    movements: int, error: float | None, home_distance: float | None, measured_at: int | None = None
) -> str:
    """``movement r = 300 · E^X = 0.01234 m · D^home = 0.452 rad`` (measures left out when unknown).

    Args:
        movements: movements run.
        error: E^X [m], or None.
        home_distance: D^home [rad], or None.
        measured_at: the movement count E^X and D^home were measured at, if not ``movements``.
    """
    parts = [f"movement r = {int(movements)}"]
    if error is not None:
        parts.append(f"E<sup>X</sup> = {float(error):.4g} m")
    if home_distance is not None:
        parts.append(f"D<sup>home</sup> = {float(home_distance):.3g} rad")
    if measured_at is not None and measured_at != movements and error is not None:
        parts[-1] += f" (at r = {int(measured_at)})"
    return " &middot; ".join(parts)


def result_status(result: Any) -> str:
    """The status line of a finished run (a :class:`~gb_pin.runs.result.BabbleResult`)."""
    return status_line(result.movements, result.error, result.home_distance)


def model_note(result: Any) -> str:
    """The legend's note under a learned model's overlay (``show``)."""
    return f"blue and dark lines: the model learned in {result.movements} movements"


def _swatch(color: int, shape: str) -> str:
    radius = "50%" if shape == "dot" else "1px"
    height = "3px" if shape == "line" else "9px"
    return (
        f'<span style="display:inline-block;width:14px;height:{height};margin:0 6px 1px 0;'
        f'vertical-align:middle;border-radius:{radius};background:#{color:06x}"></span>'
    )


def legend_items(
    meshes: bool, goal_set: bool = False, moving: bool = True, effector_only: bool = False
) -> list[tuple[int, str, str]]:
    """(colour, swatch shape, meaning) of every part drawn (:mod:`~gb_pin.viewer.style`).

    ``moving``: a run, with a current goal and a trail (a learned model shown has neither);
    ``effector_only``: a robot given as a function, drawn as its effector.
    """
    run: list[tuple[int, str, str]] = [
        (TARGET_COLOR, "dot", "current goal x<sup>*</sup><sub>t</sub>"),
        (EFFECTOR_COLOR, "dot", "reached positions, fading (the trail)"),
    ]
    robot: list[tuple[int, str, str]] = [
        (LINK_COLOR, "box", "the robot's links (joints dark, effector red)"),
    ]
    if meshes:
        robot = [(0xBBBBBB, "box", "the robot's meshes, in their own colours")]
    if effector_only:
        robot = [(EFFECTOR_COLOR, "dot", "the effector f(q) (a robot given as a function: no links to draw)")]
    return [
        *robot,
        (
            TARGET_SET_COLOR,
            "dot",
            "target set X<sup>*</sup> (grey points and grid)"
            if not goal_set
            else "test set: E<sup>X</sup> is measured here (grey points and grid)",
        ),
        *([(GOAL_SET_COLOR, "dot", "goal set: the goals come from here (pink points)")] if goal_set else []),
        *(run if moving else []),
        (REACHED_COLOR, "line", "learned model: where g(x<sup>*</sup>) reaches, f(g(x<sup>*</sup>))"),
        (POSTURE_COLOR, "line", "learned postures g(x<sup>*</sup>) of a few targets"),
        (0xE74C3C, "line", "world axes x, y, z (red, green, blue; meshcat's)"),
    ]


def legend_html(legend: Legend) -> str:
    """The box as one HTML element (text escaped; the status line is gb_pin's own markup)."""
    rows = "".join(
        f"<div>{_swatch(c, s)}{text}</div>"
        for c, s, text in legend_items(legend.meshes, legend.goal_set, legend.moving, legend.effector_only)
    )
    parts = [f'<div style="font-weight:bold;font-size:13px">{html.escape(legend.robot)}</div>']
    if legend.details:
        parts.append(f'<div style="color:#555">{html.escape(legend.details)}</div>')
    if legend.status:
        parts.append(f'<div style="margin:2px 0">{legend.status}</div>')
    parts.append(f'<div style="margin-top:2px">{rows}</div>')
    if legend.overlay_note:
        parts.append(f'<div style="color:#555;margin-top:2px">{html.escape(legend.overlay_note)}</div>')
    parts.append('<div style="color:#555">drag: rotate &middot; scroll: zoom &middot; right-drag: pan</div>')
    return f'<div id="{ELEMENT_ID}" style="{BOX_STYLE}">{"".join(parts)}</div>'


def legend_command(legend: Legend) -> dict[str, Any]:
    """A meshcat ``set_control`` command putting the box into a live page (``html``: the box, for caches)."""
    box = legend_html(legend)
    script = (
        "(function(){"
        f"var old=document.getElementById({json.dumps(ELEMENT_ID)});"
        "if(old){old.remove();}"
        "var t=document.createElement('template');"
        f"t.innerHTML={json.dumps(box)};"
        "document.body.appendChild(t.content.firstChild);"
        "return function(){};})()"
    )
    return {"type": "set_control", "name": CONTROL, "callback": script, "html": box}


def remove_control() -> dict[str, Any]:
    """The ``delete_control`` command removing the button that ``set_control`` left in meshcat's panel."""
    return {"type": "delete_control", "name": CONTROL}
