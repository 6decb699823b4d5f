"""explore_lite's give-up rules in fleetsim.nav.explore.explore: an aborted goal and a goal without
progress for ``progress_timeout`` are blacklisted; the robot pose is not used once older than
``transform_tolerance``; what the explorer tells a goal-sender watcher (done, gave up)."""

import logging
import math

import numpy as np
import pytest

from fleetsim.msgs import geometry_msgs, move_base_msgs, nav_msgs, std_msgs
from fleetsim.nav.explore import Explore, frontiers_from_grid
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, TransformBroadcaster, make_transform_stamped

ROBOT = (0.35, 1.05)  # m, where the robot stands in the map


def room() -> np.ndarray:
    """A known room x < 1 m (its east edge the big frontier) with an unknown south-west corner
    (a small frontier), unknown elsewhere; 0.1 m cells."""
    data = np.full((20, 30), -1, dtype=np.int8)
    data[:, :10] = 0
    data[:4, :6] = -1
    return data


class World(Node):
    """Publishes the costmap (``publish`` again after editing ``data``) and the robot's tf:
    static unless ``dynamic``, else a ``map -> base_link`` stamped now on each ``send_pose``."""

    def __init__(self, rt, data, dynamic: bool = False):
        super().__init__(rt, "world")
        self.data = data
        self.pub = self.create_publisher(nav_msgs.OccupancyGrid, "costmap", 1, latch=True)
        self.publish()
        self.tf = TransformBroadcaster(self) if dynamic else None
        if not dynamic:
            StaticTransformBroadcaster(self).send_transform(
                make_transform_stamped("map", "base_link", 0.0, (*ROBOT, 0.0))
            )

    def publish(self):
        info = nav_msgs.MapMetaData(
            resolution=0.1, width=self.data.shape[1], height=self.data.shape[0]
        )
        self.pub.publish(
            nav_msgs.OccupancyGrid(
                header=std_msgs.Header(frame_id="map"), info=info, data=self.data.ravel().copy()
            )
        )

    def send_pose(self):
        self.tf.send_transform(
            make_transform_stamped("map", "base_link", self.now(), (*ROBOT, 0.0))
        )


class MoveBase(Node):
    """A move_base that accepts every goal and answers each with ``outcome(goal_xy)``:
    ``"abort"`` (aborted at once), ``"succeed"`` (reached 0.5 s later) or None (never ends)."""

    def __init__(self, rt, outcome):
        super().__init__(rt, "move_base")
        self.outcome = outcome
        self.goals: list[tuple[float, float]] = []
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
        p = self.server.accept_new_goal().target_pose.pose.position
        goal = (round(p.x, 2), round(p.y, 2))
        self.goals.append(goal)
        what = self.outcome(goal)
        if what == "abort":
            self.server.set_aborted(text="no path")
        elif what == "succeed":
            self.runtime.call_later(0.5, lambda: self.server.set_succeeded(text="reached"))


def frontier_goals(data) -> tuple[tuple[float, float], tuple[float, float]]:
    big, small = frontiers_from_grid(data, 0.1, (0.0, 0.0), ROBOT)
    return tuple(tuple(round(v, 2) for v in f.centroid) for f in (big, small))


def test_a_goal_move_base_aborts_is_blacklisted_and_exploration_gives_up_on_it():
    data = room()
    big, small = frontier_goals(data)
    rt = Runtime(seed=0)
    rt.params.set("/explore/potential_scale", 0.0)  # the bigger frontier first
    World(rt, data)
    mb = MoveBase(rt, lambda g: "abort" if g == big else "succeed")
    ex = Explore(rt)
    rt.run(duration=3.0)
    assert mb.goals[:2] == [big, small]  # aborted, so the next best is tried
    assert len(ex.blacklist) == 1 and tuple(round(v, 2) for v in ex.blacklist[0]) == big
    assert big not in mb.goals[2:]  # never sent again
    # the small frontier's corner is mapped: only the blacklisted frontier is left
    data[:4, :6] = 0
    ex.grid.data = data.ravel().copy()
    rt.run(duration=2.0)
    assert ex.finished and ex.done
    assert ex.gave_up and not ex.succeeded


def test_a_goal_without_progress_for_progress_timeout_is_blacklisted():
    data = room()
    big, small = frontier_goals(data)
    rt = Runtime(seed=0)
    rt.params.set("/explore/progress_timeout", 2.0)
    rt.params.set("/explore/potential_scale", 0.0)
    World(rt, data)
    mb = MoveBase(rt, lambda g: None)  # accepted, never reached: the robot does not move
    ex = Explore(rt)
    rt.run(duration=2.5)
    assert mb.goals == [big] and not ex.blacklist  # within progress_timeout: kept
    rt.run(duration=1.5)  # 2 s without progress have passed at the 3 s plan
    assert [tuple(round(v, 2) for v in b) for b in ex.blacklist] == [big]
    assert mb.goals == [big, small]  # the next frontier replaces it
    assert not ex.finished and not ex.done


