"""Tests for fleetsim.slam.peers: the beams that end on another robot are left out of gmapping's
matching and mapping; that robot is found through tf, and a stale or missing one is warned about.

The other robot is a disc in the synthetic room (slam_world's ``peer_disc``); each test runs the
same scans without the filter too, so it fails should the filter do nothing.
"""

import logging

import numpy as np
import pytest
from slam_world import LASER, ROUTE, disc_ranges, drive, exact_ranges
from test_slam_node import START, world

from fleetsim.errors import ParameterError
from fleetsim.runtime import Node, Runtime
from fleetsim.slam import SlamGmapping
from fleetsim.slam.filter import Beams, GmappingFilter
from fleetsim.slam.params import GmappingParams
from fleetsim.slam.peers import PEER_PATIENCE, beams_clear_of_peers, peers_in_base
from fleetsim.tf import Buffer, TransformBroadcaster, make_transform_stamped

ANGLES = -np.pi + 2 * np.pi / 360 * np.arange(360)
PEER = (2.0, 3.0, 0.25)  # a robot standing next to the route's first legs: x, y, radius (m)
REACH = 0.25 + 0.1  # its radius and the margin


def scan_with_peer(true, peer=PEER, rng=None):
    """(ranges, angles, on_peer) of a 360-beam scan from ``true`` with the peer disc in view."""
    c, s = np.cos(true[2]), np.sin(true[2])
    sensor = true + np.array([c * LASER[0], s * LASER[0], 0.0])
    walls = exact_ranges(sensor, ANGLES, 12.0)
    disc = disc_ranges(sensor, ANGLES, peer[:2], peer[2])
    ranges = np.minimum(walls, disc)
    if rng is not None:
        ranges = ranges + 0.01 * rng.standard_normal(len(ranges))
    keep = np.isfinite(ranges)
    return ranges[keep], ANGLES[keep], (disc < walls)[keep]


def in_base(true, point):
    """``point`` (x, y) of the world in the base frame of a robot at ``true``."""
    c, s = np.cos(true[2]), np.sin(true[2])
    dx, dy = point[0] - true[0], point[1] - true[1]
    return np.array([[c * dx + s * dy, -s * dx + c * dy]])


def occupied_near(data, geom, centre, radius):
    """Occupied cells of a map ``data`` (H, W), ``geom`` (ox, oy, delta) within ``radius``."""
    iy, ix = np.nonzero(data == 100)
    x, y = geom[0] + (ix + 0.5) * geom[2], geom[1] + (iy + 0.5) * geom[2]
    return int(np.sum(np.hypot(x - centre[0], y - centre[1]) < radius))


def test_exactly_the_beams_that_end_on_the_peer_are_left_out():
    true = np.array([3.0, 1.6, 0.7])
    ranges, angles, on_peer = scan_with_peer(true)
    assert on_peer.sum() > 10  # the peer is in view
    keep = beams_clear_of_peers(ranges, angles, LASER, in_base(true, PEER[:2]), REACH)
    assert np.array_equal(keep, ~on_peer)
    # no peer: every beam kept
    assert beams_clear_of_peers(ranges, angles, LASER, np.zeros((0, 2)), REACH).all()
    # a peer placed 1 m off where it is: its beams kept (the filter looks where tf says)
    off = in_base(true, (PEER[0] + 1.0, PEER[1]))
    assert beams_clear_of_peers(ranges, angles, LASER, off, REACH)[on_peer].all()


@pytest.mark.parametrize("leave_out", [True, False])
def test_the_filter_does_not_map_a_peer_whose_beams_are_left_out(leave_out):
    rng = np.random.default_rng(3)
    params = GmappingParams(
        particles=5, xmin=-4, ymin=-4, xmax=14, ymax=10, linearUpdate=0.3, angularUpdate=0.3
    )
    f = GmappingFilter(params, rng, LASER, 11.99, 11.99)
    steps = drive(ROUTE[:3], rng, odom_noise=0.0, odom_bias=0.0)
    for true, odom in steps:
        ranges, angles, _ = scan_with_peer(true, rng=rng)
        if leave_out:
            keep = beams_clear_of_peers(ranges, angles, LASER, in_base(true, PEER[:2]), REACH)
            ranges, angles = ranges[keep], angles[keep]
        f.process(odom, 0.0, Beams(ranges, angles))
    assert f.updates > 5
    data, geom = f.occupancy()
    # the map frame starts on the route's first pose (yaw 0)
    peer_in_map = (PEER[0] - ROUTE[0][0], PEER[1] - ROUTE[0][1])
    near = occupied_near(data, geom, peer_in_map, PEER[2] + 0.1)
    if leave_out:
        assert near == 0
    else:
        assert near > 5  # the control: gmapping maps the standing robot


class Peer(Node):
    """Broadcasts the peer's base frame in the map frame every 0.05 s while ``alive``."""

    def __init__(self, rt, frame="peer/base_link"):
        super().__init__(rt, "peer")
        self.alive = True
        self.frame = frame
        self.tf = TransformBroadcaster(self)
        self.create_timer(0.05, self.tick)
        self.tick()

    def tick(self):
        if self.alive:
            x, y = PEER[0] - START[0], PEER[1] - START[1]  # the map frame starts on START
            self.tf.send_transform(
                make_transform_stamped("map", self.frame, self.now(), (x, y, 0.0), (0, 0, 0, 1))
            )


