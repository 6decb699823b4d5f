"""SLAM quality of slam_gmapping (issue 17): the hunter explores the office on its own, then two
hunters together (``slam_explore robots:=2``: the full one-against-two comparison lives here;
the suite's scenario test runs the pair for 20 s only).

``slam_explore`` runs until explore_lite has no frontier left (or ``--max-time`` sim seconds);
then the final map is compared with the world's true occupancy (the office map the simulator
extrudes its walls from), and the trajectory with the simulator's ground truth:

- occupied-cell precision and recall after the best rigid alignment (a grid search of
  +-0.2 m, +-2 deg; `fleetsim.slam.quality.occupancy_precision_recall`): a SLAM cell is right
  when a true occupied cell lies within 0.1 m, a true cell is found when a SLAM occupied cell
  lies within 0.1 m. The true cells are those a laser can see from where the robot can go
  (occupied cells next to the free space connected to its start), explored or not; until
  this session they were every true occupied cell within 0.3 m of a cell the SLAM map knew,
  which counted the inside of the desks and the table (never visible) and did not count rooms
  the robot never saw;
- ATE (`fleetsim.slam.quality.ate`: RMS of position error after a rigid Umeyama alignment) of
  map -> base_link sampled every 1 s;
- the time to explore (sim s) and the CPU time of the thread per filter update (median and
  p90; CPU time, as this shared machine's wall time swings with the other jobs on it), plus
  one update with 30 particles and 360 beams timed on the synthetic room of tests/slam.

Willow: the hunter, mapping with the manual's gmapping parameters, driven out along Willow's
west and north corridors and back (132 m) by a pure-pursuit controller on the simulator's
ground truth along a path that keeps 0.3 m from the walls (move_base is left out: it did not
get the hunter along the west corridor, and this measures SLAM); the same figures, the recall
over the true walls the hunter's laser hit in the scans the filter updated on (the scans its
map is made of: its own 720 beams over 180 degrees from the true pose of each, out to
maxUrange, each beam followed cell by cell to the first wall, `visible_cells`), and over the
walls any scan hit (every 20 Hz scan, most between two updates). Until this session recall
was over what a 360-degree laser saw from the route's positions every 1 s, its rays stepped
at half a cell: 180 degrees of it this laser does not have, and the steps slipped between
two cells that touch at a corner (Willow's slanted walls), counting rooms behind them.

Every part is deterministic: the same seed gives the same figures (the Willow driver reads
the simulator's pose every 0.1 sim s; two runs of seed 1 gave the same figures; an earlier
note here said the drive was not deterministic, which the current code does not show).

Usage: python benchmarks/slam_quality.py [--max-time 1500] [--seeds 1,2,3]
       [--only update|office|office1|office2|willow] [--trace]
       (office: one hunter then two; office1: one only; office2: two only; each seed in turn;
       --trace: each explorer's goals and where the exploration time went, `explore_trace`)
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "slam"))


def precision_recall(
    slam, truth, start, visible=None, at=None
) -> tuple[float, float, tuple[float, float, float]]:
    """`fleetsim.slam.quality.occupancy_precision_recall` of a published map (OccupancyGrid)
    against a true map (OccupancyMap), the robot having started at ``start`` (m); ``visible``:
    score recall on those true cells only; ``at`` (dx m, dy m, yaw rad): at that alignment
    instead of the best one."""
    from fleetsim.slam.quality import occupancy_precision_recall

    data = np.asarray(slam.data).reshape(slam.info.height, slam.info.width)
    iy, ix = np.nonzero(data == 100)
    o, res = slam.info.origin.position, slam.info.resolution
    xy = np.c_[o.x + (ix + 0.5) * res, o.y + (iy + 0.5) * res]
    search = {}
    if at is not None:  # as occupancy_precision_recall turns and shifts the map
        c, s = math.cos(at[2]), math.sin(at[2])
        xy = xy @ np.array([[c, s], [-s, c]]) + np.array(at[:2])
        search = {"shifts": 0.0, "turns": 0.0}
    return occupancy_precision_recall(
        xy, truth.data == 100, truth.resolution, truth.origin[:2], start, visible=visible, **search
    )


class UpdateLog(list):
    """Thread CPU seconds of each filter update (the list), and the scan stamps (s) updated."""

    def __init__(self) -> None:
        super().__init__()
        self.stamps: list[float] = []


@contextlib.contextmanager
def update_timer():
    """Every filter update run inside the block: its CPU time and its scan's stamp."""
    from fleetsim.slam.filter import GmappingFilter

    times = UpdateLog()
    real = GmappingFilter.process

    def timed(self, odom, stamp, *a, **k):
        t = time.thread_time()
        out = real(self, odom, stamp, *a, **k)
        if out.updated:
            times.append(time.thread_time() - t)
            times.stamps.append(stamp)
        return out

    GmappingFilter.process = timed
    try:
        yield times
    finally:
        GmappingFilter.process = real


