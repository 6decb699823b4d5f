"""/position_share across processes: a robot whose stack runs behind a Zenoh bridge appears in
the neighbour table of a robot in another runtime (the message travels as CDR)."""

import math
import socket
import threading

from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.nav.multirobot.position_share import PositionShare
from fleetsim.runtime import Node, Runtime
from fleetsim.transport import ZenohBridge


class RemoteRobot(Node):
    """Shares a robot 'far1' at (3, 4) at 10 Hz, as me_publisher would."""

    def __init__(self, rt):
        super().__init__(rt, "me_publisher", "/far1")
        self.pub = self.create_publisher(collvoid_msgs.PoseTwistWithCovariance, "/position_share")
        self.create_timer(0.1, self.tick)

    def tick(self):
        m = collvoid_msgs.PoseTwistWithCovariance(robot_id="far1", radius=0.25)
        m.header.stamp = self.now_msg()
        m.pose.pose.position = geometry_msgs.Point(x=3.0, y=4.0)
        m.holonomic_velocity = geometry_msgs.Vector3(x=0.2)
        sq = [(-0.2, -0.2), (-0.2, 0.2), (0.2, 0.2), (0.2, -0.2)]
        m.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in sq]
        self.pub.publish(m)


def free_endpoint() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


def test_a_robot_behind_a_zenoh_bridge_is_a_neighbour():
    endpoint = free_endpoint()
    sim_rt = Runtime(seed=1)
    RemoteRobot(sim_rt)
    ZenohBridge(sim_rt, listen=[endpoint])
    stop = threading.Event()
    thread = threading.Thread(target=lambda: sim_rt.run(until=stop.is_set, rate=1.0), daemon=True)
    thread.start()
    rt = Runtime(seed=2)
    try:
        bridge = ZenohBridge(rt, mode="client", connect=[endpoint], follow_clock=True)
        share = PositionShare(Node(rt, "move_base", "/near1"))
        bridge.run_following(until=rt.now() + 1.5)
        near = share.table.near(rt.now(), (0.0, 0.0), 6.0, 10)
        assert near.ids == ["far1"]
        assert near.positions.tolist() == [[3.0, 4.0]]
        assert math.isclose(near.velocities[0, 0], 0.2)
        assert near.robots[0].footprint.shape == (4, 2)
    finally:
        rt.shutdown()
        stop.set()
        thread.join(10)
        sim_rt.shutdown()
