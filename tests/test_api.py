"""Tests of gb_pin.runs.api (babble, BabbleResult) and gb_pin.runs.results_file (save_result, load_result).

Bad input must raise gb_pin's own errors (ValueError subclasses for arguments) with a message that
names the parameter and the value received; broken result files raise ResultFileError naming the file.
"""

from __future__ import annotations

import math
import zipfile

import numpy as np
import pytest

import gb_pin
from gb_pin import InvalidArgumentError, ResultFileError, UnknownRobotError

MOVEMENTS = 20


@pytest.fixture(scope="module")
def result() -> gb_pin.BabbleResult:
    """A short planar5 run (seed 0)."""
    return gb_pin.babble(robot="planar5", movements=MOVEMENTS, seed=0)


# -- bad input ------------------------------------------------------------------------------------
def test_error_classes_are_value_errors() -> None:
    """Argument errors are ValueErrors and GbPinErrors; ResultFileError is a GbPinError only."""
    assert issubclass(InvalidArgumentError, ValueError)
    assert issubclass(UnknownRobotError, InvalidArgumentError)
    assert issubclass(InvalidArgumentError, gb_pin.GbPinError)
    assert issubclass(ResultFileError, gb_pin.GbPinError)
    assert not issubclass(ResultFileError, ValueError)


@pytest.mark.parametrize("robot", ["planar1", "planar-3", "plnar5"])
def test_unknown_robot(robot: str) -> None:
    """An invalid robot name raises UnknownRobotError naming the value."""
    with pytest.raises(UnknownRobotError) as info:
        gb_pin.babble(robot=robot, movements=1)
    assert repr(robot) in str(info.value)


BAD_ARGUMENTS = [
    ("movements", 0),
    ("movements", -5),
    ("movements", 2.5),
    ("movements", "10"),
    ("learning_rate", 0),
    ("learning_rate", -1),
    ("learning_rate", math.nan),
    ("learning_rate", math.inf),
    ("learning_rate", "0.1"),
    ("sigma", -0.1),
    ("radius", 0),
    ("radius", -1),
    ("path_length", 0),
    ("p_home", 1.5),
    ("seed", -1),
    ("seed", "abc"),
]


@pytest.mark.parametrize(("name", "value"), BAD_ARGUMENTS)
def test_bad_argument_names_parameter_and_value(name: str, value: object) -> None:
    """A bad scalar argument raises InvalidArgumentError naming the parameter and the value."""
    kwargs: dict[str, object] = {"robot": "planar5", "movements": 3, "seed": 0, name: value}
    with pytest.raises(InvalidArgumentError) as info:
        gb_pin.babble(**kwargs)  # type: ignore[arg-type]
    message = str(info.value)
    assert name in message
    assert repr(value) in message


@pytest.mark.parametrize(
    ("targets", "needle"),
    [
        (np.zeros((5, 3)), "(5, 3)"),
        (np.zeros(5), "5"),
        ([[0.5, 0.0], [0.6, math.nan]], "nan"),
        ([[0.5, math.inf]], "inf"),
    ],
)
def test_bad_targets(targets: object, needle: str) -> None:
    """Targets of the wrong shape or with non-finite entries raise InvalidArgumentError naming them."""
    with pytest.raises(InvalidArgumentError) as info:
        gb_pin.babble(robot="planar5", movements=3, seed=0, targets=targets)  # type: ignore[arg-type]
    message = str(info.value)
    assert "targets" in message
    assert needle in message


# -- results --------------------------------------------------------------------------------------
def test_inverse_shapes(result: gb_pin.BabbleResult) -> None:
    """result.inverse maps (N, 2) -> (N, m) and (2,) -> (m,), the single point as a row of the batch."""
    X = np.array([[0.5, 0.1], [0.6, -0.2], [0.7, 0.0]])
    Q = result.inverse(X)
    assert Q.shape == (3, 5)
    assert result.inverse(X[1]).shape == (5,)
    np.testing.assert_array_equal(result.inverse(X[1]), Q[1])
    assert result.inverse([[0.5, 0.1]]).shape == (1, 5)
    assert gb_pin.babble("planar20", movements=2, seed=0).inverse(X).shape == (3, 20)