def report(name, slam, truth, est, true, times, wall, sim_s, visible=None, seen=None) -> None:
    """Print the figures; ``visible`` (H, W bool, `fleetsim.slam.quality.visible_cells`): score
    recall over those true walls only (a route, not an exploration); ``seen`` (same): print
    the recall over those too (at the same alignment)."""
    from fleetsim.slam.quality import ate

    p, r, (dx, dy, yaw) = precision_recall(slam, truth, true[0], visible)
    shift = f"{dx:+.2f} m, {dy:+.2f} m, {math.degrees(yaw):+.1f} deg"
    ut = np.array(times) * 1e3
    print(f"  sim time             {sim_s:8.1f} sim s ({wall:.0f} s wall)")
    print(f"  occupied precision   {p:8.3f}   recall {r:.3f}   (alignment {shift})")
    if seen is not None:
        _, r_seen, _ = precision_recall(slam, truth, true[0], seen, (dx, dy, yaw))
        print(f"  recall, every scan   {r_seen:8.3f}   (the walls any scan hit, {seen.sum()} "
              f"cells; the filter's scans hit {visible.sum()})")  # fmt: skip
    err = np.hypot(*(np.array(est) - np.array(true)).T).max()  # map frame = world frame here
    print(
        f"  ATE RMS              {ate(np.array(est), np.array(true)):8.3f} m over {len(est)} poses"
        f" (worst {err:.2f} m before alignment)"
    )
    print(f"  filter update        {np.median(ut):8.1f} ms median, p90 {np.percentile(ut, 90):.1f}"
          f" ms ({len(ut)} updates, 20 particles, 720 beams; CPU time)")  # fmt: skip


def sample(
    s, est, true, model: str = "robocluedo_robot", base: str = "base_link", frame: str = "map"
) -> None:
    pos, _ = s.monitor.sim.engine.model_pose(model)
    est.append(s.runtime.tf_buffer.lookup_pose2d(frame, base, 0.0)[:2])
    true.append((float(pos[0]), float(pos[1])))


