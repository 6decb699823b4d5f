"""NavFn against a brute-force Dijkstra reference, tolerance, and typed failures."""

import heapq
import math

import numpy as np
import pytest

from fleetsim.nav.costmap import NO_INFORMATION, Costmap2D
from fleetsim.nav.errors import GoalOccupied, GoalOutsideMap, NoPathFound, StartOutsideMap
from fleetsim.nav.planners import NavFn, NavfnParams
from fleetsim.nav.planners.navfn_kernels import (
    POT_HIGH,
    known_bounds,
    navfn_costs,
    navfn_potential,
)


def dijkstra4(costarr, nx, src):
    """Reference: 4-connected Dijkstra where entering a cell costs its navfn cost."""
    dist = np.full(costarr.size, np.inf)
    dist[src] = 0.0
    heap = [(0.0, src)]
    while heap:
        d, n = heapq.heappop(heap)
        if d > dist[n]:
            continue
        for m in (n - 1, n + 1, n - nx, n + nx):
            if 0 <= m < costarr.size and costarr[m] < 254 and d + costarr[m] < dist[m]:
                dist[m] = d + costarr[m]
                heapq.heappush(heap, (dist[m], m))
    return dist


def random_grid(rng, ny=24, nx=30):
    costs = rng.integers(0, 200, (ny, nx)).astype(np.uint8)
    costs[rng.random((ny, nx)) < 0.2] = 254
    return costs


@pytest.mark.parametrize("seed", range(6))
def test_potential_bounded_by_dijkstra(seed):
    rng = np.random.default_rng(seed)
    costs = random_grid(rng)
    nx = costs.shape[1]
    costarr = navfn_costs(costs, True)
    free = np.flatnonzero(costarr < 254)
    src = int(free[0])
    pot, finished = navfn_potential(costarr, nx, src, 0, False, 10**6)
    ref = dijkstra4(costarr, nx, src)
    assert finished
    reach = np.isfinite(ref)
    assert np.array_equal(pot < POT_HIGH, reach)  # same reachable set
    # the Eikonal potential lies between the L1 (4-connected) cost and that cost / sqrt(2)
    assert (pot[reach] <= ref[reach] * (1 + 1e-3)).all()  # float32 rounding
    assert (pot[reach] >= ref[reach] / math.sqrt(2) - 1e-3).all()


def open_map(n=60, res=0.1):
    m = Costmap2D(n, n, res)
    m.costs[:, 30] = 254
    m.costs[45:50, 30] = 0  # a door
    return m


def test_plan_goes_through_the_door_and_is_near_optimal():
    m = open_map()
    nf = NavFn(m)
    path = nf.create_plan((1.0, 1.0, 0.0), (5.0, 1.0, 1.0))
    assert path.poses[0, :2].tolist() == [1.0, 1.0]
    assert path.poses[-1].tolist() == pytest.approx([5.0, 1.0, 1.0])
    cells, inside = m.cells_of(path.poses[:, :2])
    assert inside.all() and (m.costs[cells[:, 1], cells[:, 0]] < 254).all()
    assert (cells[:, 1] >= 45).any()  # through the door
    straight = math.hypot(3.0 - 1.0, 4.75 - 1.0) + math.hypot(5.0 - 3.0, 4.75 - 1.0)
    assert straight * 0.95 < path.length < straight * 1.15


def test_typed_failures_and_tolerance():
    m = open_map()
    nf = NavFn(m)
    with pytest.raises(StartOutsideMap, match="start \\(-1.000, 1.000\\) is off the global"):
        nf.create_plan((-1.0, 1.0, 0.0), (5.0, 1.0, 0.0))
    with pytest.raises(GoalOutsideMap, match="goal \\(9.000, 1.000\\) is off"):
        nf.create_plan((1.0, 1.0, 0.0), (9.0, 1.0, 0.0))
    with pytest.raises(GoalOccupied, match="goal \\(3.050, 1.000\\) is in an obstacle"):
        nf.create_plan((1.0, 1.0, 0.0), (3.05, 1.0, 0.0))
    tol = NavFn(m, NavfnParams(default_tolerance=0.2))
    path = tol.create_plan((1.0, 1.0, 0.0), (3.05, 1.0, 0.0))
    assert math.hypot(*(path.poses[-1, :2] - [3.05, 1.0])) <= 0.2 + 1e-9
    m.costs[45:50, 30] = 254  # close the door
    with pytest.raises(NoPathFound, match="not connected"):
        nf.create_plan((1.0, 1.0, 0.0), (5.0, 1.0, 0.0))


