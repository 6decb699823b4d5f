"""Zenoh key expressions, session configuration and the small wire conventions of the bridge.

Every fleetsim key lives under ``fleetsim/<domain>/``:

========================================  ==================================================
``topic/<name>``                          one topic's messages, CDR, type in the encoding
``latched/<zid>/<name>``                  queryable: the last message of each latched
                                          publisher of a topic, one reply per publisher on
                                          ``latched/<zid>.<k>/<name>`` (distinct keys, so
                                          that zenoh does not consolidate them into one)
``service/<name>``                        queryable: a service (request and response as CDR)
``param``                                 queryable: the parameter server (JSON requests)
``graph/<zid>``                           queryable: one process's nodes, topics, services
``graph_changed/<zid>``                   a put whenever that process's graph changed
``alive/<zid>``                           liveliness token of one process
========================================  ==================================================

``<name>`` is the resolved ROS name without its leading slash (``lizi1/move_base/goal``).
A sample's encoding is ``application/cdr;<ROS 2 type>`` and its attachment
``<origin zid>;<publishing node>``.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence

from fleetsim.errors import TransportError

#: where a simulation listens unless told otherwise, and where tools connect
DEFAULT_ENDPOINT = "tcp/127.0.0.1:7447"
#: environment variable naming the endpoint tools connect to (and a simulation listens on)
ENDPOINT_ENV = "FLEETSIM_ZENOH"
#: environment variable naming the key domain (lets several simulations share a network)
DOMAIN_ENV = "FLEETSIM_DOMAIN"
CDR_ENCODING = "application/cdr"
JSON_ENCODING = "application/json"


def default_endpoint() -> str:
    """The endpoint from ``$FLEETSIM_ZENOH``, else ``tcp/127.0.0.1:7447``."""
    return os.environ.get(ENDPOINT_ENV) or DEFAULT_ENDPOINT


def default_domain() -> str:
    return os.environ.get(DOMAIN_ENV) or "0"


def no_simulation(endpoint: str) -> str:
    """The one line every tool prints when nothing answers at ``endpoint``."""
    return f"no simulation running at {endpoint} (start one with `fleetsim launch ...`)"


class Keys:
    """Key expressions of one domain."""

    def __init__(self, domain: str | int | None = None) -> None:
        d = str(default_domain() if domain is None else domain)
        if not d or any(c in d for c in "/*$?#") or d.strip() != d:
            raise TransportError(
                f"zenoh domain {d!r} is not a valid key chunk (no '/', '*', '$', '?', '#')"
            )
        self.domain = d
        self.root = f"fleetsim/{d}"

    @staticmethod
    def chunk(name: str) -> str:
        """A resolved ROS name as key chunks (``/lizi1/scan`` -> ``lizi1/scan``)."""
        return name.strip("/")

    @staticmethod
    def name_of(chunks: str) -> str:
        return "/" + chunks.strip("/")

    def topic(self, name: str) -> str:
        return f"{self.root}/topic/{self.chunk(name)}"

    def topic_name(self, key: str) -> str:
        """The ROS name of a ``topic/<name>`` key."""
        return self.name_of(str(key)[len(self.root) + len("/topic/") :])

    def latched(self, zid: str, name: str) -> str:
        return f"{self.root}/latched/{zid}/{self.chunk(name)}"

    def latched_reply(self, zid: str, k: int, name: str) -> str:
        """The key of the ``k``-th latched publisher's reply to a ``latched_any`` query."""
        return f"{self.root}/latched/{zid}.{k}/{self.chunk(name)}"

    def latched_any(self, name: str) -> str:
        return f"{self.root}/latched/*/{self.chunk(name)}"

    def service(self, name: str) -> str:
        return f"{self.root}/service/{self.chunk(name)}"

    @property
    def param(self) -> str:
        return f"{self.root}/param"

    def graph(self, zid: str = "*") -> str:
        return f"{self.root}/graph/{zid}"

    def graph_changed(self, zid: str = "*") -> str:
        return f"{self.root}/graph_changed/{zid}"

    def alive(self, zid: str = "*") -> str:
        return f"{self.root}/alive/{zid}"

    @staticmethod
    def last_chunk(key: object) -> str:
        return str(key).rsplit("/", 1)[-1]


def cdr_encoding(typename: str) -> str:
    return f"{CDR_ENCODING};{typename}"


def type_of_encoding(encoding: object) -> str:
    """The ROS 2 type name carried in a sample's encoding (``""`` when there is none)."""
    text = str(encoding)
    return text.split(";", 1)[1] if ";" in text else ""


def attachment(zid: str, node: str) -> bytes:
    return f"{zid};{node}".encode()


def parse_attachment(att: object) -> tuple[str, str]:
    """``(origin zid, publishing node)`` of a sample's attachment (empty strings if none)."""
    if att is None:
        return "", ""
    text = att.to_bytes().decode(errors="replace") if hasattr(att, "to_bytes") else str(att)
    zid, _, node = text.partition(";")
    return zid, node


def _check_endpoints(endpoints: Sequence[str], what: str) -> list[str]:
    out = []
    for ep in endpoints:
        ep = str(ep).strip()
        proto, sep, addr = ep.partition("/")
        if (
            not sep
            or proto not in ("tcp", "udp", "tls", "quic", "ws", "unixsock-stream")
            or not addr
        ):
            raise TransportError(
                f"{what} endpoint {ep!r} is not a zenoh locator; write it like '{DEFAULT_ENDPOINT}'"
            )
        out.append(ep)
    return out


def session_config(mode: str, listen: Sequence[str] = (), connect: Sequence[str] = ()):
    """A ``zenoh.Config`` for a peer (a simulation) or a client (a tool or remote node).

    Multicast scouting is off: sessions find each other only through the given endpoints, so
    tests and several simulations on one machine never join by accident.
    """
    import zenoh

    if mode not in ("peer", "client"):
        raise TransportError(f"zenoh mode must be 'peer' or 'client', got {mode!r}")
    listen = _check_endpoints(listen, "listen")
    connect = _check_endpoints(connect, "connect")
    if mode == "client" and not connect:
        raise TransportError("a zenoh client needs an endpoint to connect to (--connect)")
    cfg = zenoh.Config()
    cfg.insert_json5("mode", json.dumps(mode))
    cfg.insert_json5("listen/endpoints", json.dumps(listen))
    cfg.insert_json5("connect/endpoints", json.dumps(connect))
    cfg.insert_json5("scouting/multicast/enabled", "false")
    return cfg


def open_session(mode: str, listen: Sequence[str] = (), connect: Sequence[str] = ()):
    """Open a zenoh session; failures become a `TransportError` naming the endpoint."""
    import zenoh

    cfg = session_config(mode, listen, connect)
    try:
        return zenoh.open(cfg)
    except zenoh.ZError as e:
        if mode == "client":
            raise TransportError(no_simulation(", ".join(connect))) from None
        where = ", ".join(listen) or ", ".join(connect)
        raise TransportError(
            f"cannot open a zenoh session listening on {where}: {str(e).split(' at ')[0]} "
            "(is another simulation using that port? pick another with --listen)"
        ) from None
