"""Every ```python and ```bash block of README.md and docs/*.md runs as written, so docs cannot go stale.

Each block runs in its own folder holding small stand-ins for what a reader brings: ``my_arm.urdf``
(+ ``my_arm.srdf``), ``points.csv`` / ``poses.csv``, ``examples/`` and ``my_driver`` (a Python object
whose ``move_and_read(q)`` reads the kinematic SO-101). Runs are made small, the same way for every
block (:func:`shrink`): ``--movements N`` / ``movements=N`` at most :data:`SMALL_MOVEMENTS`, trials at
most 2, ``--samples`` at most 20, checkpoints every 20 movements.

Lines a test machine cannot run are left out by rule: ``pip install`` (the test's environment has the
extras), a venv prefix (``python3 -m venv .venv && .venv/bin/pip install ... &&``: the rest runs here),
and commands that serve a browser until Ctrl-C (``--view``, ``gb-pin replay/show FILE`` without
``--html``) and those that cannot be made small (:data:`LONG`); commands whose defaults are long
runs get small options appended (:data:`APPEND`); a line that ends with a status on purpose (the
example's simulated crash) passes with that status (:data:`STATUS`). A block that needs what a test
machine lacks says so, and is skipped with that reason: ``# needs: WHAT`` on its first line, or
``<!-- needs: WHAT -->`` on the line before its fence (invisible on the rendered page), e.g.
``browser``, ``a SLURM cluster``, ``a long run (...)``.

New blocks (other pages, other sections) are picked up without any change here.

The blocks run in one interpreter (:mod:`docs_runner`, started once for all selected blocks): each
python block in a fresh namespace, each ``gb-pin`` command of a bash block through
:func:`gb_pin.cli.main`, other bash lines in bash; numba's kernels, Pinocchio's models and MuJoCo are
loaded once, not once a block (a new interpreter a block cost about 10 minutes of CI). A block that
kills the interpreter fails alone: a new runner takes the blocks after it.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import NamedTuple

import pytest

ROOT = Path(__file__).resolve().parents[1]
RUNNER = Path(__file__).resolve().with_name("docs_runner.py")
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(
    r"(?:^<!--\s*needs:\s*(?P<html>.*?)\s*-->\n)?^```(?P<lang>python|bash)\n(?P<body>.*?)^```", re.M | re.S
)
SMALL_MOVEMENTS = 60
# A run watched by a rendered camera reads a picture per ask (about 50 ms of CPU each on Mesa's
# llvmpipe: 60 movements cost 80 s): such runs are made smaller still.
CAMERA_MOVEMENTS = 4
CAMERA = re.compile(r"--sensor\b|\bCameraSensor\b")
TIMEOUT = 600  # seconds a block may take (a cold numba cache compiles for 10-20 s)

pytestmark = pytest.mark.slow  # every docs block: not in the quick subset


class Block(NamedTuple):
    """One fenced block: where it is, its language, its text, and what it needs (None: it runs here)."""

    page: str
    line: int
    lang: str
    text: str
    needs: str | None


def blocks() -> list[Block]:
    """The ```python and ```bash blocks of README.md and docs/*.md, in order."""
    out = []
    for page in PAGES:
        text = page.read_text()
        for m in FENCE.finditer(text):
            body = m.group("body")
            first = body.lstrip().splitlines()[0] if body.strip() else ""
            marker = re.match(r"#\s*needs:\s*(.+)", first)
            needs = m.group("html") or (marker.group(1).strip() if marker else None)
            line = text.count("\n", 0, m.start("lang")) + 1
            out.append(Block(page.relative_to(ROOT).as_posix(), line, m.group("lang"), body, needs))
    return out


def _at_most(limit: int):  # type: ignore[no-untyped-def]
    def replace(m: re.Match[str]) -> str:
        return f"{m.group(1)}{min(int(m.group(2).replace('_', '')), limit)}"

    return replace


def shrink(text: str, movements: int = SMALL_MOVEMENTS) -> str:
    """The block with small runs: the same commands and calls, fewer movements, trials, samples."""
    for pattern, limit in (
        (r"(--movements[ =])([\d_]+)", movements),
        (r"(\bmovements=)([\d_]+)", movements),
        (r"(--trials[ =])(\d+)", 2),
        (r"(\btrials=)(\d+)", 2),
        (r"(--samples[ =])(\d+)", 20),
        (r"(--checkpoint-every[ =])(\d+)", 20),
        (r"(\bcheckpoint_every=)(\d+)", 20),
    ):
        text = re.sub(pattern, _at_most(limit), text)
    return text


# Commands whose defaults are long runs get small options appended (argparse keeps the last value).
APPEND = {"gb-pin bench --ik --protocol": "--movements 60 --paths 2"}
# Runs that state no length learn the default number of movements: they get a small one.
RUNS = ("gb-pin babble", "gb-pin trials")
RUN_LENGTH = re.compile(r"--(movements|resume|continue)\b")
# Commands that end with a status on purpose: the example's simulated crash (then --resume).
STATUS = {"--crash-at": 3}
# Commands that cannot be made small (a fixed schedule), left out like the serving ones.
LONG = ("gb-pin reproduce hardware", "gb-pin reproduce workspace")  # fixed schedules (10^4, 3000-3x10^4)
VENV_PREFIX = re.compile(r"^python3 -m venv \.venv && \.venv/bin/pip install [^&]*&& ")
SERVES = re.compile(r"(--view\b(?!-)|--serve\b|gb-pin (replay|show) \S+\s*($|#|--speed))")


def bash_lines(text: str) -> str:
    """The block's lines a test machine runs (see the module); the others become comments."""
    out = []
    for line in text.splitlines():
        line = VENV_PREFIX.sub("", line).replace(".venv/bin/", "")
        code, _, comment = line.partition(" #")
        if "pip install" in code or (SERVES.search(code) and "--html" not in code) or code.startswith(LONG):
            out.append(f"# (left out by tests/test_docs.py) {line}")
            continue
        for command, options in APPEND.items():
            if code.startswith(command):
                line = f"{code.rstrip()} {options}" + (f"  #{comment}" if comment else "")
        if code.startswith(RUNS) and not code.rstrip().endswith("\\") and not RUN_LENGTH.search(code):
            line = f"{code.rstrip()} --movements {SMALL_MOVEMENTS}" + (f"  #{comment}" if comment else "")
        for option, status in STATUS.items():
            if option in code:
                line = f"{code.rstrip()} || [ $? -eq {status} ]" + (f"  #{comment}" if comment else "")
        out.append(line)
    return "\n".join(out)


STAND_IN_DRIVER = """
class _StandInDriver:
    # tests/test_docs.py: the reader's driver; here, the kinematic SO-101 read exactly
    def __init__(self):
        import gb_pin
        self.arm = gb_pin.load_robot("so101")
    def move_and_read(self, q):
        return self.arm.forward(q)
my_driver = _StandInDriver()
"""

URDF = """<?xml version="1.0"?>
<robot name="my_arm">
  <link name="base"/>
  <link name="l1"/><link name="l2"/><link name="l3"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" effort="1"
      velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.05"/><axis xyz="0 1 0"/><limit lower="-1.8" upper="1.8" effort="1"
      velocity="1"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-2.5" upper="2.5" effort="1"
      velocity="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="l3"/><child link="tool"/>
    <origin xyz="0 0 0.25"/></joint>
</robot>
"""

SRDF = """<?xml version="1.0"?>
<robot name="my_arm">
  <group_state name="ready" group="arm">
    <joint name="j1" value="0.2"/><joint name="j2" value="0.5"/><joint name="j3" value="0.8"/>
  </group_state>
</robot>
"""


def _stand_ins(folder: Path) -> None:
    """What a reader brings: a URDF (and SRDF), point files, the examples."""
    (folder / "my_arm.urdf").write_text(URDF)
    (folder / "my_arm.srdf").write_text(SRDF)
    (folder / "points.csv").write_text("0.45,0.3,1.1\n0.4,0.35,1.0\n")
    (folder / "poses.csv").write_text("0.45,0.3,1.1\n")
    (folder / "examples").symlink_to(ROOT / "examples")
    (folder / "docs" / "figures").mkdir(parents=True)  # where the reproduce commands write


BLOCKS = blocks()


def test_docs_have_blocks() -> None:
    """README and docs show their commands in many blocks, and most of them run here."""
    assert len(BLOCKS) >= 30
    assert sum(b.needs is None for b in BLOCKS) >= 25
    assert {b.page for b in BLOCKS} >= {"README.md", "docs/IK.md", "docs/ROBOTS.md", "docs/TASKS.md"}


def test_shrink_and_rules() -> None:
    """The overrides keep a command's meaning and only make it small; serving lines are left out."""
    assert shrink("gb-pin babble --movements 3000 --trials 10") == "gb-pin babble --movements 60 --trials 2"
    assert shrink("babble(robot, movements=10_000, trials=4)") == "babble(robot, movements=60, trials=2)"
    assert shrink("--movements 20") == "--movements 20"
    assert bash_lines("gb-pin babble --robot so101 --table 0.0  # safe") == (
        f"gb-pin babble --robot so101 --table 0.0 --movements {SMALL_MOVEMENTS}  # safe"
    )
    assert bash_lines("gb-pin babble --resume run.ckpt") == "gb-pin babble --resume run.ckpt"
    text = bash_lines(
        "gb-pin replay run.npz   # loops\ngb-pin replay run.npz --html r.html\ngb-pin babble --view\n"
        "gb-pin babble --view-pace 3 --out x.npz --view\npip install -e .\n"
        "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/gb-pin babble --seed 0"
    ).splitlines()
    assert [line.startswith("#") for line in text] == [True, False, True, True, True, False]
    assert text[-1] == f"gb-pin babble --seed 0 --movements {SMALL_MOVEMENTS}"
    line = bash_lines("gb-pin bench --ik --protocol trac-ik --samples 20   # the protocol")
    assert (
        line == "gb-pin bench --ik --protocol trac-ik --samples 20 --movements 60 --paths 2  # the protocol"
    )
    assert bash_lines("gb-pin reproduce hardware --out x").startswith("#")
    camera = Block("p.md", 1, "bash", "gb-pin babble --sensor aruco:id=7 --movements 3000  # cam\n", None)
    assert prepared(camera) == f"gb-pin babble --sensor aruco:id=7 --movements {CAMERA_MOVEMENTS}  # cam"
    assert (
        bash_lines("python x.py --crash-at 20  # then") == "python x.py --crash-at 20 || [ $? -eq 3 ]  # then"
    )


def prepared(block: Block) -> str:
    """The block's text as it runs here: made small, the lines left out commented, a driver stand-in."""
    text = shrink(block.text)
    if block.lang == "python":
        if CAMERA.search(text):
            text = shrink(text, CAMERA_MOVEMENTS)
        if re.search(r"\bmy_driver\b", text) and not re.search(r"^my_driver\s*=", text, re.M):
            text = STAND_IN_DRIVER + text
        return text
    lines = bash_lines(text).splitlines()
    return "\n".join(
        shrink(ln, CAMERA_MOVEMENTS) if CAMERA.search(ln.partition(" #")[0]) else ln for ln in lines
    )


def block_id(block: Block) -> str:
    return f"{block.page}:{block.line}"


def run_blocks(chosen: list[Block], base: Path) -> dict[str, dict[str, object]]:
    """Run the blocks in tests/docs_runner.py, one interpreter for all of them; the result of each.

    Each block gets its own folder with the stand-ins. If the runner dies (a segfault, a timeout),
    the block it was running fails with what it printed, and a new runner takes the rest.
    """
    steps = []
    for i, block in enumerate(chosen):
        folder = base / f"{i:02d}_{re.sub(r'[^A-Za-z0-9]+', '_', block_id(block))}"
        folder.mkdir()
        _stand_ins(folder)
        steps.append(
            {"id": block_id(block), "lang": block.lang, "text": prepared(block), "folder": str(folder)}
        )
    env = {**os.environ, "MPLBACKEND": "Agg"}
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    results: dict[str, dict[str, object]] = {}
    results_file = base / "results.jsonl"
    while steps:
        steps_file = base / "steps.json"
        steps_file.write_text(json.dumps(steps))
        try:
            done = subprocess.run(
                [sys.executable, str(RUNNER), str(steps_file), str(results_file)], cwd=base, env=env,
                capture_output=True, text=True, timeout=TIMEOUT * len(steps), check=False,
            )  # fmt: skip
            tail = f"status {done.returncode}\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}"
        except subprocess.TimeoutExpired as exc:
            tail = f"timed out after {exc.timeout} s"
        if results_file.exists():
            for line in results_file.read_text().splitlines():
                result = json.loads(line)
                results[str(result["id"])] = result
        steps = [step for step in steps if step["id"] not in results]
        if steps:  # the runner died in this block
            results[steps[0]["id"]] = {
                "id": steps[0]["id"],
                "ok": False,
                "report": f"the runner died: {tail}",
            }
            steps = steps[1:]
    return results


@pytest.fixture(scope="module")
def outcomes(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict]:
    """The results of every selected block that runs here (``-k PAGE`` runs that page's blocks only)."""
    chosen = [
        item.callspec.params["block"]
        for item in request.session.items
        if getattr(item, "originalname", None) == "test_doc_block_runs"
        and item.callspec.params["block"].needs is None
    ]
    results = run_blocks(chosen, tmp_path_factory.mktemp("docs"))
    if os.environ.get("DOCS_TIMES"):  # each block's CPU and wall seconds, for finding the slow ones
        times = {key: result.get("seconds") for key, result in results.items()}
        Path(os.environ["DOCS_TIMES"]).write_text(json.dumps(times, indent=1) + "\n")
    return results


@pytest.mark.parametrize("block", BLOCKS, ids=[block_id(b) for b in BLOCKS])
def test_doc_block_runs(block: Block, outcomes: dict[str, dict]) -> None:
    """The block runs without error (imports, files and commands included), made small."""
    if block.needs is not None:
        pytest.skip(f"{block.page}:{block.line} needs {block.needs}")
    result = outcomes[block_id(block)]
    where = f"{block_id(block)} ({block.lang}, as run):\n{textwrap.indent(prepared(block), '    ')}"
    assert result["ok"], f"{where}\n{result['report']}"


def test_runner_reports_each_block(tmp_path: Path) -> None:
    """The runner reports each block: failures with their output, repeats of pure commands not rerun.

    A block that kills the interpreter fails alone: the next block still runs.
    """
    texts = [
        ("python", "print('hello')"),
        ("python", "print('before'); raise ValueError('broken block')"),
        ("bash", "gb-pin --version"),
        ("bash", "gb-pin robots --frames no_such_robot"),
        ("bash", "gb-pin --version\necho from-bash > out.txt && test -s out.txt"),
        ("python", "import os; os._exit(7)"),
        ("bash", "false"),
        ("python", "import sys; sys.exit(0)"),
        ("python", "import sys\nsys.path.insert(0, 'examples')\nfrom numpy_inverse import load_inverse"),
        ("python", "from numpy_inverse import load_inverse  # the earlier block's sys.path is gone"),
    ]
    chosen = [Block("page.md", i, lang, text, None) for i, (lang, text) in enumerate(texts)]
    results = run_blocks(chosen, tmp_path)
    ok = [results[f"page.md:{i}"]["ok"] for i in range(len(texts))]
    assert ok == [True, False, True, False, True, False, False, True, True, False]
    broken = str(results["page.md:1"]["report"])
    assert "before" in broken and "broken block" in broken
    assert "no_such_robot" in str(results["page.md:3"]["report"])
    assert "not run again" in str(results["page.md:4"]["report"])
    assert "the runner died: status 7" in str(results["page.md:5"]["report"])
