"""Issue 18: localization spread shared as a covariance and padded in the direction that
matters (across the legs of a pair's velocity obstacle), with today's radius rule for robots
that share no covariance and one warning for a bad one."""

import logging
import math
from types import SimpleNamespace

import numpy as np
import pytest

from fleetsim.msgs import collvoid_msgs, geometry_msgs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.footprint import padded_footprint
from fleetsim.nav.multirobot.me_publisher import MePublisher
from fleetsim.nav.multirobot.position_share import NeighbourTable, PositionShare
from fleetsim.nav.multirobot.uncertainty import (
    gaussian_scale,
    pair_padding,
    shared_padding,
    spread_along,
    spread_outline,
    widest_spread,
)
from fleetsim.runtime import Node, Runtime
from fleetsim.tf import StaticTransformBroadcaster, make_transform_stamped

LIZI = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
K = gaussian_scale(0.1)  # 2.146 standard deviations
ALONG_X = np.diag([0.15**2, 0.005**2])  # amcl in a corridor along x: 0.32 m of 90 % spread
ALONG_Y = np.diag([0.005**2, 0.15**2])
NONE = np.zeros((1, 2, 2))


def test_gaussian_scale_is_the_2d_quantile():
    assert pytest.approx(2.1460, abs=1e-4) == K
    # P(Mahalanobis radius > k) = exp(-k^2 / 2) for a 2-D Gaussian
    rng = np.random.default_rng(0)
    r = np.hypot(*rng.standard_normal((2, 200_000)))
    assert np.mean(r > K) == pytest.approx(0.1, abs=0.003)
    assert gaussian_scale(0.0) == math.inf


def test_spread_along_a_direction_is_the_projected_standard_deviation():
    dirs = np.array([[1.0, 0.0], [0.0, 1.0], [math.sqrt(0.5), math.sqrt(0.5)]])
    got = spread_along(ALONG_X, dirs, 0.1, cap=10.0)
    assert got[0] == pytest.approx(K * 0.15)
    assert got[1] == pytest.approx(K * 0.005)
    assert got[2] == pytest.approx(K * math.sqrt((0.15**2 + 0.005**2) / 2))
    assert spread_along(ALONG_X, dirs, 0.1, cap=0.1)[0] == 0.1  # capped as the radius rule
    assert widest_spread(ALONG_Y, 0.1, 10.0) == pytest.approx(K * 0.15)


def test_a_robot_touching_along_x_is_padded_by_the_spread_along_x_only():
    """In contact (distance <= combined radius) the line between the two is what matters."""
    rel, base = np.array([[0.6, 0.0]]), np.array([0.7])
    x = pair_padding(rel, base, ALONG_X, 0.5, NONE, np.array([0.5]), 0.1)
    y = pair_padding(rel, base, ALONG_Y, 0.5, NONE, np.array([0.5]), 0.1)
    assert x[0] == pytest.approx(K * 0.15, abs=1e-3)  # a bisection, to ~0.3 mm
    assert y[0] == pytest.approx(K * 0.005, abs=1e-3)  # almost nothing
    # the same for the other's spread instead of this robot's
    other = pair_padding(rel, base, None, 0.5, ALONG_X[None], np.array([0.5]), 0.1)
    assert other[0] == pytest.approx(x[0])


def test_a_robot_ahead_in_a_corridor_is_padded_by_the_spread_across_the_line():
    """Two robots 4 m apart along x, both uncertain along x (amcl in a featureless corridor):
    the legs of their velocity obstacle are nearly parallel to x, so the spread along x barely
    widens it; a spread across (along y) does, fully."""
    rel, base = np.array([[4.0, 0.3]]), np.array([0.7])
    along = pair_padding(rel, base, ALONG_X, 0.5, ALONG_X[None], np.array([0.5]), 0.1)[0]
    across = pair_padding(rel, base, ALONG_Y, 0.5, ALONG_Y[None], np.array([0.5]), 0.1)[0]
    assert along < 0.3 * math.sqrt(2) * K * 0.15
    # two independent spreads of 0.32 m: the relative position's is sqrt(2) x 0.32 m
    assert across == pytest.approx(math.sqrt(2) * K * 0.15, rel=0.05)
    # the disc of radius base + pad shares a tangent with the true shape (the disc of radius
    # base grown by the relative position's spread; support along n: base + sqrt(2) x the
    # spread of one along n)
    for cov, pad in ((ALONG_X, along), (ALONG_Y, across)):
        d = float(np.hypot(*rel[0]))
        r = base[0] + pad
        u = rel[0] / d
        perp = np.array([-u[1], u[0]])
        s = r / d
        tangents = [s * u + sign * math.sqrt(1 - s * s) * perp for sign in (1, -1)]
        support = [
            base[0] + math.sqrt(2) * spread_along(cov, n[None], 0.1, 0.5)[0] for n in tangents
        ]
        assert max(support) == pytest.approx(r, abs=1e-3)


