"""The ``Simulator`` node (``gazebo_ros/gzserver``): the engine on the runtime's clock.

A physics timer (priority -100) advances the ``Engine`` up to the current sim time, publishes
every reading that fell due (odometry and its tf, scans, images, joint states, ground truth),
robot contacts on ``/gazebo/robot_contacts`` and ``/clock``. Drive plugins listen on their
robot's ``commandTopic``. World services (``/gazebo/*``, ``/link_attacher_node/*``) live in
``sim.services``. Topics resolve in the robot's namespace; frames get its ``tf_prefix`` (the
``tf_prefix`` parameter found from the namespace up, else the namespace itself).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from fleetsim.msgs import geometry_msgs, nav_msgs, rosgraph_msgs, sensor_msgs
from fleetsim.runtime import Node, param
from fleetsim.runtime import names as rnames
from fleetsim.sim import messages as conv
from fleetsim.sim.engine import Engine, ModelEntry
from fleetsim.sim.plugins.base import (
    DrivePlugin,
    ImageReading,
    JointStateReading,
    OdometryReading,
    ScanReading,
    TransformsReading,
)
from fleetsim.sim.plugins.camera import CameraPlugin
from fleetsim.sim.plugins.laser import LaserPlugin
from fleetsim.sim.plugins.ros_control import start_controller_managers
from fleetsim.sim.services import WorldServices
from fleetsim.sim.world import WALL_HEIGHT

EMPTY_WORLDS = ("", "worlds/empty.world", "empty", "empty.world")

#: reading class -> (message type, conversion) of the readings published one message each
_READING_MESSAGES = {
    OdometryReading: (nav_msgs.Odometry, conv.odometry_msg),
    ScanReading: (sensor_msgs.LaserScan, conv.scan_msg),
    JointStateReading: (sensor_msgs.JointState, conv.joint_state_msg),
}


@dataclass(frozen=True)
class SimulatorParams:
    world_name: str = param("", help="SDF .world or map .yaml; empty: ground plane and sun")
    paused: bool = param(False, help="start with physics paused")
    max_step_size: float = param(0.004, unit="s", range=(1e-4, 0.02), help="physics step")
    update_period: float = param(
        0.01,
        unit="s",
        range=(1e-4, 1.0),
        help="how often physics catches up with sim time and publishes",
    )
    pub_clock_frequency: float = param(
        100.0, unit="Hz", range=(0.0, None), help="/clock rate (0: every update)"
    )
    wall_height: float = param(
        WALL_HEIGHT, unit="m", range=(0.01, None), help="map-world wall height"
    )
    publish_contacts: bool = param(True, help="publish robot contacts on ~robot_contacts")
    model_states_rate: float = param(
        10.0, unit="Hz", range=(0.0, None), help="~model_states rate (0: off; fleetsim addition)"
    )


class Simulator(Node):
    """The simulator node; ``args[0]`` (as gzserver takes it) or ``~world_name`` is the world."""

    Params = SimulatorParams

    def __init__(self, runtime, name: str = "gazebo", namespace: str = "/", **kw: Any) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p = self.params
        world = next((a for a in self.args if not a.startswith("-")), p.world_name)
        source = None if world in EMPTY_WORLDS else Path(world)
        self.engine = Engine(
            source, timestep=p.max_step_size, rng=self.rng, wall_height=p.wall_height
        )
        self.engine.paused = p.paused
        self.offset = runtime.now() - self.engine.time  # sim time = physics time + offset
        self._pubs: dict[tuple[str, type], Any] = {}
        self._reading_pubs: dict[tuple[type, str, str], Any] = {}  # (reading, topic, ns) -> pub
        self._subs: dict[str, list] = {}
        from fleetsim.tf import TransformBroadcaster

        self.tf = TransformBroadcaster(self)
        self.clock_pub = self.create_publisher(rosgraph_msgs.Clock, "/clock", queue_size=10)
        self.contacts_pub = self.create_publisher(
            conv.gazebo_msgs.ContactsState, "~robot_contacts", queue_size=10
        )
        self._last_clock = -1.0
        self._last_states = -1.0
        self.states_pub = self.create_publisher(
            conv.gazebo_msgs.ModelStates, "~model_states", queue_size=1
        )
        self.services = WorldServices(self)
        self.create_timer(p.update_period, self.on_update, priority=-100)

    # ------------------------------------------------------------------ models
    def tf_prefix_for(self, namespace: str) -> str:
        """tf_prefix of a robot namespace: the ``tf_prefix`` parameter, else the namespace."""
        found = self.runtime.params.search("tf_prefix", rnames.join(namespace, "spawned_model"))
        if found is not None:
            value = self.runtime.params.get(found)
            return str(value).strip("/") if value else ""
        return namespace.strip("/")

    def spawn_robot(
        self, name: str, robot: Any, pose=(0, 0, 0, 0, 0, 0), namespace: str | None = None
    ) -> ModelEntry:
        """Spawn a robot and wire its drive commands (see ``Engine.spawn_robot``)."""
        ns = rnames.validate_namespace(namespace if namespace else f"/{name}")
        prefix = self.tf_prefix_for(ns)
        self._warn_shared(name, ns, prefix)
        entry = self.engine.spawn_robot(name, robot, pose, ns, prefix)
        self._wire(entry)
        self.get_logger().info("spawned '%s' in namespace %s", name, ns)
        return entry

    def _warn_shared(self, name: str, ns: str, prefix: str) -> None:
        """Warn when a robot is spawned in the namespace, or with the tf_prefix, of one already
        here: Gazebo spawns it, and the two then share topics (cmd_vel, odom, the laser's) or
        frames, one robot's messages overwriting the other's without a word."""
        for other in self.engine.models.values():
            if other.kind != "robot" or other.name == name:  # a taken name is refused below
                continue
            if other.namespace == ns:
                shared = f"in namespace {ns}, as '{other.name}' is: the two share their topics "
                shared += "(cmd_vel, odom, the sensors'), each hearing the other's"
            elif other.tf_prefix == prefix:
                shared = f"with tf_prefix '{prefix}', as '{other.name}' is: the two publish the "
                shared += "same tf frames"
            else:
                continue
            self.get_logger().warning(
                f"'{name}' is spawned {shared}; give each robot its own <group ns> and "
                "tf_prefix (spawn_model inside the group)"
            )
            return

    def _wire(self, entry: ModelEntry) -> None:
        subs = []
        for p in entry.plugins:
            if isinstance(p, DrivePlugin):
                topic = self.topic(entry, p.params.commandTopic)

                def on_cmd(msg, plugin=p):
                    plugin.command(msg.linear.x, msg.angular.z, self.engine.time)

                subs.append(
                    self.create_subscription(geometry_msgs.Twist, topic, on_cmd, queue_size=1)
                )
            elif isinstance(p, CameraPlugin):
                # as gazebo_ros_camera: render only while someone subscribes to the images
                pp = p.params
                names = [pp.imageTopicName, f"{pp.imageTopicName}/compressed"]
                names.append(pp.cameraInfoTopicName)
                depth = []
                if p.depth_enabled:
                    depth = [
                        pp.depthImageTopicName,
                        pp.depthImageCameraInfoTopicName,
                        pp.pointCloudTopicName,
                    ]
                    depth = [self.topic(entry, p.topic(n)) for n in depth]
                    p.depth_wanted = lambda topics=depth: self._has_subscribers(topics)
                topics = [self.topic(entry, p.topic(n)) for n in names] + depth
                p.wanted = lambda topics=topics: self._has_subscribers(topics)
            elif isinstance(p, LaserPlugin):
                # as gazebo_ros_laser: cast only while someone subscribes to the scans
                scan = self._publisher(self.topic(entry, p.params.topicName), sensor_msgs.LaserScan)
                p.wanted = lambda topic=scan.topic: bool(topic.subscriptions)
        # gazebo_ros_control: the robot's controller_manager, destroyed with the model
        subs.extend(start_controller_managers(self, entry))
        self._subs[entry.name] = subs

    def _has_subscribers(self, topics: list[str]) -> bool:
        graph = self.runtime.graph
        return any(t in graph.topics and graph.topics[t].subscriptions for t in topics)

    def delete_model(self, name: str) -> None:
        self.engine.delete_model(name)
        for sub in self._subs.pop(name, []):
            sub.destroy()

    @staticmethod
    def topic(entry: ModelEntry, name: str) -> str:
        return rnames.resolve(name, entry.namespace)

    def _publisher(self, topic: str, msg_type: type):
        key = (topic, msg_type)
        if key not in self._pubs:
            self._pubs[key] = self.create_publisher(msg_type, topic, queue_size=10)
        return self._pubs[key]

    # ------------------------------------------------------------------ stepping
    def on_update(self) -> None:
        target = self.now() - self.offset
        if self.engine.paused:
            self.offset = self.now() - self.engine.time
            readings = []
        else:
            readings = self.engine.advance(target - self.engine.time)
        self.publish(readings)
        p = self.params
        period = 1.0 / p.pub_clock_frequency if p.pub_clock_frequency > 0 else 0.0
        if self.now() - self._last_clock >= period - 1e-9:
            self._last_clock = self.now()
            self.clock_pub.publish(rosgraph_msgs.Clock(clock=self.now_msg()))
        if (
            p.model_states_rate > 0
            and self.now() - self._last_states >= 1 / p.model_states_rate - 1e-9
        ):
            self._last_states = self.now()
            if self.states_pub.get_num_connections():  # built only for someone to read
                self.states_pub.publish(conv.model_states_msg(self.engine))
        if (
            p.publish_contacts
            and not self.engine.paused
            and self.contacts_pub.get_num_connections()
        ):
            contacts = self.engine.contacts()
            if contacts:
                self.contacts_pub.publish(conv.contacts_msg(self.now(), contacts))

    def publish(self, readings: list) -> None:
        """Turn plugin readings into messages on their robots' topics.

        Odometry transforms go out first (one ``/tf`` message), so that a scan or image of the
        same update finds its robot's ``odom -> base`` transform already in the tf buffer.
        """
        off = self.offset
        for r in readings:
            r.stamp += off
        tfs = []
        for r in readings:
            kind = type(r)
            if kind is OdometryReading and r.publish_tf:
                tfs.append(conv.odometry_tf(r))
            elif kind is TransformsReading:
                tfs.extend(conv.reading_tfs(r))
        if tfs:
            self.tf.send_transform(tfs)
        pubs = self._reading_pubs
        for r in readings:
            kind = type(r)
            if kind is ImageReading:
                self._publish_image(r, r.namespace)
                continue
            spec = _READING_MESSAGES.get(kind)
            if spec is None:
                continue
            key = (kind, r.topic, r.namespace)
            pub = pubs.get(key)
            if pub is None:
                pub = pubs[key] = self._publisher(rnames.resolve(r.topic, r.namespace), spec[0])
            if pub.topic.subscriptions:  # a message nobody reads is not built
                pub.publish(spec[1](r))

    def _publish_image(self, r: ImageReading, ns: str) -> None:
        img = conv.image_msg(r.stamp, r.frame_id, r.image, r.encoding)
        self._publisher(rnames.resolve(r.topic, ns), sensor_msgs.Image).publish(img)
        jpeg = self._publisher(
            rnames.resolve(f"{r.topic}/compressed", ns), sensor_msgs.CompressedImage
        )
        if jpeg.topic.subscriptions:  # encoded only for subscribers, as image_transport does
            from fleetsim.vision.image_transport import compress_image  # cv2 only then

            jpeg.publish(compress_image(img))
        info = conv.camera_info_msg(r)
        self._publisher(rnames.resolve(r.info_topic, ns), sensor_msgs.CameraInfo).publish(info)
        if r.depth is not None:
            d = conv.image_msg(r.stamp, r.frame_id, r.depth, "32FC1")
            self._publisher(rnames.resolve(r.depth_topic, ns), sensor_msgs.Image).publish(d)
            self._publisher(rnames.resolve(r.depth_info_topic, ns), sensor_msgs.CameraInfo).publish(
                info
            )
            if r.cloud_topic:  # advertised always, computed only for subscribers
                topic = rnames.resolve(r.cloud_topic, ns)
                pub = self._publisher(topic, sensor_msgs.PointCloud2)
                if self._has_subscribers([topic]):
                    pub.publish(conv.cloud_msg(r.stamp, r.frame_id, r.depth, r.image, r.K))
