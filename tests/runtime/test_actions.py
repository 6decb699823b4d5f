"""Actions with actionlib's SimpleActionServer semantics (what move_base uses)."""

import pytest

from fleetsim.errors import ActionError
from fleetsim.msgs import actionlib_msgs, geometry_msgs, move_base_msgs
from fleetsim.runtime import Node, Runtime

S = actionlib_msgs.GoalStatus
MoveBase = move_base_msgs.MoveBase


def goal(x: float) -> move_base_msgs.MoveBaseGoal:
    g = move_base_msgs.MoveBaseGoal()
    g.target_pose.pose.position.x = x
    return g


class FakeMoveBase(Node):
    """Polls for goals in a timer like move_base's control loop; succeeds after 3 cycles."""

    def __init__(self, rt):
        super().__init__(rt, "move_base", "/lizi1")
        self.server = self.create_action_server(MoveBase, "move_base")
        self.cycles = 0
        self.accepted = []
        self.create_timer(0.1, self.loop)

    def loop(self):
        s = self.server
        if s.is_new_goal_available():
            self.accepted.append(s.accept_new_goal().target_pose.pose.position.x)
            self.cycles = 0
        if not s.is_active():
            return
        if s.is_preempt_requested() and not s.is_new_goal_available():
            s.set_preempted(text="canceled")
            return
        self.cycles += 1
        fb = move_base_msgs.MoveBaseFeedback(base_position=geometry_msgs.PoseStamped())
        fb.base_position.pose.position.x = float(self.cycles)
        s.publish_feedback(fb)
        if self.cycles >= 3:
            s.set_succeeded(text="reached")


@pytest.fixture
def setup():
    rt = Runtime()
    server = FakeMoveBase(rt)
    client = Node(rt, "send_goals", "/lizi1").create_action_client(MoveBase, "move_base")
    return rt, server, client


def test_goal_feedback_result(setup):
    rt, server, client = setup
    assert client.wait_for_server()
    feedback, done = [], []
    h = client.send_goal(
        goal(1.0),
        done_cb=lambda h: done.append(h.status),
        feedback_cb=lambda h, fb: feedback.append(fb.base_position.pose.position.x),
    )
    rt.run(1.0)
    assert h.done and h.status == S.SUCCEEDED and h.text == "reached"
    assert feedback == [1.0, 2.0, 3.0] and done == [S.SUCCEEDED]
    assert "/lizi1/move_base/goal" in rt.graph.topics
    assert "/lizi1/move_base/status" in rt.graph.topics


def test_new_goal_preempts_the_active_one(setup):
    rt, server, client = setup
    first = client.send_goal(goal(1.0))
    rt.run(0.15)
    assert first.status == S.ACTIVE
    second = client.send_goal(goal(2.0))
    rt.run(1.0)
    assert first.status == S.PREEMPTED and "another goal" in first.text
    assert second.status == S.SUCCEEDED
    assert server.accepted == [1.0, 2.0]


def test_newer_pending_goal_recalls_the_older_pending_one(setup):
    rt, server, client = setup
    a = client.send_goal(goal(1.0))
    b = client.send_goal(goal(2.0))
    rt.run(1.0)
    assert a.status == S.RECALLED and b.status == S.SUCCEEDED
    assert server.accepted == [2.0]


def test_cancel_active_and_cancel_all(setup):
    rt, server, client = setup
    h = client.send_goal(goal(1.0))
    rt.run(0.15)
    h.cancel()
    rt.run(0.5)
    assert h.status == S.PREEMPTED
    h2 = client.send_goal(goal(3.0))
    client.cancel_all_goals()
    rt.run(0.5)
    assert h2.status == S.RECALLED


def test_goal_from_the_topic_like_rostopic_pub(setup):
    rt, server, _ = setup
    pub = Node(rt, "cli").create_publisher(MoveBase.ActionGoal, "/lizi1/move_base/goal")
    pub.publish(MoveBase.ActionGoal(goal=goal(5.0)))
    rt.run(1.0)
    assert server.accepted == [5.0]


def test_misuse_is_an_error(setup):
    rt, server, client = setup
    with pytest.raises(ActionError, match="no new goal pending"):
        server.server.accept_new_goal()
    with pytest.raises(ActionError, match="none is active"):
        server.server.set_succeeded()
    with pytest.raises(
        ActionError,
        match=r"takes move_base_msgs/msg/MoveBaseGoal, got geometry_msgs/msg/PoseStamped",
    ):
        client.send_goal(geometry_msgs.PoseStamped())