def test_unknown_space_respects_allow_unknown():
    m = Costmap2D(40, 20, 0.1)
    m.costs[:, 20] = 255
    assert len(NavFn(m).create_plan((0.5, 1.0, 0), (3.5, 1.0, 0))) > 2
    with pytest.raises(NoPathFound):
        NavFn(m, NavfnParams(allow_unknown=False)).create_plan((0.5, 1.0, 0), (3.5, 1.0, 0))


def navfn_reference(costarr, nx, goal):
    """navfn's propNavFnDijkstra + updateCell transcribed line by line (float32 scalars)."""
    f32 = np.float32
    ns = costarr.size
    pot = np.full(ns, POT_HIGH, np.float32)
    pending = np.zeros(ns, bool)
    cur, nxt, over = [], [], []

    def push(buf, n):
        if 0 <= n < ns and not pending[n] and costarr[n] < 254:
            buf.append(n)
            pending[n] = True

    pot[goal] = 0
    for n in (goal + 1, goal - 1, goal - nx, goal + nx):
        push(cur, n)
    cur_t = f32(254)
    while cur or nxt:
        for n in cur:
            pending[n] = False
        for n in cur:
            le, ri, up, dn = pot[n - 1], pot[n + 1], pot[n - nx], pot[n + nx]
            tc, ta = min(le, ri), min(up, dn)
            hf = f32(costarr[n])
            dc = tc - ta
            if dc < 0:
                dc, ta = -dc, tc
            if dc >= hf:
                p = f32(ta + hf)
            else:
                d = f32(dc / hf)
                p = f32(ta + hf * (f32(-0.2301) * d * d + f32(0.5307) * d + f32(0.7040)))
            if p < pot[n]:
                pot[n] = p
                buf = nxt if p < cur_t else over
                for m, v in ((n - 1, le), (n + 1, ri), (n - nx, up), (n + nx, dn)):
                    if v > p + f32(0.707106781) * f32(costarr[m]):
                        push(buf, m)
        cur, nxt = nxt, []
        if not cur:
            cur_t = f32(cur_t + 100)
            cur, over = over, []
    return pot


@pytest.mark.parametrize("seed", range(3))
def test_potential_is_navfns_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    costs = random_grid(rng, 16, 20)
    costarr = navfn_costs(costs, True)
    src = int(rng.choice(np.flatnonzero(costarr < 254)))
    pot, _ = navfn_potential(costarr, 20, src, 0, False, 10**6)
    assert np.array_equal(pot, navfn_reference(costarr, 20, src))


def clutter_row(res=0.05):
    """A 6 x 6 m room split by a row of clutter at y = 3 m with two gaps: 0.4 m at x = 2.5 m,
    which a lizi (0.38 x 0.32 m, circumscribed 0.25 m) passes straight but cannot turn in, and
    1.0 m at x = 4.5 m; inflated as the lizi's costmaps are (0.45 m, scaling 5)."""
    from scipy import ndimage

    from fleetsim.nav.costmap.inflation_layer import costs_from_distances

    n = round(6.0 / res)
    lethal = np.zeros((n, n), bool)
    lethal[round(2.95 / res) : round(3.05 / res), :] = True
    for lo, hi in ((2.3, 2.7), (4.0, 5.0)):  # the gaps
        lethal[:, round(lo / res) : round(hi / res)] = False
    m = Costmap2D(n, n, res)
    dist = ndimage.distance_transform_edt(~lethal)
    m.costs[:] = costs_from_distances(dist, res, 0.16, 0.45, 5.0)
    return m


