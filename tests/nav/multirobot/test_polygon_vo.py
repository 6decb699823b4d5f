"""Polygonal velocity obstacles (`polygon_vo`, collvoid's ``use_polygon_footprint``): RVO2's
disc half-planes are the reference (fine polygons round two discs give them), rectangles abreast
pass where their discs would not, overlaps and gaps are measured on the true shapes, and
collvoid's planner drives two jackals side by side in polygon mode without contact."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from shapely.geometry import MultiPoint, Polygon
from test_collvoid_planner import Fleet

from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_at
from fleetsim.nav.multirobot.orca import (
    contact_halfplanes_along,
    orca_halfplanes,
    orca_velocity,
)
from fleetsim.nav.multirobot.polygon_vo import (
    _hull,
    pair_shapes,
    polygon_orca_halfplanes,
    shape_gaps,
)
from fleetsim.runtime import Node, Runtime

#: a jackal's padded footprint (the shipped costmap_common_params.yaml, 0.05 m padding)
JACKAL = np.array([[-0.31, -0.27], [-0.31, 0.27], [0.31, 0.27], [0.31, -0.27]])


def ring(r: float, sides: int) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * math.pi, sides, endpoint=False)
    return np.stack((r * np.cos(a), r * np.sin(a)), axis=1)


def turned(poly: np.ndarray, yaw: float) -> np.ndarray:
    return footprint_at(poly, 0.0, 0.0, yaw)


def test_fine_polygons_round_two_discs_give_rvo2s_half_planes():
    """Against `orca_halfplanes` (RVO2's construction): a 2048-gon round the pair's combined
    disc, apart and overlapping, the line's direction and offset within what the polygon's
    facets allow (the Minkowski sum itself: the gap test below)."""
    rng = np.random.default_rng(0)
    n = 400
    rel = rng.uniform(-3.0, 3.0, (n, 2))
    rv = rng.uniform(-1.0, 1.0, (n, 2))
    vel = rng.uniform(-0.5, 0.5, 2)
    r = rng.uniform(0.2, 0.8, n)
    resp = rng.choice([0.5, 1.0], n)
    point = np.zeros((1, 2))
    for k in range(n):
        shape, size = pair_shapes(rel[k : k + 1], point, [ring(r[k], 2048)], 0.0)
        p, d, touching = polygon_orca_halfplanes(shape, size, rv[k], vel, 3.0, 0.1, resp[k])
        p2, d2 = orca_halfplanes(
            rel[k : k + 1], rv[k : k + 1], r[k : k + 1], vel, 3.0, 0.1, resp[k : k + 1]
        )
        dist = float(np.hypot(*rel[k]))
        if abs(dist - r[k]) > 1e-3:
            assert touching[0] == (dist < r[k])
        assert np.abs(d - d2).max() < 0.005, k
        offset = d2[0, 0] * (p[0, 1] - p2[0, 1]) - d2[0, 1] * (p[0, 0] - p2[0, 0])
        assert abs(offset) < 0.005, k


def test_two_rectangles_abreast_keep_their_way_where_their_discs_would_part_them():
    """Two jackals side by side 0.6 m apart (0.54 m wide, discs of 0.41 m), both east at
    0.5 m/s: as rectangles they may go on as they are; as discs they overlap and ORCA pushes
    them apart."""
    rel = np.array([[0.0, 0.6]])
    own, other = JACKAL, [JACKAL]
    shape, size = pair_shapes(rel, own, other, 0.0)
    p, d, touching = polygon_orca_halfplanes(shape, size, [0.0, 0.0], [0.5, 0.0], 3.0, 0.1, 0.5)
    assert not touching[0]
    v, ok = orca_velocity(p, d, 0.5, np.array([0.5, 0.0]))
    assert ok and v == pytest.approx([0.5, 0.0], abs=1e-9)
    r = float(np.hypot(*JACKAL.T).max())
    p2, d2 = orca_halfplanes(rel, [[0.0, 0.0]], [2 * r], [0.5, 0.0], 3.0, 0.1, [0.5])
    v2, _ = orca_velocity(p2, d2, 0.5, np.array([0.5, 0.0]))
    assert v2[1] < -0.1  # the discs overlap: pushed off sideways
    # nose to tail 0.6 m apart the rectangles overlap (0.62 m long): parted at once
    shape, size = pair_shapes(np.array([[0.6, 0.0]]), own, other, 0.0)
    _, _, touching = polygon_orca_halfplanes(shape, size, [0.0, 0.0], [0.5, 0.0], 3.0, 0.1, 0.5)
    assert touching[0]


#: footprints that no half turn maps onto themselves, their centres off their middles (a
#: Minkowski sum taken the wrong way round, or a footprint turned the wrong way, shows)
WEDGE = np.array([[0.35, 0.02], [-0.1, 0.22], [-0.18, -0.25]])
KITE = np.array([[0.3, -0.05], [0.1, 0.2], [-0.25, 0.1], [-0.05, -0.3]])


def test_the_shapes_overlap_exactly_when_the_footprints_do_and_the_gap_is_their_distance():
    rng = np.random.default_rng(4)
    for _ in range(400):
        rel = rng.uniform(-1.0, 1.0, 2)
        ya, yb = rng.uniform(-math.pi, math.pi, 2)
        pad = float(rng.choice([0.0, 0.07]))
        a, b = turned(WEDGE, ya), turned(KITE, yb)
        shape, size = pair_shapes(rel[None], a, [b], pad)
        normals, gaps = shape_gaps(shape, size)
        pa, pb = Polygon(a), Polygon(b + rel)
        true = pa.distance(pb) if not pa.intersects(pb) else -1.0
        # the pad is a 16-gon holding the disc: up to 2 % of it further out
        if true >= 0.0:
            assert gaps[0] == pytest.approx(true - pad, abs=0.02 * pad + 1e-9)
            if pad == 0.0:  # moving ours along the normal by the gap makes the bodies touch
                moved = Polygon(a + gaps[0] * normals[0])
                assert moved.distance(pb) == pytest.approx(0.0, abs=1e-6)
        elif pad == 0.0:
            assert gaps[0] < 0.0
            # the depth: moved back by it along the normal, they just touch
            moved = Polygon(a + (gaps[0] - 1e-9) * normals[0])
            assert moved.distance(pb) < 1e-6 and moved.intersection(pb).area < 1e-6


def test_the_hull_drops_repeated_and_collinear_points():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0], [1, 1], [0, 0], [0.5, 0.5]])
    h = _hull(square.astype(float))
    assert len(h) == 4 and Polygon(h).exterior.is_ccw and Polygon(h).area == pytest.approx(1.0)
    assert _hull(np.ones((5, 2))).tolist() == [[1.0, 1.0]]
    line = np.array([[0.0, 0.0], [1.0, 1.0], [0.5, 0.5], [2.0, 2.0]])
    assert sorted(map(tuple, _hull(line))) == [(0.0, 0.0), (2.0, 2.0)]
    rng = np.random.default_rng(6)
    for _ in range(200):
        pts = np.round(rng.uniform(-1.0, 1.0, (rng.integers(3, 30), 2)), 1)
        ref = MultiPoint(pts).convex_hull
        if ref.geom_type == "Polygon":
            h = Polygon(_hull(pts))
            assert h.exterior.is_ccw and h.area == pytest.approx(ref.area, abs=1e-12)


def test_a_follower_closes_on_a_robot_ahead_no_faster_than_the_gap_allows():
    """Nose to tail, 0.1 m between the bodies, the one ahead standing: the contact half-plane
    along the shapes' gap holds our approach to 0.1 m/s (``closing_time`` 1 s), and a sideways
    velocity stays free."""
    shape, size = pair_shapes(np.array([[0.72, 0.0]]), JACKAL, [JACKAL], 0.0)
    normals, gaps = shape_gaps(shape, size)
    assert normals[0] == pytest.approx([1.0, 0.0]) and gaps[0] == pytest.approx(0.1)
    p, d = contact_halfplanes_along(normals, gaps, [[0.5, 0.0]], [0.5, 0.0], 1.0, [1.0])
    v, ok = orca_velocity(p, d, 0.5, np.array([0.5, 0.0]))
    assert ok and v == pytest.approx([0.1, 0.0])
    v, _ = orca_velocity(p, d, 0.5, np.array([0.0, 0.5]))
    assert v == pytest.approx([0.0, 0.5])


def min_polygon_gap(f: Fleet) -> float:
    polys = [Polygon(turned(f.footprint, yaw) + np.array([x, y])) for x, y, yaw in f.state]
    return min(
        polys[i].distance(polys[j]) - (1.0 if polys[i].intersects(polys[j]) else 0.0)
        for i in range(len(polys))
        for j in range(i + 1, len(polys))
    )


class PolygonFleet(Fleet):
    """A Fleet that tracks the least distance between the robots' true footprints."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.min_body_gap = math.inf

    def see(self):
        self.min_body_gap = min(self.min_body_gap, min_polygon_gap(self))


def test_two_jackals_abreast_stay_abreast_in_polygon_mode():
    """Two jackals 0.62 m apart, side by side, sent 6 m east: as rectangles they drive on side
    by side without touching. (As discs of 0.41 m they are pushed apart, turn away from each
    other on the spot, and their corners sweep into each other: not a start disc mode meets,
    its robots never come that close.)"""
    starts = [(0.0, 0.0, 0.0), (0.0, 0.62, 0.0)]
    goals = [(6.0, 0.0, 0.0), (6.0, 0.62, 0.0)]
    f = PolygonFleet(
        starts, goals, footprint=JACKAL, use_polygon_footprint=True, safety_margin=0.0,
        min_error_holo=0.01, max_error_holo=0.05,
    )  # fmt: skip
    widest = 0.0
    for _ in range(40):
        f.run(0.3)
        widest = max(widest, float(abs(f.state[1, 1] - f.state[0, 1])))
    assert f.run(20.0)
    assert f.min_body_gap > 0.0
    assert widest < 0.66


def test_head_on_jackals_in_a_corridor_pass_in_polygon_mode_without_contact():
    """Two jackals swap ends of a 1.6 m corridor, too narrow for their discs side by side
    (0.82 m each) and wide enough for their bodies (0.54 m): they pass side by side, neither
    backs out to yield (the passage is judged by their half widths, `_sides`; as discs robot2
    backs out 2.9 m first), and their true shapes never touch."""
    walls = [(-8, 0.8, 8, 1.0), (-8, -1.0, 8, -0.8)]
    f = PolygonFleet(
        [(-4, 0, 0), (4, 0, math.pi)], [(4, 0, 0), (-4, 0, math.pi)], walls=walls,
        footprint=JACKAL, use_polygon_footprint=True, safety_margin=0.0,
    )  # fmt: skip
    assert f.run(25.0)
    assert f.min_body_gap > 0.0
    assert np.all(f.backed == 0.0)


def test_the_planners_pair_shapes_turn_both_footprints_and_carry_margin_allowance_and_spread():
    """`_pair_polygons` against shapely: our WEDGE at our heading and a neighbour's KITE at its
    own, both turned the right way (no half turn maps them onto themselves), the ORCA shape
    grown by margin + spread + tracking allowance and the contact shape by margin + spread."""
    node = Node(Runtime(), "move_base", "/robot1")
    costmap_ros = SimpleNamespace(
        costmap=Costmap2D(80, 80, 0.05, -2.0, -2.0), footprint=WEDGE, global_frame="map"
    )
    params = {"use_polygon_footprint": True, "safety_margin": 0.03}
    pl = CollvoidLocalPlanner.from_namespace(node, costmap_ros, params, "robot1")
    pl.near_by_id = {"robot2": SimpleNamespace(body=KITE)}
    rng = np.random.default_rng(7)
    for _ in range(100):
        rel = rng.uniform(-1.5, 1.5, (1, 2))
        yaw, their_yaw = rng.uniform(-math.pi, math.pi, 2)
        spread, allowance = rng.uniform(0.0, 0.08, 2)
        pl.near_spreads = {"robot2": spread}
        hard = np.array([1.0])
        (orca, body), (orca_n, body_n) = pl._pair_polygons(
            yaw, rel, ["robot2"], np.array([their_yaw]), hard + allowance, hard
        )
        ours = Polygon(turned(WEDGE, yaw))
        theirs = Polygon(turned(KITE, their_yaw) + rel[0])
        if ours.intersects(theirs):
            assert shape_gaps(body, body_n)[1][0] < 0.0
            continue
        true = ours.distance(theirs)
        for shape, n, pad in (
            (orca, orca_n, 0.03 + spread + allowance),
            (body, body_n, 0.03 + spread),
        ):
            gap = shape_gaps(shape, n)[1][0]
            assert gap == pytest.approx(true - pad, abs=0.02 * pad + 1e-9)
