"""The in-process graph: typed topics with publishers and subscriptions, and services.

Delivery is deferred and ordered: `Publisher.publish` puts the message in each subscription's
queue (bounded by its ``queue_size``; the oldest message is dropped when full, as ROS does) and
records the subscription in the runtime's FIFO of pending deliveries. The runtime drains that
FIFO after every callback, so which callback runs next depends only on the order of events,
never on the wall clock. A message is shared by reference with every subscriber.

Latched publishers keep their last message and hand it to subscriptions made later, the way
``map`` and ``/tf_static`` behave in ROS 1. `Publisher.publish_lazily` builds a message only
for someone to read it: a latched one nobody subscribes to is built when a subscription comes.

Topics and services may also have remote ends (the Zenoh bridge): `Graph.listeners` are told of
every new publisher, subscription and service, and a bridge registers itself as an ordinary
subscription or service. A subscription made ``with_publisher`` receives ``(msg, publisher)``
instead of ``msg``, so that a bridge can name each message's sending node (as ROS does per
connection); a topic without one pays a single flag test per publish for this.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from fleetsim.errors import GraphError, ServiceError, did_you_mean
from fleetsim.msgs.registry import message_class

if TYPE_CHECKING:
    from fleetsim.runtime.node import Node


def _type_name(tp: Any) -> str:
    return getattr(tp, "__msgtype__", None) or getattr(tp, "name", None) or repr(tp)


class Topic:
    __slots__ = ("name", "publishers", "subscriptions", "type", "with_publisher")

    def __init__(self, name: str, msg_type: Any) -> None:
        self.name = name
        self.type = msg_type
        self.publishers: list[Publisher] = []
        self.subscriptions: list[Subscription] = []
        self.with_publisher = 0  # subscriptions that receive (msg, publisher)


class Subscription:
    """A callback on a topic with its own bounded queue."""

    __slots__ = (
        "_pending",
        "callback",
        "graph",
        "msg_type",
        "node",
        "queue",
        "queue_size",
        "topic",
        "with_publisher",
    )

    def __init__(
        self,
        graph: Graph,
        topic: Topic,
        callback: Callable,
        queue_size: int,
        node,
        with_publisher: bool = False,
    ):
        self.graph = graph
        self.topic = topic
        self.msg_type = topic.type
        self.callback = callback
        self.queue_size = queue_size
        self.queue: deque = deque(maxlen=queue_size if queue_size > 0 else None)
        self.node = node
        self._pending = graph._pending
        self.with_publisher = with_publisher

    def destroy(self) -> None:
        if self in self.topic.subscriptions:
            self.topic.subscriptions.remove(self)
            self.topic.with_publisher -= self.with_publisher
            self.queue.clear()
            self.graph._changed("unsubscribe", self.topic.name, self)


class Publisher:
    """Publishes messages of one type on one topic."""

    __slots__ = ("_last", "_make_last", "graph", "latch", "msg_type", "node", "topic")

    def __init__(self, graph: Graph, topic: Topic, latch: bool, node) -> None:
        self.graph = graph
        self.topic = topic
        self.msg_type = topic.type
        self.latch = latch
        self._last: Any = None
        self._make_last: Callable[[], Any] | None = None
        self.node = node

    @property
    def name(self) -> str:
        return self.topic.name

    @property
    def last(self) -> Any:
        """The latched message (None: none yet, or not latched); one `publish_lazily` kept
        unbuilt is built now."""
        make = self._make_last
        if make is not None:
            self._make_last = None
            self._last = self._checked(make())
        return self._last

    def _checked(self, msg: Any) -> Any:
        if type(msg) is not self.msg_type and message_class(msg) is not self.msg_type:
            raise GraphError(
                f"topic {self.topic.name} carries {_type_name(self.msg_type)}, "
                f"cannot publish {_type_name(type(msg))}"
            )
        return msg

    def publish_lazily(self, make: Callable[[], Any]) -> None:
        """Publish ``make()``, built only for someone to read: with no subscription nothing is
        built, and a latched publisher keeps ``make`` for a later subscription (or a reader of
        `last`), which then gets the message as it would have been published now. ``make``
        must not depend on state that changes after this call (copy what it reads)."""
        if self.topic.subscriptions:
            self.publish(make())
        elif self.latch:
            self._last = None
            self._make_last = make

    def publish(self, msg: Any) -> None:
        if type(msg) is not self.msg_type and message_class(msg) is not self.msg_type:
            self._checked(msg)
        if self.latch:
            self._last = msg
            self._make_last = None
        pending = self.graph._pending
        if self.topic.with_publisher:
            for sub in self.topic.subscriptions:
                sub.queue.append((msg, self) if sub.with_publisher else msg)
                pending.append(sub)
            return
        for sub in self.topic.subscriptions:
            sub.queue.append(msg)
            pending.append(sub)

    def get_num_connections(self) -> int:
        return len(self.topic.subscriptions)

    def destroy(self) -> None:
        if self in self.topic.publishers:
            self.topic.publishers.remove(self)
            self.graph._changed("unadvertise", self.topic.name, self)


class Service:
    __slots__ = ("callback", "name", "node", "srv_type")

    def __init__(self, name: str, srv_type: Any, callback: Callable, node) -> None:
        self.name = name
        self.srv_type = srv_type
        self.callback = callback
        self.node = node


class ServiceClient:
    """Calls a service; in process the call runs the server's callback at once."""

    __slots__ = ("graph", "name", "node", "srv_type")

    def __init__(self, graph: Graph, name: str, srv_type: Any, node) -> None:
        self.graph = graph
        self.name = name
        self.srv_type = srv_type
        self.node = node

    def wait_for_service(self, timeout: float | None = None) -> bool:
        """True when a server exists (in process there is nothing to wait for)."""
        return self.name in self.graph.services

    def service_is_ready(self) -> bool:
        return self.name in self.graph.services

    def call(self, request: Any = None) -> Any:
        return self.graph.call_service(self.name, self.srv_type, request)


