"""Postures of a robot: reference configurations, the home posture, Pinocchio configuration vectors.

The learner's posture q has one entry per moved joint ([rad] or [m]); a Pinocchio
configuration vector has ``nq`` entries, two (cos, sin) for a continuous joint. The
functions here convert between the two and read the home posture, from an array or a
named reference configuration of the model (e.g. ``half_sitting`` from an SRDF).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from gb_pin import _validation as check
from gb_pin._names import listing
from gb_pin.exceptions import InvalidArgumentError

if TYPE_CHECKING:
    import pinocchio as pin


def reference_configurations(model: pin.Model) -> dict[str, NDArray[np.float64]]:
    """The model's named reference configurations (e.g. ``half_sitting`` from an SRDF)."""
    return {e.key(): np.array(e.data(), dtype=float) for e in model.referenceConfigurations}


def reference_name(model: pin.Model) -> str | None:
    """The named configuration locked joints keep: ``half_sitting``, else the only one, else None."""
    refs = reference_configurations(model)
    if "half_sitting" in refs:
        return "half_sitting"
    return next(iter(refs)) if len(refs) == 1 else None


def reference_posture(model: pin.Model) -> NDArray[np.float64]:
    """The configuration locked joints keep: ``half_sitting``, the only named one, or the neutral one."""
    name = reference_name(model)
    if name is not None:
        return reference_configurations(model)[name]
    import pinocchio as pin

    return np.array(pin.neutral(model), dtype=float)


def to_configuration(
    q: NDArray[np.float64],
    model: pin.Model,
    ids: Sequence[int],
    continuous: Sequence[bool],
    start: NDArray[np.float64],
) -> NDArray[np.float64]:
    """A configuration vector of ``model``: ``start`` with posture ``q`` written on the joints ``ids``.

    Args:
        q: the posture (m,), one entry per joint of ``ids``.
        model: the model the configuration is for.
        ids: the model's joint id of each entry of q.
        continuous: whether each joint is continuous (written as cos, sin).
        start: the configuration of the other joints (not modified).
    """
    out = start.copy()
    for a, jid in enumerate(ids):
        iq = model.joints[jid].idx_q
        if continuous[a]:
            out[iq], out[iq + 1] = np.cos(q[a]), np.sin(q[a])
        else:
            out[iq] = q[a]
    return out


def from_configuration(
    configuration: NDArray[np.float64], model: pin.Model, ids: Sequence[int], continuous: Sequence[bool]
) -> NDArray[np.float64]:
    """The posture (m,) on the joints ``ids`` of a configuration vector of ``model``."""
    q = np.empty(len(ids))
    for a, jid in enumerate(ids):
        iq = model.joints[jid].idx_q
        if continuous[a]:
            q[a] = np.arctan2(configuration[iq + 1], configuration[iq])
        else:
            q[a] = configuration[iq]
    return q


def check_within_limits(
    q: NDArray[np.float64], joints: Sequence[str], lower: NDArray[np.float64], upper: NDArray[np.float64]
) -> None:
    """Raise InvalidArgumentError naming every joint of the home posture ``q`` outside its limits."""
    bad = np.flatnonzero((q < lower) | (q > upper))
    if bad.size:
        detail = ", ".join(
            f"{joints[i]}={q[i]:.4g} not in [{lower[i]:.4g}, {upper[i]:.4g}]" for i in bad.tolist()
        )
        raise InvalidArgumentError(f"home posture outside the joint limits: {detail}")


def home_posture(
    home: ArrayLike | str | None,
    full_model: pin.Model | None,
    reference: NDArray[np.float64],
    joints: Sequence[str],
    continuous: Sequence[bool],
    limits: tuple[NDArray[np.float64], NDArray[np.float64]],
    name: str,
) -> NDArray[np.float64]:
    """The home posture over ``joints``, checked against the joint limits.

    Args:
        home: a posture (m,), the name of a reference configuration of ``full_model``,
            or None for ``reference``.
        full_model: the full model (None for a target built from arrays, whose home is a posture).
        reference: its reference posture (see :func:`reference_posture`).
        joints: the moved joints, in the order of q.
        continuous: whether each joint is continuous.
        limits: (lower, upper) joint limits (m,) each.
        name: the robot's label, for messages.

    Raises:
        InvalidArgumentError: an unknown configuration name, a wrong shape, a posture
            outside the joint limits.
    """
    if full_model is None and (home is None or isinstance(home, str)):
        raise InvalidArgumentError(f"home of {name!r} must be a posture over its joints, got {home!r}")
    if home is None:
        q_full = reference
    elif isinstance(home, str):
        refs = reference_configurations(full_model)
        if home not in refs:
            raise InvalidArgumentError(
                f"home {home!r} is not a reference configuration of {name!r}; "
                f"valid: {sorted(refs) or 'none (give an array)'}"
            )
        q_full = np.array(refs[home], dtype=float)
    else:
        try:
            q = check.vector("home", home, len(joints))
        except InvalidArgumentError as exc:
            raise InvalidArgumentError(f"{exc}: one value per joint of `joints` ({listing(joints)})") from exc
        check_within_limits(q, joints, *limits)
        return q
    assert full_model is not None  # checked above
    ids = [full_model.getJointId(j) for j in joints]
    q = from_configuration(q_full, full_model, ids, continuous)
    check_within_limits(q, joints, *limits)
    return q
