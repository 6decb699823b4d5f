"""collvoid_msgs/PoseTwistWithCovariance crosses process boundaries as CDR."""

from fleetsim.msgs import collvoid_msgs, deserialize, geometry_msgs, get_type, serialize


def test_position_share_message_round_trips_through_cdr():
    msg = collvoid_msgs.PoseTwistWithCovariance(robot_id="lizi2", radius=0.31, holo_robot=False)
    msg.header.frame_id = "map"
    msg.pose.pose.position.x = 4.5
    msg.holonomic_velocity.y = -0.2
    msg.footprint.polygon.points = [geometry_msgs.Point32(x=0.2, y=-0.1)] * 4
    back = deserialize(serialize(msg), "collvoid_msgs/msg/PoseTwistWithCovariance")
    assert back.robot_id == "lizi2" and back.radius == 0.31 and back.controlled
    assert back.pose.pose.position.x == 4.5 and back.holonomic_velocity.y == -0.2
    assert len(back.footprint.polygon.points) == 4


def test_ros1_name_resolves():
    assert get_type("collvoid_msgs/PoseTwistWithCovariance") is (
        collvoid_msgs.PoseTwistWithCovariance
    )
