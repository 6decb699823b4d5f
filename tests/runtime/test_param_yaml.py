"""Parameter YAML as rosparam reads it: angle tags, and the line of every key."""

import math

import pytest

from fleetsim.errors import ParameterError
from fleetsim.runtime.param_yaml import load_yaml_lines, load_yaml_text


def test_key_lines_nested_merged_and_offset():
    text = (
        "base: &b\n"
        "  inflation_radius: 0.5\n"
        "local_costmap:\n"
        "  <<: *b\n"
        "  width: 3\n"
        "  plugins/obstacles: {enabled: true}\n"
    )
    data, lines = load_yaml_lines(text, "c.yaml", line_offset=10)
    assert data["local_costmap"] == {"inflation_radius": 0.5, "width": 3,
                                     "plugins/obstacles": {"enabled": True}}  # fmt: skip
    assert lines[""] == "c.yaml:11"
    assert lines["base/inflation_radius"] == "c.yaml:12"
    assert lines["local_costmap/width"] == "c.yaml:15"
    # a merged key is reported where the anchor wrote it
    assert lines["local_costmap/inflation_radius"] == "c.yaml:12"
    assert lines["local_costmap/plugins/obstacles/enabled"] == "c.yaml:16"


def test_rosparam_angle_forms():
    data = load_yaml_text(
        "a: deg(180)\nb: rad(pi/4)\nc: !degrees 90\nd: !radians pi\ne: 'rad(1)'\n"
    )
    assert data["a"] == pytest.approx(math.pi) and data["b"] == pytest.approx(math.pi / 4)
    assert data["c"] == pytest.approx(math.pi / 2) and data["d"] == pytest.approx(math.pi)
    assert data["e"] == "rad(1)"


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("a: [1, 2\n", r"f.yaml:2:1: YAML does not parse"),
        ("a: 1\nb: deg(x)\n", r"f.yaml:2:4: YAML does not parse: invalid degree value: deg\(x\)"),
        ("a: rad(os.system)\n", r"f.yaml:1:4: YAML does not parse: invalid radian expression"),
    ],
)
def test_errors_name_file_line_and_column(text, match):
    with pytest.raises(ParameterError, match=match):
        load_yaml_lines(text, "f.yaml")


def test_empty_document():
    assert load_yaml_lines("# nothing\n", "f.yaml") == (None, {})
