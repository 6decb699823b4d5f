"""Topics, latching, queue sizes, services and the deterministic scheduler."""

from dataclasses import dataclass, field

import pytest

from fleetsim.errors import FleetsimError, GraphError, ServiceError
from fleetsim.runtime import Node, Runtime


@dataclass(slots=True)
class Num:
    __msgtype__ = "test_msgs/msg/Num"
    data: int = 0


@dataclass(slots=True)
class Text:
    __msgtype__ = "test_msgs/msg/Text"
    data: str = ""


@dataclass(slots=True)
class AddRequest:
    a: int = 0
    b: int = 0


@dataclass(slots=True)
class AddResponse:
    sum: int = 0


@dataclass(frozen=True)
class AddTwo:
    name: str = "test_msgs/srv/AddTwo"
    Request: type = field(default=AddRequest)
    Response: type = field(default=AddResponse)


ADD = AddTwo()


def test_publish_subscribe_in_namespaces():
    rt = Runtime()
    a = Node(rt, "talker", "/lizi1")
    b = Node(rt, "listener", "/lizi2")
    got = []
    pub = a.create_publisher(Num, "chatter")
    b.create_subscription(Num, "/lizi1/chatter", lambda m: got.append(m.data))
    b.create_subscription(Num, "chatter", lambda m: got.append(-m.data))  # /lizi2/chatter
    pub.publish(Num(3))
    rt.spin_once()
    assert got == [3]
    assert sorted(rt.graph.topics) == ["/lizi1/chatter", "/lizi2/chatter"]


def test_topic_type_conflicts_are_errors():
    rt = Runtime()
    n = Node(rt, "n")
    n.create_publisher(Num, "x")
    with pytest.raises(GraphError, match=r"topic /x already carries test_msgs/msg/Num.*Text"):
        n.create_subscription(Text, "x", print)
    # the node holding the topic is named too, not only the one that came second
    Node(rt, "slam").create_subscription(Num, "odom", print)
    with pytest.raises(
        GraphError,
        match=r"topic /odom already carries test_msgs/msg/Num \(subscriber in /slam\); publisher "
        r"in /n asked for test_msgs/msg/Text; check the remaps of both",
    ):
        n.create_publisher(Text, "odom")
    pub = n.create_publisher(Num, "x")
    with pytest.raises(GraphError, match="cannot publish test_msgs/msg/Text"):
        pub.publish(Text())


def test_queue_size_drops_the_oldest():
    rt = Runtime()
    n = Node(rt, "n")
    got = []
    pub = n.create_publisher(Num, "x")
    n.create_subscription(Num, "x", lambda m: got.append(m.data), queue_size=2)
    for i in range(5):
        pub.publish(Num(i))
    rt.spin_once()
    assert got == [3, 4]


def test_latched_topic_reaches_late_subscribers():
    rt = Runtime()
    n = Node(rt, "map_server")
    pub = n.create_publisher(Num, "map", latch=True)
    pub.publish(Num(7))
    rt.spin_once()
    got = []
    n.create_subscription(Num, "map", lambda m: got.append(m.data))
    rt.spin_once()
    assert got == [7]


def test_lazy_publish_builds_only_for_a_reader():
    """`publish_lazily`: nothing built without a subscription; a latched one is built when a
    subscription comes (the message of the last call, not of an earlier one); with a
    subscription it is published as `publish` would."""
    rt = Runtime()
    n = Node(rt, "costmap")
    built = []

    def make(v):
        return lambda: (built.append(v), Num(v))[1]

    latched = n.create_publisher(Num, "grid", latch=True)
    plain = n.create_publisher(Num, "footprint")
    for v in (1, 2, 3):
        latched.publish_lazily(make(v))
        plain.publish_lazily(make(10 + v))
    rt.spin_once()
    assert built == []
    got = []
    n.create_subscription(Num, "grid", lambda m: got.append(m.data))
    n.create_subscription(Num, "footprint", lambda m: got.append(m.data))
    rt.spin_once()
    assert got == [3] and built == [3]  # the plain topic had nothing to hand over
    latched.publish_lazily(make(4))
    plain.publish_lazily(make(14))
    rt.spin_once()
    assert got == [3, 4, 14] and built == [3, 4, 14]
    assert latched.last.data == 4
    latched.publish(Num(5))
    assert latched.last.data == 5


def test_lazy_publish_checks_the_type_when_built():
    rt = Runtime()
    n = Node(rt, "n")
    pub = n.create_publisher(Num, "a", latch=True)
    pub.publish_lazily(lambda: "not a Num")
    with pytest.raises(GraphError, match="carries"):
        _ = pub.last


def test_delivery_order_is_fifo_across_subscriptions():
    rt = Runtime()
    n = Node(rt, "n")
    log = []
    pa = n.create_publisher(Num, "a")
    pb = n.create_publisher(Num, "b")
    n.create_subscription(Num, "a", lambda m: (log.append(("a", m.data)), pb.publish(Num(m.data))))
    n.create_subscription(Num, "b", lambda m: log.append(("b", m.data)))
    pa.publish(Num(1))
    pa.publish(Num(2))
    rt.spin_once()
    assert log == [("a", 1), ("a", 2), ("b", 1), ("b", 2)]


