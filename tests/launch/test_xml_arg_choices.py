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
