"""Learning-curve plots of one run and of trials: files, content, matplotlib imported only to draw."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import gb_pin
from gb_pin.cli import main
from gb_pin.exceptions import GbPinError, InvalidArgumentError

PIL = pytest.importorskip("PIL.Image")


def _assert_drawn(path: Path, min_width: int = 800) -> None:
    """A PNG of a real figure: wide enough, and neither blank nor one colour."""
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with PIL.open(path) as img:
        assert img.width >= min_width and img.height >= 300
        pixels = np.asarray(img.convert("RGB"), dtype=float)
    dark = (pixels.sum(axis=2) < 300).mean()  # text, axes and lines
    coloured = (np.ptp(pixels, axis=2) > 60).mean()  # the blue and red curves
    assert 0.002 < dark < 0.5 and coloured > 0.002, (dark, coloured)


@pytest.fixture(scope="module")
def result() -> gb_pin.BabbleResult:
    return gb_pin.babble("planar5", movements=300, seed=0)


def test_result_plot_writes_a_labelled_png(result: gb_pin.BabbleResult, tmp_path: Path) -> None:
    """result.plot(path) draws two labelled log-axis panels with robot, movements and final E^X."""
    path = tmp_path / "curve.png"
    fig = result.plot(path)
    _assert_drawn(path)
    err_ax, home_ax = fig.axes
    assert err_ax.get_xscale() == "log" and err_ax.get_yscale() == "log"
    assert "[m]" in err_ax.get_ylabel() and "[rad]" in home_ax.get_ylabel()
    title = fig.get_suptitle()
    assert "planar5" in title and "300 movements" in title and f"{result.error:.4g} m" in title


def test_result_plot_into_given_axes_uses_a_twin(result: gb_pin.BabbleResult, tmp_path: Path) -> None:
    """result.plot(ax=ax) draws E^X on ax and D^home on a twin axis of the caller's figure."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4))
    ax = fig.subplots()
    assert result.plot(ax=ax) is fig
    assert len(fig.axes) == 2 and ax.get_yscale() == "log"
    fig.savefig(tmp_path / "twin.png")
    _assert_drawn(tmp_path / "twin.png", min_width=500)


def test_trials_plot_and_the_cli(result: gb_pin.BabbleResult, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """`gb-pin plot run.npz` and `gb-pin plot trials.json -o x.png` write the figure and say where."""
    run = tmp_path / "run.npz"
    result.save(run)
    assert main(["plot", str(run)]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {tmp_path / 'run.png'}"
    _assert_drawn(tmp_path / "run.png")
    trials = gb_pin.run_trials("planar3", trials=4, movements=200, workers=1)
    trials.save(tmp_path / "trials.json")
    out = tmp_path / "trials.png"
    assert main(["plot", str(tmp_path / "trials.json"), "-o", str(out)]) == 0
    assert str(out) in capsys.readouterr().out
    _assert_drawn(out)
    assert "4 trials of 200 movements" in trials.plot().get_suptitle()


def test_bad_plot_requests(result: gb_pin.BabbleResult, tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    """An unknown extension names the allowed ones; a missing file is one error line."""
    with pytest.raises(InvalidArgumentError, match="png"):
        result.plot(tmp_path / "curve.gif")
    assert main(["plot", str(tmp_path / "missing.npz")]) == 2
    assert "missing.npz" in capsys.readouterr().err


def test_matplotlib_only_when_drawing_and_named_when_missing() -> None:
    """Importing the result (and plot) modules loads no matplotlib; without it, plot() names the extra."""
    code = (
        "import sys, gb_pin.runs.result, gb_pin.runs.plot, gb_pin.experiments.trialset\n"
        "assert 'matplotlib' not in sys.modules\n"
        "sys.modules['matplotlib'] = None\n"
        "import gb_pin\n"
        "r = gb_pin.babble('planar3', movements=5, seed=0)\n"
        "try:\n"
        "    r.plot()\n"
        "except gb_pin.GbPinError as exc:\n"
        "    print(exc)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True
    )
    assert "pip install 'gb_pin[plots]'" in out.stdout
    assert issubclass(GbPinError, Exception)
