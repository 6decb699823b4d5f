"""`SimulationClient`: what the command-line tools use to reach a running simulation.

It is a zenoh *client* session connected to the simulation's endpoint, with no runtime of its
own: it reads graph snapshots, subscribes and publishes CDR on topic keys, calls services and
talks to the parameter server. Opening it fails fast (bounded by ``timeout``) with the one-line
"no simulation running at ..." error when nothing fleetsim answers there.

A script that forgets ``close()`` still exits. zenoh-python runs a Python callback on a
non-daemon thread of its own, which Python's exit waits for before it runs any exit handler, so
a client with a subscription kept its process alive forever. Here each subscription is a zenoh
channel read by a daemon thread of ours (`_reader`), and the client closes itself when it is
garbage collected or the interpreter exits (a `weakref.finalize`, which Python runs at exit).
``with SimulationClient() as c:`` closes it at the end of the block.
"""

from __future__ import annotations

import json
import logging
import threading
import time as _wall
import weakref
from collections.abc import Callable
from typing import Any

from fleetsim.errors import GraphError, MessageError, TransportError
from fleetsim.transport.graphinfo import merge_snapshots
from fleetsim.transport.keys import (
    Keys,
    attachment,
    cdr_encoding,
    default_endpoint,
    no_simulation,
    open_session,
    parse_attachment,
    type_of_encoding,
)
from fleetsim.transport.paramserver import request_param
from fleetsim.transport.services import call_remote_service

_log = logging.getLogger("fleetsim.transport")


def _reader(sub: Any, handle: Callable[[Any], None], name: str) -> threading.Thread:
    """A daemon thread that hands each sample of subscriber ``sub`` (a zenoh channel) to
    ``handle``, until the subscriber is undeclared."""

    def run() -> None:
        try:
            for sample in sub:  # ends when the subscriber is undeclared
                try:
                    handle(sample)
                except Exception:  # a failing callback must not stop the subscription
                    _log.exception("callback of the subscription to %s failed", name)
        except Exception:  # the session closed under the reader (interpreter exit)
            return

    thread = threading.Thread(target=run, name=f"fleetsim-client {name}", daemon=True)
    thread.start()
    return thread


class Received:
    """One message a tool received: the decoded message and where it came from."""

    __slots__ = ("msg", "node", "topic", "type", "wall", "zid")

    def __init__(self, topic: str, type_: str, msg: Any, zid: str, node: str) -> None:
        self.topic, self.type, self.msg, self.zid, self.node = topic, type_, msg, zid, node
        self.wall = _wall.monotonic()


class ToolPublisher:
    """Publishes one type on one topic from a tool."""

    def __init__(self, client: SimulationClient, name: str, msg_type: type) -> None:
        import zenoh

        self.name = name
        self.type = msg_type
        self._att = attachment(client.zid, "/fleetsim_cli")
        self._pub = client.session.declare_publisher(
            client.keys.topic(name),
            encoding=zenoh.Encoding(cdr_encoding(msg_type.__msgtype__)),
            reliability=zenoh.Reliability.RELIABLE,
        )
        client._pubs.add(self)

    def wait_for_subscribers(self, timeout: float) -> bool:
        """True once some process subscribes this topic (waits at most ``timeout`` s)."""
        deadline = _wall.monotonic() + timeout
        while self._pub is not None and not self._pub.matching_status.matching:
            if _wall.monotonic() > deadline:
                return False
            _wall.sleep(0.01)
        return True

    def publish(self, msg: Any) -> None:
        from fleetsim.msgs import serialize
        from fleetsim.msgs.registry import message_class

        if self._pub is None:
            raise GraphError(f"publisher of {self.name} is closed")
        if message_class(msg) is not self.type:
            raise GraphError(f"{self.name} carries {self.type.__msgtype__}, not {type(msg)}")
        self._pub.put(serialize(msg), attachment=self._att)

    def close(self) -> None:
        """Undeclare the publisher (idempotent)."""
        if self._pub is not None:
            self._pub.undeclare()
            self._pub = None


#: wall seconds a closing client waits for each reader thread to finish its last callback
READER_JOIN_TIMEOUT = 2.0


def _join_readers(readers: list[threading.Thread]) -> None:
    """Wait for undeclared subscriptions' reader threads to leave Python.

    A reader woken by the undeclare re-enters the interpreter; at exit, one that does so after
    Python has begun finalising is ended by a forced unwind through zenoh's Rust frames, which
    aborts the process ("FATAL: exception not rethrown", SIGABRT: a script that never closed
    its client, seen once in a loaded suite). Joined before finalisation, they end cleanly."""
    me = threading.current_thread()
    for thread in readers:
        if thread is not me:  # a callback closing its own client cannot wait for itself
            thread.join(READER_JOIN_TIMEOUT)
    readers[:] = [t for t in readers if t.is_alive()]


def _close_session(
    session: Any, subs: list, pubs: weakref.WeakSet, readers: list[threading.Thread]
) -> None:
    """Undeclare a client's subscribers and publishers, wait for their readers, and close its
    session.

    Holds no reference to the client, so that `weakref.finalize` (which calls it once) can
    call it at exit."""
    for pub in list(pubs):
        pub.close()
    for sub in subs:
        sub.undeclare()
    subs.clear()
    _join_readers(readers)
    session.close()


