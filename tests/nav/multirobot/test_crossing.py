"""Giving way at a crossing (`fleetsim.nav.multirobot.crossing`): a robot carried off its way by
a neighbour beside it that moves the same way gives way when it has the lower priority: it
stands and turns on the spot towards its way, or, with another robot within its turn's reach,
drops back."""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.nav.multirobot.crossing import (
    AGAINST_TIME,
    CROSSING_TIME,
    GIVE_WAY_TIME,
    TURN_CLEARANCE,
    GiveWay,
    across_way,
    carried_by,
    collision_course,
    room_to_turn,
)
from fleetsim.nav.multirobot.holonomic import rays_blocked
from fleetsim.runtime import Node, Runtime

LIZI = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
BODY = math.hypot(0.19, 0.16)
#: held-out seed 9 of the circle of 16, lizi10 beside lizi2 (their frame: lizi10 at the origin)
OURS = np.array([-0.27, -0.42])  # m/s
WANTED = np.array([0.31, -0.40])  # m/s, to the carrot
BESIDE, ITS_VEL = np.array([[0.58, 0.05]]), np.array([[-0.30, -0.27]])
R = np.array([0.56])


def test_across_way_is_rays_blocked_disc_by_disc():
    rng = np.random.default_rng(3)
    for _ in range(300):
        n = int(rng.integers(1, 6))
        rel, r = rng.uniform(-2, 2, (n, 2)), rng.uniform(0.1, 1.0, n)
        d, reach = rng.normal(size=2), float(rng.uniform(0.0, 2.0))
        u = d / np.hypot(*d)
        one_by_one = [
            rays_blocked(u[None], rel[k : k + 1], r[k : k + 1], reach)[0] for k in range(n)
        ]
        assert across_way(rel, r, d, reach).tolist() == one_by_one


def test_a_neighbour_beside_us_moving_our_way_across_our_preferred_way_carries_us():
    assert carried_by(BESIDE, ITS_VEL, R, OURS, WANTED, 1.0).tolist() == [True]


@pytest.mark.parametrize(
    "rel, vel, ours, why",
    [
        ([0.0, -0.8], [-0.27, -0.42], OURS, "a leader ahead on our own way: we follow it"),
        ([0.58, 0.05], [0.30, 0.27], OURS, "it moves against us: a meeting, keeping right's"),
        ([0.58, 0.05], [-0.30, -0.27], [0.2, -0.45], "our velocity within 60 deg of our way"),
        ([-0.58, 0.05], [-0.30, -0.27], OURS, "it is on the other side: not across our way"),
        ([0.58, 0.05], [-0.30, -0.27], [0.0, 0.0], "we stand: nothing carries us"),
    ],
)
def test_not_carried(rel, vel, ours, why):
    out = carried_by(np.array([rel]), np.array([vel]), R, np.array(ours), WANTED, 1.0)
    assert out.tolist() == [False], why


def test_the_lower_priority_robot_gives_way_after_crossing_time_until_the_other_has_crossed():
    yes, no = np.array([True]), np.array([False])
    low, high = GiveWay("lizi10"), GiveWay("lizi1")
    for t in np.arange(0.0, CROSSING_TIME, 0.1):
        assert low.update(t, ["lizi2"], yes, yes, yes) is None
        assert high.update(t, ["lizi2"], yes, yes, yes) is None
    t = CROSSING_TIME + 0.05
    assert low.update(t, ["lizi2"], yes, yes, yes) == "lizi2"
    assert high.update(t, ["lizi2"], yes, yes, yes) is None  # lizi1 has priority over lizi2
    # carried or not, the way is given until lizi2 is out of our way ...
    assert low.update(t + 1.0, ["lizi2"], no, yes, yes) == "lizi2"
    assert low.update(t + 1.1, ["lizi2"], no, no, yes) is None
    # ... stops navigating (parked robots are gone round; a robot slowing down for a moment
    # still navigates: the first line above), or GIVE_WAY_TIME has passed
    low.reset()
    low.update(0.0, ["lizi2"], yes, yes, yes)
    assert low.update(CROSSING_TIME, ["lizi2"], yes, yes, yes) == "lizi2"
    assert low.update(CROSSING_TIME + 0.5, ["lizi2"], yes, yes, no) is None
    low.reset()
    low.update(0.0, ["lizi2"], yes, yes, yes)
    low.update(CROSSING_TIME, ["lizi2"], yes, yes, yes)
    assert low.update(CROSSING_TIME + GIVE_WAY_TIME + 0.1, ["lizi2"], no, yes, yes) is None


