"""`LiveServer` (``--viz``): every topic of a running simulation, live in Foxglove.

The server speaks Foxglove's WebSocket protocol (``foxglove.websocket.v1``) through
``foxglove-sdk`` on ``ws://127.0.0.1:8765``. Each topic becomes a channel with its ROS 2 type
as a ``ros2msg`` schema and ``cdr`` messages, so Foxglove draws maps and costmaps
(``nav_msgs/OccupancyGrid``), laser scans, ``/tf``, paths, poses, particle clouds
(``PoseArray``) and images with its own ROS renderers. On top of that, ``/fleetsim/robots``
(a Foxglove ``SceneUpdate``) shows each robot as a scene entity: its footprint outline and its
name, attached to its base frame.

Messages are serialised only while a client is subscribed to their channel, so an idle viewer
costs the simulation almost nothing. The server's clock is the sim clock (Foxglove's ``time``
capability), and latched topics (``/map``) are sent again to a client that subscribes late.
"""

from __future__ import annotations

import atexit
import logging
import threading
from typing import Any

from fleetsim.errors import TransportError
from fleetsim.viz.robots import colour_of, footprint_from_params, robot_of_frame

_log = logging.getLogger("fleetsim.viz")

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8765
#: topic of the robots' scene entities
ROBOTS_TOPIC = "/fleetsim/robots"
#: the server's timer runs after every node of the same instant
SERVER_PRIORITY = 100


class _Listener:
    """Foxglove server callbacks (on the server's thread): note late subscriptions."""

    def __init__(self, server: LiveServer) -> None:
        self._server = server

    def on_subscribe(self, client: Any, channel: Any) -> None:
        self._server._resend_latched(channel.topic)

    def on_unsubscribe(self, client: Any, channel: Any) -> None:
        pass


