"""``joint_state_publisher``: ``joint_states`` for every movable joint of ``robot_description``.

Each joint starts at its ``zeros`` value, else 0, else (when 0 is outside its limits) the
middle of its range, as ROS's joint_state_publisher does. Messages on the ``source_list`` topics
override positions (and velocities, efforts) of the joints they name. Mimic joints follow their
leader. Publishes at ``rate`` Hz, stamped with sim time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fleetsim.description.robot_state_publisher import robot_description_text
from fleetsim.description.urdf import parse_urdf
from fleetsim.errors import ParameterError
from fleetsim.msgs import sensor_msgs, std_msgs
from fleetsim.runtime import Node, param

MOVABLE = ("revolute", "continuous", "prismatic")


@dataclass(frozen=True)
class JointStatePublisherParams:
    rate: float = param(10.0, unit="Hz", range=(0.0, None), help="publish rate of joint_states")
    source_list: list = param([], help="JointState topics whose values override the defaults")
    zeros: dict = param({}, help="initial position of each named joint, rad or m")
    publish_default_positions: bool = param(
        True, help="publish joints that no source has reported yet"
    )
    use_mimic_tags: bool = param(True, help="mimic joints follow their leader joint")


class JointStatePublisher(Node):
    """The joint_state_publisher node (ROS package ``joint_state_publisher``)."""

    Params = JointStatePublisherParams

    def __init__(self, runtime, name: str = "joint_state_publisher", namespace="/", **kw):
        super().__init__(runtime, name, namespace, **kw)
        p = self.params
        text, where = robot_description_text(self)
        robot = parse_urdf(text, source=f"parameter {where}")
        movable = [j for j in robot.joints.values() if j.type in MOVABLE]
        self.mimics = {j.name: j.mimic for j in movable if j.mimic is not None and p.use_mimic_tags}
        self.free = [j.name for j in movable if j.name not in self.mimics]
        for joint_name in p.zeros:
            if joint_name not in robot.joints:
                raise ParameterError(
                    f"{self.full_name}: ~zeros names joint '{joint_name}', which is not in "
                    f"robot '{robot.name}'"
                )
        self.position: dict[str, float] = {}
        for j in movable:
            if j.name in p.zeros:
                self.position[j.name] = float(p.zeros[j.name])
            elif (
                j.limit is not None
                and j.type != "continuous"
                and not (j.limit.lower <= 0.0 <= j.limit.upper)
            ):
                self.position[j.name] = 0.5 * (j.limit.lower + j.limit.upper)
            else:
                self.position[j.name] = 0.0
        self.velocity: dict[str, float] = {}
        self.effort: dict[str, float] = {}
        self.reported: set[str] = set()
        self.pub = self.create_publisher(sensor_msgs.JointState, "joint_states", queue_size=10)
        for topic in p.source_list:
            name = self.resolve_name(str(topic))
            if name == self.pub.topic.name:
                # its own output as a source (the manual's [/joint_states], beside a drive
                # that publishes its wheels there): its own messages are not read back, or a
                # stale value of its own could overwrite a newer one from the simulator
                self.create_subscription(
                    sensor_msgs.JointState, name, self._on_shared_topic, with_publisher=True
                )
            else:
                self.create_subscription(sensor_msgs.JointState, name, self.on_source)
        if p.rate > 0:
            self.create_timer(1.0 / p.rate, self.publish)

    def _on_shared_topic(self, item) -> None:
        msg, publisher = item  # a with_publisher subscription's (msg, publisher)
        if publisher is not self.pub:
            self.on_source(msg)

    def on_source(self, msg) -> None:
        for k, name in enumerate(msg.name):
            if name not in self.position or name in self.mimics:
                continue
            self.reported.add(name)
            if k < len(msg.position):
                self.position[name] = float(msg.position[k])
            if k < len(msg.velocity):
                self.velocity[name] = float(msg.velocity[k])
            if k < len(msg.effort):
                self.effort[name] = float(msg.effort[k])

    def joint_state(self):
        """The JointState this node publishes now."""
        names = [
            n for n in self.free if self.params.publish_default_positions or n in self.reported
        ]
        values = {n: self.position[n] for n in names}
        for name, mimic in self.mimics.items():
            if mimic.joint in self.position:
                values[name] = mimic.multiplier * self.position[mimic.joint] + mimic.offset
                names.append(name)
        msg = sensor_msgs.JointState(header=std_msgs.Header(stamp=self.now_msg()))
        msg.name = names
        msg.position = np.array([values[n] for n in names], dtype=np.float64)
        if self.velocity:
            msg.velocity = np.array([self.velocity.get(n, 0.0) for n in names])
        if self.effort:
            msg.effort = np.array([self.effort.get(n, 0.0) for n in names])
        return msg

    def publish(self) -> None:
        self.pub.publish(self.joint_state())
