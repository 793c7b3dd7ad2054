"""The sensor model (gb_pin.learn.sensor) and plants (gb_pin.robot.plant): wrong bodies, noisy readings."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gb_pin
from gb_pin.learn.sensor import Sensor, observe_into
from gb_pin.robot.plant import Miscalibration, Plant


def test_readings_have_the_given_noise_per_axis_and_loss_rate() -> None:
    """20000 readings: per-axis std within 3 % (standard error 0.5 %), losses within 5 binomial sigmas."""
    sensor = Sensor(noise=[0.001, 0.002, 0.0], loss=0.1, seed=3).start(3)
    N = 20000
    readings = []
    lost = 0
    for _ in range(N):
        x = np.zeros(3)
        if observe_into(sensor, x):
            readings.append(x)
        else:
            lost += 1
    R = np.array(readings)
    np.testing.assert_allclose(R[:, :2].std(axis=0), [0.001, 0.002], rtol=0.03)
    assert np.all(R[:, 2] == 0.0)  # no noise on that axis: no draw, the exact value
    np.testing.assert_allclose(R.mean(axis=0), 0.0, atol=5 * 0.002 / math.sqrt(N))
    assert abs(lost / N - 0.1) < 5 * math.sqrt(0.1 * 0.9 / N)


def test_a_sensor_gives_the_same_readings_for_the_same_seed() -> None:
    """Same seed, same readings bit for bit; another seed, others; a Generator given is copied."""

    def readings(sensor: Sensor) -> list[object]:
        arrays = sensor.start(2)
        out: list[object] = []
        for _ in range(50):
            x = np.array([0.3, 0.1])
            out.append(x.tolist() if observe_into(arrays, x) else None)
        return out

    assert readings(Sensor(0.001, 0.2, seed=5)) == readings(Sensor(0.001, 0.2, seed=5))
    assert readings(Sensor(0.001, 0.2, seed=5)) != readings(Sensor(0.001, 0.2, seed=6))
    rng = np.random.default_rng(9)
    given = Sensor(0.001, 0.2, seed=rng)
    assert readings(given) == readings(given)


def test_sensor_arguments_are_checked() -> None:
    """Negative, non-finite or mis-shaped noise, a loss outside [0, 1), a bad seed: gb_pin's errors."""
    for bad in (-0.001, math.nan, [[0.001]], "x"):
        with pytest.raises(gb_pin.InvalidArgumentError, match="noise"):
            Sensor(noise=bad)  # type: ignore[arg-type]
    for loss in (-0.1, 1.0, 1.5):
        with pytest.raises(gb_pin.InvalidArgumentError, match="loss"):
            Sensor(loss=loss)
    with pytest.raises(gb_pin.InvalidArgumentError, match="seed"):
        Sensor(seed=-1)
    with pytest.raises(gb_pin.InvalidArgumentError, match="axes"):
        Sensor(noise=[0.001, 0.001]).start(3)


def test_joint_offsets_shift_q_and_scales_scale_positions() -> None:
    """A plant with offsets d is the model at q + d; with translations scaled by s, s times the model."""
    arm = gb_pin.load_robot("so101")
    rng = np.random.default_rng(0)
    Q = rng.uniform(arm.lower, arm.upper, (30, 4))
    d = np.radians([2.0, -3.0, 1.5, 4.0])
    shifted = Plant(arm, offsets=d, scales=np.ones(5))
    np.testing.assert_allclose(shifted.forward(Q), arm.forward(Q + d), rtol=0, atol=1e-14)
    grown = Plant(arm, offsets=np.zeros(4), scales=np.full(5, 1.03))
    np.testing.assert_allclose(grown.forward(Q), 1.03 * arm.forward(Q), rtol=0, atol=1e-14)
    prismatic = gb_pin.load_robot("talos_torso_left_arm")  # revolute only; a scaled pose task too
    pose = gb_pin.load_robot("talos_left_arm_pose")
    q = pose.home + 0.1
    moved = Plant(pose, offsets=np.zeros(7), scales=np.full(8, 1.0))
    np.testing.assert_allclose(moved.forward(q), pose.forward(q), atol=1e-15)
    assert prismatic.n_joints == 9


def test_drawn_miscalibration_has_the_given_spread_and_is_seeded() -> None:
    """Offsets ~ N(0, sd^2), scales ~ 1 + N(0, sd^2) over many joints; same seed same body."""
    big = Miscalibration.draw(4000, math.radians(3), 0.03, seed=1)
    assert np.std(big.offsets) == pytest.approx(math.radians(3), rel=0.05)
    assert np.std(big.scales) == pytest.approx(0.03, rel=0.05)
    a, b = (
        Plant("so101", offset_std=0.05, length_std=0.03, seed=4),
        Plant("so101", offset_std=0.05, length_std=0.03, seed=4),
    )
    np.testing.assert_array_equal(a.chain.rotations, b.chain.rotations)
    c = Plant("so101", offset_std=0.05, length_std=0.03, seed=5)
    assert not np.array_equal(a.chain.translations, c.chain.translations)
    with pytest.raises(gb_pin.InvalidArgumentError, match="length_std"):
        Plant("so101", length_std=0.5)
    with pytest.raises(gb_pin.InvalidArgumentError, match="offsets"):
        Plant("so101", offsets=[0.0, 0.1])


def test_a_plant_is_learnt_from_readings_and_measured_on_its_true_body() -> None:
    """babble(plant): E^X is the true body's (f of the clipped g), misses counted, same seed same run."""
    plant = Plant("so101", offset_std=math.radians(3), length_std=0.03, noise=0.0015, loss=0.1, seed=2)
    run = gb_pin.babble(plant, movements=300, seed=1)
    again = gb_pin.babble(plant, movements=300, seed=1)
    np.testing.assert_array_equal(run.history.error, again.history.error)
    X = run.targets
    Q = np.clip(run.inverse(X), plant.lower, plant.upper)
    expected = np.mean(np.linalg.norm(X - plant.forward(Q), axis=1))
    assert run.error == pytest.approx(expected, rel=1e-12)
    assert abs(run.missing / run.steps - 0.1) < 5 * math.sqrt(0.09 / run.steps)
    assert run.history.reach is not None and np.isnan(run.history.reach[0]) and run.history.reach[-1] > 0


def test_plant_observe_reads_the_true_body_through_its_sensor() -> None:
    """plant.observe(q): the true position plus noise of the given size, None at the loss rate."""
    plant = Plant("so101", offset_std=0.05, noise=0.001, loss=0.25, seed=3)
    q = plant.home
    readings = [plant.observe(q) for _ in range(4000)]
    seen = np.array([r for r in readings if r is not None])
    assert abs(1 - len(seen) / 4000 - 0.25) < 5 * math.sqrt(0.25 * 0.75 / 4000)
    np.testing.assert_allclose(seen.mean(axis=0), plant.forward(q), atol=5 * 0.001 / math.sqrt(len(seen)))
    np.testing.assert_allclose(seen.std(axis=0), 0.001, rtol=0.06)
    assert not np.allclose(plant.forward(q), plant.target.forward(q), atol=1e-3)  # the body is not the model