class LiveServer:
    """Serve ``runtime``'s topics to Foxglove over WebSocket.

    Parameters
    ----------
    runtime : the `Runtime` to show.
    host, port : where to listen (``port=0`` picks a free port; see `port`).
    topics : global topic names to serve; ``None`` serves every topic, present and future.
    scene_period : sim seconds between updates of the robot entities and the server clock.
    """

    def __init__(
        self,
        runtime: Any,
        host: str = DEFAULT_HOST,
        port: int = DEFAULT_PORT,
        topics: list[str] | None = None,
        scene_period: float = 0.1,
    ) -> None:
        import foxglove
        from foxglove.channels import SceneUpdateChannel

        self.runtime = runtime
        self.host = host
        self.topics = None if topics is None else set(topics)
        self.context = foxglove.Context()
        try:
            self.server = foxglove.start_server(
                name="fleetsim",
                host=host,
                port=port,
                capabilities=[foxglove.Capability.Time],
                server_listener=_Listener(self),
                context=self.context,
            )
        except Exception as e:  # the SDK raises RuntimeError/OSError for a busy port
            raise TransportError(
                f"cannot serve Foxglove on ws://{host}:{port}: {e}; another viewer may hold the "
                "port: stop it or choose another port"
            ) from e
        self._lock = threading.Lock()
        self._channels: dict[str, Any] = {}
        self._latched: dict[str, bytes] = {}  # topic -> last CDR message of a latched topic
        self._resend: set[str] = set()
        self._subs: list[Any] = []
        self._robots: dict[str, str] = {}  # robot -> base frame
        self.closed = False
        self._scene = SceneUpdateChannel(ROBOTS_TOPIC, context=self.context)
        graph = runtime.graph
        graph.listeners.append(self._on_graph_event)
        for name, topic in sorted(graph.topics.items()):
            self._maybe_serve(name, topic)
        self._timer = runtime.create_timer(scene_period, self._tick, priority=SERVER_PRIORITY)
        runtime.on_shutdown(self.close)
        atexit.register(self.close)
        _log.info("Foxglove live view on %s", self.url)

    @property
    def port(self) -> int:
        return self.server.port

    @property
    def url(self) -> str:
        """The address to open in Foxglove (Open connection -> Foxglove WebSocket)."""
        return f"ws://{self.host}:{self.port}"

    # -- topics -----------------------------------------------------------------------------
    def _on_graph_event(self, event: str, name: str, obj: Any) -> None:
        if event in ("advertise", "subscribe") and not self.closed:
            self._maybe_serve(name, obj.topic)

    def _maybe_serve(self, name: str, topic: Any) -> None:
        if name in self._channels or (self.topics is not None and name not in self.topics):
            return
        import foxglove

        from fleetsim.msgs import msgdef, serialize, type_name

        typename = type_name(topic.type)
        schema = foxglove.Schema(
            name=typename, encoding="ros2msg", data=msgdef(topic.type).encode()
        )
        channel = foxglove.Channel(
            name, schema=schema, message_encoding="cdr", context=self.context
        )
        self._channels[name] = channel
        runtime = self.runtime

        def on_message(msg: Any) -> None:
            latched = any(p.latch for p in topic.publishers)
            if latched:
                data = serialize(msg)
                with self._lock:
                    self._latched[name] = data
            if channel.has_sinks():
                channel.log(data if latched else serialize(msg), log_time=runtime.time_ns)

        for pub in topic.publishers:  # a latched message waiting for delivery: ready it now
            if pub.latch and pub.last is not None:
                self._latched[name] = serialize(pub.last)
        self._subs.append(self.runtime.graph.subscribe(name, topic.type, on_message, queue_size=0))
        if name == "/tf" or name == "/tf_static":
            self._subs.append(self.runtime.graph.subscribe(name, topic.type, self._on_tf, 0))

    def _resend_latched(self, topic: str) -> None:
        with self._lock:
            data = self._latched.get(topic)
        channel = self._channels.get(topic)
        if data is not None and channel is not None:
            channel.log(data, log_time=self.runtime.time_ns)

    # -- robots -----------------------------------------------------------------------------
    def _on_tf(self, msg: Any) -> None:
        for t in msg.transforms:
            child = t.child_frame_id.lstrip("/")
            robot = robot_of_frame(child)
            if robot is not None and robot not in self._robots:
                self._robots[robot] = child

    def robot_entities(self) -> Any:
        """The ``SceneUpdate`` showing every robot found so far (footprint and name)."""
        from foxglove.messages import (
            Color,
            LinePrimitive,
            LinePrimitiveLineType,
            Point3,
            Pose,
            Quaternion,
            SceneEntity,
            SceneUpdate,
            TextPrimitive,
            Timestamp,
            Vector3,
        )

        params = self.runtime.params.get("/", {})
        sec, nsec = divmod(self.runtime.time_ns, 1_000_000_000)
        entities = []
        for i, (robot, frame) in enumerate(sorted(self._robots.items())):
            r, g, b = colour_of(i)
            fp = footprint_from_params(params, robot)
            top = float(fp[:, 0].max()) if fp.size else 0.3
            entities.append(
                SceneEntity(
                    timestamp=Timestamp(sec, nsec),
                    frame_id=frame,
                    id=f"robot/{robot}",
                    frame_locked=True,
                    lines=[
                        LinePrimitive(
                            type=LinePrimitiveLineType.LineLoop,
                            thickness=0.03,
                            points=[Point3(x=float(x), y=float(y), z=0.02) for x, y in fp],
                            color=Color(r=r, g=g, b=b, a=1.0),
                        )
                    ],
                    texts=[
                        TextPrimitive(
                            pose=Pose(
                                position=Vector3(x=0.0, y=0.0, z=0.5 + top),
                                orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                            ),
                            billboard=True,
                            font_size=14.0,
                            scale_invariant=True,
                            color=Color(r=r, g=g, b=b, a=1.0),
                            text=robot or "robot",
                        )
                    ],
                )
            )
        return SceneUpdate(entities=entities)

    def _tick(self) -> None:
        self.server.broadcast_time(self.runtime.time_ns)
        if self._robots and self._scene.has_sinks():
            self._scene.log(self.robot_entities(), log_time=self.runtime.time_ns)

    # -- lifecycle --------------------------------------------------------------------------
    def close(self) -> None:
        """Stop serving (idempotent)."""
        if self.closed:
            return
        self.closed = True
        atexit.unregister(self.close)
        if self._on_graph_event in self.runtime.graph.listeners:
            self.runtime.graph.listeners.remove(self._on_graph_event)
        self._timer.cancel()
        for sub in self._subs:
            sub.destroy()
        self._subs.clear()
        self.server.stop()

    def __enter__(self) -> LiveServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
