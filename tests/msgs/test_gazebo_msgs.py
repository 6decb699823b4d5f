"""gazebo_msgs layouts against the ROS 1 .msg/.srv definitions (field names, types, order)."""

from __future__ import annotations

import pytest

from fleetsim.msgs import gazebo_msgs, get_srv_type

REFERENCE = {
    "gazebo_msgs/ModelState": "string model_name|geometry_msgs/Pose pose|"
    "geometry_msgs/Twist twist|string reference_frame",
    "gazebo_msgs/ModelStates": "string[] name|geometry_msgs/Pose[] pose|"
    "geometry_msgs/Twist[] twist",
    "gazebo_msgs/LinkState": "string link_name|geometry_msgs/Pose pose|"
    "geometry_msgs/Twist twist|string reference_frame",
    "gazebo_msgs/ContactState": "string info|string collision1_name|string collision2_name|"
    "geometry_msgs/Wrench[] wrenches|geometry_msgs/Wrench total_wrench|"
    "geometry_msgs/Vector3[] contact_positions|geometry_msgs/Vector3[] contact_normals|"
    "float64[] depths",
    "gazebo_msgs/ContactsState": "std_msgs/Header header|gazebo_msgs/ContactState[] states",
    "gazebo_msgs/SpawnModelRequest": "string model_name|string model_xml|"
    "string robot_namespace|geometry_msgs/Pose initial_pose|string reference_frame",
    "gazebo_msgs/SpawnModelResponse": "bool success|string status_message",
    "gazebo_msgs/DeleteModelRequest": "string model_name",
    "gazebo_msgs/GetModelStateRequest": "string model_name|string relative_entity_name",
    "gazebo_msgs/GetModelStateResponse": "std_msgs/Header header|geometry_msgs/Pose pose|"
    "geometry_msgs/Twist twist|bool success|string status_message",
    "gazebo_msgs/SetModelStateRequest": "gazebo_msgs/ModelState model_state",
    "gazebo_msgs/GetWorldPropertiesResponse": "float64 sim_time|string[] model_names|"
    "bool rendering_enabled|bool success|string status_message",
    "gazebo_msgs/GetLinkStateRequest": "string link_name|string reference_frame",
    "gazebo_msgs/GetLinkStateResponse": "gazebo_msgs/LinkState link_state|bool success|"
    "string status_message",
}


@pytest.mark.parametrize("typename", sorted(REFERENCE))
def test_layout_matches_ros1(typename, own_def):
    assert own_def(typename) == REFERENCE[typename].split("|")


def test_world_services():
    for name in ("SpawnModel", "DeleteModel", "GetModelState", "SetModelState"):
        srv = get_srv_type(f"gazebo_msgs/{name}")
        assert srv is getattr(gazebo_msgs, name)
        assert srv.Response().success is False
    assert gazebo_msgs.GetWorldProperties.Request.__msgfields__ == ()
    req = gazebo_msgs.SpawnModel.Request(model_name="lizi1", model_xml="<robot/>")
    assert req.initial_pose.orientation.w == 1.0
