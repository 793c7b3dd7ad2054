"""Messages of the fourth reliability round: each names what is wrong, in one line of gb_pin's own.

Before (main 995bb8d): one outlier reading ended in a DivergenceError blaming the learning
rate; ``--plant mujoco:settle=auto`` (as --help shows it) was refused; ``--sensor noise=1,noise=2``
was last-wins; ``max_joint_step=10**400`` raised a raw OverflowError; ``noise=1e308`` a message
about the learner's internals; Ctrl-C in ``reproduce`` suggested a ``--checkpoint`` it lacks;
direction overrides went raw into exported HTML titles.
"""

from __future__ import annotations

import argparse
import warnings

import pytest

import gb_pin
from gb_pin.cli.body_options import parse_spec, sensor
from gb_pin.exceptions import DivergenceError, InvalidArgumentError
from gb_pin.experiments.execute import _interrupted
from gb_pin.learn.sensor import Sensor


def test_one_outlier_reading_is_named_when_the_estimate_diverges() -> None:
    session = gb_pin.babble_session("planar5", movements=200, seed=0)
    with pytest.raises(
        DivergenceError, match=r"the reading \[1000000\. 1000000\.\] told at movement 0"
    ) as info:
        for i in range(3000):
            q = session.ask()
            session.tell([1e6, 1e6] if i == 20 else session.target.forward(q))
    assert "learning_rate" not in str(info.value) and "\n" not in str(info.value)


def test_plant_and_sensor_strings_take_auto_and_refuse_repeated_keys() -> None:
    assert parse_spec("--plant mujoco", "settle=auto,damping=auto", {"settle": None, "damping": None}) == {
        "settle": None,
        "damping": None,
    }
    with pytest.raises(InvalidArgumentError, match="noise given twice"):
        sensor(argparse.Namespace(sensor="noise=0.01,noise=0.02"))
    with pytest.raises(InvalidArgumentError, match="kp given twice"):
        parse_spec("--plant mujoco", "kp=1,kp=2", {"kp": 10.0})
    with pytest.raises(InvalidArgumentError, match="finite number"):  # auto only where the default is auto
        parse_spec("--plant mujoco", "kp=auto", {"kp": 10.0})


def test_huge_numbers_are_refused_in_one_line() -> None:
    with pytest.raises(InvalidArgumentError, match="max_joint_step"):
        gb_pin.babble("planar5", movements=5, seed=0, max_joint_step=10**400)
    with pytest.raises(InvalidArgumentError, match="noise must be at most"):
        Sensor(1e308)


def test_an_interrupted_trial_set_names_no_option_it_lacks() -> None:
    line = _interrupted([None, None], None, "")
    assert "--checkpoint" not in line and "0 of 2 trials" in line


def test_exported_titles_escape_direction_overrides() -> None:
    pytest.importorskip("meshcat")
    from gb_pin.viewer.page import html_page

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        page = html_page([], "arm\u202egnp.exe<b>")
    title = page[page.index("<title>") : page.index("</title>")]
    assert "\u202e" not in title and "\\u202e" in title and "<b>" not in title