def test_a_give_way_ends_when_the_robot_given_way_to_stays_against_us():
    """Standing against us (discs touching) for AGAINST_TIME, it is not getting past (we may
    stand on its goal): the give-way ends, and is not taken up again with it for GIVE_WAY_TIME;
    touching for less does not end it."""
    yes, no = np.array([True]), np.array([False])
    low = GiveWay("lizi10")
    low.update(0.0, ["lizi2"], yes, yes, yes)
    t = CROSSING_TIME
    assert low.update(t, ["lizi2"], yes, yes, yes, yes) == "lizi2"
    assert low.update(t + AGAINST_TIME - 0.1, ["lizi2"], yes, yes, yes, yes) == "lizi2"
    assert low.update(t + AGAINST_TIME - 0.05, ["lizi2"], yes, yes, yes, no) == "lizi2"
    t2 = t + AGAINST_TIME
    assert low.update(t2, ["lizi2"], yes, yes, yes, yes) == "lizi2"  # touching afresh
    assert low.update(t2 + AGAINST_TIME, ["lizi2"], yes, yes, yes, yes) is None
    for dt in np.arange(0.1, GIVE_WAY_TIME, 0.1):
        assert low.update(t2 + AGAINST_TIME + dt, ["lizi2"], yes, yes, yes, no) is None
    end = t2 + AGAINST_TIME + GIVE_WAY_TIME + CROSSING_TIME + 0.1
    assert low.update(end, ["lizi2"], yes, yes, yes, no) == "lizi2"


def _beside(
    robot_id: str, neighbour_id: str, cycles: int, behind: bool = False, drift: float = 0.0
):
    """A planner at the origin moving along OURS, its plan along WANTED, and a neighbour
    published beside it every 0.1 s moving the same way at the same speed (the seed-9 pair,
    drawn together), plus ``drift`` m/s towards us, for ``cycles`` cycles (with ``behind``, a
    third robot, lizi9, follows 0.55 m behind it): (the robot given way to each cycle, the
    commands (cycles, 3), the planner)."""
    rt = Runtime()
    node = Node(rt, "move_base", f"/{robot_id}")
    costmap = SimpleNamespace(
        costmap=Costmap2D(80, 80, 0.05, -2.0, -2.0), footprint=LIZI, global_frame="map"
    )
    params = {"max_vel_x": 0.5, "min_vel_x": 0.1, "max_error_holo": 0.05}  # the lizi's
    planner = CollvoidLocalPlanner.from_namespace(node, costmap, params, robot_id)
    line = np.linspace([0.0, 0.0], WANTED / np.hypot(*WANTED) * 3.0, 40)
    planner.set_plan(np.c_[line, np.zeros(40)])
    pub = Node(rt, "sim", "/").create_publisher(
        collvoid_msgs.PoseTwistWithCovariance, "/position_share"
    )
    yaw, speed = math.atan2(OURS[1], OURS[0]), float(np.hypot(*OURS))
    c, s = math.cos(yaw), math.sin(yaw)
    others = [(neighbour_id, (0.58, -0.05))]
    if behind:
        others.append(("lizi9", (-0.55 * c, -0.55 * s)))
    given, commands = [], []
    for _ in range(cycles):
        for other, (x, y) in others:
            m = collvoid_msgs.PoseTwistWithCovariance(robot_id=other, radius=BODY)
            m.header.stamp = Time.from_sec(rt.now())
            m.controlled = True
            m.pose.pose.position = geometry_msgs.Point(x=x, y=y)
            q = geometry_msgs.Quaternion(z=math.sin(yaw / 2), w=math.cos(yaw / 2))
            m.pose.pose.orientation = q
            towards = -np.array([x, y]) / math.hypot(x, y) * (drift if other == neighbour_id else 0)
            m.holonomic_velocity = geometry_msgs.Vector3(
                x=speed * c + towards[0], y=speed * s + towards[1]
            )
            m.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in LIZI]
            pub.publish(m)
        rt.run(duration=0.1)
        cmd = planner.compute_velocity_commands((0.0, 0.0, yaw), (speed, 0.0, 0.0))
        given.append(planner.giving_way_to)
        commands.append(cmd)
    return given, np.array(commands), planner


def test_the_planner_gives_way_to_a_higher_priority_robot_that_carries_it():
    """Carried beside lizi2 (ORCA keeps it alongside, near lizi2's pace, off its own way),
    lizi10 gives way after CROSSING_TIME: it turns towards its way (to the left; dropping back
    at half speed, ORCA turned it right, off with lizi2), driving only as ORCA requires (here
    on: this lizi2 never reacts, and its way grazes lizi10's disc); lizi1 in its place keeps
    near that pace (it has priority)."""
    along = OURS / np.hypot(*OURS)  # lizi2 moves as we do
    given, cmds, low = _beside("lizi10", "lizi2", 20)
    n = round(CROSSING_TIME / 0.1)
    assert given[: n - 1] == [None] * (n - 1) and given[-1] == "lizi2"
    assert low.turning_to is not None
    assert np.all(cmds[-5:, 2] > 0.5)  # turns left, towards WANTED
    given, cmds, high = _beside("lizi1", "lizi2", 20)
    assert given == [None] * 20 and high.turning_to is None
    assert float(high.last_holo @ along) > 0.4