def test_exploration_that_ran_out_of_frontiers_without_blacklisting_succeeded():
    data = room()
    rt = Runtime(seed=0)
    world = World(rt, data)

    def reach(goal):  # the frontier's region becomes known when the robot gets there
        world.data[:] = 0
        world.publish()
        return "succeed"

    MoveBase(rt, reach)
    ex = Explore(rt)
    rt.run(duration=4.0)
    assert ex.finished and ex.done and ex.succeeded and not ex.gave_up
    assert not ex.blacklist


def test_a_robot_pose_older_than_transform_tolerance_is_not_used(caplog):
    data = room()
    rt = Runtime(seed=0)
    rt.params.set("/explore/transform_tolerance", 0.5)
    world = World(rt, data, dynamic=True)
    mb = MoveBase(rt, lambda g: None)
    ex = Explore(rt)
    rt.run(duration=0.1)
    world.send_pose()  # one map -> base_link at t = 0.1 s, then tf is silent
    with caplog.at_level(logging.WARNING):
        rt.run(duration=2.4)  # plans at 1 s and 2 s: the pose is 0.9 and 1.9 s old
    assert mb.goals == [] and ex.goals_sent == 0
    assert "more than transform_tolerance 0.5 s" in caplog.text
    world.send_pose()  # tf is back
    rt.run(duration=1.0)
    assert len(mb.goals) == 1


@pytest.mark.parametrize("switch_distance", [0.0, 5.0])
def test_a_frontier_that_only_creeps_is_given_up_with_switch_distance(switch_distance):
    # the room's east edge shrinks from its north end one cell a second while the robot does
    # not move: its centroid (the goal) creeps 5 cm a plan, its nearest cell stays put
    data = room()
    rt = Runtime(seed=0)
    rt.params.set("/explore/progress_timeout", 2.0)
    rt.params.set("/explore/potential_scale", 0.0)
    rt.params.set("/explore/switch_distance", switch_distance)
    world = World(rt, data)
    mb = MoveBase(rt, lambda g: None)  # accepted, never reached
    ex = Explore(rt)
    for row in range(19, 13, -1):
        rt.run(duration=1.0)
        world.data[row, 10:] = 100  # a wall found where the frontier's north end was
        world.publish()
    assert len(set(mb.goals)) >= 4  # the goal moved with the centroid
    if switch_distance == 0.0:
        # explore_lite: every moved goal restarts the progress clock; never given up
        assert not ex.blacklist
    else:
        # tracked as one frontier: no progress towards it for 2 s, blacklisted
        assert len(ex.blacklist) == 1
        assert ex.blacklist[0][0] == pytest.approx(1.05)  # the east edge, where it crept to


def test_the_same_frontier_sent_again_after_a_retry_does_not_resend_it_at_once():
    """One frontier, no progress to it: blacklisted, then (``blacklist_retries``) the list is
    cleared and the same point sent again, which pre-empts the first send. That send's
    PREEMPTED is told apart from the new goal by its send, not by its coordinates: taken for the
    new goal's end it replanned at once and sent the point again, pre-empting it in turn, over
    and over without the sim time advancing (office, seed 3: over 3000 sends at 730 s)."""
    data = room()
    data[:4, :6] = 0  # the east edge is the only frontier
    rt = Runtime(seed=0)
    rt.params.set("/explore/progress_timeout", 2.0)
    rt.params.set("/explore/blacklist_retries", 1)
    World(rt, data)

    def never_ends(goal):
        assert len(mb.goals) < 50, f"{len(mb.goals)} sends by {rt.now():.1f} s"

    mb = MoveBase(rt, never_ends)
    ex = Explore(rt)
    rt.run(duration=10.0)
    assert ex.retries == 1
    assert 2 <= len(mb.goals) <= 4 and len(set(mb.goals)) == 1, mb.goals


def test_with_nothing_left_of_its_own_it_waits_while_a_peer_explores_then_stops():
    """Its one frontier aborted and blacklisted, an explorer whose peer still has a goal waits
    (the peer's mapping may open a way or move a view point) instead of stopping; once the
    peer announces no goal (NaN: it stopped), it gives up as before."""
    data = room()
    data[:4, :6] = 0  # the east edge is the only frontier
    rt = Runtime(seed=0)
    rt.params.set("/explore/peer_goals", ["/peer/goal"])
    World(rt, data)
    MoveBase(rt, lambda g: "abort")
    peer = Node(rt, "peer").create_publisher(
        geometry_msgs.PointStamped, "/peer/goal", 1, latch=True
    )

    def announce(x, y):
        header = std_msgs.Header(frame_id="map")
        peer.publish(geometry_msgs.PointStamped(header=header, point=geometry_msgs.Point(x=x, y=y)))

    announce(5.0, 5.0)  # far from this robot's frontier: not the peer's
    ex = Explore(rt)
    rt.run(duration=6.0)
    assert len(ex.blacklist) == 1 and not ex.finished and ex.goal is None
    announce(math.nan, math.nan)
    rt.run(duration=4.0)
    assert ex.finished and ex.gave_up
