"""A cold start's kernels compiled in two processes: the loop's callees split between this one and a helper.

With an empty numba cache (a read-only install, a new ``NUMBA_CACHE_DIR``, no precompile step) the
first run compiles the loop (:func:`~gb_pin.learn.loop.babble_loop`) and every kernel it calls, one
after the other: numba compiles a callee when the loop's type inference meets its call. The callees
are independent compilations, each cached on disk by numba. So when the cache is cold and writable
and a second core is there, :func:`parallel_compile` starts a helper process (``python -m
gb_pin.runs.coldstart``) that compiles its share (:data:`HELPER`) into the cache, while this process
compiles its own share (:data:`OWN`), waits for the helper (at most :data:`WAIT` seconds), and then
the loop, which loads the helper's kernels from the cache instead of compiling them (a kernel the
helper has not finished by then is compiled here as well: the same function for the same types, the
same cache entry). The machine code is the same either way: the same functions with the same
options (every kernel states its reference counting, :func:`gb_pin._jit.njit`) for the same
argument types, compiled by the same numba; only the process that compiles them differs.

The helper is stopped when the loop is compiled (or on an error, or Ctrl-C); it also stops by itself
when its parent is gone. Without a writable cache, on one core, with a warm cache, on a busy
machine (a 1-minute load average above the cores less one half: the helper would only take CPU
time from this process; ``GB_PIN_PARALLEL_COMPILE=1`` starts it anyway), or with
``GB_PIN_PARALLEL_COMPILE=0``, nothing is started and the loop compiles here alone as before.

The argument types of each callee are those the loop passes (:func:`callee_signatures`, read from
the arguments of a warm-up run); tests/test_coldstart.py checks that the loop compiles exactly them.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from typing import Any

# The loop's callees by the share of the work each process does (about equal CPU time, the helper's
# less its start-up); this process compiles OWN before the loop, in this order (the map's kernels:
# the last two call the first two), then waits for the helper (at most WAIT seconds).
OWN = ("llm_predict", "jacobian_of_prediction", "llm_learn", "noise_free_reach", "start_slice", "slice_over")
# The helper's share, in this order: the evaluation calls llm_predict, by then in the cache (this
# process compiles it first; the helper would compile it again if not).
HELPER = (
    "reach_median",
    "snap_start",
    "next_goal",
    "evaluate_model",
    "noise_add",
    "efficiency_weight",
    "direction_weight",
    "noise_walk",
)
WAIT = 5.0  # seconds this process waits for the helper's share before compiling what is left itself
ENV = "GB_PIN_PARALLEL_COMPILE"


def warmup_state() -> Any:
    """The :class:`~gb_pin.learn.state.BabbleState` of :func:`gb_pin.runs.api.warmup`'s run (planar2)."""
    from gb_pin.runs import setup
    from gb_pin.runs.spec import RunSpec

    return setup.start_state(setup.prepare(RunSpec("planar2", movements=1, seed=0, schedule=[0, 1])))


def callee_signatures(rng: Any, args: tuple[Any, ...]) -> dict[str, tuple[Any, tuple[Any, ...]]]:
    """Each callee of the loop by name: (its dispatcher, the argument types the loop calls it with).

    ``rng`` and ``args``: the loop's arguments (``BabbleState.rng``, ``BabbleState.kernel_args()``).
    """
    from numba import typeof, types

    from gb_pin.learn.exploration import noise_add, noise_walk
    from gb_pin.learn.goals.kernel import next_goal, snap_start
    from gb_pin.learn.llm_kernels import _jacobian_of_prediction, llm_learn, llm_predict
    from gb_pin.learn.loop import noise_free_reach, slice_over, start_slice
    from gb_pin.learn.metrics import evaluate_model, reach_median
    from gb_pin.learn.weighting import direction_weight, efficiency_weight

    learner, robot, run, goals, monitor = args
    mo, hyper, limits, ev = run.motion, learner.hyper, robot.limits, monitor.evaluation
    t = typeof
    count, real = types.int64, types.float64
    return {
        "llm_predict": (llm_predict, (t(mo.target), t(learner.lm), count, t(mo.q))),
        "jacobian_of_prediction": (
            _jacobian_of_prediction,
            (t(learner.lm), count, real, t(learner.scratch)),
        ),
        "llm_learn": (
            llm_learn,
            (t(mo.x), t(mo.q), real, t(hyper.learning_rate), t(learner.lm), count, t(learner.scratch)),
        ),
        "noise_walk": (
            noise_walk,
            (t(rng), t(hyper.sigma), t(hyper.sigma_delta), t(learner.noise.A), t(learner.noise.b)),
        ),
        "next_goal": (next_goal, (t(goals), t(rng), t(mo.path_start), t(mo.path_end))),
        "reach_median": (reach_median, (t(run.reach), count)),
        "snap_start": (snap_start, (t(goals), t(mo.path_end), t(mo.x_prev))),
        "noise_add": (noise_add, (t(learner.noise.A), t(learner.noise.b), t(mo.target), t(mo.q))),
        "efficiency_weight": (efficiency_weight, (t(mo.x), t(mo.x_prev), t(mo.q), t(mo.q_prev))),
        "direction_weight": (direction_weight, (t(mo.target), t(mo.target_prev), t(mo.x), t(mo.x_prev))),
        "noise_free_reach": (
            noise_free_reach,
            (t(mo.path_end), t(mo.x_prev), t(mo.q_exec), t(learner), count, t(limits.lower), t(limits.upper)),
        ),
        "evaluate_model": (evaluate_model, (t(ev), count, t(robot), t(learner.lm), count, t(mo), real)),
        "start_slice": (start_slice, (t(ev), count)),
        "slice_over": (slice_over, (t(ev), count)),
    }


