"""The node base class.

A node has a name in a namespace, reads its parameters from its private namespace in the
runtime's parameter tree (validated against its ``Params`` dataclass), and declares in its
constructor the publishers, subscriptions, services, actions and timers it uses.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from fleetsim.errors import GraphError
from fleetsim.runtime import names
from fleetsim.runtime.graph import Publisher, Service, ServiceClient, Subscription
from fleetsim.runtime.params import _set_at, load_params
from fleetsim.runtime.scheduler import Timer

#: sim seconds a sensor subscription may hear nothing before it is warned about (a costmap's
#: observation source, amcl's scans), and how often the warning repeats
SILENT_AFTER = 10.0
SILENT_REPEAT = 30.0


class NodeLogger(logging.LoggerAdapter):
    """Prefixes each record with the sim time and the node's resolved name."""

    def __init__(self, node: Node) -> None:
        super().__init__(logging.getLogger("fleetsim.node"), {})
        self._node = node

    def process(self, msg, kwargs):
        return f"[{self._node.now():.3f}] [{self._node.full_name}] {msg}", kwargs


class Node:
    """Base class of every node (map_server, move_base, amcl, user nodes).

    Parameters
    ----------
    runtime : the `Runtime` the node lives in.
    name : the node's base name (one token).
    namespace : the namespace it lives in (``/lizi1``).
    remaps : ``{from: to}`` remappings, resolved in ``namespace``.
    params : parameters to set in the node's private namespace before it reads them (what
        ``<param>`` inside ``<node>`` does); they override values already in the tree.
    args : command-line arguments (``args=`` of a launch ``<node>``).
    """

    Params: ClassVar[type | None] = None
    #: keys in the private namespace that belong to plugins or sub-components, not warned about
    PARAM_NAMESPACES: ClassVar[tuple[str, ...]] = ()

    def __init__(
        self,
        runtime,
        name: str,
        namespace: str = "/",
        *,
        remaps: Mapping[str, str] | None = None,
        params: Mapping[str, Any] | None = None,
        args: Sequence[str] = (),
    ) -> None:
        names.validate_base_name(name)
        self.runtime = runtime
        self.namespace = names.validate_namespace(namespace)
        self.name = name
        self.full_name = names.join(self.namespace, name)
        self.args = list(args)
        if self.full_name in runtime.graph.nodes:
            raise GraphError(
                f"a node named {self.full_name} already exists; give this one another name or "
                "namespace"
            )
        self.remaps = names.resolve_remaps(remaps, self.namespace, self.full_name)
        self._publishers: list[Publisher] = []
        self._subscriptions: list[Subscription] = []
        self._services: list[Service] = []
        self._timers: list[Timer] = []
        self._actions: list[Any] = []
        self._logger = NodeLogger(self)
        self._warned: set[str] = set()  # keys already warned about (see _warn_once)
        self._warned_at: dict[str, float] = {}  # key -> sim time of its last warning (_warn)
        self.rng: np.random.Generator = runtime.rng(self.full_name)
        if params:
            runtime.params.update(self.full_name, dict(params))
        self.params = self._load_params()
        runtime.graph.nodes[self.full_name] = self

    # -- names and parameters -------------------------------------------------------------
    def resolve_name(self, name: str) -> str:
        """Resolve a topic/service/param name for this node, applying its remaps."""
        return names.resolve(
            name, self.namespace, self.full_name, self.remaps, where=f" (node {self.full_name})"
        )

    def _load_params(self) -> Any:
        if self.Params is None:
            return None
        values = self.runtime.params.get(self.full_name, {})
        if not isinstance(values, dict):
            values = {}
        return load_params(
            self.Params,
            values,
            where=self.full_name,
            ignore=frozenset(self.PARAM_NAMESPACES),
            logger=self._logger,
        )

    def param_origin(self, name: str) -> str:
        """`` (set at FILE:LINE)`` for the private parameter ``name`` when a file set it, else
        "": for errors a node raises on a value after loading it (a list to parse, a pair of
        parameters that disagree)."""
        return _set_at({name: self.runtime.params.origin(names.join(self.full_name, name))}, name)

    def get_param(self, name: str, default: Any = None) -> Any:
        """Read a parameter by (relative, private or global) name."""
        return self.runtime.params.get(self.resolve_name(name), default)

    def set_param(self, name: str, value: Any) -> None:
        self.runtime.params.set(self.resolve_name(name), value)

    def has_param(self, name: str) -> bool:
        return self.runtime.params.has(self.resolve_name(name))

    def search_param(self, key: str) -> str | None:
        """ROS searchParam: the closest ``key`` from the private namespace upward."""
        return self.runtime.params.search(key, self.full_name)

    @property
    def tf_prefix(self) -> str:
        """The robot's ``tf_prefix`` (searched up the namespace), without slashes."""
        found = self.search_param("tf_prefix")
        if found is None:
            return ""
        value = self.runtime.params.get(found)
        return str(value).strip("/") if value else ""

    def frame(self, frame_id: str) -> str:
        """A frame id with this node's tf_prefix applied (``/map`` stays ``map``)."""
        from fleetsim.tf.names import resolve_frame

        return resolve_frame(self.tf_prefix, frame_id)

    # -- time, logging, tf ------------------------------------------------------------------
    def now(self) -> float:
        return self.runtime.now()

    def now_msg(self):
        from fleetsim.msgs.builtin_interfaces import Time

        return Time.from_nsec(self.runtime.time_ns)

    def get_logger(self) -> NodeLogger:
        return self._logger

    def _warn(self, key: str, text: str, period: float = 5.0) -> None:
        """Log ``text`` as a warning at most once every ``period`` s of sim time per ``key``
        (``ROS_WARN_THROTTLE`` by key; ``math.inf``: once)."""
        now = self.now()
        last = self._warned_at.get(key)
        if last is None or now - last >= period:
            self._warned_at[key] = now
            self._logger.warning(text)

    def _warn_once(self, key: str, text: str) -> None:
        """Log ``text`` as a warning the first time ``key`` is seen (``ROS_WARN_ONCE`` by key);
        discarding ``key`` from ``_warned`` lets it warn again."""
        if key not in self._warned:
            self._warned.add(key)
            self._logger.warning(text)

    def unpublished_hint(self, sub: Subscription) -> str:
        """For a subscription that hears nothing: "" when its topic has a publisher here, else
        " (no publisher; LaserScan is published on /a, /b)" naming up to six topics of its
        type that have one, those in this node's namespace first (a laser on ``base_scan`` for
        a node reading ``scan``). A publisher in another process is not seen here."""
        topic = sub.topic
        if topic.publishers:
            return ""
        own = self.namespace.rstrip("/") + "/"
        others = sorted(
            (
                name
                for name, t in self.runtime.graph.topics.items()
                if t.type is topic.type and t.publishers and name != topic.name
            ),
            key=lambda name: (not name.startswith(own), name),
        )
        seen = f"; {topic.type.__name__} is published on {', '.join(others[:6])}"
        return f" (no publisher{seen if others else ''})"

    def warn_while_silent(
        self, sub: Subscription, heard: Callable[[], bool], what: str, then: str
    ) -> Timer:
        """Every `SILENT_AFTER` s until ``heard()``: warn (every `SILENT_REPEAT` s)
        "``what`` on TOPIC in N s (no publisher; ...): ``then``" with `unpublished_hint` (amcl
        and slam_gmapping without scans, explore without a costmap). Returns the timer, which
        cancels itself once heard."""
        started = self.now()

        def check() -> None:
            if heard():
                timer.cancel()
                return
            self._warn(
                f"silent:{sub.topic.name}",
                f"{what} on {sub.topic.name} in {self.now() - started:.0f} s"
                f"{self.unpublished_hint(sub)}: {then}",
                SILENT_REPEAT,
            )

        timer = self.create_timer(SILENT_AFTER, check)
        return timer

    @property
    def tf_buffer(self):
        return self.runtime.tf_buffer

    # -- communication ----------------------------------------------------------------------
    def create_publisher(
        self, msg_type: Any, topic: str, queue_size: int = 10, latch: bool = False
    ) -> Publisher:
        pub = self.runtime.graph.advertise(self.resolve_name(topic), msg_type, latch, self)
        self._publishers.append(pub)
        return pub

    def create_subscription(
        self,
        msg_type: Any,
        topic: str,
        callback: Callable[[Any], None],
        queue_size: int = 10,
        with_publisher: bool = False,
    ) -> Subscription:
        """Subscribe; ``with_publisher``: ``callback`` gets ``(msg, publisher)`` (see
        `fleetsim.runtime.graph`)."""
        sub = self.runtime.graph.subscribe(
            self.resolve_name(topic), msg_type, callback, queue_size, self, with_publisher
        )
        self._subscriptions.append(sub)
        return sub

    def create_service(self, srv_type: Any, name: str, callback: Callable[[Any], Any]) -> Service:
        srv = self.runtime.graph.advertise_service(
            self.resolve_name(name), srv_type, callback, self
        )
        self._services.append(srv)
        return srv

    def create_client(self, srv_type: Any, name: str) -> ServiceClient:
        return ServiceClient(self.runtime.graph, self.resolve_name(name), srv_type, self)

    def create_timer(self, period: float, callback: Callable[[], None], priority: int = 0) -> Timer:
        timer = self.runtime.create_timer(period, callback, priority)
        self._timers.append(timer)
        return timer

    def create_action_server(self, action_type: Any, name: str, **kw: Any):
        from fleetsim.runtime.actions import ActionServer

        server = ActionServer(self, action_type, name, **kw)
        self._actions.append(server)
        return server

    def create_action_client(self, action_type: Any, name: str):
        from fleetsim.runtime.actions import ActionClient

        client = ActionClient(self, action_type, name)
        self._actions.append(client)
        return client

    # -- lifecycle --------------------------------------------------------------------------
    def destroy(self) -> None:
        """Withdraw every publisher, subscription, service and timer of this node."""
        for t in self._timers:
            t.cancel()
        for s in self._subscriptions:
            s.destroy()
        for p in self._publishers:
            p.destroy()
        for srv in self._services:
            self.runtime.graph.unadvertise_service(srv)
        self._timers.clear()
        self._subscriptions.clear()
        self._publishers.clear()
        self._services.clear()
        if self.runtime.graph.nodes.get(self.full_name) is self:
            del self.runtime.graph.nodes[self.full_name]

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.full_name}>"
