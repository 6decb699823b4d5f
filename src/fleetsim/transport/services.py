"""Services across processes, and what a bridge knows of the other processes' graphs.

Exported: each local service answers zenoh queries on ``service/<name>``; the query carries
the request as CDR (its type in the encoding) and gets the response as CDR, or an error reply
with the one-line reason. Queries are answered on the simulation thread, in `pump`.

Imported: the bridge watches the other processes (liveliness tokens, ``graph_changed`` puts),
fetches their graph snapshots and advertises a local proxy for every remote service this graph
lacks, so ``create_client(...).call(req)`` in a node works whichever process serves it. A proxy
call blocks the calling callback until the reply (at most ``service_timeout`` seconds), as a
ROS 1 service call does.
"""

from __future__ import annotations

import json
import logging
from typing import Any

from fleetsim.errors import FleetsimError, MessageError, ServiceError
from fleetsim.transport.keys import Keys, cdr_encoding, type_of_encoding

_log = logging.getLogger("fleetsim.transport")


def _type_name(tp: Any) -> str:
    return getattr(tp, "__msgtype__", None) or getattr(tp, "name", None) or repr(tp)


def call_remote_service(
    session: Any, keys: Keys, name: str, srv_type: Any, request: Any, timeout: float
) -> Any:
    """Call service ``name`` over zenoh and return the decoded response.

    Raises `ServiceError` with the server's reason, or when nothing answers in ``timeout`` s.
    """
    import zenoh

    from fleetsim.msgs import deserialize, serialize

    if request is None:
        request = srv_type.Request()
    replies = session.get(
        keys.service(name),
        payload=serialize(request),
        encoding=zenoh.Encoding(cdr_encoding(_type_name(srv_type.Request))),
        timeout=timeout,
    )
    for reply in replies:
        if reply.ok is not None:
            try:
                return deserialize(reply.ok.payload.to_bytes(), srv_type.Response)
            except MessageError as e:
                raise ServiceError(f"service {name}: the response does not decode: {e}") from e
        raise ServiceError(reply.err.payload.to_bytes().decode(errors="replace"))
    raise ServiceError(
        f"service {name} did not answer within {timeout:g} s (no server, or the simulation is "
        "paused)"
    )


class ServiceBridging:
    """The service half of `ZenohBridge` (a mixin: it uses the bridge's session and inbox)."""

    def _init_services(self, proxy_services: bool) -> None:
        self._proxy_services = proxy_services
        self._exported: dict[str, Any] = {}
        self._proxies: dict[str, Any] = {}
        self._remote: dict[str, dict] = {}
        self._watch: list = []
        self._master_lost = False

    # -- export ---------------------------------------------------------------------------
    def _export_service(self, name: str, srv: Any) -> None:
        old = self._exported.pop(name, None)
        if old is not None:
            old.undeclare()
        self._exported[name] = self.session.declare_queryable(
            self.keys.service(name), lambda q, n=name: self._inbox.put(("query", n, q))
        )

    def _unexport_service(self, name: str, srv: Any) -> None:
        q = self._exported.pop(name, None)
        if q is not None:
            q.undeclare()

    def _answer_service(self, name: str, query: Any) -> None:
        from fleetsim.msgs import deserialize, serialize

        try:
            srv = self.graph.services.get(name)
            if srv is None or srv in self._own:
                raise ServiceError(f"service {name} is not available in this process any more")
            req_cls = srv.srv_type.Request
            theirs = type_of_encoding(query.encoding) if query.encoding is not None else ""
            if theirs and theirs != _type_name(req_cls):
                raise ServiceError(
                    f"service {name} takes {_type_name(req_cls)}, called with {theirs}"
                )
            data = query.payload.to_bytes() if query.payload is not None else b""
            request = deserialize(data, req_cls) if data else req_cls()
            response = self.graph.call_service(name, None, request)
            query.reply(
                query.key_expr,
                serialize(response),
                encoding=self._zenoh.Encoding(cdr_encoding(_type_name(type(response)))),
            )
        except FleetsimError as e:
            query.reply_err(str(e))
        finally:
            query.drop()

    # -- remote processes -------------------------------------------------------------------
    def _declare_remote_watch(self) -> None:
        zenoh, s, k = self._zenoh, self.session, self.keys
        #: other bridges' processes alive (simulations, ``fleetsim node run``), by zid
        self.alive_peers: set[str] = set()

        def on_alive(sample: Any) -> None:
            zid = k.last_chunk(sample.key_expr)
            if zid == self.zid:
                return
            if sample.kind == zenoh.SampleKind.DELETE:
                if zid == getattr(self, "_clock_origin", None):
                    self._master_lost = True
                self.alive_peers.discard(zid)
                self._inbox.put(("gone", zid))
            else:
                self.alive_peers.add(zid)
                self._inbox.put(("want_graph", zid))

        self._watch = [
            s.liveliness().declare_subscriber(k.alive("*"), on_alive, history=True),
            s.declare_subscriber(
                k.graph_changed("*"),
                lambda smp: self._inbox.put(("want_graph", k.last_chunk(smp.key_expr))),
                allowed_origin=zenoh.Locality.REMOTE,
            ),
        ]

    def _handle_remote(self, item: tuple) -> None:
        kind, zid = item[0], item[1]
        if kind == "want_graph":

            def on_reply(reply: Any, zid: str = zid) -> None:
                if reply.ok is not None:
                    self._inbox.put(("graph", zid, reply.ok.payload.to_bytes()))

            self.session.get(self.keys.graph(zid), on_reply, timeout=self.service_timeout)
        elif kind == "graph":
            try:
                self._remote[zid] = json.loads(item[2].decode())
            except ValueError:
                return
            self._sync_proxies()
        elif kind == "gone":
            self._remote.pop(zid, None)
            self._sync_proxies()
        else:
            raise FleetsimError(f"bridge: unknown inbox item {kind!r}")

    @property
    def remote_graphs(self) -> dict[str, dict]:
        """The latest graph snapshot of every other process, by zenoh id."""
        return dict(self._remote)

    def _sync_proxies(self) -> None:
        if not self._proxy_services:
            return
        from fleetsim.msgs import get_srv_type

        wanted: dict[str, str] = {}
        for snap in self._remote.values():
            for name, info in snap.get("services", {}).items():
                wanted.setdefault(name, info["type"])
        for name in [n for n in self._proxies if n not in wanted]:
            proxy = self._proxies.pop(name)
            self.graph.unadvertise_service(proxy)
            self._own.discard(proxy)
        for name, tname in wanted.items():
            if name in self._proxies or name in self.graph.services:
                continue
            try:
                srv_type = get_srv_type(tname)
            except MessageError as e:
                self._warn_once(f"srv:{name}", "cannot call remote service %s: %s", name, e)
                continue

            def call(request: Any, name: str = name, srv_type: Any = srv_type) -> Any:
                return call_remote_service(
                    self.session, self.keys, name, srv_type, request, self.service_timeout
                )

            with self._own_objects():
                proxy = self.graph.advertise_service(name, srv_type, call)
            self._own.add(proxy)
            self._proxies[name] = proxy

    def _close_services(self) -> None:
        for proxy in self._proxies.values():
            self.graph.unadvertise_service(proxy)
        self._proxies.clear()
        self._exported.clear()
        self._watch.clear()