def office(
    max_time: float, seed: int, robots: int = 1, robot: str = "hunter", trace: bool = False
) -> float:
    """Explore the office with ``robots`` robots (slam_explore robots:=N robot:=...); the sim
    time it took. One hunter is the manual's hunter_run (no namespace), any other robot runs in
    namespaces ``<robot>1``, ``<robot>2``. ``trace``: print where the time went
    (`explore_trace`)."""
    import fleetsim
    from explore_trace import ExploreTrace
    from fleetsim.cli.launch import resolve_launch_file
    from fleetsim.launch.runner import LaunchSession, load_plan
    from fleetsim.nav.map_io import load_map

    truth = load_map(Path(fleetsim.__file__).parent / "assets" / "maps" / "office.yaml")
    t0 = time.perf_counter()
    plan = load_plan(resolve_launch_file("slam_explore"), {"robots": str(robots), "robot": robot})
    alone = robots == 1 and robot == "hunter"
    names = [""] if alone else [f"{robot}{i + 1}" for i in range(robots)]
    tracer = ExploreTrace()
    patched = tracer.patch() if trace else contextlib.nullcontext()
    with update_timer() as times, patched, LaunchSession(plan, seed=seed) as s:
        explorers = [s.nodes[f"/{n}/explore".replace("//", "/")] for n in names]
        est, true = [[] for _ in names], [[] for _ in names]
        slam_node = s.nodes[f"/{names[0]}/slam_gmapping".replace("//", "/")]
        while not all(ex.finished for ex in explorers) and s.runtime.now() < max_time:
            s.runtime.run(duration=1.0)
            for i, n in enumerate(names):
                if n:  # alone, the robot's own map frame; two: the merged map's
                    frame = f"{n}/map" if robots == 1 else "map"
                    sample(s, est[i], true[i], n, f"{n}/base_link", frame)
                else:
                    sample(s, est[i], true[i])
            if trace:
                grid = slam_node.grid_msg if robots == 1 else s.nodes["/map_merge"].merged
                by_ns = {ex.namespace: ex for ex in explorers}
                tracer.sample(s.runtime.now(), by_ns, [t[-1] for t in true], grid)
        explored_at = s.runtime.now()
        slam = slam_node.grid_msg if robots == 1 else s.nodes["/map_merge"].merged
        touches = [(r.namespace, r.collision_events) for r in s.monitor.results()]
        until_goals = 0 if s.monitor.success() else 1
    state = ", ".join(
        f"{n or robot}: finished={ex.finished} gave_up={ex.gave_up} blacklisted={len(ex.blacklist)}"
        f" observed={ex.observed}"
        for n, ex in zip(names, explorers)
    )
    print(f"office ({robots} {robot}(s) explore, seed {seed}): {state}")
    # the run monitor's verdict, as `fleetsim launch ... --until-goals` exits: a touch counts
    for ns, events in touches:
        where = "; ".join(f"{t:.0f} s {other} at ({x:.1f}, {y:.1f})" for t, other, x, y in events)
        print(f"  {ns}: {len(events)} collisions{': ' + where if events else ''}")
    print(f"  --until-goals would exit {until_goals}")
    if trace:
        tracer.summary()
    if robots > 1:
        from fleetsim.slam.quality import ate

        for n, e, t in zip(names, est, true):
            print(f"  {n}: ATE {ate(np.array(e), np.array(t)):.3f} m over {len(e)} poses")
    # the robots' trajectories share the map frame: one alignment for all
    report(
        "office", slam, truth, [*itertools.chain(*est)], [*itertools.chain(*true)], times,
        time.perf_counter() - t0,
        explored_at,
    )  # fmt: skip
    return explored_at


#: Willow: the hunter out along the west corridor and the north one, and back (map frame m)
WILLOW_START = (7.3, 14.0)
WILLOW_ROUTE = [(7.3, 14.0), (7.5, 29.0), (7.2, 43.4), (13.0, 46.8), (21.0, 48.2), (31.0, 48.2),
                (21.0, 48.2), (13.0, 46.8), (7.2, 43.4), (7.5, 29.0), (7.3, 14.0)]  # fmt: skip
CLEARANCE = 0.3  # m from the walls that the scripted path keeps (the hunter is 0.15 m round)


