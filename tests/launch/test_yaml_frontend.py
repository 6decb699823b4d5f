"""ROS 2 launch YAML into the same plan as XML."""

from pathlib import Path

import pytest

from fleetsim.errors import FleetsimError
from fleetsim.launch.yaml_frontend import load_yaml, ros2_params

FIX = Path(__file__).parent / "fixtures" / "multi_pkg"


def test_groups_namespaces_params_and_remaps(tmp_path):
    params = tmp_path / "amcl.yaml"
    params.write_text("amcl:\n  ros__parameters:\n    min_particles: 50\n")
    f = tmp_path / "robots.launch.yaml"
    f.write_text(
        f"""
launch:
- arg: {{name: robot, default: lizi1}}
- arg: {{name: use_amcl, default: "true"}}
- group:
    children:
    - push-ros-namespace: {{namespace: $(var robot)}}
    - set_parameter: {{name: tf_prefix, value: $(var robot)}}
    - node:
        pkg: amcl
        exec: amcl
        name: amcl
        if: $(var use_amcl)
        param:
        - {{name: odom_frame_id, value: odom}}
        - {{from: {params}}}
        remap:
        - {{from: scan, to: base_scan}}
- node: {{pkg: map_server, exec: map_server, name: map_server, args: "a.yaml"}}
"""
    )
    plan = load_yaml(f, {"robot": "lizi2"})
    assert [n.full_name for n in plan.nodes] == ["/lizi2/amcl", "/map_server"]
    tree = plan.param_tree()
    assert tree.get("/lizi2/tf_prefix") == "lizi2"
    assert tree.get("/lizi2/amcl") == {"odom_frame_id": "odom", "min_particles": 50}
    assert plan.nodes[0].remaps == {"scan": "base_scan"} and plan.nodes[1].args == ["a.yaml"]
    assert [n.name for n in load_yaml(f, {"use_amcl": "false"}).nodes] == ["map_server"]


def test_yaml_can_include_xml(tmp_path):
    f = tmp_path / "top.launch.yaml"
    f.write_text(
        "launch:\n- include:\n"
        "    file: $(find-pkg-share gazebo_navigation_multi)/launch/robots.launch\n"
    )
    plan = load_yaml(f, finder=lambda pkg: FIX if pkg == "gazebo_navigation_multi" else None)
    assert "/lizi2/move_base" in [n.full_name for n in plan.nodes]


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("nodes: []", "top-level 'launch:' list"),
        ("launch:\n- nod: {}", r"launch\[0\]: unknown entry 'nod' \(did you mean 'node'\?\)"),
        ("launch:\n- node: {pkg: a, exec: b}", r"launch\[0\].node: missing 'name'"),
        ("launch:\n- node: {pkg: a, exec: b, name: c, remapp: []}", r"unknown key 'remapp'"),
        ("launch:\n- node: {pkg: a, exec: b, name: c, param: [{name: x}]}", r"param\[0\]: needs"),
        ("launch: [", "YAML does not parse"),
    ],
)
def test_errors_name_the_entry(tmp_path, text, match):
    f = tmp_path / "x.launch.yaml"
    f.write_text(text)
    with pytest.raises(FleetsimError, match=match):
        load_yaml(f)


def test_ros2_param_files():
    data = {"/**": {"ros__parameters": {"a": 1}}, "amcl": {"ros__parameters": {"b": 2}}}
    assert ros2_params(data, "amcl") == {"a": 1, "b": 2}
    assert ros2_params(data, "other") == {"a": 1}
    assert ros2_params({"plain": 1}, "amcl") == {"plain": 1}