def test_no_spread_anywhere_pads_exactly_nothing():
    rel = np.array([[1.0, 0.0], [0.0, 2.0]])
    pads = pair_padding(rel, np.array([0.6, 0.6]), None, 0.5, np.zeros((2, 2, 2)), [0.5, 0.5], 0.1)
    assert pads.tolist() == [0.0, 0.0]


@pytest.mark.parametrize("widest", [0.05, 0.3, 0.49, 2.0])
def test_the_padding_a_publisher_applied_is_recovered_from_its_footprint(widest):
    body_r = float(np.hypot(0.19, 0.16))
    pad = min(widest, 2 * body_r)  # me_publisher: capped at twice the robot radius
    assert shared_padding(padded_footprint(LIZI, pad), widest) == pytest.approx(pad, abs=1e-9)


class Robot(Node):
    def __init__(self, rt):
        super().__init__(rt, "robot", "/lizi1")
        rt.params.set("/lizi1/tf_prefix", "lizi1")
        StaticTransformBroadcaster(self).send_transform(
            make_transform_stamped("map", "lizi1/base_link", 0.0, (1.0, 2.0, 0), (0, 0, 0, 1))
        )
        self.cloud = self.create_publisher(geometry_msgs.PoseArray, "particlecloud", latch=True)
        self.got = []
        self.create_subscription(
            collvoid_msgs.PoseTwistWithCovariance, "/position_share", self.got.append
        )


def test_me_publisher_to_the_table_the_body_and_the_covariance_come_through():
    rt = Runtime()
    robot = Robot(rt)
    MePublisher(rt, "me_publisher", "/lizi1", params={"footprint": LIZI.tolist()})
    rng = np.random.default_rng(1)
    xy = rng.standard_normal((300, 2)) * [0.15, 0.01] + [1.0, 2.0]
    robot.cloud.publish(
        geometry_msgs.PoseArray(
            poses=[geometry_msgs.Pose(position=geometry_msgs.Point(x=a, y=b)) for a, b in xy]
        )
    )
    rt.run(duration=0.3)
    msg = robot.got[-1]
    table = NeighbourTable()
    assert table.update(msg) is None
    r = table.robots["lizi1"]
    assert r.covariance == pytest.approx(np.cov(xy.T))
    assert r.body_radius == pytest.approx(math.hypot(0.19, 0.16), abs=1e-9)
    assert r.radius > r.body_radius + 0.3  # padded for consumers that ignore the covariance
    near = table.near(0.3, (0.0, 0.0), 10.0, 5)
    assert near.body_radii.tolist() == [r.body_radius]
    assert near.covariances[0] == pytest.approx(r.covariance)


def message(rid, cov=None, radius=0.4, x=1.0):
    msg = collvoid_msgs.PoseTwistWithCovariance(robot_id=rid, radius=radius)
    msg.header.stamp = Time.from_sec(1.0)
    msg.pose.pose.position = geometry_msgs.Point(x=x, y=0.0)
    msg.footprint.polygon.points = [geometry_msgs.Point32(x=a, y=b) for a, b in LIZI]
    if cov is not None:
        msg.pose.covariance[[0, 1, 6, 7]] = np.asarray(cov, dtype=float).reshape(-1)
    return msg


def planner_stub(own_cov=None):
    """What `CollvoidLocalPlanner.neighbour_radii` reads of the planner."""
    return SimpleNamespace(_covariance=own_cov, body_radius=0.25, params=SimpleNamespace(eps=0.1))


