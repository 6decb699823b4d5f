from __future__ import annotations

from fleetsim.msgs import deserialize, geometry_msgs, get_type, serialize, tf2_msgs


def test_tf_message():
    assert get_type("tf/tfMessage") is tf2_msgs.TFMessage
    t = geometry_msgs.TransformStamped(child_frame_id="lizi1/odom")
    t.header.frame_id = "map"
    t.transform.translation.x = 1.5
    back = deserialize(serialize(tf2_msgs.TFMessage([t])), "tf2_msgs/TFMessage")
    assert back.transforms[0].child_frame_id == "lizi1/odom"
    assert back.transforms[0].transform.translation.x == 1.5