class ToolSubscription:
    """One subscription of a tool; ``close()`` ends it (the client's ``close`` ends them all)."""

    def __init__(self, client: SimulationClient, name: str, sub: Any) -> None:
        self.name = name
        self._client = client
        self._sub = sub

    def close(self) -> None:
        """Undeclare the subscription (idempotent); its reader thread then ends."""
        subs = self._client._subs
        if self._sub in subs:
            subs.remove(self._sub)
            self._sub.undeclare()


class SimulationClient:
    """A connection from a tool to a running simulation.

    Parameters
    ----------
    connect : the simulation's endpoint; default ``$FLEETSIM_ZENOH`` or ``tcp/127.0.0.1:7447``.
    domain : key domain (default ``$FLEETSIM_DOMAIN`` or ``0``).
    timeout : seconds to wait for any answer (connection, graph, services, parameters).
    """

    def __init__(
        self, connect: str | None = None, domain: str | int | None = None, timeout: float = 2.0
    ) -> None:
        self.endpoint = connect or default_endpoint()
        self.keys = Keys(domain)
        self.timeout = timeout
        self._subs: list = []
        self._readers: list[threading.Thread] = []
        self._pubs: weakref.WeakSet[ToolPublisher] = weakref.WeakSet()
        self.session = open_session("client", connect=[self.endpoint])
        # closes the session at garbage collection or interpreter exit if close() was not called
        self._finalizer = weakref.finalize(
            self, _close_session, self.session, self._subs, self._pubs, self._readers
        )
        self.zid = str(self.session.zid())
        alive = [
            r for r in self.session.liveliness().get(self.keys.alive("*"), timeout=timeout) if r.ok
        ]
        if not alive:
            self.close()
            raise TransportError(no_simulation(self.endpoint))

    # -- graph ------------------------------------------------------------------------------
    def snapshots(self) -> list[dict]:
        """Each process's graph snapshot (the simulation first)."""
        out = []
        for reply in self.session.get(self.keys.graph("*"), timeout=self.timeout):
            if reply.ok is not None:
                try:
                    out.append(json.loads(reply.ok.payload.to_bytes().decode()))
                except ValueError:
                    continue
        if not out:
            raise TransportError(no_simulation(self.endpoint))
        return sorted(out, key=lambda s: (s.get("role") != "simulation", s.get("zid", "")))

    def graph(self) -> dict:
        """Nodes, topics (types, publishers, subscribers) and services of every process."""
        return merge_snapshots(self.snapshots())

    def sim_time(self) -> float:
        """The simulation's current sim time, seconds."""
        snaps = self.snapshots()
        return float(snaps[0].get("time", 0.0))

    def topic_type(self, name: str) -> str | None:
        info = self.graph()["topics"].get(name)
        return info["type"] if info is not None else None

    def check_type(self, name: str, msg_type: type) -> None:
        """Raise `GraphError` when ``name`` already carries a different type."""
        have = self.topic_type(name)
        if have is not None and msg_type.__msgtype__ not in have.split(" | "):
            raise GraphError(
                f"topic {name} carries {have}, not {msg_type.__msgtype__}; publish that type "
                "or use another topic"
            )

    # -- topics -----------------------------------------------------------------------------
    def subscribe(
        self, name: str, callback: Callable[[Received], None], latched: bool = True
    ) -> ToolSubscription:
        """Call ``callback`` (on a daemon thread, one per subscription) with every message on
        ``name``.

        With ``latched``, a latched topic's last message is fetched first. Messages whose type is
        unknown here are skipped with one `MessageError` passed to ``callback`` as ``msg``.
        """
        from fleetsim.msgs import deserialize, get_type

        def decode(payload: bytes, encoding: object, att: object) -> None:
            tname = type_of_encoding(encoding)
            zid, node = parse_attachment(att)
            try:
                msg: Any = deserialize(payload, get_type(tname))
            except MessageError as e:
                msg = e
            callback(Received(name, tname, msg, zid, node))

        sub = self.session.declare_subscriber(self.keys.topic(name))
        self._subs.append(sub)
        self._readers[:] = [t for t in self._readers if t.is_alive()]  # closed ones' are done
        self._readers.append(
            _reader(sub, lambda s: decode(s.payload.to_bytes(), s.encoding, s.attachment), name)
        )
        if latched:
            for reply in self.session.get(self.keys.latched_any(name), timeout=self.timeout):
                if reply.ok is not None:
                    ok = reply.ok
                    decode(ok.payload.to_bytes(), ok.encoding, ok.attachment)
        return ToolSubscription(self, name, sub)

    def publisher(self, name: str, msg_type: type) -> ToolPublisher:
        self.check_type(name, msg_type)
        return ToolPublisher(self, name, msg_type)

    # -- services and parameters --------------------------------------------------------------
    def service_type(self, name: str) -> str:
        services = self.graph()["services"]
        info = services.get(name)
        if info is None:
            from fleetsim.errors import did_you_mean

            raise GraphError(f"service {name} is not available{did_you_mean(name, services)}")
        return info["type"]

    def call_service(self, name: str, request: Any, srv_type: Any, timeout: float = 10.0) -> Any:
        return call_remote_service(self.session, self.keys, name, srv_type, request, timeout)

    def param(self, op: str, name: str = "/", value: Any = None) -> Any:
        """A parameter server request (``get``, ``set``, ``list``, ``dump``, ``delete``)."""
        return request_param(self.session, self.keys, op, name, value, self.timeout)

    def close(self) -> None:
        """Close the connection (idempotent; also done at interpreter exit)."""
        self._finalizer()

    @property
    def closed(self) -> bool:
        return not self._finalizer.alive

    def __enter__(self) -> SimulationClient:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
