"""The targeted probes of the fourth reliability round (issue 33), run by tests/fuzz_files.py.

10 viewer backpressure (browsers that stop reading); 11 a MuJoCo plant that never lies
(instabilities, time settings, tampered states); 12 waits that Ctrl-C ends (long IK solves);
13 memory (joint paths, map storage, protocol samples); 14 onboarding budget; 15 kernel files named
in results; 16 silently wrong values (complex numbers, SRDF states, inverted limits); 17 disk
(explicit checkpoints on a full disk); 9 messages (outlier readings, --plant/--sensor keys, huge
numbers, HTML titles). The leftovers closed after the round: 12 the babbling loop's slices (Ctrl-C in
a babble whose E^X runs over many test targets), 16 SRDF states of example-robot-data robots, 17 a
trial journal on a disk that fills (the rerun reads its fallback), 18 checkpoints that verify
themselves (edited arrays and plant states refused by their digest).
"""

from __future__ import annotations

import _thread
import contextlib
import json
import signal
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
from fuzz_probes import CTX, SMALL_URDF, cli, expect_error, probe

import gb_pin
import gb_pin.ik
from gb_pin.exceptions import OnboardingBudgetError


# -- 10 viewer backpressure -------------------------------------------------------------------------
@probe("viewer", "10 viewer backpressure", "30 tabs that never read, one that does", limit_mb=400, seconds=60)
def _stalled_tabs(tmp: Path) -> None:
    import test_viewer_backpressure as t

    t.test_thirty_stalled_browsers_keep_memory_bounded_and_a_reader_served()


# -- 11 plant -------------------------------------------------------------------------------------------
def _mujoco() -> bool:
    try:
        import mujoco  # noqa: F401
    except ImportError:
        return False
    return True


@probe("plant", "11 plant", "kp=1e12 and commands of 1e6 rad: SimulationError, not the reset arm", seconds=60)
def _unstable(tmp: Path) -> None:
    if not _mujoco():
        return
    import os

    from gb_pin.sim import MujocoPlant

    os.chdir(tmp)  # MUJOCO_LOG.TXT
    stiff = MujocoPlant("so101", kp=1e12)
    expect_error(lambda: stiff.forward(np.zeros(stiff.n_joints) + 0.3), "unstable", "kp=1e+12", within=30)
    plant = MujocoPlant("so101")
    expect_error(lambda: plant.forward(np.zeros(plant.n_joints) + 1e6), "unstable")


@probe(
    "plant",
    "11 plant",
    "time settings beyond their bounds, in Python and on the command line",
    seconds=60,
    limit_mb=384,  # a gb-pin process with pinocchio, numba and MuJoCo loaded peaks at 260-300 MB
)
def _time_settings(tmp: Path) -> None:
    if not _mujoco():
        return
    from gb_pin.sim import MujocoPlant

    for options, needle in (
        ({"period": 1e6}, "period"),
        ({"period": 1e9}, "period"),
        ({"settle": 1e9, "tolerance": 1e-300}, "tolerance"),
        ({"settle": 1e9}, "settle"),
        ({"timestep": 1e-9}, "timestep"),
    ):
        expect_error(lambda o=options: MujocoPlant("so101", **o), needle)
    done = cli(["babble", "--robot", "so101", "--plant", "mujoco:period=1e9", "--movements", "5"], tmp)
    assert done.rc == 2 and "period must be at most" in done.err, done.err[-300:]


@probe("plant", "11 plant", "a tampered plant state in a checkpoint", seconds=60)
def _tampered_state(tmp: Path) -> None:
    if not _mujoco():
        return
    from gb_pin.sim import MujocoPlant

    plant = MujocoPlant("so101", period=0.03)
    plant.forward(plant.home)
    saved = plant.robot_state()
    for index, delta in ((1, 5.0), (0, 1.0), (1 + plant.mj_model.nq, 1e5)):
        state = saved["mujoco"].copy()
        state[index] += delta
        expect_error(
            lambda s=state: MujocoPlant("so101", period=0.03).set_robot_state({**saved, "mujoco": s})
        )


