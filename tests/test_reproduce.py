"""The paper's figures on tiny data: files, numbers consistent with the trials, cache, snapshots, CLI."""

from __future__ import annotations

import ast
import json
import os
import pathlib

import numpy as np
import pytest

import gb_pin
from gb_pin import reproduce as rp
from gb_pin.cli import main
from gb_pin.exceptions import GbPinError
from gb_pin.reproduce import cache, paper

PACKAGE = pathlib.Path(rp.__file__).parent

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def small(tmp_path_factory):  # type: ignore[no-untyped-def]
    """Figs. 4, 5, 7 and 8 with 3 trials of 120 movements (every condition of the paper, tiny)."""
    out = tmp_path_factory.mktemp("repro")
    result = rp.reproduce(["fig4", "fig5", "fig7", "fig8"], out=str(out), trials=3, movements=120, workers=2)
    return out, result


def test_figures_and_numbers_are_written(small) -> None:  # type: ignore[no-untyped-def]
    """Each figure comes as PNG and SVG (non-empty, valid headers), with CSV numbers and results.md."""
    out, result = small
    for fig in ("fig4", "fig5", "fig7", "fig8"):
        png = (out / f"{fig}.png").read_bytes()
        assert png.startswith(b"\x89PNG") and len(png) > 10_000
        assert b"<svg" in (out / f"{fig}.svg").read_bytes()[:1000]
    for csv in (
        "fig4_planar5_eta0.1.csv",
        "fig4_planar5_eta0.01.csv",
        "fig5.csv",
        "fig7_planar50.csv",
        "fig8.csv",
    ):
        assert (out / csv).stat().st_size > 0
    text = (out / "results.md").read_text()
    assert "## Paper vs gb_pin" in text
    assert "planar50: S(0.5, 0.1 E_0)" in text
    assert {os.path.basename(f) for f in result.files} >= {
        "fig4.png",
        "fig8.svg",
        "results.md",
        "results.json",
    }


def test_numbers_follow_from_the_trials(small) -> None:  # type: ignore[no-untyped-def]
    """The reported numbers are those of run_trials with the same seeds (recomputed here)."""
    out, result = small
    ts = gb_pin.run_trials(
        "planar5",
        trials=3,
        movements=120,
        seed=0,
        workers=1,
        learning_rate=0.1,
        schedule=rp.schedule(120, 120),
    )
    curve = result.numbers["fig4"]["curves"]["0.1"]
    assert curve["median_error_at_100"] == pytest.approx(float(np.median(ts.error[:, 100])), rel=1e-12)
    assert curve["speed"]["0.5"] == ts.speed(0.5, 0.1 * ts.initial_error)
    rows = result.numbers["fig5"]["rows"]
    assert [r["length"] for r in rows] == [1200, 600, 240, 120, 120, 120, 120, 120, 120]  # N * 0.01 / eta
    m50 = result.numbers["fig8"]["rows"][-1]
    assert m50["robot"] == "planar50"
    with open(out / "fig8.csv") as fh:
        last = fh.read().strip().splitlines()[-1].split(",")
    assert last[0] == "50" and last[5] == ("" if m50["speed"]["0.5"] is None else str(m50["speed"]["0.5"]))
    saved = json.loads((out / "results.json").read_text())
    assert saved["numbers"]["fig7"]["curves"]["20"]["robot"] == "planar20"


