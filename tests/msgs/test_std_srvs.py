from __future__ import annotations

from fleetsim.msgs import deserialize, serialize, std_srvs


def test_layouts(own_def):
    assert own_def("std_srvs/srv/Empty_Request") == []
    assert own_def("std_srvs/TriggerResponse") == ["bool success", "string message"]
    assert own_def("std_srvs/SetBoolRequest") == ["bool data"]
    assert own_def("std_srvs/SetBoolResponse") == ["bool success", "string message"]


def test_empty_request_is_one_byte_like_ros2():
    data = serialize(std_srvs.Empty.Request())
    assert data == b"\x00\x01\x00\x00\x00"
    assert deserialize(data, "std_srvs/srv/Empty_Request") == std_srvs.EmptyRequest()
    assert std_srvs.SetBool.Request(data=True).data is True