def two_robots(peer_frames, **kw):
    params = {"map_update_interval": 1.0, "linearUpdate": 0.3, "peer_frames": peer_frames, **kw}
    rt, robot, slam, out = world(params=params, route=ROUTE[:3])
    robot.peer_disc = PEER
    peer = Peer(rt)
    return rt, robot, slam, out, peer


def published_near_peer(grid):
    data = np.asarray(grid.data).reshape(grid.info.height, grid.info.width)
    o = grid.info.origin.position
    peer_in_map = (PEER[0] - START[0], PEER[1] - START[1])
    return occupied_near(data, (o.x, o.y, grid.info.resolution), peer_in_map, PEER[2] + 0.1)


def test_slam_gmapping_leaves_out_a_peer_found_through_tf(caplog):
    with caplog.at_level(logging.WARNING):
        rt, robot, slam, out, _ = two_robots(["/peer/base_link"])
        rt.run(duration=8.0)
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    assert slam.filter.updates > 5 and slam.peer_beams_dropped > 100
    assert published_near_peer(out.maps[-1]) == 0
    # the control: without peer_frames gmapping maps the peer as an obstacle
    rt, robot, slam, out, _ = two_robots([])
    rt.run(duration=8.0)
    assert slam.peer_beams_dropped == 0 and published_near_peer(out.maps[-1]) > 5


def test_a_stale_or_missing_peer_is_warned_about_once_naming_its_frame(caplog):
    rt, robot, slam, out, peer = two_robots(["peer/base_link"])
    rt.run(duration=2.0)
    dropped, updates = slam.peer_beams_dropped, slam.filter.updates
    assert dropped > 0
    peer.alive = False  # the peer's tf stops: scans wait PEER_PATIENCE, then keep its beams
    with caplog.at_level(logging.WARNING):
        rt.run(duration=4.0)
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert len(warnings) == 1, warnings
    assert "keeping the beams of /scan that may end on the peer peer/base_link" in warnings[0]
    assert "no pose of peer/base_link at the scan's time" in warnings[0]
    assert slam.filter.updates > updates  # the scans go on, unfiltered
    dropped, updates = slam.peer_beams_dropped, slam.filter.updates
    rt.run(duration=3.0)
    assert slam.peer_beams_dropped == dropped and slam.filter.updates > updates
    # a peer frame that never appears: waited for through the start, then warned about
    caplog.clear()
    with caplog.at_level(logging.WARNING):
        rt, robot, slam, out, _ = two_robots(["ghost/base_link"])
        rt.run(duration=3.0)
    warnings = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert (
        len(warnings) == 1
        and "the peer ghost/base_link: cannot find ghost/base_link in " in (warnings[0])
    )
    assert slam.filter.updates > 1


def test_peers_in_base_waits_for_a_peer_a_little_behind_then_reports_it_missing():
    buf = Buffer()
    own = make_transform_stamped("map", "base_link", 1.0, (1.0, 0.0, 0.0), (0, 0, 0, 1))
    buf.set_transform(own, is_static=True)
    for t in (0.9, 1.0):
        buf.set_transform(
            make_transform_stamped("map", "peer/base_link", t, (3.0, 0.0, 0.0), (0, 0, 0, 1))
        )
    found = peers_in_base(buf, "base_link", ["peer/base_link"], 1.0, 1.05, grace=1.0)
    assert found.positions == pytest.approx(np.array([[2.0, 0.0]])) and not found.wait
    behind = peers_in_base(buf, "base_link", ["peer/base_link"], 1.1, 1.1, grace=1.0)
    assert behind.wait and not behind.missing and len(behind.positions) == 0
    late = peers_in_base(buf, "base_link", ["peer/base_link"], 1.1, 1.11 + PEER_PATIENCE, 1.0)
    assert not late.wait and "peer/base_link" in late.missing
    # a scan from before the peer's first transform: dropped at the start, missing after it
    assert peers_in_base(buf, "base_link", ["peer/base_link"], 0.5, 0.6, grace=1.0).skip
    old = peers_in_base(buf, "base_link", ["peer/base_link"], 0.5, 1.2, grace=1.0)
    assert not old.skip and "extrapolation into the past" in old.missing["peer/base_link"]
    # not in tf: waited for during the start (grace), missing after it
    assert peers_in_base(buf, "base_link", ["x/base_link"], 0.5, 0.5, grace=1.0).wait
    gone = peers_in_base(buf, "base_link", ["x/base_link"], 1.0, 1.0, grace=1.0)
    assert not gone.wait and "does not exist" in gone.missing["x/base_link"]


def test_peer_frames_are_checked():
    rt = Runtime(seed=0)
    rt.params.set("/slam_gmapping/peer_frames", ["hunter2/base_link", 3])
    with pytest.raises(ParameterError, match="peer_frames holds 3"):
        SlamGmapping(rt)
    rt = Runtime(seed=0)
    rt.params.set("/r1/tf_prefix", "r1")
    rt.params.set("/r1/slam_gmapping/peer_frames", ["r1/base_link"])
    with pytest.raises(ParameterError, match="the robot's own base frame r1/base_link"):
        SlamGmapping(rt, "slam_gmapping", "/r1")
