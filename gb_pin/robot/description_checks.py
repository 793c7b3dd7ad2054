"""Checks of a robot description that pinocchio's parsers let through: limits and SRDF states.

Pinocchio builds a model whose joint has ``lower > upper`` as given (gb_pin then reported "no home
candidate has a reachable goal grid"), and its SRDF loader skips a ``group_state`` joint the model
lacks and keeps a ``nan`` value (which then became the robot's home). :func:`check_limits` and
:func:`check_reference_states` refuse both, naming the joint.

A state may name joints the URDF lacks for a good reason: example-robot-data's SRDFs describe
fuller robots than some of their URDFs (Romeo's toes and fingers). Such a joint matters only where
it hides a typo that leaves a joint the target needs at 0: :func:`check_used_states` refuses a
state that the target uses (its home, or the reference posture that locks the other joints), names
a joint the URDF lacks, and leaves unset a joint of the chain; any other missing joint is ignored
(a debug note).
"""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from gb_pin._names import printable
from gb_pin.exceptions import InvalidArgumentError

_LOG = logging.getLogger(__name__)

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


class SrdfStates(NamedTuple):
    """What an SRDF's ``group_state`` entries set: the joints each names, and those the URDF lacks."""

    label: str
    named: dict[str, frozenset[str]]
    missing: dict[str, tuple[str, ...]]


def check_reference_states(model: Any, xml: str, label: str, urdf: str | None) -> SrdfStates:
    """Refuse an SRDF ``group_state`` holding a non-number; say which joints each state sets.

    Args:
        model: the model built from ``urdf`` with the SRDF's states loaded.
        xml: the SRDF's text.
        label: how messages name the SRDF file.
        urdf: the URDF's text (a state may name its fixed joints, which the model drops); None:
            only the model's joints count as known.

    Returns:
        The joints each state names, and those among them the URDF lacks (for :func:`check_used_states`).

    Raises:
        InvalidArgumentError: naming the state, the joint and the value.
    """
    names = set(model.names)
    for joint in _JOINT.finditer(urdf or ""):
        name = _attribute(joint.group(1), "name")
        if name is not None:
            names.add(name)
    named: dict[str, set[str]] = {}
    missing: dict[str, list[str]] = {}
    for state in _STATE.finditer(xml):
        raw = _attribute(state.group(1), "name") or "?"
        state_name = printable(raw)
        for joint in _JOINT.finditer(state.group(2)):
            name = _attribute(joint.group(1), "name")
            value = _attribute(joint.group(1), "value")
            if name is None:
                continue
            named.setdefault(raw, set()).add(name)
            if name not in names:
                missing.setdefault(raw, []).append(name)
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
    return SrdfStates(
        label,
        {k: frozenset(v) for k, v in named.items()},
        {k: tuple(v) for k, v in missing.items()},
    )


def check_used_states(
    states: SrdfStates | None, used: Sequence[str], needed: Sequence[str], frame: str
) -> None:
    """Refuse a used state that names a joint the URDF lacks and leaves a needed joint unset.

    Args:
        states: the SRDF's states (:func:`check_reference_states`), or None (no SRDF).
        used: the states the target uses (its home, the reference posture of the locked joints).
        needed: the joints whose value the target takes from them (the chain's).
        frame: the target's frame, for the message.

    Raises:
        InvalidArgumentError: one line naming the missing joint, the state and the file.
    """
    if states is None:
        return
    for state in dict.fromkeys(used):
        missing = states.missing.get(state, ())
        if not missing:
            continue
        unset = [j for j in needed if j not in states.named.get(state, frozenset())]
        if unset:
            raise InvalidArgumentError(
                f"{states.label}: group_state {printable(state)!r} sets joint {printable(missing[0])!r}, "
                f"which the URDF does not have, and leaves joint {printable(unset[0])!r} of the chain to "
                f"{printable(frame)!r} unset (check the joint's name)"
            )
        _LOG.debug(
            "%s: group_state %r names joints the URDF lacks, ignored: %s",
            states.label, state, ", ".join(missing),
        )  # fmt: skip
