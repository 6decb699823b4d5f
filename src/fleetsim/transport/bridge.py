"""`ZenohBridge`: a runtime's graph, reachable from other processes and machines over Zenoh.

Outgoing: each topic with a local publisher gets a zenoh publisher on ``topic/<name>``; while a
remote subscriber matches, a forwarding subscription in the local graph serialises every message
as CDR and puts it. Latched topics also answer ``latched/<zid>/<name>`` queries with their last
message, so a late remote subscriber gets the map once.

Incoming: each topic with a local subscription gets a zenoh subscriber (remote origins only, so
nothing echoes). Zenoh callbacks run on zenoh's threads; they only put items in a thread-safe
inbox. `pump` (a runtime timer at priority -90, right after physics) empties the inbox on the
simulation thread: it decodes messages into the subscriptions' queues, answers service and
parameter queries, and applies remote graph changes, so a run stays ordered by sim time.

Services are exported as queryables and remote services are imported as local proxy services;
the parameter tree answers on ``param``; a liveliness token and a ``graph/<zid>`` queryable
describe the process to tools. See `fleetsim.transport.keys` for the key layout.
"""

from __future__ import annotations

import json
import logging
import queue
import time as _wall
from collections.abc import Sequence
from contextlib import contextmanager
from typing import Any

from fleetsim.errors import FleetsimError, TransportError
from fleetsim.transport.clock_follow import ClockFollowing
from fleetsim.transport.graphinfo import graph_snapshot
from fleetsim.transport.keys import Keys, default_endpoint, open_session
from fleetsim.transport.paramserver import answer_param_request
from fleetsim.transport.services import ServiceBridging
from fleetsim.transport.topics import TopicBridging

_log = logging.getLogger("fleetsim.transport")

#: the bridge's inbox timer priority: after physics (-100), before sensors (-50) and nodes (0)
PUMP_PRIORITY = -90


def _type_name(tp: Any) -> str:
    return getattr(tp, "__msgtype__", None) or getattr(tp, "name", None) or repr(tp)


