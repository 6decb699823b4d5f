"""tf over the bridge: every latched /tf_static publisher reaches a remote subscriber (as a late
ROS subscriber gets each publisher's latched message), and each edge names its broadcaster."""

from __future__ import annotations

import threading
import time

from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped
from fleetsim.transport import SimulationClient
from fleetsim.transport.tfview import TfListener, frames_text

from .conftest import SimThread

ROBOTS = ("alpha", "bravo", "charlie")


class Robot(Node):
    """One robot's tf: its state publisher's static frames (base_link -> base_scan) and a
    drive's odom -> base_link at 20 Hz (another node, as in the simulator)."""

    def __init__(self, runtime, name: str) -> None:
        super().__init__(runtime, "robot_state_publisher", f"/{name}")
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped(f"{name}/base_link", f"{name}/base_scan", 0.0, (0.1, 0, 0.2))
        )
        self.drive = Node(runtime, "diff_drive", f"/{name}")
        self.tf = TransformBroadcaster(self.drive)
        self.name_ = name
        self.drive.create_timer(0.05, self.on_timer)

    def on_timer(self) -> None:
        self.tf.send_transform(
            make_transform_stamped(f"{self.name_}/odom", f"{self.name_}/base_link", self.now())
        )


def wait_until(condition, timeout: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.02)
    return False


def test_every_robots_static_frames_and_broadcasters_reach_a_remote_tool(endpoint):
    rt = Runtime(seed=1)
    localizer = Node(rt, "fake_localization", "/")
    StaticTransformBroadcaster(localizer).send_transform(
        [make_transform_stamped("map", f"{n}/odom", 0.0, (i, 0, 0)) for i, n in enumerate(ROBOTS)]
    )
    for n in ROBOTS:
        Robot(rt, n)
    with SimThread(rt, endpoint, rate=1.0), SimulationClient(endpoint) as c:
        tf = TfListener(c)
        # a late subscriber: all four latched /tf_static messages, then /tf as it comes
        assert wait_until(lambda: all(f"{n}/base_link" in tf.frames() for n in ROBOTS))
        infos = tf.frames()
        for i, n in enumerate(ROBOTS):
            t = tf.lookup("map", f"{n}/base_scan").transform.translation
            assert (t.x, t.z) == (i + 0.1, 0.2)
            assert infos[f"{n}/base_scan"].authority == f"/{n}/robot_state_publisher"
            assert infos[f"{n}/base_link"].authority == f"/{n}/diff_drive"
            assert infos[f"{n}/odom"].authority == "/fake_localization"
        text = frames_text(infos)
        assert [line for line in text.splitlines() if not line.startswith(" ")] == ["map"]
        assert " or " not in text


def test_a_static_frame_sent_later_reaches_a_subscribed_tool(endpoint):
    """Live /tf_static messages of two publishers both arrive (not only the latched query)."""
    rt = Runtime(seed=1)
    first, second = Node(rt, "first", "/"), Node(rt, "second", "/")
    a, b = StaticTransformBroadcaster(first), StaticTransformBroadcaster(second)
    a.send_transform(make_transform_stamped("map", "a", 0.0))
    go = threading.Event()

    def later() -> None:  # on the simulation thread, once the tool listens
        if go.is_set() and not b.transforms:
            b.send_transform(make_transform_stamped("map", "b", 0.0))

    second.create_timer(0.05, later)
    with SimThread(rt, endpoint, rate=1.0), SimulationClient(endpoint) as c:
        tf = TfListener(c)
        assert wait_until(lambda: "a" in tf.frames())
        go.set()
        assert wait_until(lambda: "b" in tf.frames())
        assert tf.frames()["a"].authority == "/first"
        assert tf.frames()["b"].authority == "/second"
