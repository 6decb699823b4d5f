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
    assert multi_robot.scenario_item("circle:8:model=turtlebot3_burger")[2] == {
        "model": "turtlebot3_burger"
    }


@pytest.mark.parametrize(
    "item",
    ["willow_swap", "circle:", "circle:x", "circle:0", "circle:16:foo", "circle:8:model=burger"],
)
def test_a_bad_item_is_named(item):
    with pytest.raises(SystemExit, match=re.escape(repr(item))):
        multi_robot.scenario_item(item)


def test_makespan_cells_give_mean_and_max_and_the_seeds_over_the_target():
    """The row's makespan cells read as mean/max (they printed "17.8-20.2", which read as a
    range over seeds whose fastest took 15.9 s), and count the seeds over 1.5 x alone."""
    nan = float("nan")
    spans = [20.2, 16.0, 18.1, 18.6, 15.9]  # circle of 16, seeds 200-204
    assert multi_robot.makespan_summary(spans, 12.0) == ("17.8/20.2", "1.48/1.68", "3")
    span, ratio, over = multi_robot.makespan_summary([20.0, nan], 12.0)
    assert (span, ratio, over) == ("20.0/20.0", "-", "2")  # an unfinished seed counts as over
    assert multi_robot.makespan_summary([nan], 12.0) == ("-", "-", "1")
