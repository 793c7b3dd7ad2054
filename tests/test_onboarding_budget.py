"""Onboarding within a time budget proportional to the chain, then one line saying how to skip it.

Before (main 995bb8d) a 200-joint URDF onboarded in about 9 minutes and a 998-joint one ran on
past 5 minutes; now the search stops after 30 s + 0.1 s a joint (199 joints: an error at 63 s).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.exceptions import OnboardingBudgetError
from gb_pin.robot import onboarding

URDF = Path(__file__).resolve().parent / "data" / "small_arm.urdf"


def test_a_search_past_its_budget_stops_with_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(onboarding, "BUDGET_SECONDS", 0.0)
    monkeypatch.setattr(onboarding, "BUDGET_PER_JOINT", 0.0)
    with pytest.raises(OnboardingBudgetError, match=r"took more than its 0 s.*give a home") as info:
        gb_pin.KinematicTarget.from_urdf(URDF, "tool")
    assert "\n" not in str(info.value)
    # with a home given, the goal grid's own search is bounded too (not turned into a warning)
    with pytest.raises(OnboardingBudgetError):
        gb_pin.KinematicTarget.from_urdf(URDF, "tool", home=[0.1, 0.2, 0.05, 0.3])


def test_the_budget_grows_with_the_chain() -> None:
    assert onboarding.Budget(200).seconds == pytest.approx(
        onboarding.BUDGET_SECONDS + 200 * onboarding.BUDGET_PER_JOINT
    )


def test_jacobians_in_chunks_are_the_jacobians_at_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """Chunked forward differences (bounded memory on long chains) equal the one-batch ones bit for bit."""
    arm = gb_pin.KinematicTarget.from_urdf(
        URDF, "tool", home=[0.1, 0.2, 0.05, 0.3], targets=[[0.3, 0.1, 0.4]]
    )
    Q = np.random.default_rng(0).uniform(-1, 1, (13, arm.n_joints)) * 0.5
    whole = onboarding._jacobians(arm, Q)
    monkeypatch.setattr(onboarding, "JACOBIAN_ENTRIES", 3 * (arm.n_joints + 1) * arm.n_joints)
    np.testing.assert_array_equal(onboarding._jacobians(arm, Q), whole)
