"""SLAM quality of slam_gmapping (issue 17): the hunter explores the office on its own.

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

Willow: the hunter driven by move_base goals out along Willow's west and north corridors and
back (about 90 m), mapping with the manual's gmapping parameters; the same figures. Not done
yet: two robots (issue 17 asks for it).

Usage: python benchmarks/slam_quality.py [--max-time 900] [--seed 1] [--only willow]
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "slam"))


def precision_recall(slam, truth, start) -> tuple[float, float, tuple[float, float, float]]:
    """`fleetsim.slam.quality.occupancy_precision_recall` of a published map (OccupancyGrid)
    against a true map (OccupancyMap), the robot having started at ``start`` (m)."""
    from fleetsim.slam.quality import occupancy_precision_recall

    data = np.asarray(slam.data).reshape(slam.info.height, slam.info.width)
    iy, ix = np.nonzero(data == 100)
    o, res = slam.info.origin.position, slam.info.resolution
    xy = np.c_[o.x + (ix + 0.5) * res, o.y + (iy + 0.5) * res]
    return occupancy_precision_recall(
        xy, truth.data == 100, truth.resolution, truth.origin[:2], start
    )


@contextlib.contextmanager
def update_timer():
    """Thread CPU seconds of every filter update run inside the block (appended to a list)."""
    from fleetsim.slam.filter import GmappingFilter

    times: list[float] = []
    real = GmappingFilter.process

    def timed(self, *a, **k):
        t = time.thread_time()
        out = real(self, *a, **k)
        if out.updated:
            times.append(time.thread_time() - t)
        return out

    GmappingFilter.process = timed
    try:
        yield times
    finally:
        GmappingFilter.process = real


def report(name, slam, truth, est, true, times, wall, sim_s) -> None:
    from fleetsim.slam.quality import ate

    p, r, (dx, dy, yaw) = precision_recall(slam, truth, true[0])
    shift = f"{dx:+.2f} m, {dy:+.2f} m, {math.degrees(yaw):+.1f} deg"
    ut = np.array(times) * 1e3
    print(f"  sim time             {sim_s:8.1f} sim s ({wall:.0f} s wall)")
    print(f"  occupied precision   {p:8.3f}   recall {r:.3f}   (alignment {shift})")
    print(
        f"  ATE RMS              {ate(np.array(est), np.array(true)):8.3f} m over {len(est)} poses"
    )
    print(f"  filter update        {np.median(ut):8.1f} ms median, p90 {np.percentile(ut, 90):.1f}"
          f" ms ({len(ut)} updates, 20 particles, 720 beams; CPU time)")  # fmt: skip


def sample(s, est, true) -> None:
    pos, _ = s.monitor.sim.engine.model_pose("robocluedo_robot")
    est.append(s.runtime.tf_buffer.lookup_pose2d("map", "base_link", 0.0)[:2])
    true.append((float(pos[0]), float(pos[1])))


def office(max_time: float, seed: int) -> None:
    import fleetsim
    from fleetsim.cli.launch import resolve_launch_file
    from fleetsim.launch.runner import LaunchSession, load_plan
    from fleetsim.nav.map_io import load_map

    truth = load_map(Path(fleetsim.__file__).parent / "assets" / "maps" / "office.yaml")
    t0 = time.perf_counter()
    plan = load_plan(resolve_launch_file("slam_explore"), {})
    with update_timer() as times, LaunchSession(plan, seed=seed) as s:
        ex = s.nodes["/explore"]
        est, true = [], []
        while not ex.finished and s.runtime.now() < max_time:
            s.runtime.run(duration=1.0)
            sample(s, est, true)
        explored_at = s.runtime.now()
        slam = s.nodes["/slam_gmapping"].grid_msg
        blacklisted = len(ex.blacklist)
    print(
        f"office (hunter explores, seed {seed}): finished={ex.finished} blacklisted={blacklisted}"
    )
    report("office", slam, truth, est, true, times, time.perf_counter() - t0, explored_at)


#: Willow: the hunter out along the west corridor and the north one, and back (map frame m)
WILLOW_START = (7.3, 14.0)
WILLOW_ROUTE = [(7.5, 29.0), (7.2, 43.4), (13.0, 46.8), (21.0, 48.2), (31.0, 48.2), (21.0, 48.2),
                (13.0, 46.8), (7.2, 43.4), (7.5, 29.0), (7.3, 14.0)]  # fmt: skip


def willow(seed: int, goals: int = len(WILLOW_ROUTE)) -> None:
    """The hunter (the manual's nav_stack: gmapping + move_base) driven along WILLOW_ROUTE in
    the Willow map world, as benchmarks/fleet_rtf.py builds it."""
    import tempfile

    from fleetsim.launch.runner import LaunchSession, load_plan
    from fleetsim.nav.map_io import load_map
    from fleetsim.nav.navigator import Navigator

    world = ROOT.parent / "shared" / "data" / "maps" / "willow-full.yaml"
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
    truth = load_map(world)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "willow_slam.launch"
        path.write_text(xml)
        plan = load_plan(path, {})
    reached = 0
    with update_timer() as times, LaunchSession(plan, seed=seed) as s:
        nav = Navigator(s.runtime, "/")
        est, true = [], []
        s.runtime.run(duration=1.0)
        prev = WILLOW_START
        for gx, gy in WILLOW_ROUTE[:goals]:
            nav.go_to_pose(gx, gy, math.atan2(gy - prev[1], gx - prev[0]))
            deadline = s.runtime.now() + 150.0
            while not nav.is_task_complete() and s.runtime.now() < deadline:
                s.runtime.run(duration=1.0)
                sample(s, est, true)
            reached += nav.get_result().name == "SUCCEEDED"
            prev = (gx, gy)
            print(f"  goal ({gx}, {gy}): {nav.get_result().name} at {s.runtime.now():.0f} sim s,"
                  f" {time.perf_counter() - t0:.0f} s wall", flush=True)  # fmt: skip
        slam = s.nodes["/slam_gmapping"].grid_msg
        sim_s = s.runtime.now()
    print(f"willow (hunter, scripted route, seed {seed}): {reached}/{goals} goals")
    report("willow", slam, truth, est, true, times, time.perf_counter() - t0, sim_s)


def update_30x360() -> None:
    from slam_world import LASER, ROUTE, drive, exact_ranges

    from fleetsim.slam.filter import Beams, GmappingFilter
    from fleetsim.slam.params import GmappingParams

    angles = -np.pi + 2 * np.pi / 360 * np.arange(360)
    rng = np.random.default_rng(0)
    params = GmappingParams(particles=30, xmin=-5, ymin=-5, xmax=15, ymax=12)
    f = GmappingFilter(params, rng, LASER, 11.99, 11.99)
    times = []
    for i, (true, odom) in enumerate(drive(ROUTE, np.random.default_rng(1))):
        c, s = math.cos(true[2]), math.sin(true[2])
        sensor = true + np.array([c * LASER[0], s * LASER[0], 0.0])
        r = exact_ranges(sensor, angles, 12.0) + 0.01 * rng.standard_normal(360)
        r = np.where(np.isfinite(r), r, 12.0)
        t = time.thread_time()
        res = f.process(odom, 0.1 * i, Beams(r, angles))
        if res.updated and f.updates > 2:  # past numba's compilation
            times.append(time.thread_time() - t)
    ms = np.array(times) * 1e3
    print(
        f"one update, 30 particles x 360 beams (gmapping defaults): median {np.median(ms):.1f} "
        f"ms, p90 {np.percentile(ms, 90):.1f} ms over {len(ms)} updates (target 20 ms)"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-time", type=float, default=900.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--only", choices=["update", "office", "willow"], default=None)
    ap.add_argument("--willow-goals", type=int, default=len(WILLOW_ROUTE))
    a = ap.parse_args()
    if a.only in (None, "update"):
        update_30x360()
    if a.only in (None, "office"):
        office(a.max_time, a.seed)
    if a.only in (None, "willow"):
        willow(a.seed, a.willow_goals)


if __name__ == "__main__":
    main()