def test_cached_trials_are_reused(small, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A second reproduction with the same settings reads OUT/trials instead of running trials again."""
    out, result = small

    def no_sweep(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise AssertionError("trials were run again")

    monkeypatch.setattr(cache, "run_sweep", no_sweep)
    again = rp.reproduce(["fig7"], out=str(out), trials=3, movements=120)
    assert again.numbers["fig7"] == result.numbers["fig7"]
    assert (out / "trials" / ".gitignore").read_text().strip().endswith("*")
    with pytest.raises(AssertionError, match="run again"):
        rp.reproduce(["fig7"], out=str(out), trials=3, movements=120, fresh=True)


def test_snapshots_are_the_inverse_estimate_of_that_trial(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """Fig. 3's postures after r movements equal g(X*) of a babble run stopped at r, same seed."""
    st = rp.Settings(trials=1, movements=100, seed=3, out=str(tmp_path))
    _files, numbers = rp.snapshot_figure("fig3", "planar5", st, ("png",), at=(10, 40))
    assert (tmp_path / "fig3.png").exists()
    saved = json.loads((tmp_path / "fig3.json").read_text())
    for snap in saved["snapshots"]:
        run = gb_pin.babble("planar5", movements=snap["movements"], seed=3, learning_rate=0.1)
        np.testing.assert_allclose(snap["postures"], run.inverse(run.targets), rtol=0, atol=1e-12)
        reached = run.target.forward(run.inverse(run.targets))
        np.testing.assert_allclose(snap["reached"], reached, atol=1e-12)
        assert snap["error"] == pytest.approx(run.error, rel=1e-12)
    assert [s["movements"] for s in numbers["snapshots"]] == [10, 40]


def test_arm_points_match_pinocchio() -> None:
    """The drawn arm starts at the base, its joints are one segment apart, and it ends at f(q) (Pinocchio)."""
    target = gb_pin.load_robot("planar7")
    q = np.random.default_rng(0).uniform(-1, 1, 7)
    pts = rp.arm_points(target.chain, q)
    assert pts.shape == (8, 2)
    np.testing.assert_allclose(pts[0], [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(np.diff(pts, axis=0), axis=1), 1.0 / 7, atol=1e-12)
    np.testing.assert_allclose(pts[-1], target.forward(q), atol=1e-12)


def test_planar5_median_error_after_100_movements_is_the_papers() -> None:
    """Sec. III-A, CI-sized: over 20 trials, planar5 at eta 0.1 has median E^X in [0.03, 0.055]."""
    ts = gb_pin.run_trials("planar5", trials=20, movements=100, seed=0, learning_rate=0.1, schedule=[100])
    assert 0.03 <= float(np.median(ts.error[:, -1])) <= 0.055


def test_cli_reproduce_and_bad_figure_names(tmp_path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin reproduce fig4` writes its files; an unknown figure exits 2 naming it and the valid ones."""
    out = tmp_path / "r"
    argv = ["reproduce", "fig4", "--trials", "2", "--movements", "100", "--out", str(out), "--quiet"]
    assert main([*argv, "--workers", "1"]) == 0
    assert (out / "fig4.svg").exists()
    assert "results.md" in capsys.readouterr().out
    assert main(["reproduce", "fig9", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "fig9" in err and "fig4" in err
    assert main(["reproduce", "fig4", "--movements", "50", "--out", str(out)]) == 2


def test_paper_numbers_are_data_and_fill_the_table(small) -> None:  # type: ignore[no-untyped-def]
    """paper.toml holds the paper's numbers once; the table's paper and range columns are read from it."""
    _out, result = small
    assert rp.MEDIAN_LEVEL == 0.04
    expected = {"e100": 0.04, "first_median_le_004": 2000, "speedup": 20, "s50_eta05": 34}
    expected |= {"s50_m50": 128, "s90_m50": 364}
    assert {k: rp.PAPER[k].value for k in expected} == expected
    assert (rp.PAPER["e100"].paper, rp.PAPER["e100"].range) == ("≈ 0.04", "[0.03, 0.055]")
    assert (rp.PAPER["s90_m50"].paper, rp.PAPER["s90_m50"].range) == ("364", "≤ 500")
    assert rp.PAPER["s50_m50"].accepts(95) and not rp.PAPER["s50_m50"].accepts(176)
    assert not rp.PAPER["s50_m50"].accepts(None)
    rows = rp.paper_table(result.numbers)
    claims = [c for c in rp.PAPER.values() if c.figure in result.numbers]
    assert [[r[0], r[1], r[3]] for r in rows] == [[c.quantity, c.paper, c.range] for c in claims]
    m50 = result.numbers["fig8"]["rows"][-1]["speed"]["0.5"]
    row = rows[[c.id for c in claims].index("s50_m50")]
    assert row[4] == ("no" if m50 is None else "yes" if 95 <= m50 <= 175 else "**no**")


def test_malformed_paper_numbers_are_refused() -> None:
    """A claim with an unknown key, a missing level or a repeated id raises GbPinError naming the file."""
    good = 'median_level = 0.04\n[[claim]]\nid = "a"\nfigure = "fig4"\nquantity = "q"\nsource = "s"\n'
    level, claims = paper.load(good)
    assert level == 0.04 and claims["a"].paper == "" and not claims["a"].bounded
    for bad in (
        good + "colour = 1\n",
        good.replace("median_level = 0.04", ""),
        good + good.split("\n", 1)[1],
    ):
        with pytest.raises(GbPinError, match=r"paper\.toml"):
            paper.load(bad)


def _imports(path: pathlib.Path) -> set[str]:
    """Every module a file imports, at the top or inside functions."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
            found |= {f"{node.module}.{a.name}" for a in node.names}
    return found


def test_submodules_form_no_import_cycle_and_only_figures_imports_matplotlib() -> None:
    """The modules of gb_pin.reproduce import each other without a cycle; only figures.py names matplotlib."""
    modules = {p.stem: _imports(p) for p in PACKAGE.glob("*.py") if p.stem != "__init__"}
    graph = {m: {d for d in modules if f"gb_pin.reproduce.{d}" in imports} for m, imports in modules.items()}
    assert all("gb_pin.reproduce" not in imports for imports in modules.values())  # never the package itself
    done: set[str] = set()

    def visit(m: str, path: tuple[str, ...]) -> None:
        assert m not in path, f"import cycle: {' -> '.join((*path, m))}"
        if m not in done:
            for d in graph[m]:
                visit(d, (*path, m))
            done.add(m)

    for m in graph:
        visit(m, ())
    assert [m for m, imports in modules.items() if any(i.startswith("matplotlib") for i in imports)] == [
        "figures"
    ]


def test_nothing_but_the_cli_imports_reproduce() -> None:
    """gb_pin.reproduce sits on top: no other sub-package of gb_pin imports it (the CLI calls it)."""
    root = PACKAGE.parent
    users = [
        str(p.relative_to(root))
        for p in root.rglob("*.py")
        if PACKAGE not in p.parents
        and any(i == "gb_pin.reproduce" or i.startswith("gb_pin.reproduce.") for i in _imports(p))
    ]
    assert users and all(u.startswith("cli" + os.sep) for u in users), users


def test_files_are_written_atomically() -> None:
    """No module of the reproduction opens a file for writing: every write goes through gb_pin._files."""
    for p in PACKAGE.glob("*.py"):
        text = p.read_text(encoding="utf-8")
        assert "os.replace" not in text and ".tmp" not in text, p.name
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "open":
                modes = [a.value for a in node.args[1:2] if isinstance(a, ast.Constant)]
                assert not any("w" in str(m) or "a" in str(m) for m in modes), p.name
