"""Tests for fleetsim.description.gazebo: <gazebo> blocks, sensors, plugins, transmissions."""

from __future__ import annotations

import pytest

from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import DescriptionError

BASE = '<robot name="r"><link name="base_link"/>{}</robot>'


def test_plugin_params_nested_and_repeated():
    r = parse_urdf(
        BASE.format(
            '<gazebo><plugin name="p" filename="libx.so"><a>1</a><b><c>2</c></b>'
            '<joint>j1</joint><joint>j2</joint><flag enabled="1"/></plugin></gazebo>'
        )
    )
    (p,) = r.plugins()
    assert p.params == {"a": "1", "b": {"c": "2"}, "joint": ["j1", "j2"], "flag": {"@enabled": "1"}}


def test_sensor_fields_and_properties():
    r = parse_urdf(
        BASE.format(
            '<gazebo reference="base_link"><mu1>0.5</mu1><sensor name="cam" type="camera">'
            "<always_on>1</always_on><update_rate>15</update_rate><pose>0 0 1 0 0 0.5</pose>"
            "<camera><image><width>320</width></image></camera><imu/></sensor></gazebo>"
        )
    )
    (g,) = r.gazebo_for("base_link")
    assert g.properties == {"mu1": "0.5"}
    (s,) = g.sensors
    assert (s.name, s.type, s.reference, s.update_rate, s.always_on) == (
        "cam",
        "camera",
        "base_link",
        15.0,
        True,
    )
    assert s.pose.xyz == (0.0, 0.0, 1.0) and s.pose.rpy == (0.0, 0.0, 0.5)
    assert s.camera == {"image": {"width": "320"}} and "imu" in s.extra


@pytest.mark.parametrize(
    ("block", "pattern"),
    [
        (
            '<gazebo reference="base_link"><sensor name="s" type="ray"><update_rate>fast'
            "</update_rate></sensor></gazebo>",
            r"sensor 's': update_rate 'fast' is not a number",
        ),
        (
            '<gazebo reference="base_link"><sensor name="s" type="ray"><pose>0 0</pose>'
            "</sensor></gazebo>",
            r"sensor 's': <pose>0 0</pose> is not 'x y z r p y'",
        ),
        (
            '<gazebo reference="base_link"><sensor name="s" type="ray"><visualize>maybe'
            "</visualize></sensor></gazebo>",
            r"<visualize>maybe</visualize> is not a boolean",
        ),
        ('<gazebo><plugin name="p"/></gazebo>', r"<plugin> is missing the required attribute"),
        (
            '<transmission name="t"><type>x</type><joint name="nope"><hardwareInterface>h'
            "</hardwareInterface></joint></transmission>",
            r"transmission 't' names joint 'nope'",
        ),
    ],
)
def test_bad_gazebo_input(block, pattern):
    with pytest.raises(DescriptionError, match=pattern):
        parse_urdf(BASE.format(block), source="g.urdf")