def test_a_robot_without_covariance_keeps_todays_radius_rule():
    table = NeighbourTable()
    table.update(message("old", radius=0.4))
    r = table.robots["old"]
    assert r.covariance is None and r.body_radius == 0.4
    near = table.near(1.0, (0.0, 0.0), 10.0, 5)
    # fake localization here too: the radii as sent, the very array
    orca, wide, room = CollvoidLocalPlanner.neighbour_radii(planner_stub(), 0.4, np.zeros(2), near)
    assert orca is near.radii and wide is near.radii and room is near.radii
    # this robot uncertain, the other as sent plus this robot's spread (in contact: along x)
    got, wide, room = CollvoidLocalPlanner.neighbour_radii(
        planner_stub(ALONG_X), 0.7, np.zeros(2), near
    )
    assert got[0] == pytest.approx(0.4 + K * 0.15, abs=1e-3)
    # side by side (the line between them across x) only the spread across x counts, halved
    assert wide[0] == pytest.approx(0.4 + 0.5 * K * 0.005)
    assert room[0] == wide[0]  # sharing no spread: its disc


def test_a_robot_sharing_a_covariance_is_its_body_padded_in_the_direction_that_matters():
    table = NeighbourTable()
    pad = widest_spread(ALONG_X, 0.1, 2 * math.hypot(0.19, 0.16))
    msg = message("amcl", cov=ALONG_X, x=4.0)
    msg.holonomic_velocity.x = -0.3  # on its way: its disc (it may turn)
    msg.footprint.polygon.points = [
        geometry_msgs.Point32(x=a, y=b) for a, b in padded_footprint(LIZI, pad)
    ]
    msg.radius = float(np.hypot(0.19 + pad, 0.16 + pad))
    table.update(msg)
    near = table.near(1.0, (0.0, 0.0), 10.0, 5)
    got = CollvoidLocalPlanner.neighbour_radii(planner_stub(), 0.35, np.zeros(2), near)[0][0]
    body = math.hypot(0.19, 0.16)
    # ahead along the corridor: padded by 0.05 m, not the 0.32 m of its widest spread
    assert body + 0.03 < got < body + 0.08 < msg.radius - 0.3
    # standing still it is its body's outline: ahead, its half width (0.16 m), not its disc
    msg.holonomic_velocity.x = 0.0
    table.update(msg)
    near = table.near(1.0, (0.0, 0.0), 10.0, 5)
    orca, wide, room = CollvoidLocalPlanner.neighbour_radii(planner_stub(), 0.35, np.zeros(2), near)
    assert 0.16 + 0.03 < orca[0] < 0.16 + 0.08 < got - 0.05
    # the room beside it (its way round: across the line between the two, here y) is its
    # half width (0.16 m) plus half the spread across, where a passage takes its disc
    assert room[0] == pytest.approx(0.16 + 0.5 * K * 0.005, abs=1e-6)
    assert wide[0] == pytest.approx(body + 0.5 * K * 0.005, abs=1e-6)
    # turned a quarter: its half length (0.19 m) across the line between the two
    msg.pose.pose.orientation = geometry_msgs.Quaternion(
        z=math.sin(math.pi / 4), w=math.cos(math.pi / 4)
    )
    table.update(msg)
    near = table.near(1.0, (0.0, 0.0), 10.0, 5)
    room = CollvoidLocalPlanner.neighbour_radii(planner_stub(), 0.35, np.zeros(2), near)[2]
    assert room[0] == pytest.approx(0.19 + 0.5 * K * 0.005, abs=1e-6)