def clear_path(truth, points, clearance: float = CLEARANCE) -> np.ndarray:
    """(N, 2) cell centres (m) of the shortest path through ``points`` on the true map that keeps
    ``clearance`` from every non-free cell, pulled to the middle of corridors (Dijkstra over the
    8-connected cells, scipy's csgraph)."""
    from scipy import ndimage, sparse
    from scipy.sparse.csgraph import dijkstra

    res = truth.resolution
    dist = ndimage.distance_transform_edt(truth.data == 0) * res
    ok = dist >= clearance
    h, w = ok.shape
    index = np.full((h, w), -1, dtype=np.int64)
    ys, xs = np.nonzero(ok)
    index[ys, xs] = np.arange(len(ys))
    rows, cols, costs = [], [], []
    for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):
        y2, x2 = ys + dy, xs + dx
        good = (y2 < h) & (x2 >= 0) & (x2 < w)
        good[good] &= ok[y2[good], x2[good]]
        a, b = index[ys[good], xs[good]], index[y2[good], x2[good]]
        c = math.hypot(dx, dy) * res * (1.0 + 2.0 / dist[ys[good], xs[good]])
        rows += [a, b]
        cols += [b, a]
        costs += [c, c]
    graph = sparse.csr_matrix(
        (np.concatenate(costs), (np.concatenate(rows), np.concatenate(cols))),
        shape=(len(ys), len(ys)),
    )
    path = []
    for a, b in itertools.pairwise(points):
        ia = index[int((a[1] - truth.origin[1]) / res), int((a[0] - truth.origin[0]) / res)]
        ib = index[int((b[1] - truth.origin[1]) / res), int((b[0] - truth.origin[0]) / res)]
        if ia < 0 or ib < 0:
            raise SystemExit(f"waypoint {a if ia < 0 else b} is within {clearance} m of a wall")
        _, pred = dijkstra(graph, indices=ia, return_predecessors=True)
        node, seg = ib, []
        while node != ia:
            if node < 0:
                raise SystemExit(f"no path {a} -> {b} with {clearance} m clearance")
            seg.append(node)
            node = pred[node]
        path += [(truth.origin[0] + (xs[n] + 0.5) * res, truth.origin[1] + (ys[n] + 0.5) * res)
                 for n in seg[::-1]]  # fmt: skip
    return np.array(path)


def pursuit(pose: np.ndarray, path: np.ndarray, k: int, lookahead: float = 0.6):
    """(v m/s, w rad/s, next k): pure pursuit of ``path`` from index k on the true pose."""
    while k < len(path) - 1 and math.dist(pose[:2], path[k]) < lookahead:
        k += 1
    dx, dy = path[k] - pose[:2]
    err = (math.atan2(dy, dx) - pose[2] + math.pi) % (2 * math.pi) - math.pi
    if abs(err) > 0.6:  # turn on the spot first
        return 0.0, math.copysign(0.8, err), k
    return 0.4, 1.5 * err, k


def true_pose(engine) -> np.ndarray:
    """(x m, y m, yaw rad) of the hunter in the simulator (= map frame here)."""
    pos, q = engine.model_pose("robocluedo_robot")
    yaw = math.atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2))
    return np.array([pos[0], pos[1], yaw])


def walls_in_sight(truth, scans, slam_filter) -> np.ndarray:
    """(H, W) bool: the true walls the hunter's laser hit first from where each of its ``scans``
    (true base pose, LaserScan) was taken: its own beams (720 over 180 degrees), out to
    gmapping's usable range (a longer beam marks no wall), placed by the filter's laser pose
    (`fleetsim.slam.quality.visible_cells`)."""
    from fleetsim.slam.quality import visible_cells

    base = np.array([p for p, _ in scans])
    lx, ly, lyaw = slam_filter.laser
    c, s = np.cos(base[:, 2]), np.sin(base[:, 2])
    laser = np.c_[base[:, 0] + c * lx - s * ly, base[:, 1] + s * lx + c * ly, base[:, 2] + lyaw]
    msg = scans[-1][1]
    angles = msg.angle_min + msg.angle_increment * np.arange(len(msg.ranges))
    return visible_cells(
        truth.data == 100, truth.resolution, truth.origin[:2], laser, angles,
        slam_filter.usable_range,
    )  # fmt: skip


