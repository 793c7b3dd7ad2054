"""The architecture's rules, checked on the code itself (docs/ARCHITECTURE.md).

- the learner layer (gb_pin.learn) loads neither pinocchio, meshcat, matplotlib, dask nor
  tornado, and learns on a chain given as arrays without Pinocchio;
- ``import gb_pin`` is lazy (PEP 562) and every public name resolves;
- no import cycles between gb_pin's modules, imports inside functions included;
- no module over 500 lines; no compiled kernel with more than 8 positional parameters;
- the hyperparameters have one source of truth (gb_pin.learn.config).
"""

from __future__ import annotations

import ast
import importlib
import inspect
import json
import pkgutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.learn.config import BY_NAME, HYPERPARAMETERS, NAMES, BabbleConfig

ROOT = Path(gb_pin.__file__).parent
HEAVY = ("pinocchio", "meshcat", "matplotlib", "dask", "distributed", "tornado")


def _run(code: str) -> str:
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def _modules() -> dict[str, Path]:
    """Every module of gb_pin: dotted name -> file."""
    out = {}
    for path in sorted(ROOT.rglob("*.py")):
        rel = path.relative_to(ROOT.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def test_learner_layer_loads_no_robot_viewer_plot_or_cluster_library() -> None:
    """Importing every module of gb_pin.learn, in a fresh interpreter, loads none of the heavy libraries."""
    names = [n for n in _modules() if n == "gb_pin.learn" or n.startswith("gb_pin.learn.")]
    code = (
        "import importlib, json, sys\n"
        f"for n in {names!r}: importlib.import_module(n)\n"
        f"print(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    )
    assert json.loads(_run(code)) == []
    assert len(names) >= 15


def test_import_gb_pin_is_lazy_and_loads_no_compiler_or_robot_library() -> None:
    """``import gb_pin`` imports nothing heavy; the first use of a name imports its module (PEP 562)."""
    code = (
        "import json, sys, gb_pin\n"
        "before = [m for m in ('numba', 'pinocchio', 'numpy') if m in sys.modules]\n"
        "gb_pin.LocalLinearMap\n"
        "after = [m for m in ('numba', 'pinocchio') if m in sys.modules]\n"
        "print(json.dumps([before, after]))"
    )
    before, after = json.loads(_run(code))
    assert before == []
    assert after == ["numba"]  # the learner's map needs the compiler, not the robot library


def test_every_public_name_resolves_and_is_listed() -> None:
    """Each name of gb_pin.__all__ resolves to an object defined in the module the export table names."""
    import gb_pin.learn

    assert sorted(gb_pin.__all__) == sorted([*gb_pin._EXPORTS, "__version__"])
    assert sorted(gb_pin.learn.__all__) == sorted(gb_pin.learn._EXPORTS)
    for name in gb_pin.__all__:
        assert getattr(gb_pin, name) is not None
    for name in gb_pin.learn.__all__:
        assert getattr(gb_pin.learn, name) is not None
    assert set(gb_pin.__all__) <= set(dir(gb_pin))
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        _ = gb_pin.nope  # type: ignore[attr-defined]


PLANAR_SCRIPT = """
import json, math, sys
sys.modules["pinocchio"] = None  # any import of pinocchio now fails
import numpy as np
from gb_pin.learn import GoalBabbling, KinematicChain

m = 5
seg = 1.0 / m
chain = KinematicChain(
    parents=np.arange(-1, m - 1, dtype=np.int64),
    rotations=np.tile(np.eye(3), (m, 1, 1)),
    translations=np.array([[0.0 if i == 0 else seg, 0.0, 0.0] for i in range(m)]),
    axes=np.tile([0.0, 0.0, 1.0], (m, 1)),
    kinds=np.zeros(m, dtype=np.int64),
    q_index=np.arange(m, dtype=np.int64),
    frame_parent=m - 1,
    frame_translation=np.array([seg, 0.0, 0.0]),
    task_axes=np.array([0, 1], dtype=np.int64),
)
class Arm:
    chain = chain
    home = np.array([-math.pi / 3] + [2 * math.pi / (3 * (m - 1))] * (m - 1))
    lower = np.full(m, -np.inf)
    upper = np.full(m, np.inf)
targets = [[x, y] for x in (0.3, 0.55, 0.8) for y in (-0.4, 0.0, 0.4)]
learner = GoalBabbling().fit(Arm(), targets, 200, seed=3)
print(json.dumps({"error": learner.history_.error.tolist(), "pin": "pinocchio" in sys.modules and
                  sys.modules["pinocchio"] is not None}))
"""


def test_learner_runs_on_a_chain_given_as_arrays_without_pinocchio() -> None:
    """A planar arm written as arrays learns with Pinocchio unimportable, as the Pinocchio model does."""
    out = json.loads(_run(PLANAR_SCRIPT))
    assert out["pin"] is False
    from gb_pin.learn import GoalBabbling

    target = gb_pin.KinematicTarget(gb_pin.planar_chain(5), "tip", home=gb_pin.planar_home(5), axes="xy")
    targets = [[x, y] for x in (0.3, 0.55, 0.8) for y in (-0.4, 0.0, 0.4)]
    expected = GoalBabbling().fit(target, targets, 200, seed=3).history_.error
    np.testing.assert_allclose(out["error"], expected, rtol=0, atol=1e-12)
    assert out["error"][-1] < 0.5 * out["error"][0]


def _imports(path: Path, module: str, known: set[str]) -> set[str]:
    """gb_pin modules imported anywhere in the file (functions included), except under TYPE_CHECKING."""
    tree = ast.parse(path.read_text())
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skip.update(id(n) for n in ast.walk(node))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("gb_pin"))
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join([*parts[: len(parts) - node.level + 1], base]).strip(".")
            if not base.startswith("gb_pin"):
                continue
            for a in node.names:
                sub = f"{base}.{a.name}"
                out.add(sub if sub in known else base)
    return {m for m in out if m in known and m != module}


def test_no_import_cycles_even_through_imports_inside_functions() -> None:
    """The graph of gb_pin's imports (at module level and inside functions) has no cycle."""
    mods = _modules()
    graph = {m: _imports(p, m, set(mods)) for m, p in mods.items()}
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[list[str]] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for d in sorted(graph[m]):
            if state.get(d) == 1:
                cycles.append([*stack[stack.index(d) :], d])
            elif d not in state:
                visit(d)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)
    assert cycles == []
    # the checker sees imports inside functions (babble() imports the checkpoint module there)
    assert "def resume" in mods["gb_pin.runs.api"].read_text()
    assert "gb_pin.runs.checkpoint" in graph["gb_pin.runs.api"]