def test_a_body_in_the_pair_padding_shares_the_tangent_of_its_outline():
    """`pair_padding` with ``bodies``: the radius R (beyond ``base``) with R = the body's
    support plus the spread along the normal of the leg at R (the disc then shares the true
    shape's tangent), never more than with the body's circumscribed disc."""
    rng = np.random.default_rng(4)
    body = LIZI @ np.array([[math.cos(0.4), math.sin(0.4)], [-math.sin(0.4), math.cos(0.4)]])
    circ = math.hypot(0.19, 0.16)
    for _ in range(20):
        rel = rng.uniform(-3.0, 3.0, (1, 2))
        rel[0] += np.sign(rel[0]) * 0.8
        vrel = rng.uniform(-0.5, 0.5, (1, 2))
        args = (None, 0.5, np.array([ALONG_X]), np.array([0.5]), 0.1, vrel)
        with_body = pair_padding(rel, np.array([0.26]), *args, bodies=body[None], iterations=30)
        disc = circ + pair_padding(rel, np.array([0.26 + circ]), *args, iterations=30)
        assert with_body[0] <= disc[0] + 1e-6
        # self-consistent on one of the legs: R = body support + spread along its normal
        d = float(np.hypot(*rel[0]))
        u = rel[0] / d
        perp = np.array([-u[1], u[0]])
        s = min(1.0, (0.26 + with_body[0]) / d)
        c = math.sqrt(1.0 - s * s)
        legs = [s * u + c * perp, s * u - c * perp]
        shapes = [(body @ n).max() + spread_along(ALONG_X, n[None], 0.1, 0.5)[0] for n in legs]
        assert min(abs(h - with_body[0]) for h in shapes) < 1e-3 or s == 1.0


def test_the_outline_is_the_body_plus_the_spread_in_every_direction():
    cov = np.array([[0.2**2, 0.01], [0.01, 0.06**2]])
    out = spread_outline(LIZI, cov, 0.5, 0.1)
    ang = np.linspace(0.0, 2.0 * math.pi, 721)
    n = np.stack((np.cos(ang), np.sin(ang)), axis=1)
    want = (LIZI @ n.T).max(axis=0) + spread_along(cov, n, 0.1, 0.5)
    got = (out @ n.T).max(axis=0)
    # it holds the true sum (never inside it) and stands off it by under 5 mm
    assert (got >= want - 1e-9).all()
    assert (got - want).max() < 0.005
    # capped: a spread of 1 m along x at 0.3 m, 0.1 m along y as it is
    capped = spread_outline(LIZI, np.diag([1.0, (0.1 / K) ** 2]), 0.3, 0.1)
    assert capped[:, 0].max() == pytest.approx(0.19 + 0.3)
    assert capped[:, 1].max() == pytest.approx(0.16 + 0.1)


def test_without_a_spread_the_outline_is_the_footprint_itself():
    # the polygon of support lines is the footprint's own outline (with repeated corners)
    for cov in (None, np.zeros((2, 2))):
        out = spread_outline(LIZI, cov, 0.5, 0.1)
        assert set(map(tuple, np.round(out, 12))) == set(map(tuple, np.round(LIZI, 12)))
    table = NeighbourTable()
    table.update(message("fake"))
    r = table.robots["fake"]
    assert r.outline(0.1) is r.footprint  # fake_localization: the footprint as sent, exactly