def test_timers_order_by_time_then_priority_then_creation():
    rt = Runtime()
    log = []
    rt.create_timer(0.5, lambda: log.append(("node", rt.now())))
    rt.create_timer(0.25, lambda: log.append(("physics", rt.now())), priority=-100)
    rt.run(1.0)
    assert log == [
        ("physics", 0.25),
        ("physics", 0.5),
        ("node", 0.5),
        ("physics", 0.75),
        ("physics", 1.0),
        ("node", 1.0),
    ]
    assert rt.now() == 1.0


def test_periods_do_not_drift():
    rt = Runtime()
    ticks = []
    rt.create_timer(0.1, lambda: ticks.append(rt.time_ns))
    rt.run(100.0)
    assert len(ticks) == 1000 and ticks[-1] == 100_000_000_000


def test_run_until_condition_and_call_later():
    rt = Runtime()
    fired = []
    rt.call_later(2.0, lambda: fired.append(rt.now()))
    rt.create_timer(0.1, lambda: None)
    rt.run(until=lambda: bool(fired))
    assert fired == [2.0]
    with pytest.raises(FleetsimError, match="needs a duration or an until"):
        rt.run()


def test_same_seed_same_streams():
    assert Runtime(seed=4).rng("/a").random() == Runtime(seed=4).rng("/a").random()
    assert Runtime(seed=4).rng("/a").random() != Runtime(seed=5).rng("/a").random()
    assert Runtime(seed=4).rng("/a").random() != Runtime(seed=4).rng("/b").random()


def test_services_call_and_errors():
    rt = Runtime()
    server = Node(rt, "adder", "/lizi1")
    server.create_service(ADD, "add", lambda req: AddResponse(req.a + req.b))
    client = Node(rt, "user", "/lizi1").create_client(ADD, "add")
    assert client.wait_for_service()
    assert client.call(AddRequest(2, 3)).sum == 5
    with pytest.raises(GraphError, match=r"service /lizi1/add is already provided by /lizi1/adder"):
        server.create_service(ADD, "add", lambda r: None)
    with pytest.raises(ServiceError, match=r"service /lizi1/ad is not available.*'/lizi1/add'"):
        Node(rt, "u2", "/lizi1").create_client(ADD, "ad").call(AddRequest())
    with pytest.raises(ServiceError, match="takes .*AddRequest.*got .*Num"):
        client.call(Num())


def test_service_exceptions_become_service_errors():
    rt = Runtime()
    n = Node(rt, "n")
    n.create_service(ADD, "boom", lambda req: 1 / 0)
    with pytest.raises(ServiceError, match="service /boom failed: ZeroDivisionError"):
        n.create_client(ADD, "boom").call(AddRequest())


def test_nodes_are_unique_and_destroy_withdraws_everything():
    rt = Runtime()
    n = Node(rt, "n", "/a")
    with pytest.raises(GraphError, match="a node named /a/n already exists"):
        Node(rt, "n", "/a")
    got = []
    pub = Node(rt, "p").create_publisher(Num, "/x")
    n.create_subscription(Num, "/x", got.append)
    n.create_service(ADD, "s", lambda r: None)
    n.create_timer(0.1, lambda: got.append("tick"))
    n.destroy()
    pub.publish(Num())
    rt.run(1.0)
    assert got == [] and "/a/s" not in rt.graph.services and "/a/n" not in rt.graph.nodes


def test_remaps_and_private_params_reach_the_node():
    rt = Runtime()
    rt.params.set("/lizi1/tf_prefix", "lizi1")
    n = Node(rt, "amcl", "/lizi1", remaps={"scan": "base_scan"}, params={"min_particles": 10})
    assert n.resolve_name("scan") == "/lizi1/base_scan"
    assert n.get_param("~min_particles") == 10
    assert rt.params.get("/lizi1/amcl/min_particles") == 10
    assert n.tf_prefix == "lizi1"


def test_a_subscription_with_publisher_is_told_who_sent_each_message():
    """Bridges name each message's node: (msg, publisher); plain subscriptions are unchanged."""
    rt = Runtime()
    a, b = Node(rt, "a"), Node(rt, "b")
    pa = a.create_publisher(Num, "/tf_static", latch=True)
    pb = b.create_publisher(Num, "/tf_static", latch=True)
    pa.publish(Num(1))
    pb.publish(Num(2))
    tagged, plain = [], []
    sub = rt.graph.subscribe("/tf_static", Num, tagged.append, with_publisher=True)
    rt.graph.subscribe("/tf_static", Num, plain.append)
    rt.spin_once()  # a late subscriber gets every latched publisher's message
    assert [(m.data, p.node.full_name) for m, p in tagged] == [(1, "/a"), (2, "/b")]
    assert [m.data for m in plain] == [1, 2]
    pb.publish(Num(3))
    rt.graph.deliver(sub, Num(4))  # handed in by a bridge: no local publisher
    rt.spin_once()
    assert [(m.data, p) for m, p in tagged[2:]] == [(3, pb), (4, None)]
    assert [m.data for m in plain[2:]] == [3]
    sub.destroy()
    assert rt.graph.topics["/tf_static"].with_publisher == 0
    pa.publish(Num(5))
    rt.spin_once()
    assert len(tagged) == 4 and plain[-1].data == 5


def test_a_node_warns_once_per_key_until_the_key_is_discarded(caplog):
    node = Node(Runtime(), "n")
    for _ in range(3):
        node._warn_once("tf", "no tf yet")
    node._warn_once("map", "no map yet")
    assert caplog.text.count("no tf yet") == 1 and caplog.text.count("no map yet") == 1
    node._warned.discard("tf")
    node._warn_once("tf", "no tf yet")
    assert caplog.text.count("no tf yet") == 2