def willow(seed: int) -> None:
    """The hunter in the Willow map world mapping with the manual's slam_gmapping, driven along
    WILLOW_ROUTE by a pure-pursuit controller on the simulator's ground truth (move_base did
    not get it along the west corridor: the benchmark measures SLAM, not navigation), so
    move_base is left out of the manual's nav_stack."""
    import tempfile

    from fleetsim.launch.runner import LaunchSession, load_plan
    from fleetsim.msgs import geometry_msgs, sensor_msgs
    from fleetsim.nav.map_io import load_map
    from fleetsim.runtime import Node

    world = ROOT.parent / "shared" / "data" / "maps" / "willow-full.yaml"
    truth = load_map(world)
    path = clear_path(truth, WILLOW_ROUTE)
    length = float(np.hypot(*np.diff(path, axis=0).T).sum())
    x, y = WILLOW_START
    xml = f"""<launch>
  <include file="$(find robocluedo_robot_hunter)/launch/gazebo.launch">
    <arg name="gazebo_gui" value="false"/><arg name="world_file_path" value="{world}"/>
    <arg name="x" value="{x}"/><arg name="y" value="{y}"/>
    <arg name="model_name" value="robocluedo_robot"/>
  </include>
  <node name="robot_state_publisher" pkg="robot_state_publisher" type="robot_state_publisher"/>
  <include file="$(find fleetsim_launch)/nav_stack.launch"/>
</launch>
"""
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        launch = Path(tmp) / "willow_slam.launch"
        launch.write_text(xml)
        plan = load_plan(launch, {})
    plan.nodes = [n for n in plan.nodes if n.name != "move_base"]
    with update_timer() as times, LaunchSession(plan, seed=seed) as s:
        driver = Node(s.runtime, "scripted_driver")
        cmd = driver.create_publisher(geometry_msgs.Twist, "/cmd_vel", 1)
        engine = s.monitor.sim.engine
        est, true = [], []
        scans: list[tuple[np.ndarray, sensor_msgs.LaserScan]] = []  # every scan, its true pose

        def on_scan(msg: sensor_msgs.LaserScan) -> None:  # delivered within ~6 ms of its stamp
            scans.append((true_pose(engine), msg))

        driver.create_subscription(sensor_msgs.LaserScan, "/scan", on_scan, 10)
        k = 0
        s.runtime.run(duration=1.0)  # the hunter is spawned
        while k < len(path) - 1 or math.dist(true[-1], path[-1]) > 0.3:
            for _ in range(10):
                v, w, k = pursuit(true_pose(engine), path, k)
                cmd.publish(geometry_msgs.Twist(linear=geometry_msgs.Vector3(x=v),
                                                angular=geometry_msgs.Vector3(z=w)))  # fmt: skip
                s.runtime.run(duration=0.1)
            sample(s, est, true)
            if int(s.runtime.now()) % 60 == 0:
                print(f"  {s.runtime.now():.0f} sim s: {k}/{len(path)} path cells, "
                      f"{time.perf_counter() - t0:.0f} s wall", flush=True)  # fmt: skip
            if s.runtime.now() > 3 * length / 0.4:
                print("  the scripted drive got stuck; stopping")
                break
        cmd.publish(geometry_msgs.Twist())
        s.runtime.run(duration=6.0)  # one more map_update_interval
        slam = s.nodes["/slam_gmapping"].grid_msg
        sim_s = s.runtime.now()
        slam_filter = s.nodes["/slam_gmapping"].filter
        # recall over the walls in the scans the map was built from: gmapping maps the scans
        # it updates on (every linearUpdate / angularUpdate / temporalUpdate), and its
        # published map replays those only; the walls any scan hit are printed too
        used = set(times.stamps)
        visible = walls_in_sight(
            truth, [sc for sc in scans if sc[1].header.stamp.to_sec() in used], slam_filter
        )
        seen = walls_in_sight(truth, scans, slam_filter)
    print(f"willow (hunter, scripted drive on ground truth, {length:.0f} m, seed {seed})")
    report("willow", slam, truth, est, true, times, time.perf_counter() - t0, sim_s, visible, seen)


