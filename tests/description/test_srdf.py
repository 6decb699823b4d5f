"""Tests for fleetsim.description.srdf: groups, chains, group states, checks against a URDF."""

from __future__ import annotations

import pytest

from fleetsim.description.srdf import parse_srdf
from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import DescriptionError

URDF = parse_urdf(
    """<robot name="arm">
  <link name="base"/><link name="l1"/><link name="l2"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/></joint>
</robot>"""
)

SRDF = """<robot name="arm">
  <group name="arm"><chain base_link="base" tip_link="l2"/></group>
  <group name="tip"><link name="l2"/></group>
  <group name="all"><group name="arm"/><joint name="j1"/></group>
  <group_state name="home" group="arm"><joint name="j1" value="0"/><joint name="j2" value="0.5"/>
  </group_state>
  <end_effector name="ee" parent_link="l1" group="tip" parent_group="arm"/>
  <virtual_joint name="vj" type="planar" parent_frame="odom" child_link="base"/>
  <disable_collisions link1="base" link2="l1" reason="Adjacent"/>
</robot>"""


def test_parse_groups_states_and_collisions():
    s = parse_srdf(SRDF, "arm.srdf", URDF)
    assert s.groups["arm"].chains == [("base", "l2")]
    assert s.group_joints("arm", URDF) == ["j1", "j2"]
    assert s.group_joints("all", URDF) == ["j1", "j2"]
    assert s.group_states[("arm", "home")] == {"j1": 0.0, "j2": 0.5}
    assert s.end_effectors[0].parent_link == "l1"
    assert s.virtual_joints[0].type == "planar"
    assert s.disabled_collisions == [("base", "l1", "Adjacent")]


@pytest.mark.parametrize(
    ("old", "new", "pattern"),
    [
        (
            '<joint name="j2" value="0.5"/>',
            '<joint name="j3" value="0.5"/>',
            r"arm\.srdf:5: joint 'j3' is not in robot 'arm'",
        ),
        (
            'group="arm"><joint',
            'group="arms"><joint',
            r"arm\.srdf:5: group_state 'home' names unknown group 'arms'.*did you mean 'arm'",
        ),
        ('link2="l1"', 'link2="l9"', r"arm\.srdf:9: link 'l9' is not in robot 'arm'"),
        ('value="0.5"', 'value="up"', r"joint 'j2' value 'up' is not a number"),
        ('type="planar"', 'type="hinge"', r"virtual_joint type 'hinge'"),
    ],
)
def test_errors_name_file_line(old, new, pattern):
    with pytest.raises(DescriptionError, match=pattern):
        parse_srdf(SRDF.replace(old, new), "arm.srdf", URDF)


def test_robot_name_mismatch():
    with pytest.raises(DescriptionError, match=r"SRDF is for robot 'arm' but the URDF is 'x'"):
        parse_srdf(SRDF, "arm.srdf", parse_urdf('<robot name="x"><link name="base"/></robot>'))
