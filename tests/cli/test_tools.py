"""`fleetsim topic|service|param|node|tf|goal|initialpose` against a simulation in a thread."""

import math
import socket
import subprocess
import sys
import threading
import time

import pytest
import typer
from typer.testing import CliRunner

from fleetsim.cli.tools import node_app, param_app, register, service_app, tf_app, topic_app
from fleetsim.errors import FleetsimError
from fleetsim.msgs import (
    builtin_interfaces,
    geometry_msgs,
    move_base_msgs,
    std_msgs,
    std_srvs,
    tf2_msgs,
)
from fleetsim.runtime import Node, Runtime
from fleetsim.transport import ZenohBridge

app = typer.Typer()
for _sub, _name in (
    (topic_app, "topic"),
    (service_app, "service"),
    (param_app, "param"),
    (node_app, "node"),
    (tf_app, "tf"),
):
    app.add_typer(_sub, name=_name)
register(app)
runner = CliRunner()


def free_endpoint() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


class Robot(Node):
    """A stand-in robot for the tools: tf, a move_base action server, topics and a service."""

    def __init__(self, runtime, name="robot", namespace="/lizi1", **kw):
        super().__init__(runtime, name, namespace, **kw)
        self.goals, self.poses, self.chatter = [], [], []
        self.create_subscription(
            geometry_msgs.PoseStamped, "move_base_simple/goal", self.goals.append
        )
        self.create_subscription(
            geometry_msgs.PoseWithCovarianceStamped, "initialpose", self.poses.append
        )
        self.create_subscription(std_msgs.String, "/chatter", self.chatter.append)
        self.pub = self.create_publisher(std_msgs.String, "/chatter_out")
        self.tf = self.create_publisher(tf2_msgs.TFMessage, "/tf")
        static = self.create_publisher(tf2_msgs.TFMessage, "/tf_static", latch=True)
        static.publish(tf2_msgs.TFMessage(transforms=[self._tf("map", "lizi1/odom", 1.0, 0.0)]))
        self.create_timer(0.1, self.on_timer)
        self.create_service(std_srvs.SetBool, "enable", self.on_enable)
        self.server = self.create_action_server(move_base_msgs.MoveBase, "move_base")
        self.create_timer(0.1, self.on_action)

    def _tf(self, parent, child, x, y):
        t = geometry_msgs.TransformStamped()
        t.header.frame_id, t.child_frame_id = parent, child
        t.header.stamp = builtin_interfaces.Time.from_nsec(self.runtime.time_ns)
        t.transform.translation.x, t.transform.translation.y = x, y
        return t

    def on_timer(self):
        self.pub.publish(std_msgs.String(data="hi"))
        self.tf.publish(
            tf2_msgs.TFMessage(transforms=[self._tf("lizi1/odom", "lizi1/base_link", 0.5, 0.25)])
        )

    def on_enable(self, req):
        return std_srvs.SetBool.Response(success=req.data, message="enabled" if req.data else "no")

    def on_action(self):
        if self.server.is_new_goal_available():
            self.started = self.now()
            self.target = self.server.accept_new_goal().target_pose
        if self.server.is_active():
            fb = move_base_msgs.MoveBase.Feedback()
            fb.base_position.pose.position.x = self.now() - self.started
            self.server.publish_feedback(fb)
            if self.now() - self.started >= 1.0:
                self.server.set_succeeded(text=f"reached {self.target.pose.position.x:g}")


@pytest.fixture(scope="module")
def sim():
    ep = free_endpoint()
    rt = Runtime()
    rt.params.set("/lizi1/amcl", {"min_particles": 100, "odom_frame_id": "odom"})
    robot = Robot(rt)
    ZenohBridge(rt, listen=[ep])
    stop = threading.Event()
    th = threading.Thread(target=lambda: rt.run(until=stop.is_set, rate=2.0), daemon=True)
    th.start()
    yield ep, robot
    stop.set()
    th.join(10)
    rt.shutdown()