def test_result_fields(result: gb_pin.BabbleResult) -> None:
    """target, targets, history and the run's bookkeeping describe the run."""
    assert isinstance(result.target, gb_pin.KinematicTarget)
    assert (result.target.n_joints, result.target.n_task) == (5, 2)
    np.testing.assert_array_equal(result.targets, gb_pin.load_robot("planar5").targets)
    assert result.targets.shape == (25, 2)
    history = result.history
    np.testing.assert_array_equal(history.movements, np.arange(MOVEMENTS + 1))
    assert history.error.shape == history.home_distance.shape == (MOVEMENTS + 1,)
    assert np.all(np.isfinite(history.error)) and np.all(np.isfinite(history.home_distance))
    assert result.error == history.error[-1]
    assert result.home_distance == history.home_distance[-1]
    assert history.at(MOVEMENTS) == (result.error, result.home_distance)
    with pytest.raises(InvalidArgumentError, match="movements"):
        history.at(MOVEMENTS + 1)
    assert (result.robot, result.seed, result.movements, result.steps) == ("planar5", 0, MOVEMENTS, 500)
    assert result.n_prototypes == result.model.prototypes_.shape[0] >= 1
    # The paper's values (Sec. III-A); sigma from Eq. 12 and sigma_delta = 0.1 sigma, up to rounding.
    expected = {"learning_rate": 0.1, "sigma": 0.05, "sigma_delta": 0.005, "radius": 0.1, "p_home": 0.1}
    config = result.config.as_dict()
    assert config.pop("cutoff") is None  # the paper's sums over every prototype
    assert config == pytest.approx({**expected, "path_length": 25}, rel=1e-12)


def test_eval_targets_become_result_targets() -> None:
    """With eval_targets, result.targets is that set and E^X is measured on it (E_0 by hand)."""
    X = np.array([[0.5, 0.0], [0.6, 0.3]])
    res = gb_pin.babble("planar5", movements=3, seed=0, eval_targets=X)
    np.testing.assert_array_equal(res.targets, X)
    x_home = res.target.forward(res.target.home)
    assert res.history.error[0] == pytest.approx(np.mean(np.linalg.norm(X - x_home, axis=1)), abs=1e-12)


# -- save and load --------------------------------------------------------------------------------
def test_save_load_round_trip(result: gb_pin.BabbleResult, tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A saved and loaded result predicts identically and keeps the history and bookkeeping."""
    path = tmp_path / "run.npz"
    gb_pin.save_result(result, path)
    assert [p.name for p in tmp_path.iterdir()] == ["run.npz"]  # no temporary file left behind
    loaded = gb_pin.load_result(path)
    X = np.random.default_rng(0).uniform([0.2, -0.5], [0.9, 0.5], (50, 2))
    np.testing.assert_array_equal(loaded.inverse(X), result.inverse(X))
    for field in ("movements", "error", "home_distance"):
        np.testing.assert_array_equal(getattr(loaded.history, field), getattr(result.history, field))
    np.testing.assert_array_equal(loaded.targets, result.targets)
    assert loaded.config == result.config
    assert (loaded.robot, loaded.seed, loaded.movements, loaded.steps) == (
        result.robot,
        result.seed,
        result.movements,
        result.steps,
    )
    assert loaded.n_prototypes == result.n_prototypes


def test_save_method_and_generator_seed(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """BabbleResult.save writes what load_result reads; a Generator-seeded run loads with seed None."""
    res = gb_pin.babble("planar3", movements=5, seed=np.random.default_rng(1))
    path = tmp_path / "gen.npz"
    res.save(str(path))
    loaded = gb_pin.load_result(str(path))
    assert loaded.seed is None
    np.testing.assert_array_equal(loaded.inverse(res.targets), res.inverse(res.targets))


def test_save_load_keeps_recording(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Recorded steps survive the round trip; a run without recording loads with recording None."""
    res = gb_pin.babble("planar3", movements=6, seed=2, record=gb_pin.Recording(every=5))
    assert res.recording is not None
    path = tmp_path / "recorded.npz"
    gb_pin.save_result(res, path)
    loaded = gb_pin.load_result(path)
    assert loaded.recording is not None
    for field in ("step", "movement", "posture", "target", "position"):
        np.testing.assert_array_equal(getattr(loaded.recording, field), getattr(res.recording, field))
    plain = gb_pin.babble("planar3", movements=2, seed=2)
    gb_pin.save_result(plain, tmp_path / "plain.npz")
    assert gb_pin.load_result(tmp_path / "plain.npz").recording is None


@pytest.fixture
def saved(result: gb_pin.BabbleResult, tmp_path) -> bytes:  # type: ignore[no-untyped-def]
    """The bytes of a valid result file."""
    path = tmp_path / "valid.npz"
    gb_pin.save_result(result, path)
    return path.read_bytes()


def assert_result_file_error(path) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ResultFileError) as info:
        gb_pin.load_result(path)
    assert str(path) in str(info.value)


