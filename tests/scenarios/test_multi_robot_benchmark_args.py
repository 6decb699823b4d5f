"""benchmarks/multi_robot.py's ``--scenarios`` items: NAME:ROBOTS[:arg=value...], a bad one
refused by name before any run (it was a bare ValueError traceback for ``willow_swap``)."""

import re
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
import multi_robot


def test_items_give_name_robots_and_launch_args():
    assert multi_robot.scenario_item("circle:16") == ("circle", 16, {})
    assert multi_robot.scenario_item("swap_corridor:2:localization=amcl:width=1.0") == (
        "swap_corridor",
        2,
        {"localization": "amcl", "width": "1.0"},
    )


@pytest.mark.parametrize(
    "item", ["willow_swap", "circle:", "circle:x", "circle:0", "circle:16:foo"]
)
def test_a_bad_item_is_named(item):
    with pytest.raises(SystemExit, match=re.escape(repr(item))):
        multi_robot.scenario_item(item)
