"""Topics across processes: the topic half of `ZenohBridge` (a mixin over its session and inbox).

Outgoing, per topic with a local publisher: a zenoh publisher with a matching listener; while a
remote subscriber matches, a forwarding subscription in the local graph puts each message as
CDR, its attachment naming the node that published it (the subscription is made
``with_publisher``). A latched topic also answers ``latched/<zid>/<name>`` with the last
message of each of its latched publishers, as a late ROS subscriber gets one from each.

Incoming, per topic with a local subscription: a zenoh subscriber for remote origins only (so
nothing echoes) whose samples go to the inbox; `_deliver` (simulation thread) decodes them into
the local subscriptions' queues exactly as `Publisher.publish` would, skipping the bridge's own
forwarding subscription. A new local subscription also asks the other processes for the
topic's latched message, which only that subscription receives.
"""

from __future__ import annotations

import logging
from typing import Any

from fleetsim.errors import MessageError
from fleetsim.transport.keys import attachment, cdr_encoding, type_of_encoding

_log = logging.getLogger("fleetsim.transport")


def _type_name(tp: Any) -> str:
    return getattr(tp, "__msgtype__", None) or getattr(tp, "name", None) or repr(tp)


class _Outgoing:
    __slots__ = ("attach", "forward", "latched_q", "listener", "zpub")

    def __init__(self, zpub: Any, listener: Any) -> None:
        self.zpub = zpub
        self.listener = listener
        self.forward: Any = None
        self.latched_q: Any = None
        self.attach: dict[Any, bytes] = {}  # publisher -> its attachment


class TopicBridging:
    """The topic half of `ZenohBridge`."""

    def _local_publishers(self, name: str) -> list:
        topic = self.graph.topics.get(name)
        return [p for p in topic.publishers if p not in self._own] if topic is not None else []

    def _export_topic(self, name: str, pub: Any) -> None:
        out = self._out.get(name)
        if out is None:
            zpub = self.session.declare_publisher(
                self.keys.topic(name),
                encoding=self._zenoh.Encoding(cdr_encoding(_type_name(pub.msg_type))),
            )
            listener = zpub.declare_matching_listener(
                lambda status, n=name: self._inbox.put(("match", n, status.matching))
            )
            out = self._out[name] = _Outgoing(zpub, listener)
            if zpub.matching_status.matching:
                self._set_forwarding(name, True)
        if pub.latch and out.latched_q is None:
            out.latched_q = self.session.declare_queryable(
                self.keys.latched(self.zid, name), lambda q, n=name: self._reply_latched(n, q)
            )

    def _unexport_topic(self, name: str) -> None:
        out = self._out.get(name)
        if out is None:
            return
        if self._local_publishers(name):
            out.attach.clear()  # forget the attachments of publishers that are gone
            return
        del self._out[name]
        self._set_forwarding_off(out)
        for ent in (out.latched_q, out.listener, out.zpub):
            if ent is not None:
                ent.undeclare()

    def _set_forwarding(self, name: str, matching: bool) -> None:
        out = self._out.get(name)
        if out is None:
            return
        if not matching:
            self._set_forwarding_off(out)
            return
        if out.forward is not None:
            return
        topic = self.graph.topics[name]
        zpub = out.zpub
        serialize = self._serialize
        attach = out.attach

        def forward(item: tuple[Any, Any]) -> None:
            msg, pub = item
            data = serialize(name, msg)
            if data is None:
                return
            att = attach.get(pub)
            if att is None:
                att = attach[pub] = self._attachment_of(pub)
            zpub.put(data, attachment=att)

        with self._own_objects():
            sub = self.graph.subscribe(name, topic.type, forward, queue_size=0, with_publisher=True)
        sub.queue.clear()  # a latched message reaches remote subscribers through its query
        self._own.add(sub)
        out.forward = sub

    def _set_forwarding_off(self, out: _Outgoing) -> None:
        if out.forward is not None:
            self._own.discard(out.forward)
            with self._own_objects():
                out.forward.destroy()
            out.forward = None

    def _serialize(self, name: str, msg: Any) -> bytes | None:
        from fleetsim.msgs import serialize

        try:
            return serialize(msg)
        except MessageError as e:
            self._warn_once(f"ser:{name}", "not sending a message on %s: %s", name, e)
            return None

    def _attachment_of(self, pub: Any) -> bytes:
        """The attachment naming ``pub``'s node (empty for a message handed in by `deliver`)."""
        node = getattr(pub, "node", None)
        return attachment(self.zid, node.full_name if node is not None else "")

    def _reply_latched(self, name: str, query: Any) -> None:
        """Answer a latched-topic query with each latched publisher's last message, each under
        its own key and naming its node (zenoh thread: only reads the publishers' messages)."""
        topic = self.graph.topics.get(name)
        latched = [
            pub
            for pub in (list(topic.publishers) if topic is not None else ())
            if pub.latch and pub.last is not None and pub not in self._own
        ]
        for k, pub in enumerate(latched):
            last = pub.last
            data = self._serialize(name, last)
            if data is not None:
                query.reply(
                    self.keys.latched_reply(self.zid, k, name),
                    data,
                    encoding=self._zenoh.Encoding(cdr_encoding(_type_name(type(last)))),
                    attachment=self._attachment_of(pub),
                )

    def _import_topic(self, name: str, sub: Any) -> None:
        if name not in self._in:
            self._in[name] = self.session.declare_subscriber(
                self.keys.topic(name),
                lambda s, n=name: self._inbox.put(
                    ("msg", n, s.payload.to_bytes(), str(s.encoding), None)
                ),
                allowed_origin=self._zenoh.Locality.REMOTE,
            )

        def on_latched(reply: Any, sub: Any = sub) -> None:
            ok = reply.ok
            if ok is not None:
                self._inbox.put(("msg", name, ok.payload.to_bytes(), str(ok.encoding), sub))

        self.session.get(
            self.keys.latched_any(name),
            on_latched,
            timeout=self.service_timeout,
            allowed_destination=self._zenoh.Locality.REMOTE,
        )

    def _unimport_topic(self, name: str) -> None:
        topic = self.graph.topics.get(name)
        if topic is not None and any(s not in self._own for s in topic.subscriptions):
            return
        zsub = self._in.pop(name, None)
        if zsub is not None:
            zsub.undeclare()

    def _deliver(self, name: str, data: bytes, encoding: str, only: Any) -> None:
        from fleetsim.msgs import deserialize

        topic = self.graph.topics.get(name)
        if topic is None:
            return
        mine = _type_name(topic.type)
        theirs = type_of_encoding(encoding)
        if theirs and theirs != mine:
            self._warn_once(
                f"type:{name}:{theirs}",
                "dropping %s messages on %s from another process: this graph's topic carries %s",
                theirs,
                name,
                mine,
            )
            return
        try:
            msg = deserialize(data, topic.type)
        except MessageError as e:
            self._warn_once(f"decode:{name}", "dropping a message on %s: %s", name, e)
            return
        targets = topic.subscriptions if only is None else [only]
        own = self._own
        for sub in targets:
            if sub in own or sub.topic is not topic or sub not in topic.subscriptions:
                continue
            self.graph.deliver(sub, msg)
