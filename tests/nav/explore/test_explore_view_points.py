"""explore's ``view_points`` (fleetsim.nav.explore.view_points) in the node: goals at view
points, progress along the way there, and a frontier that stays after the robot stood at its
view point observed as far as it can be, not given up; one whose view point move_base could
not reach still given up."""

import numpy as np
import pytest
from test_explore_blacklist import MoveBase, World, room
from test_path_costs import rooms

from fleetsim.msgs import geometry_msgs, std_msgs
from fleetsim.nav.explore import Explore
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import make_transform_stamped


def republishing(rt, data) -> World:
    """The test world, its costmap published every second as a costmap node does."""
    world = World(rt, data)
    world.create_timer(1.0, world.publish)
    return world


class Reaching(MoveBase):
    """A move_base that reaches every goal 0.5 s after it was sent, unless replaced."""

    def __init__(self, rt):
        super().__init__(rt, lambda g: None)

    def on_goal(self):
        super().on_goal()
        handle = self.server.current
        self.runtime.call_later(0.5, lambda: self._reach(handle))

    def _reach(self, handle):
        if self.server.is_active() and self.server.current is handle:
            self.server.set_succeeded(text="reached")


def explorer(rt, view_points: bool = True, **params) -> Explore:
    rt.params.set("/explore/view_points", view_points)
    for k, v in params.items():
        rt.params.set(f"/explore/{k}", v)
    return Explore(rt)


def test_the_goal_is_a_drivable_cell_seeing_the_frontier_not_its_centroid():
    data = room()
    rt = Runtime(seed=0)
    World(rt, data)
    mb = MoveBase(rt, lambda g: None)
    ex = explorer(rt, potential_scale=0.0)
    rt.run(duration=1.5)
    big = ex.frontiers[0]
    assert big.view_point is not None and big.view_point != big.centroid
    x, y = mb.goals[0]
    assert data[int(y / 0.1), int(x / 0.1)] == 0  # known and free: the robot can drive there
    assert data[int(big.centroid[1] / 0.1), int(big.centroid[0] / 0.1)] == -1  # unknown


def test_a_frontier_still_there_after_the_robot_stood_at_its_view_point_is_observed():
    # move_base reaches every goal and the map never changes: nothing more can be seen
    rt = Runtime(seed=0)
    republishing(rt, room())
    mb = Reaching(rt)
    ex = explorer(rt, potential_scale=0.0, observe_delay=2.0)
    rt.run(duration=12.0)
    assert ex.finished and ex.succeeded and not ex.gave_up
    assert ex.observed == 2 and not ex.blacklist
    assert len(set(mb.goals)) == 2
    # explore_lite's rule sends the centroids again and again and never stops
    rt = Runtime(seed=0)
    republishing(rt, room())
    Reaching(rt)
    ex = explorer(rt, view_points=False, potential_scale=0.0)
    rt.run(duration=12.0)
    assert not ex.finished


def test_a_frontier_is_not_observed_before_the_map_can_show_what_was_seen():
    rt = Runtime(seed=0)
    republishing(rt, room())
    Reaching(rt)
    ex = explorer(rt, potential_scale=0.0, observe_delay=30.0)
    rt.run(duration=12.0)
    assert ex.stood_at and not ex.finished  # reached, but within observe_delay


def test_a_view_point_move_base_cannot_reach_is_still_given_up():
    rt = Runtime(seed=0)
    World(rt, room())
    MoveBase(rt, lambda g: "abort")
    ex = explorer(rt, observe_delay=0.0)
    rt.run(duration=4.0)
    assert ex.finished and ex.gave_up and not ex.succeeded
    assert ex.observed == 0 and len(ex.blacklist) == 2


def test_progress_is_measured_along_the_way_to_the_view_point():
    # the robot leaves the west room by its door and heads along the corridor for the east
    # room's unknown strip: the straight line to the frontier grows for the first seconds
    # (explore_lite blacklists it), the distance driven to its view point shrinks all along
    data = rooms()
    data[1:5, 1:30] = 0  # only the east room's strip is unknown
    route = np.array([(2.5, 2.0), (1.4, 3.1), (3.6, 3.1), (3.6, 1.0)])
    legs = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(route, axis=0), axis=1))]

    def run(view_points: bool) -> Explore:
        rt = Runtime(seed=0)
        world = World(rt, data, dynamic=True)
        MoveBase(rt, lambda g: None)  # accepted, never reached
        ex = explorer(rt, view_points, progress_timeout=2.0, transform_tolerance=1.5)
        for step in range(12):  # 0.4 m a second
            s = min(0.4 * step, legs[-1])
            at = (np.interp(s, legs, route[:, 0]), np.interp(s, legs, route[:, 1]))
            world.tf.send_transform(
                make_transform_stamped("map", "base_link", rt.now(), (*at, 0.0))
            )
            rt.run(duration=1.0)
        return ex

    assert run(view_points=False).blacklist  # given up on the way
    ex = run(view_points=True)
    assert not ex.blacklist and ex.goal is not None


