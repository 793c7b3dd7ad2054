"""A :class:`~gb_pin.learn.state.BabbleState` as plain arrays and back, validated.

Checkpoint files hold these arrays. Everything read back is checked (dtype, shape, range,
consistency) before any compiled code sees it: a tampered or corrupted file gets
:class:`~gb_pin.exceptions.InvalidArgumentError` (reported as ``ResultFileError`` by the
checkpoint reader), never an out-of-bounds read.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError
from gb_pin.learn import layout
from gb_pin.learn.body.chain import KinematicChain
from gb_pin.learn.config import BabbleConfig
from gb_pin.learn.goals import GoalGenerator
from gb_pin.learn.history import RecordedSteps
from gb_pin.learn.llm import LocalLinearMap

if TYPE_CHECKING:
    from gb_pin.learn.state import BabbleState

# The bit generators a checkpoint may name (never np.random's legacy global functions).
BIT_GENERATORS = {"PCG64": np.random.PCG64, "PCG64DXSM": np.random.PCG64DXSM, "MT19937": np.random.MT19937,
                  "Philox": np.random.Philox, "SFC64": np.random.SFC64}  # fmt: skip


def state_to_arrays(st: BabbleState) -> dict[str, NDArray[Any]]:
    """Every array of the state, trimmed to what is in use."""
    c = int(st.istate[layout.RECORDED])
    out: dict[str, NDArray[Any]] = {
        "home": st.home,
        "lower": st.lower,
        "upper": st.upper,
        "targets": st.targets,
        "eval_targets": st.eval_targets,
        "schedule": st.schedule,
        "errors": st.errors,
        "distances": st.distances,
        "components": st.components,
        **st.llm.to_arrays(),
        "noise_A": st.A,
        "noise_b": st.b,
        "istate": st.istate,
        "record": np.array(st.record, dtype=np.int64),
        "goal_istate": st.goal_state.istate,
        "goal_fstate": st.goal_state.fstate,
        "until_error": np.array(np.nan if st.until_error is None else st.until_error),
        "max_joint_step": np.array(st.max_step),
        "reach": st.reach,
        "reaches": st.reaches,
    }
    if st.sensor is not None:  # its generator's state goes to the file's header (sensor_rng)
        out["sensor_std"] = st.sensor.std
        out["sensor_loss"] = np.array(st.sensor.loss)
    for key in st.VECTORS:
        out[key] = st.vectors[key]
    for key, arr in st.rec.items():
        out["rec_" + key] = arr[:c]
    if st.chain is not None:  # a robot given as a function or on hardware has none
        out.update(st.chain.to_arrays())
    if st.changes:
        out["change_movements"] = np.array([at for at, _ in st.changes], dtype=np.int64)
        for i, (_, chain) in enumerate(st.changes):
            out.update(chain.to_arrays(prefix=f"change{i}_chain_"))
    return out


def _real(
    arrays: dict[str, Any], key: str, shape: tuple[int, ...], finite: bool = True
) -> NDArray[np.float64]:
    arr = np.asarray(arrays[key])
    if arr.dtype.kind not in "fiu" or arr.shape != shape:
        raise InvalidArgumentError(f"{key} must be real of shape {shape}, got {arr.dtype} {arr.shape}")
    out = np.array(arr, dtype=np.float64, order="C")  # a copy: the state owns its arrays
    if finite and not np.all(np.isfinite(out)):
        raise InvalidArgumentError(f"{key} must be finite")
    return out


def _ints(arrays: dict[str, Any], key: str, shape: tuple[int, ...]) -> NDArray[np.int64]:
    arr = np.asarray(arrays[key])
    if arr.dtype.kind not in "iu" or arr.shape != shape:
        raise InvalidArgumentError(f"{key} must be integers of shape {shape}, got {arr.dtype} {arr.shape}")
    return np.array(arr, dtype=np.int64, order="C")


def _rng(rng_state: Any) -> np.random.Generator:
    if not isinstance(rng_state, dict) or rng_state.get("bit_generator") not in BIT_GENERATORS:
        raise InvalidArgumentError(
            f"unknown random generator state (bit generators: {', '.join(BIT_GENERATORS)})"
        )
    bit_generator = BIT_GENERATORS[rng_state["bit_generator"]]()
    try:
        bit_generator.state = rng_state
    except (TypeError, ValueError, KeyError, OverflowError) as exc:
        raise InvalidArgumentError(f"invalid random generator state ({exc})") from exc
    return np.random.Generator(bit_generator)


def state_from_arrays(
    st: BabbleState,
    arrays: dict[str, Any],
    config: BabbleConfig,
    rng_state: Any,
    goals: GoalGenerator,
    sensor_rng: Any = None,
) -> BabbleState:
    """Fill ``st`` from the arrays of :func:`state_to_arrays`, validating every one of them.

    ``sensor_rng``: the sensor generator's state, for a run with a sensor model.
    """
    try:
        _fill(st, arrays, config, rng_state, goals)
        _fill_extras(st, arrays, sensor_rng)
    except KeyError as exc:
        raise InvalidArgumentError(f"incomplete babbling state (missing {exc})") from exc
    except (TypeError, ValueError, OverflowError) as exc:
        if isinstance(exc, InvalidArgumentError):
            raise
        raise InvalidArgumentError(f"inconsistent babbling state ({exc!r})") from exc
    return st


def _fill(
    st: BabbleState, arrays: dict[str, Any], config: BabbleConfig, rng_state: Any, goals: GoalGenerator
) -> None:
    st.config = config
    st.rng = _rng(rng_state)
    if "chain_parents" in arrays:
        chain = st.chain = KinematicChain.from_arrays(arrays)
        m, n, C = chain.n_joints, chain.n_task, chain.n_components
    else:  # a robot given as a Python function or on hardware: no compiled chain
        st.chain = None
        m = np.shape(arrays["home"])[0] if np.ndim(arrays["home"]) == 1 else 0
        n = np.shape(arrays["targets"])[1] if np.ndim(arrays["targets"]) == 2 else 0
        C = 0
        if m < 1 or n < 1:
            raise InvalidArgumentError("home and targets must give at least one joint and one task axis")
    st.home = _real(arrays, "home", (m,))
    st.lower = _real(arrays, "lower", (m,), finite=False)
    st.upper = _real(arrays, "upper", (m,), finite=False)
    if np.any(np.isnan(st.lower)) or np.any(np.isnan(st.upper)) or np.any(st.lower > st.upper):
        raise InvalidArgumentError("joint limits must satisfy lower <= upper")
    N = np.shape(arrays["targets"])[0] if np.ndim(arrays["targets"]) == 2 else 0
    st.targets = _real(arrays, "targets", (max(N, 1), n))
    E = np.shape(arrays["eval_targets"])[0] if np.ndim(arrays["eval_targets"]) == 2 else 0
    st.eval_targets = _real(arrays, "eval_targets", (max(E, 1), n))
    T = np.shape(arrays["schedule"])[0] if np.ndim(arrays["schedule"]) == 1 else 0
    st.schedule = _ints(arrays, "schedule", (max(T, 1),))
    if np.any(np.diff(st.schedule) <= 0) or st.schedule[0] < 0:
        raise InvalidArgumentError("schedule must be increasing movement counts >= 0")
    st.errors = _real(arrays, "errors", (T,), finite=False)
    st.distances = _real(arrays, "distances", (T,), finite=False)
    # Files written before per-component histories have none: not measured (NaN).
    fresh_components = np.full((T, C), np.nan)
    st.components = (
        _real(arrays, "components", (T, C), finite=False) if "components" in arrays else fresh_components
    )
    for name, values in (("errors", st.errors), ("distances", st.distances), ("components", st.components)):
        if np.any(np.isinf(values) | (values < 0)):  # distances: NaN (not measured yet) or finite >= 0
            raise InvalidArgumentError(f"{name} must be distances >= 0 or NaN")
    K = np.shape(arrays["prototypes"])[0] if np.ndim(arrays["prototypes"]) == 2 else 0
    st.llm = LocalLinearMap.from_arrays(
        arrays, config.radius, config.learning_rate, capacity=max(2 * K, 256), cutoff=config.cutoff
    )
    if st.llm.n_inputs_ != n or st.llm.n_outputs_ != m:
        raise InvalidArgumentError(f"the map has {st.llm.n_outputs_} outputs and {st.llm.n_inputs_} inputs")
    st.A = _real(arrays, "noise_A", (m, n))
    st.b = _real(arrays, "noise_b", (m,))
    # Files written before motor babbling have no q_end: it was always q_home then.
    st.vectors = {k: _real(arrays, k, (m,) if k.startswith("q") else (n,))
                  for k in st.VECTORS if k in arrays or k not in ("q_end", "q_exec")}  # fmt: skip
    st.vectors.setdefault("q_end", st.home.copy())
    # Files written before missing readings existed: the last executed posture was the observed one.
    st.vectors.setdefault("q_exec", st.vectors["q_prev"].copy())
    if np.shape(arrays["istate"]) == (layout.OLD_ISTATE_SIZE,):  # before the reach ring and missing readings
        pad = np.zeros(layout.ISTATE_SIZE - layout.OLD_ISTATE_SIZE, dtype=np.asarray(arrays["istate"]).dtype)
        arrays = {**arrays, "istate": np.concatenate([np.asarray(arrays["istate"]), pad])}
    st.istate = _ints(arrays, "istate", (layout.ISTATE_SIZE,))
    record = _ints(arrays, "record", (3,))
    st.record = (int(record[0]), int(record[1]), int(record[2]))
    R = np.shape(arrays["rec_step"])[0] if np.ndim(arrays["rec_step"]) == 1 else -1
    rec = RecordedSteps.from_arrays(arrays, m, n)
    if rec is None or R < 0:
        raise InvalidArgumentError("the recording arrays are missing")
    st.rec = {}
    for key in RecordedSteps.FIELDS:
        arr = getattr(rec, key)
        grown = np.zeros((max(16, 2 * arr.shape[0]), *arr.shape[1:]), dtype=arr.dtype)
        grown[: arr.shape[0]] = arr
        st.rec[key] = grown
    st.goals = goals
    fresh = goals.start(st.targets)
    if "goal_istate" in arrays:  # files of gb_pin 0.1 have none: the paper's uniform goals
        gi = _ints(arrays, "goal_istate", fresh.istate.shape)
        gf = _real(arrays, "goal_fstate", fresh.fstate.shape, finite=False)
        st.goal_state = fresh._replace(targets=st.targets, istate=gi, fstate=gf)
        goals.check_state(st.goal_state)
    else:
        st.goal_state = fresh
    st.until_error = None
    if "until_error" in arrays:  # files written before until_error have none
        level = _real(arrays, "until_error", (), finite=False)
        if not (np.isnan(level) or level > 0):
            raise InvalidArgumentError(f"until_error must be a level > 0 or NaN, got {float(level)!r}")
        st.until_error = None if np.isnan(level) else float(level)
    st.changes = []
    if "change_movements" in arrays:
        C = np.shape(arrays["change_movements"])[0] if np.ndim(arrays["change_movements"]) == 1 else 0
        at = _ints(arrays, "change_movements", (max(C, 1),))
        chains: dict[int, Any] = {
            int(a): KinematicChain.from_arrays(arrays, prefix=f"change{i}_chain_") for i, a in enumerate(at)
        }
        st.set_changes(chains)
    _check_counters(st, K, R, T)


def _fill_extras(st: BabbleState, arrays: dict[str, Any], sensor_rng: Any) -> None:
    """The joint-step limit, the reach ring and the sensor (absent from files written before them)."""
    T = st.schedule.shape[0]
    st.max_step = np.inf
    if "max_joint_step" in arrays:
        step = float(_real(arrays, "max_joint_step", (), finite=False))
        if not step > 0:
            raise InvalidArgumentError(f"max_joint_step must be > 0 (inf: none), got {step!r}")
        st.max_step = step
    W = np.shape(arrays["reach"])[0] if "reach" in arrays and np.ndim(arrays["reach"]) == 1 else 50
    if not 1 <= W <= 10**6:
        raise InvalidArgumentError(f"reach window must hold 1 to 10^6 entries, got {W}")
    st.reach = _real(arrays, "reach", (W,)) if "reach" in arrays else np.zeros(W)
    if np.any(st.reach < 0):
        raise InvalidArgumentError("reach errors must be >= 0")
    st.reaches = _real(arrays, "reaches", (T,), finite=False) if "reaches" in arrays else np.full(T, np.nan)
    if st.istate[layout.REACHES] < 0 or st.istate[layout.MISSING] < 0:
        raise InvalidArgumentError("the counts of observed reaches and missing readings must be >= 0")
    st.sensor = None
    if "sensor_std" in arrays:
        n = st.targets.shape[1]
        std = _real(arrays, "sensor_std", (n,))
        loss = float(_real(arrays, "sensor_loss", ()))
        if np.any(std < 0) or not 0.0 <= loss < 1.0:
            raise InvalidArgumentError(f"sensor noise must be >= 0 and its loss in [0, 1), got loss {loss!r}")
        from gb_pin.learn.sensor import SensorArrays

        st.sensor = SensorArrays(std, loss, _rng(sensor_rng))


def _check_counters(st: BabbleState, K: int, R: int, T: int) -> None:
    """The counters must be consistent with the arrays they index (no out-of-bounds access)."""
    i = st.istate
    every, first, _ = st.record
    L = st.config.path_length
    ok = (
        i[layout.PROTOTYPES] == K
        and i[layout.MOVEMENTS] >= 0
        and 0 <= i[layout.STEP] <= L
        and i[layout.KIND] in (layout.NONE, layout.GOAL, layout.HOME, layout.BABBLE)
        and i[layout.LAST_KIND] in (layout.NONE, layout.GOAL, layout.HOME, layout.BABBLE)
        and 0 <= i[layout.EVAL_CURSOR] <= T
        and i[layout.STEPS] >= 0
        and i[layout.RECORDED] == R
        and every >= 1
        and first >= 0
        and (i[layout.KIND] != layout.NONE or i[layout.STEP] in (0, L))
    )
    if not ok:
        raise InvalidArgumentError(f"babbling state counters out of range or inconsistent: {i.tolist()}")
