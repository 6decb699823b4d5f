"""robot_state_publisher and joint_state_publisher nodes on a small runtime."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fleetsim.description.joint_state_publisher import JointStatePublisher
from fleetsim.description.robot_state_publisher import RobotStatePublisher
from fleetsim.errors import ParameterError
from fleetsim.msgs import sensor_msgs, tf2_msgs
from fleetsim.runtime import Runtime

URDF = """<robot name="r">
  <link name="base_link"/><link name="arm"/><link name="slider"/><link name="laser"/>
  <link name="twin"/>
  <joint name="laser_joint" type="fixed"><origin xyz="0.1 0 0.2"/>
    <parent link="base_link"/><child link="laser"/></joint>
  <joint name="arm_joint" type="revolute"><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <parent link="base_link"/><child link="arm"/>
    <limit lower="0.5" upper="1.5" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><origin xyz="1 0 0" rpy="0 0 1.5707963267948966"/>
    <axis xyz="1 0 0"/><parent link="arm"/><child link="slider"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="twin_joint" type="revolute"><axis xyz="0 0 1"/><parent link="arm"/>
    <child link="twin"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="arm_joint" multiplier="2" offset="0.1"/></joint>
</robot>"""


@pytest.fixture
def rt():
    rt = Runtime(seed=0)
    rt.params.set("/lizi1/robot_description", URDF)
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    return rt


def test_rsp_static_and_moving_frames_with_tf_prefix(rt):
    static, moving = [], []
    rt.graph.subscribe("/tf_static", tf2_msgs.TFMessage, static.append, queue_size=0)
    rt.graph.subscribe("/tf", tf2_msgs.TFMessage, moving.append, queue_size=0)
    buf = rt.tf_buffer  # created on first use: subscribe before anything is published
    RobotStatePublisher(rt, namespace="/lizi1")
    JointStatePublisher(rt, namespace="/lizi1", params={"zeros": {"slide": 0.25}})
    rt.run(0.5)
    (t,) = static[-1].transforms
    assert (t.header.frame_id, t.child_frame_id) == ("lizi1/base_link", "lizi1/laser")
    assert (t.transform.translation.x, t.transform.translation.z) == (0.1, 0.2)
    assert moving, "robot_state_publisher published nothing on /tf"
    # arm_joint starts mid-range (0 is outside [0.5, 1.5]): 1.0 rad about z
    tr = buf.lookup_transform("lizi1/base_link", "lizi1/slider", 0.0)
    x, y = tr.transform.translation.x, tr.transform.translation.y
    # slider origin (1,0,0) rotated by 1 rad, plus 0.25 m along the slide axis (rotated 1+pi/2)
    expect = np.array([math.cos(1.0), math.sin(1.0)]) + 0.25 * np.array(
        [math.cos(1.0 + math.pi / 2), math.sin(1.0 + math.pi / 2)]
    )
    assert (x, y) == pytest.approx(tuple(expect), abs=1e-9)
    twin = buf.lookup_transform("lizi1/arm", "lizi1/twin", 0.0).transform.rotation
    assert 2 * math.atan2(twin.z, twin.w) == pytest.approx(2 * 1.0 + 0.1)


def test_jsp_merges_source_list(rt):
    out = []
    rt.graph.subscribe("/lizi1/joint_states", sensor_msgs.JointState, out.append, queue_size=0)
    JointStatePublisher(rt, namespace="/lizi1", params={"source_list": ["arm_states"], "rate": 20})
    src = rt.graph.advertise("/lizi1/arm_states", sensor_msgs.JointState, False, None)
    rt.run(0.1)
    assert out[-1].name == ["arm_joint", "slide", "twin_joint"]
    msg = sensor_msgs.JointState(name=["arm_joint", "unknown"], position=np.array([0.7, 3.0]))
    src.publish(msg)
    rt.run(0.1)
    last = out[-1]
    assert dict(zip(last.name, last.position)) == pytest.approx(
        {"arm_joint": 0.7, "slide": 0.0, "twin_joint": 1.5}
    )
    assert len(out) == pytest.approx(0.2 * 20, abs=1)


def test_jsp_with_its_own_topic_as_a_source_reads_only_the_others(rt):
    """source_list [joint_states] beside a diff drive publishing its wheels there (the
    hunter): the node's own message, queued after a newer one from the drive, must not put
    its older value back."""
    jsp = JointStatePublisher(
        rt, namespace="/lizi1", params={"source_list": ["joint_states"], "rate": 10}
    )
    drive = rt.graph.advertise("/lizi1/joint_states", sensor_msgs.JointState, False, None)
    rt.run(0.05)
    drive.publish(sensor_msgs.JointState(name=["arm_joint"], position=np.array([0.7])))
    jsp.publish()  # its 0.0, sent before it read the drive's 0.7
    rt.run(0.01)
    assert jsp.position["arm_joint"] == 0.7


def test_robot_description_must_be_urdf_text(rt):
    rt.params.set("/lizi1/robot_description", "/path/to/lizi.urdf")
    with pytest.raises(ParameterError, match=r"/lizi1/robot_description must hold URDF XML text"):
        RobotStatePublisher(rt, namespace="/lizi1")


def test_missing_robot_description(rt):
    with pytest.raises(ParameterError, match=r"'robot_description' not found in /other"):
        RobotStatePublisher(rt, namespace="/other")


def test_jsp_zeros_must_name_joints(rt):
    with pytest.raises(ParameterError, match=r"~zeros names joint 'elbow'"):
        JointStatePublisher(rt, namespace="/lizi1", params={"zeros": {"elbow": 1.0}})