# -- 12 interrupts --------------------------------------------------------------------------------------
@probe("ik", "12 interrupts", "Ctrl-C 0.3 s into a 60 s IK solve lands within 2 s", seconds=60)
def _ik_interrupt(tmp: Path) -> None:
    signal.signal(signal.SIGINT, signal.default_int_handler)  # the harness's children ignore Ctrl-C
    arm = gb_pin.load_robot("planar5")
    gb_pin.ik.solve(arm, [[5.0, 5.0]], seed="home", timeout=1e-3)
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    start = time.perf_counter()
    try:
        gb_pin.ik.solve(arm, [[5.0, 5.0]], seed="home", timeout=60.0)
    except KeyboardInterrupt:
        elapsed = time.perf_counter() - start
        assert elapsed < 2.3, f"{elapsed:.1f} s"
        return
    finally:
        timer.cancel()
    raise AssertionError("the solve was not interrupted")


@probe("ik", "12 interrupts", "gb-pin ik --timeout 120: SIGINT ends the process (130) within 3 s", seconds=90)
def _ik_cli_interrupt(tmp: Path) -> None:
    gb_pin.babble("planar5", movements=50, seed=0).save(tmp / "run.npz")
    done = cli(["ik", "run.npz", "5", "5", "--timeout", "120"], tmp, interrupt=20.0, timeout=80)
    # the solve stops within milliseconds; the rest is the interpreter's exit (0.9-2.2 s measured)
    assert done.rc == 130 and done.after_interrupt < 3.0, (done.rc, done.after_interrupt, done.err[-200:])


@probe(
    "result",
    "12 interrupts",
    "Ctrl-C in gb-pin babble with 3*10^4 test targets (E^X every movement)",
    seconds=90,
    slow=True,
)  # fmt: skip  (tests/test_loop_slices.py runs the same in CI)
def _babble_interrupt(tmp: Path) -> None:
    np.savetxt(tmp / "t.csv", np.random.default_rng(0).uniform(-0.5, 0.5, (30_000, 2)), delimiter=",")
    args = ["babble", "--robot", "planar5", "--movements", "1000000", "--eval-targets", "t.csv",
            "--checkpoint", "c.ckpt", "--quiet"]  # fmt: skip
    done = cli(args, tmp, interrupt=12.0, timeout=80)
    # a chunk of 1000 evaluations took 5-10 s before the slices; now the loop returns every 0.1 s
    assert done.rc == 130 and done.after_interrupt < 3.0, (done.rc, done.after_interrupt, done.err[-200:])
    assert "checkpoint written to" in done.err, done.err[-300:]


# -- 13 memory ---------------------------------------------------------------------------------------------
@probe("api", "13 memory", "max_joint_step 1e-8 and 1e-300 in feedback reaching", limit_mb=200, seconds=60)
def _tiny_steps(tmp: Path) -> None:
    from gb_pin.learn.feedback import FeedbackReach

    result = gb_pin.babble("planar5", movements=50, seed=0)
    arm = result.target
    reach = FeedbackReach(
        result.model, [0.4, 0.3], arm.lower, arm.upper, start=arm.home - 0.5, max_joint_step=1e-8
    )
    for _ in range(2000):
        reach.tell(arm.forward(reach.ask()))
    expect_error(
        lambda: result.reach([0.4, 0.3], arm.forward, start=arm.home, max_joint_step=1e-300), "max_joint_step"
    )


@probe("api", "13 memory", "10^4 joints x 1000 task axes: refused before the map is allocated", seconds=60)
def _huge_map(tmp: Path) -> None:
    arm = gb_pin.FunctionTarget(
        lambda q: np.resize(q, 1000), np.zeros(10**4), lower=-1, upper=1, targets=np.zeros((2, 1000))
    )
    expect_error(lambda: gb_pin.babble(arm, movements=2, seed=0), "GiB", "fewer joints")


