"""What one process tells others about its graph, and how tools merge several processes.

A snapshot is a JSON-able dict::

    {"zid": "...", "pid": 123, "role": "simulation", "time": 12.5,
     "nodes": ["/lizi1/move_base", ...],
     "topics": {"/lizi1/scan": {"type": "sensor_msgs/msg/LaserScan", "latched": false,
                                "publishers": ["/lizi1/laser"], "subscribers": [...]}},
     "services": {"/static_map": {"type": "nav_msgs/srv/GetMap", "node": "/map_server"}}}

The bridge's own subscriptions and proxy services are left out: they are plumbing, not nodes.
"""

from __future__ import annotations

import os
from collections.abc import Container, Iterable
from typing import Any

#: how an endpoint with no owning node is listed (the runtime's tf buffer, the bridge's clock)
NO_NODE = "(runtime)"


def _type_name(tp: Any) -> str:
    return getattr(tp, "__msgtype__", None) or getattr(tp, "name", None) or repr(tp)


def _node_name(obj: Any) -> str:
    node = getattr(obj, "node", None)
    return node.full_name if node is not None else NO_NODE


def graph_snapshot(graph: Any, own: Container, zid: str, role: str, now: float) -> dict:
    """Describe ``graph`` (a runtime `Graph`), leaving out the objects in ``own``."""
    topics = {}
    for name, topic in sorted(graph.topics.items()):
        pubs = [p for p in topic.publishers if p not in own]
        subs = [s for s in topic.subscriptions if s not in own]
        if not pubs and not subs:
            continue
        topics[name] = {
            "type": _type_name(topic.type),
            "latched": any(p.latch for p in pubs),
            "publishers": sorted({_node_name(p) for p in pubs}),
            "subscribers": sorted({_node_name(s) for s in subs}),
        }
    services = {
        name: {"type": _type_name(srv.srv_type), "node": _node_name(srv)}
        for name, srv in sorted(graph.services.items())
        if srv not in own
    }
    return {
        "zid": zid,
        "pid": os.getpid(),
        "role": role,
        "time": now,
        "nodes": sorted(graph.nodes),
        "topics": topics,
        "services": services,
    }


def merge_snapshots(snapshots: Iterable[dict]) -> dict:
    """One view of several processes: union of nodes, topics (publishers and subscribers from
    every process) and services. Conflicting topic types are kept as ``"A | B"``."""
    nodes: set[str] = set()
    topics: dict[str, dict] = {}
    services: dict[str, dict] = {}
    processes = []
    for snap in snapshots:
        processes.append({k: snap.get(k) for k in ("zid", "pid", "role", "time")})
        nodes.update(snap.get("nodes", ()))
        for name, t in snap.get("topics", {}).items():
            have = topics.setdefault(
                name, {"type": t["type"], "latched": False, "publishers": [], "subscribers": []}
            )
            if t["type"] not in have["type"].split(" | "):
                have["type"] = f"{have['type']} | {t['type']}"
            have["latched"] = have["latched"] or t.get("latched", False)
            have["publishers"] = sorted(set(have["publishers"]) | set(t["publishers"]))
            have["subscribers"] = sorted(set(have["subscribers"]) | set(t["subscribers"]))
        for name, s in snap.get("services", {}).items():
            services.setdefault(name, s)
    return {
        "processes": sorted(
            processes, key=lambda p: (p["role"] != "simulation", str(p["zid"] or ""))
        ),
        "nodes": sorted(nodes),
        "topics": dict(sorted(topics.items())),
        "services": dict(sorted(services.items())),
    }