def test_circumscribed_clearance_plans_through_the_gap_the_body_can_turn_in():
    from fleetsim.nav.costmap.footprint import footprint_costs, outline_points
    from fleetsim.nav.move_base_plugins import circumscribed_cost

    m = clutter_row()
    footprint = np.array([[-0.19, -0.16], [-0.19, 0.16], [0.19, 0.16], [0.19, -0.16]])
    start, goal = (2.5, 3.6, -math.pi / 2), (1.0, 1.0, 0.0)  # the narrow gap is on the way

    class Layered:  # what circumscribed_cost reads of a LayeredCostmap
        from fleetsim.nav.costmap.inflation_layer import InflationLayer, InflationLayerParams

        inscribed_radius, circumscribed_radius, costmap = 0.16, math.hypot(0.19, 0.16), m
        layers = [InflationLayer(params=InflationLayerParams(cost_scaling_factor=5.0))]

    cost, radius = circumscribed_cost(Layered)
    assert 150 < cost < 253 and radius == pytest.approx(0.248, abs=1e-3)

    def turnable(path):
        """Per pose: can the footprint turn a full circle there without a lethal cell?"""
        outline = outline_points(footprint, m.resolution)
        yaws = np.linspace(-math.pi, math.pi, 72, endpoint=False)
        out = []
        for x, y, _ in path.poses:
            poses = np.c_[np.full(72, x), np.full(72, y), yaws]
            fc = footprint_costs(m.costs, m.origin_x, m.origin_y, m.resolution, outline, poses)
            out.append(bool((fc >= 0).all()))
        return np.array(out)

    plain = NavFn(m).create_plan(start, goal)  # ROS: through the 0.4 m gap, a turn inside it
    assert (np.abs(plain.poses[:, 0] - 2.5) < 0.3)[np.abs(plain.poses[:, 1] - 3.0) < 0.1].all()
    assert not turnable(plain).all()

    roomy = NavFn(m, NavfnParams(circumscribed_clearance=True))
    roomy.set_circumscribed(cost, radius)
    path = roomy.create_plan(start, goal)
    crossing = path.poses[np.abs(path.poses[:, 1] - 3.0) < 0.1]
    assert len(crossing) and (np.abs(crossing[:, 0] - 4.5) < 0.3).all()  # the wide gap
    assert turnable(path).all()
    assert path.poses[-1, :2].tolist() == pytest.approx([1.0, 1.0])

    m.costs[:, round(4.0 / 0.05) : round(5.0 / 0.05)] = 254  # the wide gap closed:
    path = roomy.create_plan(start, goal)  # as ROS, through the narrow one
    assert path.poses[-1, :2].tolist() == pytest.approx([1.0, 1.0])
    assert not turnable(path).all()


def _slam_costmap(rng):
    """A gmapping-sized costmap (16 x 14 m at 0.05 m) that is unknown but for a 5 x 3 m office
    of two rooms, a door between them, a gap in the outer wall onto the unknown outside, and
    random cost inside; placed off the middle."""
    m = Costmap2D(320, 280, 0.05, -8.0, -7.0, default_value=255)
    room = rng.integers(0, 120, (60, 100)).astype(np.uint8)
    room[rng.random(room.shape) < 0.03] = 254
    room[0, :] = room[-1, :] = room[:, 0] = room[:, -1] = room[:, 50] = 254
    room[20:35, 50] = 0  # the door
    room[-1, 70:80] = 0  # the gap in the outer wall, onto unknown cells
    m.costs[150:210, 60:160] = room
    return m