def test_a_carrier_drifting_into_us_is_no_meeting_that_keeps_us_from_giving_way():
    """lizi2 beside lizi10 drifts towards it as well (their lanes converge): it closes in ahead
    of lizi10, which makes it one of the robots keeping right turns for, but it comes the same
    way, not against lizi10: lizi10 still gives way to it after CROSSING_TIME (circle of 16,
    seed 26: lizi14 beside lizi6 was kept from giving way, carried 1.6 m off its plan for 6 s,
    while lizi6 alone made its meeting)."""
    rel = np.array([[0.58, -0.05]])  # as _beside publishes it
    its_vel = OURS - rel / np.hypot(*rel[0]) * 0.05
    low = _beside("lizi10", "lizi2", 1)[2]
    meets = low._oncoming(rel, its_vel, OURS, WANTED, np.hypot(*rel.T), 3.0)
    assert meets.tolist() == [True]  # closing in ahead: keeping right's, as before
    given, _, low = _beside("lizi10", "lizi2", 20, drift=0.05)
    n = round(CROSSING_TIME / 0.1)
    assert given[: n - 1] == [None] * (n - 1) and given[-1] == "lizi2"


def test_with_a_robot_close_behind_the_planner_drops_back_instead_of_turning():
    """lizi9 0.55 m behind lizi10, within its turning corners' reach: lizi10 gives way to
    lizi2 as it did before (half its preferred speed, all the responsibility: here ORCA keeps
    it going, lizi9 never slows down), not turning towards its way."""
    given, cmds, low = _beside("lizi10", "lizi2", 20, behind=True)
    assert given[-1] == "lizi2" and low.turning_to is None
    assert np.all(cmds[-5:, 2] < 0.5)


def test_room_to_turn_is_no_other_robot_within_the_combined_radius_and_clearance():
    rel = np.array([[0.56, 0.0], [0.0, 0.70], [-1.0, 0.0]])
    r = np.array([0.52, 0.52, 0.52])
    assert room_to_turn(rel, r, 0)  # the one given way to does not count
    assert not room_to_turn(rel, r + TURN_CLEARANCE * 0.5, 0)  # 0.70 < 0.52 + 0.075 + 0.15
    assert room_to_turn(rel[[0, 2]], r[:2], 0)


def test_collision_course_is_the_pair_meeting_within_the_horizon():
    """`collision_course` against the pair's motion sampled finely: the robot at the origin at
    ``velocity``, each neighbour at its own, meeting when their distance drops under the
    combined radius within the horizon (or they overlap and close in)."""
    rng = np.random.default_rng(5)
    horizon, steps = 3.0, np.linspace(0.0, 3.0, 3001)
    for _ in range(300):
        n = int(rng.integers(1, 6))
        rel = rng.uniform(-2.0, 2.0, (n, 2))
        nvel = rng.uniform(-0.5, 0.5, (n, 2))
        radii = rng.uniform(0.3, 0.7, n)
        vel = rng.uniform(-0.5, 0.5, 2)
        got = collision_course(vel, rel, nvel, radii, horizon)
        for k in range(n):
            w = vel - nvel[k]
            gap = np.hypot(*(rel[k][None, :] - steps[:, None] * w[None, :]).T) - radii[k]
            inside_now = gap[0] < 0.0
            closing = float(w @ rel[k]) > 0.0
            meets = bool((gap[1:] < -1e-3).any()) if not inside_now else closing
            if inside_now or abs(gap.min()) > 1e-3:  # off the grazing cases
                assert got[k] == meets, (rel[k], w, radii[k])


def test_a_robot_crossing_out_of_our_way_is_no_longer_in_it():
    """Circle of 16, seed 10, lizi10 giving way to lizi2 (its frame, 1.5 s into the give-way):
    lizi2's disc still lies on the ray of lizi10's way within `REACH`, but it moves off it
    faster than lizi10 would reach it: driving along its way lizi10 passes behind it, so the
    give-way ends here (it stood and turned another 0.9 s while lizi2's disc cleared the ray)."""
    wanted = 0.5 * np.array([math.cos(math.radians(-56)), math.sin(math.radians(-56))])
    b = math.radians(-70)
    rel = np.array([[0.65 * math.cos(b), 0.65 * math.sin(b)]])
    its = 0.5 * np.array([[math.cos(math.radians(-125)), math.sin(math.radians(-125))]])
    assert across_way(rel, R, wanted, 1.0).tolist() == [True]
    assert collision_course(wanted, rel, its, R, 3.0).tolist() == [False]
    # standing, it still comes our way: in our way
    assert collision_course(wanted, rel, np.zeros((1, 2)), R, 3.0).tolist() == [True]