@probe("bench", "13 memory", "bench --ik --protocol --samples 10^7: refused at once", seconds=60)
def _bench_samples(tmp: Path) -> None:
    done = cli(["bench", "--ik", "--protocol", "trac-ik", "--robot", "panda", "--samples", "10000000"], tmp)
    assert done.rc == 2 and "samples fit" in done.err, done.err[-300:]


# -- 14 onboarding ----------------------------------------------------------------------------------------
def _chain(tmp: Path, n: int) -> Path:
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="{0.5 / n:.6f} 0 0"/><axis xyz="0 {i % 2} {1 - i % 2}"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(n)
    )
    path = tmp / f"chain{n}.urdf"
    path.write_text(f'<robot name="chain{n}">{links}{joints}</robot>')
    return path


@probe("urdf", "14 onboarding", "a 200-joint chain: onboarded or refused within its budget", limit_mb=600,
       seconds=150, slow=True)  # fmt: skip
def _long_chain(tmp: Path) -> None:
    start = time.perf_counter()
    with contextlib.suppress(OnboardingBudgetError):
        gb_pin.KinematicTarget.from_urdf(_chain(tmp, 200), "l200")
    assert time.perf_counter() - start < 120


@probe("urdf", "14 onboarding", "a budget of 0 s: the one-line error", seconds=60)
def _zero_budget(tmp: Path) -> None:
    from gb_pin.robot import onboarding

    onboarding.BUDGET_SECONDS, onboarding.BUDGET_PER_JOINT = 0.0, 0.0
    expect_error(lambda: gb_pin.KinematicTarget.from_urdf(SMALL_URDF, "tool"), "give a home")


# -- 15 kernel files ---------------------------------------------------------------------------------------
@probe("result_urdf", "15 kernel files", "a recorded robot path linking to /proc/kmsg or /proc/self/status",
       seconds=60)  # fmt: skip