def test_layers_import_only_downwards() -> None:
    """learn imports no other layer; robot no runs/experiments/viewer/cli/reproduce; ik only learn; no cli.

    (ik may import the robot layer's presets, to resolve a preset name.) sim imports only safety, robot, learn
    and vision (a rendering plant's marker texture and intrinsics); vision and safety only robot and learn.
    """
    mods = _modules()
    graph = {m: _imports(p, m, set(mods)) for m, p in mods.items()}
    allowed_below = {
        "gb_pin.learn": ("gb_pin.learn", "gb_pin._", "gb_pin.exceptions"),
        "gb_pin.robot": ("gb_pin.robot", "gb_pin.learn", "gb_pin._", "gb_pin.exceptions"),
        # ik resolves a preset name through the robot layer's presets (gb_pin.ik.robot.resolve, inside the
        # function): nothing else of the robot layer, and no pinocchio for a chain given as arrays
        "gb_pin.ik": ("gb_pin.ik", "gb_pin.learn", "gb_pin._", "gb_pin.exceptions", "gb_pin.robot.presets"),
        "gb_pin.sim": (
            "gb_pin.sim",
            "gb_pin.safety",
            "gb_pin.robot",
            "gb_pin.learn",
            "gb_pin.vision",
            "gb_pin._",
            "gb_pin.exceptions",
        ),
        "gb_pin.vision": ("gb_pin.vision", "gb_pin.robot", "gb_pin.learn", "gb_pin._", "gb_pin.exceptions"),
        "gb_pin.safety": ("gb_pin.safety", "gb_pin.robot", "gb_pin.learn", "gb_pin._", "gb_pin.exceptions"),
    }
    for m, deps in graph.items():
        for layer, ok in allowed_below.items():
            if m.startswith(layer):
                bad = [d for d in deps if not d.startswith(ok)]
                assert bad == [], f"{m} imports {bad}"
        if not m.startswith("gb_pin.cli") and m != "gb_pin.__main__":  # `python -m gb_pin` runs the CLI
            assert not [d for d in deps if d.startswith("gb_pin.cli")], m


