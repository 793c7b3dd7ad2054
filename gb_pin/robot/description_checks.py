"""Checks of a robot description that pinocchio's parsers let through: limits and SRDF states.

Pinocchio builds a model whose joint has ``lower > upper`` as given (gb_pin then reported "no home
candidate has a reachable goal grid"), and its SRDF loader skips a ``group_state`` joint the model
lacks and keeps a ``nan`` value (which then became the robot's home). :func:`check_limits` and
:func:`check_reference_states` refuse both, naming the joint.
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from gb_pin._names import printable
from gb_pin.exceptions import InvalidArgumentError

_STATE = re.compile(r"<group_state\b([^>]*)>(.*?)</group_state\s*>", re.DOTALL)
_JOINT = re.compile(r"<joint\b([^>]*?)/?>", re.DOTALL)


def _attribute(attributes: str, name: str) -> str | None:
    found = re.search(rf"\b{name}\s*=\s*(\"([^\"]*)\"|'([^']*)')", attributes)
    return None if found is None else (found.group(2) if found.group(2) is not None else found.group(3))


def check_limits(model: Any, label: str) -> None:
    """Refuse a joint whose lower position limit exceeds its upper one.

    Raises:
        InvalidArgumentError: naming the joint and its limits.
    """
    lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
    for j in range(1, model.njoints):
        start, nq = int(model.idx_qs[j]), int(model.nqs[j])
        lo, hi = lower[start : start + nq], upper[start : start + nq]
        if np.any(lo > hi):
            raise InvalidArgumentError(
                f"{label}: joint {printable(model.names[j])!r} has lower limit {lo.tolist()} above its upper "
                f"limit {hi.tolist()}: swap them in the <limit> element"
            )


def check_reference_states(model: Any, xml: str, label: str, urdf: str | None) -> None:
    """Refuse an SRDF ``group_state`` naming a joint the URDF lacks or holding a non-number.

    Args:
        model: the model built from ``urdf`` with the SRDF's states loaded.
        xml: the SRDF's text.
        label: how messages name the SRDF file.
        urdf: the URDF's text (a state may name its fixed joints, which the model drops); None:
            joints the URDF lacks are let through (pinocchio skips them), values are still checked.

    Raises:
        InvalidArgumentError: naming the state, the joint and the value.
    """
    names = set(model.names)
    for joint in _JOINT.finditer(urdf or ""):
        name = _attribute(joint.group(1), "name")
        if name is not None:
            names.add(name)
    for state in _STATE.finditer(xml):
        state_name = printable(_attribute(state.group(1), "name") or "?")
        for joint in _JOINT.finditer(state.group(2)):
            name = _attribute(joint.group(1), "name")
            value = _attribute(joint.group(1), "value")
            if name is None:
                continue
            if urdf is not None and name not in names:
                raise InvalidArgumentError(
                    f"{label}: group_state {state_name!r} sets joint {printable(name)!r}, which the URDF "
                    "does not have (check the joint's name)"
                )
            try:
                numbers = [float(v) for v in (value or "").split()]
            except ValueError:
                numbers = [math.nan]
            if not numbers or not all(math.isfinite(v) for v in numbers):
                raise InvalidArgumentError(
                    f"{label}: group_state {state_name!r} gives joint {printable(name)!r} the value "
                    f"{printable(value)!r}, not a finite number"
                )
    for entry in model.referenceConfigurations:
        if not np.all(np.isfinite(np.asarray(entry.data()))):
            raise InvalidArgumentError(
                f"{label}: group_state {printable(entry.key())!r} holds non-finite values"
            )
