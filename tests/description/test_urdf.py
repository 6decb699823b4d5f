"""Tests for fleetsim.description.urdf: parsing, checks with file:line errors, xacro loading."""

from __future__ import annotations

from pathlib import Path

import pytest

from fleetsim.description.urdf import (
    Box,
    Cylinder,
    Limit,
    Mesh,
    Origin,
    load_robot,
    parse_urdf,
)
from fleetsim.errors import DescriptionError

FIXTURES = Path(__file__).parent / "fixtures"
DEMO = FIXTURES / "demo_pkg" / "urdf" / "demo.urdf.xacro"

INERTIA = '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>'


def robot_xml(body: str, name: str = "r") -> str:
    return f'<robot name="{name}">\n{body}\n</robot>\n'


GOOD = robot_xml(
    f"""  <material name="blue"><color rgba="0 0 1 1"/></material>
  <link name="base_link">
    <inertial><origin xyz="0 0 0.1"/><mass value="3"/>{INERTIA}</inertial>
    <visual><geometry><box size="0.4 0.3 0.2"/></geometry><material name="blue"/></visual>
    <collision><geometry><box size="0.4 0.3 0.2"/></geometry></collision>
  </link>
  <link name="arm"/>
  <link name="tool"><visual><geometry><mesh filename="meshes/tool.stl" scale="2 2 2"/></geometry>
    </visual></link>
  <link name="wheel"><collision><geometry><cylinder radius="0.1" length="0.05"/></geometry>
    </collision></link>
  <joint name="arm_joint" type="revolute">
    <origin xyz="0.1 0 0.2" rpy="0 0 1.57"/><parent link="base_link"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="0.5"/>
    <dynamics damping="0.7"/>
  </joint>
  <joint name="tool_joint" type="fixed"><parent link="arm"/><child link="tool"/></joint>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/>
    <axis xyz="0 1 0"/></joint>
  <transmission name="t1"><type>transmission_interface/SimpleTransmission</type>
    <joint name="arm_joint"><hardwareInterface>hardware_interface/EffortJointInterface
    </hardwareInterface></joint>
    <actuator name="m1"><mechanicalReduction>50</mechanicalReduction></actuator>
  </transmission>"""
)


def test_parse_links_joints_materials_and_tree_order():
    r = parse_urdf(GOOD, source="good.urdf", base_dir=Path("/models"))
    assert r.name == "r"
    assert r.root_link() == "base_link"
    assert [j.name for j in r.children("base_link")] == ["arm_joint", "wheel_joint"]
    assert r.parent_joint("tool").name == "tool_joint"
    assert r.parent_joint("base_link") is None
    base = r.links["base_link"]
    assert base.inertial.mass == 3.0
    assert base.inertial.origin == Origin((0.0, 0.0, 0.1), (0.0, 0.0, 0.0))
    assert base.visuals[0].geometry == Box((0.4, 0.3, 0.2))
    assert base.visuals[0].material.rgba == (0.0, 0.0, 1.0, 1.0)
    assert r.links["wheel"].collisions[0].geometry == Cylinder(0.1, 0.05)
    assert r.links["tool"].visuals[0].geometry == Mesh("/models/meshes/tool.stl", (2.0, 2.0, 2.0))
    arm = r.joints["arm_joint"]
    assert arm.limit == Limit(-1.0, 1.0, 10.0, 0.5)
    assert arm.dynamics.damping == 0.7 and arm.dynamics.friction == 0.0
    assert arm.axis == (0.0, 0.0, 1.0)
    assert r.joints["tool_joint"].axis == (1.0, 0.0, 0.0)
    tr = r.transmissions[0]
    assert tr.joints == [("arm_joint", "hardware_interface/EffortJointInterface")]
    assert tr.actuators == [("m1", 50.0)]


def test_to_urdf_round_trips():
    r = parse_urdf(GOOD, base_dir=Path("/models"))
    again = parse_urdf(r.to_urdf())
    assert again.links == r.links
    assert again.joints == r.joints
    assert again.materials == r.materials
    assert again.transmissions == r.transmissions


def test_children_of_unknown_link_suggests():
    r = parse_urdf(GOOD)
    with pytest.raises(DescriptionError, match=r"no link 'bse_link'.*did you mean 'base_link'"):
        r.children("bse_link")