def _third_party_imports(path: Path) -> set[str]:
    """Top-level names of the modules a file imports anywhere (functions included)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            out.add(node.module.split(".")[0])
    return out


def test_only_gb_pin_sim_imports_mujoco_and_importing_gb_pin_loads_it_nowhere() -> None:
    """MuJoCo (the sim extra) is imported by gb_pin.sim alone, and only when a plant is built.

    In a fresh interpreter, importing every module of gb_pin (gb_pin.sim's included, the viewer's
    left out: they need meshcat) loads no mujoco: runs without the extra never touch it.
    """
    mods = _modules()
    users = sorted(m for m, p in mods.items() if "mujoco" in _third_party_imports(p))
    assert users and all(m.startswith("gb_pin.sim.") for m in users), users
    names = [m for m in mods if not m.startswith("gb_pin.viewer") and not m.endswith("__main__")]
    code = (
        "import importlib, sys\n"
        f"for n in {names!r}: importlib.import_module(n)\n"
        "print('mujoco' in sys.modules)"
    )
    assert _run(code).strip() == "False"


def test_only_gb_pin_vision_imports_opencv_and_importing_gb_pin_loads_it_nowhere() -> None:
    """OpenCV (the vision extra) is imported by gb_pin.vision.dependency alone, and only when it is used."""
    mods = _modules()
    users = sorted(m for m, p in mods.items() if "cv2" in _third_party_imports(p))
    assert users == ["gb_pin.vision.dependency"], users
    names = [m for m in mods if not m.startswith("gb_pin.viewer") and not m.endswith("__main__")]
    code = (
        f"import importlib, sys\nfor n in {names!r}: importlib.import_module(n)\nprint('cv2' in sys.modules)"
    )
    assert _run(code).strip() == "False"


def test_no_module_over_500_lines() -> None:
    """Modules stay readable: none is over 500 lines."""
    long = {m: n for m, p in _modules().items() if (n := len(p.read_text().splitlines())) > 500}
    assert long == {}


def test_no_compiled_kernel_takes_more_than_8_positional_parameters() -> None:
    """Compiled functions take named structures, not long positional lists."""
    kernels = {}
    for info in pkgutil.walk_packages([str(ROOT)], "gb_pin."):
        if info.name.startswith(("gb_pin.viewer", "gb_pin.cli")):
            continue  # no compiled code there (and the viewer needs meshcat)
        module = importlib.import_module(info.name)
        for name, obj in vars(module).items():
            if hasattr(obj, "py_func") and getattr(obj.py_func, "__module__", "") == info.name:
                kernels[f"{info.name}.{name}"] = len(inspect.signature(obj.py_func).parameters)
    assert len(kernels) >= 15
    assert {k: n for k, n in kernels.items() if n > 8} == {}


def test_hyperparameters_have_one_source_of_truth() -> None:
    """BabbleConfig, GoalBabbling, babble(), trials and the CLI take their names from the table."""
    from gb_pin.experiments.trials import BABBLE_ARGS
    from gb_pin.learn.learner import GoalBabbling
    from gb_pin.runs.api import babble

    assert NAMES == ("learning_rate", "sigma", "sigma_delta", "radius", "path_length", "p_home", "cutoff")
    assert tuple(f for f in BabbleConfig.__dataclass_fields__) == NAMES
    sig = inspect.signature(GoalBabbling)
    assert tuple(sig.parameters) == NAMES
    assert all(sig.parameters[n].default == BY_NAME[n].default for n in NAMES)
    babble_params = inspect.signature(babble).parameters
    assert all(babble_params[n].default is None for n in NAMES)
    assert tuple(BABBLE_ARGS) == NAMES
    assert GoalBabbling().get_params() == {h.name: h.default for h in HYPERPARAMETERS}
    resolved = BabbleConfig.resolve(5)
    assert resolved == BabbleConfig(0.1, 0.05, 0.1 * 0.05, 0.1, 25, 0.1, None)
    help_text = _run("from gb_pin.cli import main; main(['babble', '--help'])")
    for h in HYPERPARAMETERS:
        assert h.option in help_text