def test_a_parked_robot_uncertain_along_a_corridor_leaves_room_beside_it():
    """A lizi parked in the middle of a 2 m corridor (along x), amcl's particles 0.25 m along
    it and 0.06 m across: padded by its widest spread (what it shares) it closes the corridor
    to another lizi (0.32 m wide, and a 5 cm cell either side), by the spread in each
    direction it leaves room."""
    cov = np.diag([0.25**2, 0.06**2])
    pad = widest_spread(cov, 0.1, 2 * math.hypot(0.19, 0.16))
    msg = message("amcl", cov=cov)
    msg.footprint.polygon.points = [
        geometry_msgs.Point32(x=a, y=b) for a, b in padded_footprint(LIZI, pad)
    ]
    table = NeighbourTable()
    table.update(msg)
    r = table.robots["amcl"]
    assert r.body_footprint == pytest.approx(LIZI)
    room_shared = 1.0 - r.footprint[:, 1].max()  # to the wall on either side
    room = 1.0 - r.outline(0.1)[:, 1].max()
    assert room_shared < 0.32 + 2 * 0.05 < room
    # turned 30 degrees, the spread stays the map's: the outline, placed, has the body's
    # support plus the map covariance's spread along every map direction
    half = math.radians(30.0) / 2
    msg.pose.pose.orientation = geometry_msgs.Quaternion(z=math.sin(half), w=math.cos(half))
    cov = np.array([[0.2**2, 0.004], [0.004, 0.06**2]])
    msg.pose.covariance[[0, 1, 6, 7]] = cov.reshape(-1)
    pad = widest_spread(cov, 0.1, 2 * math.hypot(0.19, 0.16))
    msg.footprint.polygon.points = [
        geometry_msgs.Point32(x=a, y=b) for a, b in padded_footprint(LIZI, pad)
    ]
    table.update(msg)
    r = table.robots["amcl"]
    c, s = math.cos(r.yaw), math.sin(r.yaw)
    to_map = np.array([[c, s], [-s, c]])  # row vectors: p @ to_map is R p
    ang = np.linspace(0.0, 2.0 * math.pi, 361)
    n = np.stack((np.cos(ang), np.sin(ang)), axis=1)
    want = ((LIZI @ to_map) @ n.T).max(axis=0) + spread_along(cov, n, 0.1, 2 * r.body_radius)
    got = ((r.outline(0.1) @ to_map) @ n.T).max(axis=0)
    assert (got >= want - 1e-9).all() and (got - want).max() < 0.005
    # padded (a planner's inscribed radius): the same plus the padding in every direction
    padded = ((r.outline(0.1, pad=0.16) @ to_map) @ n.T).max(axis=0)
    assert (padded >= want + 0.16 - 1e-9).all() and (padded - want - 0.16).max() < 0.005


def test_with_eps_zero_the_outline_is_the_body_and_a_disc_of_the_cap():
    out = spread_outline(LIZI, np.diag([0.0, 0.01]), 0.5, 0.0)
    r = np.hypot(out[:, 0], out[:, 1])
    assert r.max() < math.hypot(0.19, 0.16) + 0.5 + 0.005  # bounded, where a cap by
    assert out[:, 0].max() == pytest.approx(0.19 + 0.5)  # direction of a degenerate
    assert out[:, 1].max() == pytest.approx(0.16 + 0.5)  # spread was not convex


@pytest.mark.parametrize(
    "cov, words",
    [
        ([[math.nan, 0.0], [0.0, 0.01]], "non-finite covariance"),
        ([[0.01, 0.0], [0.0, -0.01]], "not symmetric positive semi-definite"),
        ([[0.01, 0.005], [0.0, 0.01]], "not symmetric positive semi-definite"),
    ],
)
def test_a_bad_covariance_is_ignored_with_one_warning_naming_the_robot(cov, words, caplog):
    rt = Runtime()
    node = Node(rt, "listener", "/lizi2")
    share = PositionShare(node)
    with caplog.at_level(logging.WARNING):
        for _ in range(3):
            share.on_message(message("lizi7", cov=cov, radius=0.4))
    warned = [r.getMessage() for r in caplog.records if "lizi7" in r.getMessage()]
    assert len(warned) == 1 and words in warned[0]
    r = share.table.robots["lizi7"]  # the robot is kept, with the radius as sent
    assert r.covariance is None and r.body_radius == 0.4 and share.rejected == 0


def test_the_leg_the_relative_velocity_passes_sets_the_padding():
    """Two robots uncertain along x, standing diagonally (0.4 m apart along x, 1.3 m across):
    passing each other along x, the leg that matters is the near one, nearly across x; the far
    leg runs much more along x, over the spread (both legs' larger without a velocity, or
    drawing apart, where the far leg is the near one)."""
    rel, base = np.array([[0.4, 1.3]]), np.array([0.57])
    covs, caps = ALONG_X[None], np.array([0.5])
    passing = pair_padding(rel, base, ALONG_X, 0.5, covs, caps, 0.1, vrel=[[0.6, 0.0]])[0]
    apart = pair_padding(rel, base, ALONG_X, 0.5, covs, caps, 0.1, vrel=[[-0.6, 0.0]])[0]
    both = pair_padding(rel, base, ALONG_X, 0.5, covs, caps, 0.1)[0]
    assert passing < 0.7 * both and apart == both
    mirrored = pair_padding(-rel, base, ALONG_X, 0.5, covs, caps, 0.1, vrel=[[-0.6, 0.0]])[0]
    assert mirrored == pytest.approx(passing)