class Graph:
    """Topics and services of one runtime."""

    def __init__(self) -> None:
        self.topics: dict[str, Topic] = {}
        self.services: dict[str, Service] = {}
        self.nodes: dict[str, Node] = {}
        self._pending: deque[Subscription] = deque()
        self.listeners: list[Callable[[str, str, Any], None]] = []

    # -- topics ---------------------------------------------------------------------------
    def _topic(self, name: str, msg_type: Any, who: str) -> Topic:
        topic = self.topics.get(name)
        if topic is None:
            topic = self.topics[name] = Topic(name, msg_type)
        elif topic.type is not msg_type:
            # name who holds it with the other type: a remap gone wrong in one of them (slam's
            # scan remapped to odom) had been blamed on the node that came second
            holders = [
                f"{kind} in {end.node.full_name}"
                for kind, ends in (
                    ("publisher", topic.publishers),
                    ("subscriber", topic.subscriptions),
                )
                for end in ends
                if end.node is not None
            ]
            held = f" ({', '.join(sorted(set(holders))[:4])})" if holders else ""
            raise GraphError(
                f"topic {name} already carries {_type_name(topic.type)}{held}; {who} asked for "
                f"{_type_name(msg_type)}; check the remaps of both"
            )
        return topic

    def advertise(self, name: str, msg_type: Any, latch: bool = False, node=None) -> Publisher:
        who = f"publisher in {node.full_name}" if node is not None else "a publisher"
        topic = self._topic(name, msg_type, who)
        pub = Publisher(self, topic, latch, node)
        topic.publishers.append(pub)
        self._changed("advertise", name, pub)
        return pub

    def subscribe(
        self,
        name: str,
        msg_type: Any,
        callback: Callable,
        queue_size: int = 10,
        node=None,
        with_publisher: bool = False,
    ) -> Subscription:
        """Subscribe ``callback`` to topic ``name``; ``with_publisher``: it is called with
        ``(msg, publisher)`` (``publisher`` None for a message `deliver` hands in)."""
        if queue_size < 0:
            raise GraphError(f"subscription to {name}: queue_size must be >= 0, got {queue_size}")
        who = f"subscription in {node.full_name}" if node is not None else "a subscription"
        topic = self._topic(name, msg_type, who)
        sub = Subscription(self, topic, callback, queue_size, node, with_publisher)
        topic.subscriptions.append(sub)
        topic.with_publisher += with_publisher
        for pub in topic.publishers:
            if pub.latch and pub.last is not None:
                sub.queue.append((pub.last, pub) if with_publisher else pub.last)
                self._pending.append(sub)
        self._changed("subscribe", name, sub)
        return sub

    def deliver(self, sub: Subscription, msg: Any) -> None:
        """Queue ``msg`` for one subscription, as a publish would (bridges use this to hand
        messages from other processes to local subscribers)."""
        sub.queue.append((msg, None) if sub.with_publisher else msg)
        self._pending.append(sub)

    def drain(self) -> int:
        """Deliver every pending message in FIFO order; returns how many were delivered."""
        pending = self._pending
        n = 0
        while pending:
            sub = pending.popleft()
            queue = sub.queue
            if queue:
                sub.callback(queue.popleft())
                n += 1
        return n

    # -- services ---------------------------------------------------------------------------
    def advertise_service(self, name: str, srv_type: Any, callback: Callable, node=None) -> Service:
        if name in self.services:
            owner = self.services[name].node
            owner_name = owner.full_name if owner is not None else "another provider"
            raise GraphError(f"service {name} is already provided by {owner_name}")
        srv = self.services[name] = Service(name, srv_type, callback, node)
        self._changed("advertise_service", name, srv)
        return srv

    def unadvertise_service(self, srv: Service) -> None:
        if self.services.get(srv.name) is srv:
            del self.services[srv.name]
            self._changed("unadvertise_service", srv.name, srv)

    def call_service(self, name: str, srv_type: Any, request: Any = None) -> Any:
        srv = self.services.get(name)
        if srv is None:
            raise ServiceError(
                f"service {name} is not available{did_you_mean(name, self.services)}"
            )
        if srv_type is not None and srv.srv_type is not srv_type:
            raise ServiceError(
                f"service {name} is {_type_name(srv.srv_type)}, called as {_type_name(srv_type)}"
            )
        if request is None:
            request = srv.srv_type.Request()
        elif type(request) is not srv.srv_type.Request:
            raise ServiceError(
                f"service {name} takes {_type_name(srv.srv_type.Request)}, "
                f"got {_type_name(type(request))}"
            )
        try:
            response = srv.callback(request)
        except ServiceError:
            raise
        except Exception as e:
            raise ServiceError(f"service {name} failed: {type(e).__name__}: {e}") from e
        if response is None:
            response = srv.srv_type.Response()
        return response

    # -- introspection ----------------------------------------------------------------------
    def topic_types(self) -> dict[str, str]:
        return {name: _type_name(t.type) for name, t in sorted(self.topics.items())}

    def _changed(self, event: str, name: str, obj: Any) -> None:
        for listener in self.listeners:
            listener(event, name, obj)
