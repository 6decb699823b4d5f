"""The run monitor and goal senders (fleetsim.launch.monitor.GoalSender): a run succeeds only when
every sender is done and succeeded; a goal its sender withdrew is no failure, any other cancel
is. Explore is the sender here (finished vs. gave up), with a stand-in move_base and no
simulator."""

import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.launch.monitor import GoalSender, RunMonitor
from fleetsim.msgs import actionlib_msgs, move_base_msgs, nav_msgs, std_msgs
from fleetsim.nav.explore import Explore
from fleetsim.nav.send_goals import SendGoals
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, make_transform_stamped

sys.path.insert(0, str(Path(__file__).parents[1] / "nav"))
from fake_move_base import FakeMoveBase  # tests/nav/fake_move_base.py

PLAN = SimpleNamespace(
    nodes=[SimpleNamespace(pkg="move_base", type="move_base", namespace="/", name="move_base")]
)


class World(Node):
    """A costmap (``publish`` after editing ``data``) and a robot standing at (0.35, 1.05)."""

    def __init__(self, rt):
        super().__init__(rt, "world")
        self.data = np.full((20, 30), -1, dtype=np.int8)
        self.data[:, :10] = 0  # big frontier along x = 1 m
        self.data[:4, :6] = -1  # small frontier in the south-west corner
        self.pub = self.create_publisher(nav_msgs.OccupancyGrid, "costmap", 1, latch=True)
        self.publish()
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped("map", "base_link", 0.0, (0.35, 1.05, 0.0))
        )

    def publish(self):
        info = nav_msgs.MapMetaData(resolution=0.1, width=30, height=20)
        self.pub.publish(
            nav_msgs.OccupancyGrid(
                header=std_msgs.Header(frame_id="map"), info=info, data=self.data.ravel().copy()
            )
        )


class MoveBase(Node):
    """Accepts goals; ``on_goal(n, server)`` decides what happens to the n-th (from 1)."""

    def __init__(self, rt, on_goal):
        super().__init__(rt, "move_base")
        self.n, self.decide = 0, on_goal
        self.server = self.create_action_server(
            move_base_msgs.MoveBase,
            "move_base",
            goal_callback=self.on_goal,
            preempt_callback=self.on_preempt,
        )

    def on_preempt(self):
        if not self.server.is_new_goal_available():
            self.server.set_preempted(text="canceled")

    def on_goal(self):
        self.server.accept_new_goal()
        self.n += 1
        self.decide(self.n, self.server)


def run(rt, monitor, limit=30.0):
    rt.run(duration=limit, until=monitor.all_goals_done)


def test_explore_and_send_goals_are_goal_senders():
    for cls in (Explore, SendGoals):
        assert cls.sends_goals is True
        for name in ("done", "succeeded"):  # GoalSender's members
            assert name in GoalSender.__dict__ and isinstance(getattr(cls, name), property)


def test_an_explorer_that_finished_with_a_goal_active_succeeds_and_its_cancel_is_no_failure():
    """explore_lite cancels its active goal when no frontier is left: that is not a failure."""
    rt = Runtime(seed=0)
    world = World(rt)

    def on_goal(n, server):  # the goal is never reached; meanwhile the map fills in
        world.data[:] = 0
        rt.call_later(1.0, world.publish)

    MoveBase(rt, on_goal)
    ex = Explore(rt)
    monitor = RunMonitor(rt, PLAN, {"/explore": ex})
    run(rt, monitor)
    assert ex.finished and ex.succeeded and len(ex.withdrawn_goals) == 1
    rt.run(duration=0.5)  # the cancel's result arrives
    r = monitor.robots["/"]
    assert (r.goals_sent, r.goals_failed) == (0, 0)
    assert r.last_text == "withdrawn by /explore"
    assert monitor.all_goals_done() and monitor.success()


def test_an_explorer_that_gave_up_on_a_frontier_fails_the_run():
    """The audit's case: goal 1 makes no progress (blacklisted, replaced by goal 2), goal 2 is
    reached and maps its frontier; the blacklisted frontier is all that is left."""
    rt = Runtime(seed=0)
    rt.params.set("/explore/progress_timeout", 2.0)
    world = World(rt)

    def on_goal(n, server):
        if n >= 2:
            world.data[:4, :6] = 0
            world.publish()
            rt.call_later(0.5, lambda: server.set_succeeded(text="reached"))

    MoveBase(rt, on_goal)
    ex = Explore(rt)
    monitor = RunMonitor(rt, PLAN, {"/explore": ex})
    run(rt, monitor)
    assert ex.finished and ex.gave_up and len(ex.blacklist) == 1
    assert monitor.all_goals_done()
    assert monitor.senders_failed() == ["/explore"]
    assert not monitor.success()


def test_a_goal_canceled_by_anyone_else_still_fails():
    rt = Runtime(seed=0)
    world = World(rt)
    MoveBase(rt, lambda n, server: None)
    ex = Explore(rt)
    monitor = RunMonitor(rt, PLAN, {"/explore": ex})
    rt.run(duration=1.5)  # the first goal is out
    Node(rt, "user").create_publisher(actionlib_msgs.GoalID, "/move_base/cancel", 1).publish(
        actionlib_msgs.GoalID()
    )
    rt.run(duration=0.5)
    assert monitor.robots["/"].goals_failed == 1
    world.data[:] = 0
    world.publish()
    run(rt, monitor)
    assert ex.succeeded and monitor.all_goals_done() and not monitor.success()