def _kernel_robot_path(tmp: Path) -> None:
    gb_pin.babble(gb_pin.KinematicTarget.from_urdf(SMALL_URDF, "tool"), movements=20, seed=0).save(
        tmp / "r.npz"
    )
    with np.load(tmp / "r.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    for i, target in enumerate(("/proc/kmsg", "/proc/self/status")):
        link = tmp / f"robot{i}.urdf"
        link.symlink_to(target)
        meta = json.loads(str(arrays["meta"]))
        meta["robot_source"]["path"] = str(link)
        np.savez(tmp / f"k{i}.npz", **{**arrays, "meta": np.array(json.dumps(meta))})
        expect_error(lambda p=tmp / f"k{i}.npz": gb_pin.BabbleResult.load(p), "robot")
        done = cli(["show", f"k{i}.npz"], tmp, timeout=60)
        assert done.rc in (0, 2) and "Traceback" not in done.err, done.err[-300:]


# -- 16 silent values --------------------------------------------------------------------------------------
@probe("api", "16 silent values", "complex outputs and targets, SRDF states, inverted limits", seconds=60)
def _silent_values(tmp: Path) -> None:
    expect_error(lambda: gb_pin.FunctionTarget(lambda q: np.cumsum(q) + 1j, [0.1, 0.2]), "complex")
    expect_error(lambda: gb_pin.ik.solve("planar5", np.array([[0.3 + 1e-3j, 0.3]]), seed="home"), "complex")
    load = gb_pin.KinematicTarget.from_urdf
    for joint, needle in (('name="nope" value="0.5"', "nope"), ('name="j1" value="nan"', "nan")):
        (tmp / "s.srdf").write_text(
            f'<robot name="a"><group_state name="g" group="a"><joint {joint}/></group_state></robot>'
        )
        expect_error(lambda: load(SMALL_URDF, "tool", home="g", srdf=tmp / "s.srdf"), needle)
    text = SMALL_URDF.read_text().replace('lower="-2.0" upper="2.0"', 'lower="2.0" upper="-2.0"', 1)
    (tmp / "inv.urdf").write_text(text)
    expect_error(lambda: gb_pin.KinematicTarget.from_urdf(tmp / "inv.urdf", "tool"), "lower limit")


# -- 17 disk -------------------------------------------------------------------------------------------------
@probe("checkpoint", "17 disk", "an explicit save_checkpoint on a full disk names the file", seconds=60)
def _explicit_checkpoint_full(tmp: Path) -> None:
    session = gb_pin.babble_session("planar5", movements=20, seed=0)
    session.tell(session.target.forward(session.ask()))
    CTX.full.clear()
    CTX.full.fill()
    CTX.full.patch()
    where = CTX.full.path / "explicit.ckpt"
    expect_error(lambda: session.save_checkpoint(where), "explicit.ckpt")


@probe("journal", "17 disk", "reproduce on a disk that fills: the rerun reads the moved journal", seconds=90)
def _journal_rerun(tmp: Path) -> None:
    import test_disk_round4 as t

    with contextlib.ExitStack() as stack:
        mp = stack.enter_context(_monkeypatch())
        t.test_reproduce_on_a_disk_that_fills_keeps_every_finished_trial_for_the_rerun(tmp, mp)


# -- 18 checkpoints that verify themselves ---------------------------------------------------------------
@probe("checkpoint", "18 digests", "edited arrays, headers and plant states of a checkpoint", seconds=60)
def _digests(tmp: Path) -> None:
    import test_checkpoint_digest as t

    t.test_the_digest_covers_every_array_and_the_header(tmp)
    if _mujoco():
        t.test_a_plant_state_edited_within_its_bounds_is_refused(tmp)


@probe("urdf", "16 silent values", "SRDF states of example-robot-data and user SRDFs naming missing joints",
       seconds=60)  # fmt: skip
def _srdf_states(tmp: Path) -> None:
    import test_silent_values as t

    t.test_a_used_srdf_state_naming_a_missing_joint_and_leaving_a_chain_joint_unset_is_refused(tmp)
    t.test_example_robot_data_srdfs_naming_joints_of_fuller_robots_load(tmp)


@contextlib.contextmanager
def _monkeypatch() -> Any:
    import pytest

    with pytest.MonkeyPatch.context() as mp:
        yield mp


# -- 9 messages ---------------------------------------------------------------------------------------
@probe("api", "9 messages", "one outlier reading told: the error names the reading", seconds=60)
def _outlier(tmp: Path) -> None:
    session = gb_pin.babble_session("planar5", movements=200, seed=0)

    def run() -> None:
        for i in range(3000):
            q = session.ask()
            session.tell([1e6, 1e6] if i == 20 else session.target.forward(q))

    expect_error(run, "the reading [1000000. 1000000.]")


@probe(
    "cli",
    "9 messages",
    "--plant/--sensor: auto as --help shows it, repeated keys refused",
    seconds=90,
    limit_mb=384,  # (MuJoCo loaded, as above)
)
def _cli_keys(tmp: Path) -> None:
    done = cli(["babble", "--robot", "planar5", "--sensor", "noise=0.01,noise=0.02", "--movements", "5"], tmp)
    assert done.rc == 2 and "given twice" in done.err, done.err[-300:]
    done = cli(["babble", "--robot", "planar5", "--sensor", "noise=1e308", "--movements", "5"], tmp)
    assert done.rc == 2 and "noise must be at most" in done.err, done.err[-300:]
    if _mujoco():
        done = cli(
            ["babble", "--robot", "so101", "--plant", "mujoco:settle=auto,damping=auto", "--movements", "3"],
            tmp,
        )
        assert done.rc == 0, done.err[-300:]


@probe("api", "9 messages", "max_joint_step=10**400; a direction override in an exported title", seconds=60)
def _huge_and_titles(tmp: Path) -> None:
    expect_error(
        lambda: gb_pin.babble("planar5", movements=5, seed=0, max_joint_step=10**400), "max_joint_step"
    )
    from gb_pin.viewer.page import html_page

    page = html_page([], "arm\u202egnp.exe")
    assert "\u202e" not in page[page.index("<title>") : page.index("</title>")]
