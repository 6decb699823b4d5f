"""Graph snapshots and how tools merge them."""

from fleetsim.msgs import std_msgs, std_srvs
from fleetsim.runtime import Node, Runtime
from fleetsim.transport.graphinfo import NO_NODE, graph_snapshot, merge_snapshots


def _graph():
    rt = Runtime()
    a = Node(rt, "a", "/lizi1")
    a.create_publisher(std_msgs.String, "chatter", latch=True)
    b = Node(rt, "b")
    b.create_subscription(std_msgs.String, "/lizi1/chatter", lambda m: None)
    b.create_service(std_srvs.Empty, "reset", lambda r: None)
    plumbing = rt.graph.subscribe("/lizi1/chatter", std_msgs.String, lambda m: None)
    anon = rt.graph.advertise("/clock_like", std_msgs.String)
    return rt, plumbing, anon


def test_snapshot_lists_nodes_topics_services_without_plumbing():
    rt, plumbing, _ = _graph()
    snap = graph_snapshot(rt.graph, {plumbing}, "z1", "simulation", 1.5)
    assert snap["nodes"] == ["/b", "/lizi1/a"]
    assert snap["topics"]["/lizi1/chatter"] == {
        "type": "std_msgs/msg/String",
        "latched": True,
        "publishers": ["/lizi1/a"],
        "subscribers": ["/b"],
    }
    assert snap["topics"]["/clock_like"]["publishers"] == [NO_NODE]
    assert snap["services"] == {"/reset": {"type": "std_srvs/srv/Empty", "node": "/b"}}
    assert snap["zid"] == "z1" and snap["time"] == 1.5


def test_only_plumbing_means_no_topic():
    rt = Runtime()
    sub = rt.graph.subscribe("/x", std_msgs.String, lambda m: None)
    assert graph_snapshot(rt.graph, {sub}, "z", "node", 0.0)["topics"] == {}


def test_merge_unions_processes_and_flags_conflicting_types():
    s1 = {
        "zid": "b",
        "role": "node",
        "nodes": ["/n2"],
        "topics": {"/t": {"type": "A", "publishers": ["/n2"], "subscribers": []}},
        "services": {"/s": {"type": "S", "node": "/n2"}},
    }
    s2 = {
        "zid": "a",
        "role": "simulation",
        "nodes": ["/n1"],
        "topics": {"/t": {"type": "B", "publishers": [], "subscribers": ["/n1"], "latched": True}},
        "services": {},
    }
    m = merge_snapshots([s1, s2])
    assert [p["zid"] for p in m["processes"]] == ["a", "b"]
    assert m["nodes"] == ["/n1", "/n2"]
    assert m["topics"]["/t"] == {
        "type": "A | B",
        "latched": True,
        "publishers": ["/n2"],
        "subscribers": ["/n1"],
    }
    assert m["services"] == {"/s": {"type": "S", "node": "/n2"}}


def test_merge_orders_a_process_that_has_not_named_itself_last():
    named = {"zid": "b", "role": "node", "nodes": [], "topics": {}, "services": {}}
    m = merge_snapshots([{"time": 0.5, "endpoints": ["tcp/127.0.0.1:1"]}, named])
    assert [p["zid"] for p in m["processes"]] == [None, "b"]