def update_30x360() -> None:
    """One update with 30 particles x 360 beams on the synthetic room of tests/slam (gmapping's
    defaults), thread CPU time; the exact climber (``climb_skip 0``) is fed the same scans in
    the same run, update by update, and the ratio printed: this machine's speed swings 2x."""
    from slam_world import LASER, ROUTE, drive, exact_ranges

    from fleetsim.slam.filter import Beams, GmappingFilter
    from fleetsim.slam.params import GmappingParams

    angles = -np.pi + 2 * np.pi / 360 * np.arange(360)
    rng = np.random.default_rng(0)
    params = GmappingParams(particles=30, xmin=-5, ymin=-5, xmax=15, ymax=12)
    f = GmappingFilter(params, rng, LASER, 11.99, 11.99)
    exact_params = GmappingParams(particles=30, xmin=-5, ymin=-5, xmax=15, ymax=12, climb_skip=0)
    exact = GmappingFilter(exact_params, np.random.default_rng(0), LASER, 11.99, 11.99)
    times, exact_times = [], []
    for i, (true, odom) in enumerate(drive(ROUTE, np.random.default_rng(1))):
        c, s = math.cos(true[2]), math.sin(true[2])
        sensor = true + np.array([c * LASER[0], s * LASER[0], 0.0])
        r = exact_ranges(sensor, angles, 12.0) + 0.01 * rng.standard_normal(360)
        r = np.where(np.isfinite(r), r, 12.0)
        for filt, out in ((f, times), (exact, exact_times)):
            t = time.thread_time()
            res = filt.process(odom, 0.1 * i, Beams(r, angles))
            if res.updated and filt.updates > 2:  # past numba's compilation
                out.append(time.thread_time() - t)
    ms, exact_ms = np.array(times) * 1e3, np.array(exact_times) * 1e3
    print(
        f"one update, 30 particles x 360 beams (gmapping defaults): median {np.median(ms):.1f} "
        f"ms, p90 {np.percentile(ms, 90):.1f} ms over {len(ms)} updates (target 20 ms); the "
        f"exact climber (climb_skip 0) in the same run {np.median(exact_ms):.1f} ms, p90 "
        f"{np.percentile(exact_ms, 90):.1f} ms: {np.median(ms) / np.median(exact_ms):.2f} of it"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-time", type=float, default=1500.0)
    ap.add_argument("--seeds", default="1", help="comma-separated runtime seeds, run in turn")
    ap.add_argument("--robot", default="hunter", help="office1: the robot (hunter or lizi)")
    ap.add_argument("--trace", action="store_true", help="office: where the time went")
    ap.add_argument(
        "--only", choices=["update", "office", "office1", "office2", "willow"], default=None
    )
    a = ap.parse_args()
    parts = [x.strip() for x in a.seeds.split(",") if x.strip()]
    if not parts or not all(x.isdigit() for x in parts):
        ap.error(f"--seeds: whole numbers, comma separated; got {a.seeds!r}")
    seeds = [int(x) for x in parts]
    if a.only in (None, "update"):
        update_30x360()
    for seed in seeds:
        if a.only in (None, "office", "office1", "office2"):
            one = (
                office(a.max_time, seed, robot=a.robot, trace=a.trace)
                if a.only != "office2"
                else None
            )
            two = office(a.max_time, seed, robots=2, trace=a.trace) if a.only != "office1" else None
            if one is not None and two is not None:
                print(f"two hunters explored the office in {two / one:.0%} of one hunter's time")
        if a.only in (None, "willow"):
            willow(seed)


if __name__ == "__main__":
    main()