@pytest.mark.parametrize("circumscribed", [False, True])
@pytest.mark.parametrize("margin", ["shipped", "tight"])
def test_planning_in_the_known_part_first_gives_the_whole_maps_paths(
    circumscribed, margin, monkeypatch
):
    """NavFn plans first in the known part of a mostly unknown costmap and keeps that run only
    when the whole map's run would repeat it (the wavefront never reached the part's cut
    edges): every potential is the whole map's bit for bit, and both kinds of run happen
    (a tight margin forces the whole map's run on most plans)."""
    import fleetsim.nav.planners.navfn as navfn_module

    if margin == "tight":
        monkeypatch.setattr(navfn_module, "PART_MARGIN", 0.1)
        monkeypatch.setattr(navfn_module, "PART_REACH", 0.0)
    rng = np.random.default_rng(7)
    m = _slam_costmap(rng)
    known = np.argwhere(m.costs[:, :] < 120)
    pairs = []
    for _ in range(40):
        (sy, sx), (gy, gx) = known[rng.integers(len(known), size=2)]
        pairs.append(((-8.0 + (sx + 0.5) * 0.05, -7.0 + (sy + 0.5) * 0.05, 0.0),
                      (-8.0 + (gx + 0.5) * 0.05, -7.0 + (gy + 0.5) * 0.05, 0.3)))  # fmt: skip
    pairs.append(((-8.0 + 65 * 0.05, -7.0 + 155 * 0.05, 0.0), (6.0, -5.0, 0.0)))  # far outside

    def planner():
        nf = NavFn(m, NavfnParams(circumscribed_clearance=circumscribed))
        nf.set_circumscribed(200, 0.25)
        return nf

    fast, sizes = planner(), []
    got = []
    for s, g in pairs:
        try:
            got.append(fast.create_plan(s, g).poses)
        except NoPathFound as e:
            got.append(str(e))
        sizes.append((fast.window[2] - fast.window[0]) * (fast.window[3] - fast.window[1]))
        got.append((fast.window, fast.potential.copy()))
    monkeypatch.setattr(NavFn, "_known_part", lambda self, full, s, c: full)
    whole = planner()
    for k, (s, g) in enumerate(pairs):
        mine, ((x0, y0, xn, yn), pot) = got[2 * k], got[2 * k + 1]
        try:
            ref = whole.create_plan(s, g).poses
        except NoPathFound as e:
            ref = str(e)
        assert whole.window == (0, 0, m.size_x, m.size_y)
        full = whole.potential
        np.testing.assert_array_equal(pot, full[y0:yn, x0:xn])  # bit for bit
        outside = np.ones(full.shape, bool)
        outside[y0:yn, x0:xn] = False
        assert (full[outside] >= POT_HIGH).all()
        if isinstance(ref, str):
            assert mine == ref
        else:  # cell coordinates offset by the part's corner: the last bits of a float differ
            np.testing.assert_allclose(mine, ref, rtol=0, atol=1e-9)
    assert min(sizes) < m.costs.size / 3  # planned in the known part
    assert max(sizes) == m.costs.size  # and, where the wavefront left it, in the whole map


def test_a_robot_whose_centre_is_in_inscribed_space_gets_a_way_out():
    """NavfnROS clears only the robot's cell: a robot whose centre came into the inscribed band
    by a wall (its polygon footprint still clear of it) had no plan at all, and move_base
    aborted every goal. With the footprint's circumscribed radius known, the plan leaves the
    band through the inscribed (never the lethal) cells nearest the robot."""
    m = Costmap2D(60, 40, 0.05)
    m.costs[20, :] = 254  # a wall along y = 1.0 m
    m.costs[14:20, :] = 253  # its inscribed band, 0.3 m
    m.costs[21:27, :] = 253
    m.costs[13, :] = 200
    start, goal = (1.0, 0.8, 0.0), (2.5, 0.3, 0.0)
    ros = NavFn(m)  # no radius known: as ROS, no way out
    with pytest.raises(NoPathFound, match="not connected"):
        ros.create_plan(start, goal)
    nf = NavFn(m)
    nf.set_circumscribed(200, 0.48)
    path = nf.create_plan(start, goal)
    assert path.poses[-1, :2].tolist() == pytest.approx([2.5, 0.3])
    cells, inside = m.cells_of(path.poses[:, :2])
    costs = m.costs[cells[:, 1], cells[:, 0]]
    assert inside.all() and (costs < 254).all()
    out = int(np.argmax(costs < 253))  # the first point out of the band, straight down
    assert out > 0 and abs(path.poses[out, 0] - 1.0) < 0.15
    # a start off the band plans as before
    assert nf.create_plan((1.0, 0.3, 0.0), goal).poses[0, :2].tolist() == [1.0, 0.3]


def _known_bounds_reference(costs: np.ndarray) -> tuple[int, int, int, int]:
    known = costs != 255
    rows, cols = np.flatnonzero(known.any(axis=1)), np.flatnonzero(known.any(axis=0))
    if rows.size == 0:
        return 0, 0, 0, 0
    return int(cols[0]), int(rows[0]), int(cols[-1]) + 1, int(rows[-1]) + 1


