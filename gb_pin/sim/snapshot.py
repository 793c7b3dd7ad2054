"""A simulated plant's state between asks, as plain arrays for session checkpoints.

A :class:`~gb_pin.sim.plant.MujocoPlant` is a physical thing with a state: where its links are
and how fast they move when the next posture is asked (after a short settling, still on the way),
and where its sensor's random stream stands. A session resumed from a checkpoint continues
bit-identical only if the plant continues from that same state, so sessions save the plant's
arrays beside the learner's (``robot_state()``) and restore them on resume
(``set_robot_state(arrays)``). The arrays:

- ``mujoco``: MuJoCo's full integration state (``mj_getState(..., mjSTATE_INTEGRATION)``: time,
  positions, velocities, controls, the solver's warm start), enough for an exact continuation;
- ``sensor``: the sensor generator's PCG64 state as six unsigned 64-bit words;
- ``counters``: asks and simulation steps so far;
- ``settings``: a SHA-256 digest of the model text, the settling rule and the sensor, so that a
  checkpoint is never continued on a plant with other servos, physics or sensor;
- ``camera`` (a rendering plant only): its pictures so far and its pixel noise's PCG64 state (7 words),
  so that a run watched by the plant's camera continues with the pictures it would have taken.

The arrays come from files (untrusted): :func:`unpack` checks every one before use.
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np
from numpy.typing import NDArray

from gb_pin.exceptions import InvalidArgumentError

KEYS = ("counters", "mujoco", "sensor", "settings")
OPTIONAL = ("camera",)
_MASK = (1 << 64) - 1


def digest(*parts: str) -> NDArray[np.uint8]:
    """SHA-256 of the texts, as 32 bytes."""
    h = hashlib.sha256()
    for part in parts:
        h.update(part.encode())
        h.update(b"\0")
    return np.frombuffer(h.digest(), dtype=np.uint8).copy()


def generator_words(rng: np.random.Generator) -> NDArray[np.uint64]:
    """A PCG64 generator's state as (6,) uint64: state (low, high), increment (low, high), cache."""
    st = rng.bit_generator.state
    if st.get("bit_generator") != "PCG64":
        raise InvalidArgumentError(
            f"the plant's sensor needs a PCG64 generator, got {st.get('bit_generator')}"
        )
    s, inc = int(st["state"]["state"]), int(st["state"]["inc"])
    words = [s & _MASK, s >> 64, inc & _MASK, inc >> 64, int(st["has_uint32"]), int(st["uinteger"])]
    return np.array(words, dtype=np.uint64)


def set_generator(rng: np.random.Generator, words: NDArray[np.uint64]) -> None:
    """Put ``rng`` (PCG64) in the state of :func:`generator_words`."""
    w = [int(v) for v in words]
    rng.bit_generator.state = {
        "bit_generator": "PCG64",
        "state": {"state": w[0] | (w[1] << 64), "inc": w[2] | (w[3] << 64)},
        "has_uint32": w[4],
        "uinteger": w[5],
    }


def unpack(arrays: Any, state_size: int, settings: NDArray[np.uint8]) -> dict[str, NDArray[Any]]:
    """The plant arrays of a checkpoint, checked: keys, dtypes, shapes, finite values, same settings.

    Raises:
        InvalidArgumentError: anything missing, malformed, or written by a plant of other settings.
    """
    if not isinstance(arrays, dict) or not set(KEYS) <= set(arrays) <= set(KEYS + OPTIONAL):
        keys = sorted(arrays) if isinstance(arrays, dict) else arrays
        raise InvalidArgumentError(
            f"a simulated plant's state has the arrays {list(KEYS)} (and a camera's {list(OPTIONAL)}), "
            f"got {keys!r:.200}"
        )
    out = {k: np.asarray(arrays[k]) for k in arrays}
    expected = {
        "counters": (np.int64, (2,)),
        "mujoco": (np.float64, (state_size,)),
        "sensor": (np.uint64, (6,)),
        "settings": (np.uint8, (32,)),
        "camera": (np.uint64, (7,)),
    }
    for key, (dtype, shape) in expected.items():
        if key not in out:
            continue
        if out[key].dtype != dtype or out[key].shape != shape:
            raise InvalidArgumentError(
                f"the plant's {key!r} must be {np.dtype(dtype).name} of shape {shape}, "
                f"got {out[key].dtype} of shape {out[key].shape}"
            )
    if not np.array_equal(out["settings"], settings):
        raise InvalidArgumentError(
            "the checkpoint's plant state was written by a plant of other settings (servos, gravity, "
            "settling, time step or sensor): resume with the plant the run was started with"
        )
    if not np.all(np.isfinite(out["mujoco"])) or np.any(out["counters"] < 0):
        raise InvalidArgumentError("the plant's state holds non-finite numbers or negative counters")
    for key, words in (("sensor", out["sensor"]), ("camera", out.get("camera", np.zeros(7, np.uint64))[1:])):
        if key in out and (int(words[4]) > 1 or int(words[5]) > 0xFFFFFFFF or not int(words[2]) & 1):
            raise InvalidArgumentError(f"the plant's {key} state is not a PCG64 state")
    return out