class ZenohBridge(TopicBridging, ServiceBridging, ClockFollowing):
    """Attach a `Runtime`'s graph to a Zenoh network.

    Parameters
    ----------
    runtime : the runtime whose graph is shared.
    mode : ``"peer"`` for a simulation (listens; tools and nodes connect to it) or
        ``"client"`` for a process joining one (``fleetsim node run``, tools).
    listen : endpoints a peer listens on; default ``$FLEETSIM_ZENOH`` or ``tcp/127.0.0.1:7447``.
    connect : endpoints to connect to (a simulation, or a zenoh router for multi-host runs).
    domain : key domain (``fleetsim/<domain>/...``); default ``$FLEETSIM_DOMAIN`` or ``0``.
    poll_period : sim-time period of the inbox pump, seconds.
    serve_params : answer parameter requests (default: true for a peer).
    publish_clock : publish ``/clock`` (rosgraph_msgs/Clock) at each pump (default: true for a
        peer, unless something in the graph already publishes it).
    follow_clock : run on the remote ``/clock`` (see `run_following`); waits up to
        ``clock_timeout`` seconds for the first clock and starts the runtime's time there.
    proxy_services : make remote services callable in this graph.
    role : how tools list this process (``simulation``, ``node``).
    """

    def __init__(
        self,
        runtime: Any,
        mode: str = "peer",
        listen: Sequence[str] | None = None,
        connect: Sequence[str] = (),
        *,
        domain: str | int | None = None,
        poll_period: float = 0.01,
        serve_params: bool | None = None,
        publish_clock: bool | None = None,
        follow_clock: bool = False,
        clock_timeout: float = 5.0,
        proxy_services: bool = True,
        service_timeout: float = 10.0,
        role: str | None = None,
    ) -> None:
        import zenoh

        self._zenoh = zenoh
        if not poll_period > 0:
            raise TransportError(f"bridge poll_period must be > 0 s, got {poll_period!r}")
        if listen is None:
            listen = [default_endpoint()] if mode == "peer" else []
        self.runtime = runtime
        self.graph = runtime.graph
        self.keys = Keys(domain)
        self.mode = mode
        self.endpoints = list(listen) or list(connect)
        self.role = role or ("simulation" if mode == "peer" else "node")
        self.service_timeout = service_timeout
        self.session = open_session(mode, listen, connect)
        self.zid = str(self.session.zid())
        self._inbox: queue.SimpleQueue = queue.SimpleQueue()
        self._own: set = set()
        self._making_own = False
        self._closed = False
        self._dirty = True
        self._warned: set[str] = set()
        self._out: dict[str, Any] = {}  # name -> topics._Outgoing
        self._in: dict[str, Any] = {}
        # the graph queryable answers from zenoh's threads as soon as it is declared, before
        # this constructor's first `_publish_snapshot`: it must never see a snapshot without
        # the process's identity (a tool's merge sorts processes by role and zid)
        self._snapshot: dict = graph_snapshot(self.graph, (), self.zid, self.role, runtime.now())
        self._clock_pub = None
        self._timer = None
        self._init_services(proxy_services)
        self._init_clock(follow_clock, clock_timeout)
        try:
            self._declare_process(mode == "peer" if serve_params is None else serve_params)
            self.graph.listeners.append(self._on_graph_event)
            self._replay_graph()
            if publish_clock if publish_clock is not None else mode == "peer":
                self._start_clock()
            self._timer = runtime.create_timer(poll_period, self.pump, priority=PUMP_PRIORITY)
            runtime.on_shutdown(self.close)
            self._publish_snapshot()
        except BaseException:
            self.close()
            raise

    # -- process-level declarations -------------------------------------------------------
    def _declare_process(self, serve_params: bool) -> None:
        s, k = self.session, self.keys
        self._token = s.liveliness().declare_token(k.alive(self.zid))
        self._graph_q = s.declare_queryable(k.graph(self.zid), self._reply_graph)
        self._param_q = (
            s.declare_queryable(k.param, lambda q: self._inbox.put(("param", q)))
            if serve_params
            else None
        )
        self._changed_pub = s.declare_publisher(k.graph_changed(self.zid))
        self._declare_remote_watch()

    def _replay_graph(self) -> None:
        for name, topic in list(self.graph.topics.items()):
            for pub in list(topic.publishers):
                self._on_graph_event("advertise", name, pub)
            for sub in list(topic.subscriptions):
                self._on_graph_event("subscribe", name, sub)
        for name, srv in list(self.graph.services.items()):
            self._on_graph_event("advertise_service", name, srv)

    def _start_clock(self) -> None:
        from fleetsim.msgs import rosgraph_msgs

        topic = self.graph.topics.get("/clock")
        if topic is not None and topic.publishers:
            return
        self._clock_msg = rosgraph_msgs.Clock
        self._clock_pub = self.graph.advertise("/clock", rosgraph_msgs.Clock)

    @contextmanager
    def _own_objects(self):
        """Graph objects made inside this block are the bridge's plumbing, not exported."""
        self._making_own = True
        try:
            yield
        finally:
            self._making_own = False

    # -- graph events (simulation thread) -------------------------------------------------
    def _on_graph_event(self, event: str, name: str, obj: Any) -> None:
        if self._making_own or obj in self._own or self._closed:
            return
        self._dirty = True
        if event == "advertise":
            if name == "/clock" and self._clock_pub is not None and obj is not self._clock_pub:
                clock, self._clock_pub = self._clock_pub, None  # the simulator publishes it
                clock.destroy()
            self._export_topic(name, obj)
        elif event == "unadvertise":
            self._unexport_topic(name)
        elif event == "subscribe":
            self._import_topic(name, obj)
        elif event == "unsubscribe":
            self._unimport_topic(name)
        elif event == "advertise_service":
            self._export_service(name, obj)
        elif event == "unadvertise_service":
            self._unexport_service(name, obj)

    # -- the inbox (simulation thread) ----------------------------------------------------
    def pump(self) -> int:
        """Handle everything received since the last call; returns how many items."""
        n = 0
        inbox = self._inbox
        if self.alive_peers:
            # yield the GIL so that zenoh's callback threads queue what has arrived. Only while
            # another bridge's process is alive (nodes on other processes run in step with this
            # one): on a loaded machine each sleep(0) also gave the CPU away, ~0.5 ms a pump, a
            # fifth of a slam_explore run's wall time; tools' messages and queries wait at most
            # the interpreter's switch interval (5 ms) for a busy simulation thread instead
            _wall.sleep(0)
        while not self._closed:
            try:
                item = inbox.get_nowait()
            except queue.Empty:
                break
            n += 1
            try:
                self._handle(item)
            except FleetsimError as e:  # one bad item must not stop the simulation
                self._warn_once(f"{item[0]}:{e}", "bridge: %s", e)
        if self._closed:
            return n
        if self._dirty:
            self._publish_snapshot()
        if self._clock_pub is not None:
            from fleetsim.msgs.builtin_interfaces import Time

            self._clock_pub.publish(self._clock_msg(clock=Time.from_nsec(self.runtime.time_ns)))
        return n

    def spin_once(self) -> int:
        """Pump the inbox and deliver pending messages, without advancing sim time."""
        n = self.pump()
        return n + self.runtime.spin_once()

    def _handle(self, item: tuple) -> None:
        kind = item[0]
        if kind == "msg":
            self._deliver(*item[1:])
        elif kind == "match":
            self._set_forwarding(item[1], item[2])
        elif kind == "query":
            self._answer_service(item[1], item[2])
        elif kind == "param":
            q = item[1]
            try:
                payload = q.payload.to_bytes() if q.payload is not None else b""
                q.reply(q.key_expr, answer_param_request(self.runtime.params, payload))
            finally:
                q.drop()
        else:
            self._handle_remote(item)

    def _publish_snapshot(self) -> None:
        self._dirty = False
        self._snapshot = graph_snapshot(
            self.graph, self._own, self.zid, self.role, self.runtime.now()
        )
        self._changed_pub.put(b"")

    def _reply_graph(self, query: Any) -> None:
        snap = dict(self._snapshot, time=self.runtime.now(), endpoints=self.endpoints)
        query.reply(self.keys.graph(self.zid), json.dumps(snap).encode())

    def _warn_once(self, key: str, fmt: str, *args: Any) -> None:
        if key not in self._warned:
            self._warned.add(key)
            _log.warning(fmt, *args)

    # -- lifecycle --------------------------------------------------------------------------
    def close(self) -> None:
        """Withdraw from the network (idempotent); the runtime keeps running locally."""
        if self._closed:
            return
        self._closed = True
        if self._on_graph_event in self.graph.listeners:
            self.graph.listeners.remove(self._on_graph_event)
        if self._timer is not None:
            self._timer.cancel()
        for out in self._out.values():
            self._set_forwarding_off(out)
        self._close_services()
        if self._clock_pub is not None:
            self._clock_pub.destroy()
        self._out.clear()
        self._in.clear()
        self.session.close()

    def __enter__(self) -> ZenohBridge:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