@pytest.mark.parametrize(
    ("body", "pattern"),
    [
        (
            '<link name="a"/><link name="b"/>'
            '\n<joint name="j" type="fixed"><parent link="x"/><child link="b"/></joint>',
            r"bad\.urdf:3: joint 'j' names parent link 'x', which is not defined",
        ),
        (
            '<link name="a"/>\n<joint name="j" type="fixed"><parent link="a"/>'
            '<child link="bb"/></joint>',
            r"bad\.urdf:3: joint 'j' names child link 'bb', which is not defined",
        ),
        (
            '<link name="a"/>\n<link name="b"/>',
            r"bad\.urdf:1: robot 'r' has 2 root links \(a, b\)",
        ),
        (
            '<link name="a"/><link name="b"/><link name="c"/>\n'
            '<joint name="j1" type="fixed"><parent link="b"/><child link="c"/></joint>\n'
            '<joint name="j2" type="fixed"><parent link="c"/><child link="b"/></joint>',
            r"bad\.urdf:\d: the joints form a cycle \((b|c) -> (b|c) -> (b|c)\)",
        ),
        (
            '<link name="a"/>\n<joint name="j" type="fixed"><child link="a"/></joint>',
            r"bad\.urdf:3: joint 'j' has no <parent link=",
        ),
        (
            '<link name="a"/><link name="b"/>\n<joint name="j" type="hinge"><parent link="a"/>'
            '<child link="b"/></joint>',
            r"bad\.urdf:3: joint 'j' has type=\"hinge\"; valid types",
        ),
        (
            '<link name="a">\n<visual><origin xyz="0 0"/><geometry><sphere radius="1"/>'
            "</geometry></visual></link>",
            r'bad\.urdf:3: <origin> attribute xyz="0 0" is not 3 finite number',
        ),
        (
            '<link name="a">\n<inertial><mass value="-1"/>' + INERTIA + "</inertial></link>",
            r'bad\.urdf:3: <mass> attribute value="-1" must be >= 0',
        ),
        (
            '<link name="a"/><link name="b"/>\n<joint name="j" type="revolute">'
            '<parent link="a"/><child link="b"/></joint>',
            r"bad\.urdf:3: joint 'j' of type revolute has no <limit>",
        ),
        (
            '<link name="a"/><link name="b"/>\n<joint name="j" type="revolute">'
            '<parent link="a"/><child link="b"/><limit lower="0" upper="1" effort="x" '
            'velocity="1"/></joint>',
            r'bad\.urdf:3: <limit> attribute effort="x" is not 1 finite number',
        ),
        (
            '<link name="a"/>\n<link name="a"/>',
            r"bad\.urdf:3: link 'a' is defined twice",
        ),
        (
            '<link name="a">\n<visual><geometry><box size="1 1 1"/></geometry>'
            '<material name="red"/></visual></link>',
            r"bad\.urdf:3: material 'red' is not defined",
        ),
        (
            '<link name="a">\n<visual><geometry><cone/></geometry></visual></link>',
            r"bad\.urdf:3: unknown geometry <cone>",
        ),
        (
            '<link name="a"/>\n<gazebo reference="b"><mu1>1</mu1></gazebo>',
            r"bad\.urdf:3: <gazebo reference=\"b\"> names no link or joint",
        ),
    ],
)
def test_invalid_models_name_file_line_and_reason(body, pattern):
    with pytest.raises(DescriptionError, match=pattern):
        parse_urdf(robot_xml(body), source="bad.urdf")


def test_xml_syntax_error_has_line():
    with pytest.raises(
        DescriptionError, match=r"bad\.urdf:3: XML syntax error.*mismatch: link line 2"
    ):
        parse_urdf('<robot name="r">\n<link name="a">\n</robot>', source="bad.urdf")


def test_root_must_be_robot():
    with pytest.raises(DescriptionError, match=r"root element is <sdf>"):
        parse_urdf("<sdf/>")


def test_load_xacro_with_find_include_macro_and_args():
    r = load_robot(DEMO)
    assert r.name == "demo"
    assert [j.child for j in r.children("base_link")] == ["left_wheel", "right_wheel"]
    assert r.links["left_wheel"].collisions[0].geometry == Cylinder(0.05, 0.02)
    r2 = load_robot(DEMO, args={"wheel_radius": "0.08"})
    assert r2.links["right_wheel"].collisions[0].geometry == Cylinder(0.08, 0.02)
    assert r2.joints["right_wheel_joint"].origin.xyz == (0.0, -0.12, 0.0)


def test_find_from_package_path_env(tmp_path, monkeypatch):
    top = tmp_path / "top.urdf.xacro"
    top.write_text(
        '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="$(find demo_pkg)/urdf/wheel.xacro"/>'
        '<xacro:property name="r" value="0.1"/><link name="base_link"/>'
        '<xacro:wheel side="l" y="0.2"/></robot>'
    )
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("FLEETSIM_PACKAGE_PATH", raising=False)
    with pytest.raises(DescriptionError, match=r"package 'demo_pkg' not found.*FLEETSIM_PACKAGE"):
        load_robot(top)
    monkeypatch.setenv("FLEETSIM_PACKAGE_PATH", str(FIXTURES))
    assert load_robot(top).links["l_wheel"].collisions[0].geometry == Cylinder(0.1, 0.02)
    monkeypatch.delenv("FLEETSIM_PACKAGE_PATH")
    assert "l_wheel" in load_robot(top, package_path=[FIXTURES]).links


def test_xacro_missing_arg_is_reported(tmp_path):
    top = tmp_path / "a.xacro"
    top.write_text(
        '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="$(arg link_name)"/></robot>'
    )
    with pytest.raises(DescriptionError, match=r"a\.xacro: xacro argument 'link_name' is not set"):
        load_robot(top)
    assert "foo" in load_robot(top, args={"link_name": "foo"}).links


def test_xacro_semantic_error_points_into_included_file(tmp_path):
    (tmp_path / "part.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n\n'
        '<joint name="bad_joint" type="fixed">\n<parent link="base_link"/>'
        '<child link="ghost"/></joint>\n</robot>'
    )
    top = tmp_path / "top.urdf.xacro"
    top.write_text(
        '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n<link name="base_link"/>\n'
        '<xacro:include filename="part.xacro"/>\n</robot>'
    )
    with pytest.raises(
        DescriptionError, match=r"part\.xacro:3: joint 'bad_joint' names child link 'ghost'"
    ):
        load_robot(top)


def test_xacro_include_of_missing_file(tmp_path):
    top = tmp_path / "top.urdf.xacro"
    top.write_text(
        '<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:include filename="nope.xacro"/></robot>'
    )
    with pytest.raises(DescriptionError, match=r"top\.urdf\.xacro.*xacro error.*nope\.xacro"):
        load_robot(top)


def test_missing_file():
    with pytest.raises(DescriptionError, match=r"no such robot description file"):
        load_robot("/nonexistent/robot.urdf")