@pytest.mark.parametrize("keep", [0.0, 0.5, 0.99])
def test_truncated_file(saved: bytes, tmp_path, keep: float) -> None:  # type: ignore[no-untyped-def]
    """A truncated result file raises ResultFileError naming the file."""
    path = tmp_path / "truncated.npz"
    path.write_bytes(saved[: int(keep * len(saved))])
    assert_result_file_error(path)


def test_random_bytes(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A file of random bytes raises ResultFileError naming the file."""
    path = tmp_path / "random.npz"
    path.write_bytes(np.random.default_rng(0).bytes(4096))
    assert_result_file_error(path)


def test_foreign_npz(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """An npz archive that is not a gb_pin result raises ResultFileError naming the file."""
    path = tmp_path / "foreign.npz"
    np.savez(path, weights=np.arange(3.0), bias=np.zeros(2))
    assert_result_file_error(path)


def test_foreign_npz_with_the_right_keys(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """An npz with gb_pin's array names but another header raises ResultFileError naming the file."""
    path = tmp_path / "lookalike.npz"
    keys = ("movements", "error", "home_distance", "targets", "prototypes", "matrices", "offsets")
    np.savez(path, meta=np.array('{"format": "something.else"}'), **{k: np.zeros(1) for k in keys})
    assert_result_file_error(path)


def test_missing_file(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A missing file raises ResultFileError naming the file."""
    assert_result_file_error(tmp_path / "missing.npz")


def test_npy_file(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A plain .npy array file raises ResultFileError naming the file."""
    path = tmp_path / "array.npy"
    np.save(path, np.arange(3.0))
    assert_result_file_error(path)


def test_corrupted_member(saved: bytes, tmp_path) -> None:  # type: ignore[no-untyped-def]
    """A result file whose compressed data is damaged raises ResultFileError naming the file."""
    path = tmp_path / "corrupted.npz"
    path.write_bytes(saved)
    with zipfile.ZipFile(path) as archive:
        info = archive.getinfo("offsets.npy")
    data = bytearray(saved)
    # The member's data follow its 30-byte local header, its name and its extra field.
    name_length = int.from_bytes(data[info.header_offset + 26 : info.header_offset + 28], "little")
    extra_length = int.from_bytes(data[info.header_offset + 28 : info.header_offset + 30], "little")
    start = info.header_offset + 30 + name_length + extra_length + info.compress_size // 2
    for i in range(start, start + 16):
        data[i] ^= 0xFF
    path.write_bytes(bytes(data))
    assert_result_file_error(path)


@pytest.mark.parametrize("header", ["[1]", "null", '{"format": "gb_pin.result", "format_version": "2"}'])
def test_malformed_header(tmp_path, header: str) -> None:  # type: ignore[no-untyped-def]
    """An npz with gb_pin's array names and a malformed JSON header raises ResultFileError naming the file."""
    path = tmp_path / "header.npz"
    keys = ("movements", "error", "home_distance", "targets", "prototypes", "matrices", "offsets")
    np.savez(path, meta=np.array(header), **{k: np.zeros(1) for k in keys})
    assert_result_file_error(path)