def test_a_way_the_map_blocks_restarts_the_progress_clock():
    # the robot stands still in a known 3 x 4 m room whose east edge is the frontier; at 2.5 s
    # a wall found between it and the view point makes the way there 2.7 m longer: a new
    # route, measured afresh (blacklisted 2 s after that, not at 4 s, as it would be had the
    # longer way been no progress)
    data = np.full((40, 60), -1, dtype=np.int8)
    data[:, :30] = 0
    rt = Runtime(seed=0)
    world = republishing(rt, data)
    MoveBase(rt, lambda g: None)
    ex = explorer(rt, progress_timeout=2.0)
    rt.run(duration=2.5)
    goal = ex.goal
    assert goal is not None and not ex.blacklist
    world.data[1:38, 15] = 100
    world.publish()
    rt.run(duration=2.0)
    assert ex.goal == goal and not ex.blacklist  # 4.5 s
    rt.run(duration=2.0)
    assert ex.blacklist == [goal]  # 6.5 s: standing still is still no progress


def test_blacklisted_frontiers_are_tried_again_once_nothing_else_is_left():
    # the first try at each frontier fails (a robot stuck in a door); on the second the robot
    # maps the rest: finished, not given up
    data = room()
    rt = Runtime(seed=0)
    world = republishing(rt, data)
    tries: dict = {}

    def outcome(goal):
        tries[goal] = tries.get(goal, 0) + 1
        if tries[goal] == 1:
            return "abort"
        world.data[:] = 0  # on its way there it maps the rest
        world.publish()
        return None

    mb = MoveBase(rt, outcome)
    ex = explorer(rt, blacklist_retries=1)
    rt.run(duration=6.0)
    assert ex.retries == 1 and ex.finished and ex.succeeded and not ex.gave_up
    assert len(mb.goals) == 3  # two given up, the first of them tried again and reached
    # without retries: given up
    rt = Runtime(seed=0)
    republishing(rt, room())
    MoveBase(rt, lambda g: "abort")
    ex = explorer(rt)
    rt.run(duration=6.0)
    assert ex.finished and ex.gave_up and ex.retries == 0


def test_a_frontier_given_up_twice_is_given_up():
    rt = Runtime(seed=0)
    republishing(rt, room())
    mb = MoveBase(rt, lambda g: "abort")
    ex = explorer(rt, blacklist_retries=1)
    rt.run(duration=6.0)
    assert ex.finished and ex.gave_up and ex.retries == 1
    assert len(mb.goals) == 4 and len(set(mb.goals)) == 2


class Peer(Node):
    """A peer explorer's announcements: a goal far away, and its observed points."""

    def __init__(self, rt):
        super().__init__(rt, "peer")
        self.goal = self.create_publisher(
            geometry_msgs.PointStamped, "/peer/explore/goal", 1, latch=True
        )
        self.goal.publish(geometry_msgs.PointStamped(point=geometry_msgs.Point(x=50.0, y=50.0)))
        self.observed = self.create_publisher(
            geometry_msgs.PoseArray, "/peer/explore/observed", 1, latch=True
        )
        self.heard = []
        self.create_subscription(geometry_msgs.PoseArray, "/explore/observed", self.heard.append)

    def announce(self, points):
        self.observed.publish(
            geometry_msgs.PoseArray(
                header=std_msgs.Header(stamp=self.now_msg(), frame_id="map"),
                poses=[
                    geometry_msgs.Pose(position=geometry_msgs.Point(x=x, y=y)) for x, y in points
                ],
            )
        )


def test_with_peers_a_frontier_closed_in_its_own_costmap_is_told_to_them_as_observed():
    # the frontier it heads for vanishes from its own costmap (its laser saw it) before it got
    # there: a peer, whose costmap reads the merged map, may still see it, so it is told
    data = room()
    rt = Runtime(seed=0)
    world = republishing(rt, data)
    mb = MoveBase(rt, lambda g: None)  # accepted, never reached
    peer = Peer(rt)
    ex = explorer(
        rt, potential_scale=0.0, peer_goals=["/peer/explore/goal"],
        peer_observed=["/peer/explore/observed"],
    )  # fmt: skip
    rt.run(duration=1.5)
    goal = ex.goal  # the frontier it heads for (move_base got it, rounded: mb.goals)
    assert mb.goals and not ex.closed_at
    world.data[:, :] = 0  # everything known now: every frontier closed
    world.data[0, :] = 100
    rt.run(duration=2.0)
    assert ex.closed_at == [goal]
    told = [(p.position.x, p.position.y) for p in peer.heard[-1].poses]
    assert told == [goal]
    # without peers nothing is told (explore_lite's own behaviour)
    rt = Runtime(seed=0)
    world = republishing(rt, room())
    MoveBase(rt, lambda g: None)
    ex = explorer(rt, potential_scale=0.0)
    rt.run(duration=1.5)
    world.data[:, :] = 0
    rt.run(duration=2.0)
    assert not ex.closed_at


def test_a_peers_observed_point_keeps_the_time_it_was_first_heard_of():
    # a peer republishes its whole list, stamped anew, as it grows: the points it had already
    # told keep their first time, so they do not wait observe_delay again
    rt = Runtime(seed=0)
    republishing(rt, room())
    MoveBase(rt, lambda g: None)
    peer = Peer(rt)
    ex = explorer(rt, peer_goals=["/peer/explore/goal"], peer_observed=["/peer/explore/observed"])
    peer.announce([(1.0, 1.0)])
    rt.run(duration=3.0)
    peer.announce([(1.0, 1.0), (2.0, 0.5)])
    rt.run(duration=0.5)
    (heard,) = ex.link.stood_at.values()
    assert heard == [(1.0, 1.0, 0.0), (2.0, 0.5, pytest.approx(3.0))]
