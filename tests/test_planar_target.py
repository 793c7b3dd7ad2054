"""The planar presets' targets built from arrays (gb_pin.robot.planar.planar_target).

A planar preset writes the learner's arrays directly and builds its pin.Model only when asked
for, so that a planar run never imports pinocchio (the warm start of ``gb-pin babble``). These
tests hold it to the target read from the pin.Model by ``KinematicTarget``: every array bit for
bit, the same lazily built model, the same runs.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

import gb_pin
from gb_pin.robot.planar import planar_chain, planar_home, planar_kinematics, planar_target
from gb_pin.robot.target import KinematicTarget


def _read(m: int, length: float, axes: str = "xy") -> KinematicTarget:
    return KinematicTarget(planar_chain(m, length), "tip", home=planar_home(m), axes=axes)


@pytest.mark.parametrize(
    ("m", "length", "axes"), [(2, 1.0, "xy"), (5, 1.0, "xy"), (20, 0.7, "xyz"), (50, 1.0, "xy")]
)
def test_arrays_equal_the_ones_read_from_the_model(m: int, length: float, axes: str) -> None:
    built, read = planar_target(m, length, axes=axes), _read(m, length, axes)
    a, b = built.chain.to_arrays(), read.chain.to_arrays()
    assert a.keys() == b.keys()
    for key in a:
        x, y = np.asarray(a[key]), np.asarray(b[key])
        assert x.dtype == y.dtype and x.shape == y.shape and np.array_equal(x, y), key
    for name in ("lower", "upper", "home", "reference", "_q_ref"):
        x, y = getattr(built, name), getattr(read, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name
    assert built.joints == read.joints and built.name == read.name and built.axes == read.axes
    assert built._full_ids == read._full_ids
    assert built._table.order == read._table.order and built._table.kinds == read._table.kinds
    assert built._table.continuous == read._table.continuous
    assert np.array_equal(built._table.axes, read._table.axes)
    assert planar_kinematics(m, length, axes).n_task == len(axes)


def test_model_is_built_on_first_use_and_matches() -> None:
    target = planar_target(7, targets=np.array([[0.5, 0.1]]))
    assert target._model is None and target._full_model is None
    read = _read(7, 1.0)
    assert target.frame_id == read.frame_id
    assert target.model.nq == read.model.nq == 7 and target.full_model.njoints == read.full_model.njoints
    q = np.random.default_rng(0).uniform(-2.0, 2.0, (20, 7))
    np.testing.assert_allclose(target.forward(q), target.forward_pinocchio(q), atol=1e-14)
    np.testing.assert_array_equal(target.forward(q), read.forward(q))
    np.testing.assert_array_equal(target.full_configuration(q[0]), read.full_configuration(q[0]))


def test_preset_runs_equal_the_runs_on_the_read_model() -> None:
    preset = gb_pin.babble("planar5", movements=60, seed=3)
    read = gb_pin.babble(_read(5, 1.0), movements=60, seed=3, targets=preset.targets)
    np.testing.assert_array_equal(preset.history.error, read.history.error)
    np.testing.assert_array_equal(preset.model.predict(preset.targets), read.model.predict(read.targets))


def test_bad_arguments_raise_the_package_error() -> None:
    with pytest.raises(gb_pin.InvalidArgumentError, match="m"):
        planar_target(0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="total_length"):
        planar_target(3, -1.0)
    with pytest.raises(gb_pin.InvalidArgumentError, match="axes"):
        planar_target(3, axes="xq")


def test_a_planar_run_does_not_import_pinocchio() -> None:
    code = (
        "import sys, gb_pin\n"
        "r = gb_pin.babble('planar5', movements=5, seed=0)\n"
        "r.inverse(r.targets[:2])\n"
        "assert 'pinocchio' not in sys.modules, 'pinocchio imported'\n"
        "r.target.model\n"
        "assert 'pinocchio' in sys.modules\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False
    )
    assert out.returncode == 0, out.stderr[-2000:]