def test_known_bounds_match_numpy_on_whole_maps_windows_and_odd_widths():
    """The known cells' bounds, word by word on whole maps and cell by cell on windows of them
    and on widths that are no whole number of words, agree with NumPy's."""
    rng = np.random.default_rng(11)
    for shape in ((64, 64), (40, 24), (33, 57), (1, 8), (9, 1)):
        for _ in range(20):
            costs = np.full(shape, 255, np.uint8)
            k = int(rng.integers(0, 6))
            costs[rng.integers(0, shape[0], k), rng.integers(0, shape[1], k)] = rng.integers(
                0, 255, k
            )
            assert known_bounds(costs) == _known_bounds_reference(costs), (shape, costs.nonzero())
            window = costs[1:, 3:]  # not C-contiguous
            assert known_bounds(window) == _known_bounds_reference(window)
    assert known_bounds(np.full((16, 16), 255, np.uint8)) == (0, 0, 0, 0)
    edge = np.full((16, 16), 255, np.uint8)
    edge[15, 15] = 0  # the last byte of the last word
    assert known_bounds(edge) == (15, 15, 16, 16)


def test_a_descent_caught_on_a_plateaus_edge_still_finds_its_way():
    """A jackal's global costmap on the circle of 16 (seed 2, 76 s): parked robots as the robots
    layer's 252 cells, no walls. navfn's descent turned back and forth inside one cell on a
    plateau's edge, never repeating a point exactly, until its steps ran out; the goal was
    aborted. A descent that stays in one cell for STUCK_STEPS steps now moves to the lowest
    neighbour, as on navfn's own oscillation."""
    from pathlib import Path

    data = np.load(Path(__file__).with_name("navfn_plateau_edge.npz"))
    costs = data["costs"]
    cm = Costmap2D(costs.shape[1], costs.shape[0], float(data["resolution"]), *data["origin"])
    cm.costs[:] = costs
    path = NavFn(cm, NavfnParams(), "map").create_plan(tuple(data["start"]), tuple(data["goal"]))
    poses = path.poses
    assert np.hypot(*(poses[0, :2] - data["start"][:2])) < 0.05
    assert np.hypot(*(poses[-1, :2] - data["goal"][:2])) < 0.05
    cells = ((poses[:, :2] - data["origin"]) / data["resolution"]).astype(int)
    assert costs[cells[:, 1], cells[:, 0]].max() < 252  # round the parked robots
    steps = np.hypot(*np.diff(poses[:, :2], axis=0).T)
    assert steps.max() < 2.5 * float(data["resolution"])  # a connected path
    assert steps.sum() < 1.6 * np.hypot(*(data["goal"][:2] - data["start"][:2]))


def test_known_bounds_are_read_once_per_costmap_update_and_stale_ones_change_no_plan(monkeypatch):
    """With its costmap's update count (`costmap_revision`) NavFn reads the known cells' bounds
    once per update; bounds left stale by a write between updates (here the whole map made
    known, free, with the count held) still give the whole map's plans."""
    import fleetsim.nav.planners.navfn as navfn_module

    rng = np.random.default_rng(3)
    m = _slam_costmap(rng)
    reads, revision = [], [0]
    real = navfn_module.known_bounds
    monkeypatch.setattr(navfn_module, "known_bounds", lambda c: reads.append(1) or real(c))
    nf = NavFn(m, NavfnParams())
    nf.costmap_revision = lambda: revision[0]
    s, g = (-8.0 + 65 * 0.05, -7.0 + 155 * 0.05, 0.0), (-8.0 + 150 * 0.05, -7.0 + 200 * 0.05, 0)
    first = nf.create_plan(s, g).poses
    nf.create_plan(s, g)
    assert len(reads) == 1
    revision[0] += 1
    again = nf.create_plan(s, g).poses
    assert len(reads) == 2 and np.array_equal(first, again)
    m.costs[m.costs == NO_INFORMATION] = 0  # known and free now, the count held: stale bounds
    stale = nf.create_plan(s, g).poses
    assert len(reads) == 2
    whole = NavFn(m, NavfnParams())
    monkeypatch.setattr(NavFn, "_known_part", lambda self, full, s, c: full)
    np.testing.assert_allclose(stale, whole.create_plan(s, g).poses, rtol=0, atol=1e-9)
