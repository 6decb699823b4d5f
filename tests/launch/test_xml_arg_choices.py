"""ROS 2's ``<arg><choice value="..."/></arg>`` in fleetsim.launch.xml_frontend: a value outside
the choices is refused, naming the arg, the value and the allowed values."""

from pathlib import Path

import pytest

from fleetsim.errors import LaunchError
from fleetsim.launch.xml_frontend import load_xml

ROBOTS = """<launch>
  <arg name="robots" default="1">
    <choice value="1"/>
    <choice value="2"/>
  </arg>
  <param name="n" value="$(arg robots)"/>
</launch>
"""


def test_a_value_among_the_choices_is_taken(tmp_path: Path):
    p = tmp_path / "t.launch"
    p.write_text(ROBOTS)
    assert load_xml(p).param_tree().get("/n") == 1
    assert load_xml(p, {"robots": "2"}).param_tree().get("/n") == 2


@pytest.mark.parametrize("value", ["3", "0", "two", ""])
def test_a_value_outside_the_choices_is_an_error_naming_arg_and_choices(tmp_path, value):
    p = tmp_path / "t.launch"
    p.write_text(ROBOTS)
    with pytest.raises(
        LaunchError, match=rf"t.launch:2 <arg>: arg 'robots' is '{value}'; allowed values: 1, 2"
    ):
        load_xml(p, {"robots": value})


def test_a_default_outside_the_choices_is_an_error_too(tmp_path: Path):
    p = tmp_path / "t.launch"
    p.write_text(ROBOTS.replace('default="1"', 'default="5"'))
    with pytest.raises(LaunchError, match="arg 'robots' is '5'; allowed values: 1, 2"):
        load_xml(p)


def test_anything_but_choice_inside_arg_is_an_error(tmp_path: Path):
    p = tmp_path / "t.launch"
    p.write_text(ROBOTS.replace('<choice value="2"/>', '<choise value="2"/>'))
    with pytest.raises(LaunchError, match=r"t.launch:4 <choise>: <arg> may hold only <choice"):
        load_xml(p)


@pytest.mark.parametrize(
    "scenario, arg, value, allowed",
    [
        ("hunter_run", "sim_type", "gazeboo", "gazebo, rviz, gazeborviz"),
        ("navigation_multi", "localization", "amlc", "fake, amcl"),
        ("pioneer_multi", "localization", "AMCL", "fake, amcl"),
        ("visual_servoing", "follower", "predictiv", "follow_marker, predictive"),
        ("visual_servoing", "exploration_strategy", "rotat", "move_to_target, rotate"),
        ("visual_servoing", "patrol", "buildng", "circle, building"),
    ],
)
def test_shipped_switches_refuse_a_misspelt_value(scenario, arg, value, allowed):
    """Switches read with if/unless match no branch on a misspelt value: the manual's
    run2.launch with sim_type:=gazeboo ran on with no simulator and no robot, exit 0. The
    shipped files list their values, so any other is an error naming the arg."""
    from fleetsim.launch.runner import load_plan
    from fleetsim.launch.scenarios import resolve_launch_file

    with pytest.raises(LaunchError, match=rf"arg '{arg}' is '{value}'; allowed values: {allowed}"):
        load_plan(resolve_launch_file(scenario), {arg: value})
