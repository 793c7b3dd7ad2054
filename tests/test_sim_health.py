"""A simulated plant that never lies: instabilities raise, time settings bounded, restored states checked.

Before (main 995bb8d), ``--plant mujoco:kp=1e12`` and commands far beyond the limits made MuJoCo
reset the arm with a warning on stderr and gb_pin returned the reset arm's readings (exit 0);
``period=1e6`` or ``timestep=1e-9`` hung inside MuJoCo; a tampered checkpoint state continued.
"""

from __future__ import annotations

import numpy as np
import pytest

from gb_pin.exceptions import InvalidArgumentError, SimulationError

pytest.importorskip("mujoco")

from gb_pin.sim import MujocoPlant, health


@pytest.mark.parametrize(
    ("options", "command"),
    [({"kp": 1e12}, 0.3), ({}, 1e6)],  # a gain far too stiff for the step; a command far beyond the limits
)
def test_an_unstable_simulation_raises_naming_the_settings(
    options: dict, command: float, tmp_path: object, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # MuJoCo writes MUJOCO_LOG.TXT where it runs
    plant = MujocoPlant("so101", **options)
    with pytest.raises(SimulationError, match=r"unstable during ask 1.*kp=") as info:
        plant.forward(np.zeros(plant.n_joints) + command)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    ("options", "needle"),
    [
        ({"period": 1e6}, "period must be at most 10 s"),
        ({"period": 1e9}, "period must be at most 10 s"),
        ({"settle": 1e9}, "settle must be at most 10 s"),
        ({"tolerance": 1e-300}, "tolerance must be at least"),
        ({"timestep": 1e-9}, "timestep must be in"),
        ({"timestep": 1e-5, "settle": 5.0}, "MuJoCo steps per ask"),
    ],
)
def test_time_settings_are_bounded(options: dict, needle: str) -> None:
    with pytest.raises(InvalidArgumentError, match=needle):
        MujocoPlant("so101", **options)


def test_a_true_body_evaluation_has_a_step_budget(monkeypatch: pytest.MonkeyPatch) -> None:
    """Servos too soft to hold the arm: the resting postures are simulated, within a budget."""
    plant = MujocoPlant("so101", kp=0.05)
    Q = np.random.default_rng(0).uniform(-1, 1, (4, plant.n_joints))
    monkeypatch.setattr(health, "EVALUATION_STEPS", 3000)
    with pytest.raises(SimulationError, match=r"more than 3000 MuJoCo steps.*kp=0.05"):
        plant.true_forward(Q)


def test_a_tampered_plant_state_is_refused() -> None:
    plant = MujocoPlant("so101", period=0.03)
    plant.forward(plant.home)
    saved = plant.robot_state()
    nq = plant.mj_model.nq
    moved = saved["mujoco"].copy()
    moved[1 : 1 + nq] += 5.0  # joints far beyond their limits
    late = saved["mujoco"].copy()
    late[0] += 1.0  # a simulated time the steps do not account for
    fast = saved["mujoco"].copy()
    fast[1 + nq] = 1e5  # a joint speed no servo arm reaches
    other = MujocoPlant("so101", period=0.03)
    for state, needle in ((moved, "beyond the joint limits"), (late, "simulated time"), (fast, "moving at")):
        with pytest.raises(InvalidArgumentError, match=needle):
            other.set_robot_state({**saved, "mujoco": state})
    other.set_robot_state(saved)  # the untouched state still continues bit-identical
    np.testing.assert_array_equal(other.forward(plant.home), plant.forward(plant.home))