def run(*args):
    return runner.invoke(app, [str(a) for a in args])


def ok(*args) -> str:
    r = run(*args)
    assert r.exit_code == 0, (r.output, r.exception)
    return r.stdout


def fails(*args) -> str:
    r = run(*args)
    assert r.exit_code != 0
    assert isinstance(r.exception, FleetsimError), r.exception
    return str(r.exception)


def test_every_tool_says_no_simulation_quickly():
    ep = free_endpoint()
    commands = [
        ("topic", "list"),
        ("topic", "echo", "/x", "--once"),
        ("topic", "pub", "/x", "std_msgs/String", "{data: a}"),
        ("service", "list"),
        ("param", "get", "/x"),
        ("node", "list"),
        ("tf", "tree"),
        ("goal", "lizi1", "1", "2"),
        ("initialpose", "lizi1", "1", "2", "0"),
    ]
    for cmd in commands:
        t0 = time.monotonic()
        msg = fails(*cmd, "--connect", ep)
        assert msg == f"no simulation running at {ep} (start one with `fleetsim launch ...`)"
        assert time.monotonic() - t0 < 2.5


def test_no_simulation_is_one_line_on_stderr_through_main():
    ep = free_endpoint()
    code = (
        "import sys\n"
        "from fleetsim.cli import main as m, tools\n"
        "m.app.add_typer(tools.topic_app, name='topic')\n"
        f"sys.exit(m.main(['topic', 'list', '--connect', '{ep}']))\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1
    assert r.stderr.strip().splitlines() == [
        f"error: no simulation running at {ep} (start one with `fleetsim launch ...`)"
    ]


def test_topic_list_info_echo_hz(sim):
    ep, _ = sim
    names = ok("topic", "list", "-c", ep).split()
    assert {"/chatter_out", "/tf", "/lizi1/move_base/goal", "/clock"} <= set(names)
    assert "/chatter_out [std_msgs/msg/String] 1 publishers" in ok("topic", "list", "-v", "-c", ep)
    info = ok("topic", "info", "chatter_out", "-c", ep)
    assert info.startswith("Type: std_msgs/msg/String\n\nPublishers: \n * /lizi1/robot\n")
    assert "Subscribers: \n None" in info
    assert "unknown topic /chatter_ou (did you mean '/chatter_out'?)" in fails(
        "topic", "info", "/chatter_ou", "-c", ep
    )
    assert ok("topic", "echo", "/chatter_out", "--once", "-c", ep) == "data: hi\n---\n"
    assert ok("topic", "echo", "/chatter_out", "-n", 3, "-c", ep).count("---") == 3
    out = ok("topic", "hz", "/chatter_out", "--duration", 1.5, "-c", ep)
    rate = float(out.split("average rate: ")[1].split()[0])
    assert rate == pytest.approx(10.0, rel=0.05)  # sim time: 10 Hz at any wall rate


def test_topic_pub_lesson_example_and_rate(sim):
    ep, robot = sim
    n0 = len(robot.goals)
    yaml_goal = "{header: {frame_id: map}, pose: {position: {x: 22, y: 17}, orientation: {w: 1}}}"
    ok(
        "topic",
        "pub",
        "/lizi1/move_base_simple/goal",
        "geometry_msgs/PoseStamped",
        yaml_goal,
        "-1",
        "-c",
        ep,
    )
    deadline = time.monotonic() + 3
    while len(robot.goals) == n0 and time.monotonic() < deadline:
        time.sleep(0.01)
    g = robot.goals[-1]
    assert (g.header.frame_id, g.pose.position.x, g.pose.position.y) == ("map", 22.0, 17.0)
    n1 = len(robot.chatter)
    ok("topic", "pub", "/chatter", "std_msgs/msg/String", "{data: x}", "-r", 50, "-n", 5, "-c", ep)
    deadline = time.monotonic() + 3
    while len(robot.chatter) < n1 + 5 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert [m.data for m in robot.chatter[n1:]] == ["x"] * 5


def test_topic_pub_bad_input_is_one_clear_error(sim):
    ep, robot = sim
    assert "topic pub /chatter: the YAML does not parse at line 1" in fails(
        "topic", "pub", "/chatter", "std_msgs/String", "{data: [", "-c", ep
    )
    assert "unknown message type 'std_msgs/Strin'" in fails(
        "topic", "pub", "/chatter", "std_msgs/Strin", "{data: a}", "-c", ep
    )
    assert "topic /chatter carries std_msgs/msg/String, not std_msgs/msg/Int32" in fails(
        "topic", "pub", "/chatter", "std_msgs/Int32", "{data: 1}", "-c", ep
    )
    assert "unknown field 'dat'" in fails(
        "topic", "pub", "/chatter", "std_msgs/String", "{dat: a}", "-c", ep
    )
    assert "rate must be > 0" in fails(
        "topic", "pub", "/chatter", "std_msgs/String", "-r", 0, "-c", ep
    )
    assert ok("topic", "echo", "/chatter_out", "--once", "-c", ep) == "data: hi\n---\n"  # alive


def test_services(sim):
    ep, _ = sim
    assert "/lizi1/enable" in ok("service", "list", "-c", ep).split()
    assert "/lizi1/enable [std_srvs/srv/SetBool] /lizi1/robot" in ok(
        "service", "list", "-v", "-c", ep
    )
    assert ok("service", "call", "/lizi1/enable", "{data: true}", "-c", ep) == (
        "success: true\nmessage: enabled\n"
    )
    assert "unknown field 'dta'" in fails("service", "call", "/lizi1/enable", "{dta: 1}", "-c", ep)
    assert "field 'data' expected bool, got int" in fails(
        "service", "call", "/lizi1/enable", "{data: 3}", "-c", ep
    )
    assert "service /lizi1/enabl is not available (did you mean '/lizi1/enable'?)" in fails(
        "service", "call", "/lizi1/enabl", "-c", ep
    )


def test_params(sim):
    ep, _ = sim
    assert ok("param", "list", "/lizi1", "-c", ep).split() == [
        "/lizi1/amcl/min_particles",
        "/lizi1/amcl/odom_frame_id",
    ]
    assert ok("param", "get", "/lizi1/amcl/min_particles", "-c", ep) == "100\n"
    ok("param", "set", "lizi1/amcl/min_particles", "-5", "-c", ep)
    assert ok("param", "get", "/lizi1/amcl/min_particles", "-c", ep) == "-5\n"
    ok("param", "set", "lizi1/amcl/min_particles", "500", "-c", ep)
    assert ok("param", "get", "/lizi1/amcl/min_particles", "-c", ep) == "500\n"
    assert "min_particles: 500" in ok("param", "dump", "/lizi1", "-c", ep)
    assert "parameter '/nope' is not set" in fails("param", "get", "/nope", "-c", ep)
    assert "param set /a: the YAML does not parse" in fails("param", "set", "/a", "[1,", "-c", ep)


def test_node_list_and_run_argument_errors(sim):
    ep, _ = sim
    assert "/lizi1/robot" in ok("node", "list", "-c", ep).split()
    assert "--param 'rate' must look like NAME:=VALUE" in fails(
        "node", "run", "x:Y", "--param", "rate", "-c", ep
    )
    assert "must be given as module:Class" in fails("node", "run", "nocolon", "-c", ep)
    assert "cannot import module 'no_such_mod'" in fails("node", "run", "no_such_mod:X", "-c", ep)


def test_goal_prints_feedback_and_result(sim):
    ep, _ = sim
    out = ok("goal", "lizi1", 3, 4, 0.5, "--wait", "--timeout", 10, "-c", ep)
    lines = out.splitlines()
    assert lines[0].startswith("feedback: x=")
    assert lines[-1] == "result: SUCCEEDED (reached 3)"
    sent = ok("goal", "/lizi1", 1, 1, "-c", ep)
    assert sent.strip() in ("goal sent: PENDING", "goal sent: ACTIVE")
    assert "no move_base action server at /lizi9/move_base (servers running: /lizi1/move_base)" in (
        fails("goal", "lizi9", 1, 1, "-c", ep)
    )


class NeverDone(Robot):
    """A move_base that accepts a goal and never finishes it."""

    def on_action(self):
        if self.server.is_new_goal_available():
            self.server.accept_new_goal()


def test_a_goal_waited_for_ends_with_an_error_when_the_simulation_goes_away():
    """``goal --wait`` on a run that ends first: not a client waiting for ever after its last
    feedback, but an error saying the simulation went away."""
    ep = free_endpoint()
    rt = Runtime()
    NeverDone(rt)
    ZenohBridge(rt, listen=[ep])
    stop = threading.Event()
    th = threading.Thread(target=lambda: rt.run(until=stop.is_set, rate=2.0), daemon=True)
    th.start()

    def end_the_run():
        time.sleep(3.0)
        stop.set()
        th.join(10)
        rt.shutdown()

    ender = threading.Thread(target=end_the_run, daemon=True)
    ender.start()
    try:
        message = fails("goal", "lizi1", 1, 1, "--wait", "--timeout", 15, "-c", ep)
    finally:
        ender.join(15)
    assert "went away before goal" in message and "/lizi1/move_base" in message, message


def test_initialpose(sim):
    ep, robot = sim
    n0 = len(robot.poses)
    out = ok("initialpose", "lizi1", 1.5, -2, math.pi / 2, "-c", ep)
    assert out.strip() == "published initial pose on /lizi1/initialpose"
    deadline = time.monotonic() + 3
    while len(robot.poses) == n0 and time.monotonic() < deadline:
        time.sleep(0.01)
    p = robot.poses[-1]
    assert p.header.frame_id == "map" and p.pose.pose.position.x == 1.5
    assert p.pose.pose.orientation.z == pytest.approx(math.sqrt(0.5))
    assert p.pose.covariance[0] == p.pose.covariance[7] == 0.25
    assert "nothing subscribes /lizi2/initialpose" in fails(
        "initialpose", "lizi2", 0, 0, 0, "-c", ep
    )


def test_tf_echo_and_tree(sim, tmp_path):
    ep, _ = sim
    out = ok("tf", "echo", "map", "lizi1/base_link", "-n", 1, "--rate", 5, "-c", ep)
    assert "- Translation: [1.500, 0.250, 0.000]" in out
    assert "- Rotation: in Quaternion [0.000, 0.000, 0.000, 1.000]" in out
    tree = ok("tf", "tree", "--duration", 1.0, "-c", ep)
    assert tree.splitlines()[0] == "map"
    assert "  lizi1/odom  [/lizi1/robot, static]" in tree
    assert "    lizi1/base_link  [/lizi1/robot, 10.0 Hz]" in tree
    pdf = tmp_path / "frames.pdf"
    assert ok("tf", "tree", "-o", pdf, "--duration", 0.6, "-c", ep).strip() == f"wrote {pdf}"
    assert pdf.read_bytes().startswith(b"%PDF")
    assert "use a .pdf, .png, .svg or .gv name" in fails(
        "tf", "tree", "-o", tmp_path / "f.doc", "--duration", 0.3, "-c", ep
    )


def test_a_yaw_of_more_than_a_turn_is_noted_as_likely_degrees():
    from fleetsim.cli.tools import yaw_note

    assert yaw_note(1.57) is None and yaw_note(-6.28) is None
    note = yaw_note(90.0)
    assert "yaw 90 rad is more than a full turn" in note and "would be 1.5708" in note
