from __future__ import annotations

from fleetsim.msgs import deserialize, gazebo_ros_link_attacher, get_srv_type, serialize


def test_attach_service(own_def):
    srv = get_srv_type("gazebo_ros_link_attacher/Attach")
    assert srv is gazebo_ros_link_attacher.Attach
    assert own_def("gazebo_ros_link_attacher/AttachRequest") == [
        "string model_name_1",
        "string link_name_1",
        "string model_name_2",
        "string link_name_2",
    ]
    assert own_def("gazebo_ros_link_attacher/AttachResponse") == ["bool ok"]
    req = srv.Request("lizi1", "base_link", "box", "link")
    assert deserialize(serialize(req), "gazebo_ros_link_attacher/srv/Attach_Request") == req