def test_a_sender_that_is_not_done_fails_the_run():
    rt = Runtime(seed=0)
    sender = SimpleNamespace(sends_goals=True, done=False, succeeded=True, full_name="/s")
    monitor = RunMonitor(rt, PLAN, {"/s": sender})
    assert not monitor.all_goals_done() and not monitor.success()
    sender.done = True  # finished without a goal to send
    assert monitor.all_goals_done() and monitor.success()
    sender.succeeded = False
    assert monitor.senders_failed() == ["/s"] and not monitor.success()


def test_a_follower_keeps_a_goal_run_going_and_is_no_failure():
    """follow_marker streams move_base_simple goals for as long as the run lasts: its first
    goal reached had ended --until-goals runs (and batch runs) as a success at ~10 s of 60.
    A follower is a sender never done (the run lasts its duration) and that is no failure."""
    from fleetsim.apps.follow_marker import FollowMarker
    from fleetsim.apps.predictive_follower import PredictiveFollower

    for cls in (FollowMarker, PredictiveFollower):
        assert cls.sends_goals and cls.follows and not cls.done
    rt = Runtime(seed=0)
    MoveBase(rt, lambda n, server: rt.call_later(0.5, lambda: server.set_succeeded(text="ok")))
    follower = SimpleNamespace(sends_goals=True, follows=True, done=False, full_name="/f")
    monitor = RunMonitor(rt, PLAN, {"/f": follower})
    goals = Node(rt, "user").create_action_client(move_base_msgs.MoveBase, "/move_base")
    rt.run(duration=0.2)
    goals.send_goal(move_base_msgs.MoveBase.Goal())
    rt.run(duration=2.0)
    assert monitor.robots["/"].all_done  # its goal has its result (no ground truth here)
    assert not monitor.all_goals_done()  # the run goes on
    assert monitor.senders_failed() == [] and "/f" not in " ".join(monitor.failures())


def test_a_followers_goal_still_going_or_withdrawn_at_the_end_is_no_failure():
    """A follower's newest goal is normally still active when the run ends, and the exploration
    goals it cancels on seeing the marker again end PREEMPTED: neither fails its robot."""
    rt = Runtime(seed=0)
    MoveBase(rt, lambda n, server: None)  # never finishes: the marker keeps moving
    follower = SimpleNamespace(
        sends_goals=True, follows=True, done=False, full_name="/f", namespace="/",
        withdrawn_goals=set(),
    )  # fmt: skip
    monitor = RunMonitor(rt, PLAN, {"/f": follower})
    client = Node(rt, "user").create_action_client(move_base_msgs.MoveBase, "/move_base")
    rt.run(duration=0.2)
    first = client.send_goal(move_base_msgs.MoveBase.Goal())
    rt.run(duration=0.5)
    follower.withdrawn_goals.add(first.goal_id.id)
    first.cancel()
    rt.run(duration=0.5)
    client.send_goal(move_base_msgs.MoveBase.Goal())  # still going when the run ends
    rt.run(duration=0.5)
    (r,) = monitor.results()
    assert r.followed and not r.all_done and r.goals_failed == 0
    assert monitor.failures() == [] and r.ok


@pytest.mark.parametrize(
    ("goals", "succeeded"),
    [([[1.0, 0.0], [1.0, 1.0]], True), ([[1.0, 0.0], [-2.0, 0.0]], False), ([], False)],
)
def test_send_goals_succeeded_only_when_it_reached_every_goal(goals, succeeded):
    """FakeMoveBase aborts goals with x < 0; a send_goals given no goals did not succeed."""
    rt = Runtime(seed=0)
    FakeMoveBase(rt, "/lizi1")
    rt.params.set("/send_goals/goals", {"lizi1": goals} if goals else {})
    sg = SendGoals(rt)
    assert not sg.succeeded
    rt.run(until=lambda: sg.done, duration=30.0)
    assert sg.done and sg.succeeded is succeeded


def test_an_aborted_goal_the_explorer_moved_on_from_does_not_fail_a_finished_exploration():
    """move_base aborts the goal; explore blacklists its frontier and would go on, but the map
    has filled in meanwhile (mapped from elsewhere), the blacklisted frontier with it:
    exploration finished, so the run succeeds (explore's doc: exit status 0), the abort still
    counted as the goal's failure."""
    rt = Runtime(seed=0)
    world = World(rt)

    def on_goal(n, server):
        world.data[:] = 0
        world.publish()
        server.set_aborted(text="no valid plan")

    MoveBase(rt, on_goal)
    ex = Explore(rt)
    monitor = RunMonitor(rt, PLAN, {"/explore": ex})
    run(rt, monitor)
    r = monitor.robots["/"]
    assert ex.finished and ex.succeeded and len(ex.handled_goals) == 1
    assert r.goals_failed == 1 and not r.ok
    assert monitor.all_goals_done() and monitor.success()
    # the same abort with no sender that moved on from it fails the run
    ex.handled_goals.clear()
    assert not monitor.success()