def compile_share(names: tuple[str, ...], state: Any | None = None) -> None:
    """Compile (or load from the cache) the named callees for the warm-up run's types, in order."""
    state = warmup_state() if state is None else state
    plan = callee_signatures(state.rng, state.kernel_args())
    for name in names:
        dispatcher, sig = plan[name]
        dispatcher.compile(sig)


def cache_is_cold_and_writable() -> bool:
    """True when the loop has no cached machine code yet and numba can write its cache directory.

    Reads numba's cache index of the loop (internal attributes, guarded: False if they moved).
    """
    from gb_pin.learn.loop import babble_loop

    try:
        cache = babble_loop._cache
        path = cache._cache_path
        index = cache._cache_file._load_index()
    except Exception:  # another numba's internals: no helper, the loop compiles here as before
        return False
    return not index and _writable(path)


def _writable(path: str) -> bool:
    """Whether a file can be created in ``path`` (as numba's cache locators test it)."""
    try:
        with tempfile.TemporaryFile(dir=path):
            return True
    except OSError:
        return False


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def _idle_core(cores: int) -> bool:
    """Whether a core is free: the 1-minute load average below ``cores - 0.5`` (True if unknown)."""
    try:
        return os.getloadavg()[0] < cores - 0.5
    except (OSError, AttributeError):  # pragma: no cover - no load average on this system
        return True


def wanted() -> bool:
    """Whether a cold start here should compile in two processes (see the module's docstring)."""
    setting = os.environ.get(ENV, "").strip().lower()
    if setting in ("0", "false", "no", "off"):
        return False
    cores = _cores()
    if cores < 2 or not (setting in ("1", "true", "yes", "on") or _idle_core(cores)):
        return False
    return cache_is_cold_and_writable()


def start_helper() -> subprocess.Popen[bytes] | None:
    """The helper process compiling :data:`HELPER` (output discarded); None if it cannot start."""
    package_parent = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (package_parent, env.get("PYTHONPATH")) if p)
    env[ENV] = "0"  # the helper never starts a helper
    try:
        return subprocess.Popen(
            [sys.executable, "-m", "gb_pin.runs.coldstart", str(os.getpid())],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            env=env,
        )
    except OSError:
        return None


def wait_for(proc: subprocess.Popen[bytes], seconds: float) -> None:
    """Wait until the helper has compiled its share (it then exits), at most ``seconds``.

    Compiling the loop before the helper is done would compile the helper's unfinished kernels here
    as well (the loop's type inference meets them first): waiting is shorter.
    """
    with contextlib.suppress(subprocess.TimeoutExpired):  # a slow helper: the loop compiles the rest
        proc.wait(timeout=seconds)


def stop_helper(proc: subprocess.Popen[bytes]) -> None:
    """End the helper (its kernels are in the cache or no longer needed) and reap it."""
    if proc.poll() is None:
        proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:  # pragma: no cover - a helper stuck in a system call
        proc.kill()
        proc.wait()


@contextlib.contextmanager
def parallel_compile() -> Iterator[subprocess.Popen[bytes] | None]:
    """Within: a cold start's kernels compile in two processes (yields the helper), or here alone (None).

    On entry, if :func:`wanted`, starts the helper and compiles this process's share (:data:`OWN`);
    the block then compiles the loop. On exit the helper is stopped and reaped, whatever happened
    in the block (an error, Ctrl-C).
    """
    proc = start_helper() if wanted() else None
    try:
        if proc is not None:
            compile_share(OWN)
            wait_for(proc, WAIT)
        yield proc
    finally:
        if proc is not None:
            stop_helper(proc)


def _watch_parent(parent: int) -> None:
    """End this helper once the process that started it is gone (killed, or exited without stopping us)."""
    while True:
        if os.getppid() != parent:
            os._exit(0)
        time.sleep(0.2)


def main(argv: list[str] | None = None) -> int:
    """The helper: ``python -m gb_pin.runs.coldstart PARENT_PID`` compiles :data:`HELPER`."""
    args = sys.argv[1:] if argv is None else argv
    if args:
        threading.Thread(target=_watch_parent, args=(int(args[0]),), daemon=True).start()
    compile_share(HELPER)
    return 0


if __name__ == "__main__":
    os._exit(main())  # the kernels are in the cache: no interpreter teardown for the parent to wait on
