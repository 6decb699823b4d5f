"""Real-time factor of a fleet of lizis in the Willow Garage map, from the engine to whole stacks.

For each fleet size N (default 1, 3, 10, 30, 100) one row per layer, side by side:

- ``engine``: the simulation engine alone (``Engine.advance`` with random wheel commands, the
  lizi's plugins: drive, odometry, p3d ground truth, laser; no runtime, no messages);
- ``robots``: the robots alone through a launch file (simulator node, spawn_model,
  joint_state_publisher, robot_state_publisher, the laser's static transform: plugins and their
  messages, no navigation nodes);
- ``scans``: the robots alone with a reader of every lizi's ``base_scan`` in the benchmark's
  process (the simulator casts a laser only while its scan topic has a subscriber, as
  gazebo_ros_laser; the stacks' costmaps and amcl subscribe, so this is the robots' share of a
  stack);
- ``fake``: the whole stack with fake_localization (move_base + fake_localization per robot,
  map_server, send_goals looping over random reachable goals);
- ``amcl``: the same with amcl instead of fake_localization;

with each one's ratio to ``robots`` and the stacks' to ``scans`` (measured in the same
invocation: this shared 2-core machine's speed swings by up to 2x from one minute to the next,
so ratios within one run are the figure to compare), memory per robot (resident set growth over
the run, from before the launch to its end; per added robot over the smallest fleet measured, so
that the modules and kernels loaded once do not count, and for the smallest fleet the whole
growth divided by N) and, when ``ir-sim`` is installed (``pip install fleetsim[bench]``), IR-
SIM's real-time factor for comparable robots (diff drive, 360-beam 2D lidar at every step) on
the same map. Every run is a fresh subprocess, so that memory and caches do not leak from one
row into the next. WARNING lines logged by a run are counted and the first one is shown.

Targets (issue 14) at N = 10: robots >= 10x real time, fake >= 0.6 of robots, amcl >= 0.4;
at N = 100 both whole stacks >= 1x.

``--soak``: 10 robots with fake_localization (``--soak-localization amcl`` for amcl) and random
goals for one hour of sim time (``--soak-minutes``); prints the real-time factor and resident
memory per ten minutes of sim time, the growth and drift between the first and the last ten
minutes (targets: memory <= 5 %, RTF <= 10 %) and every warning. The soak's lizis run
collvoid's local planner by default (``--soak-planner trajectory`` for TrajectoryPlannerROS):
a lizi's laser sweeps 1 m up, above the other lizis' bodies, so with TrajectoryPlannerROS ten
lizis on random routes cannot see each other and collide; that is the robot model, not the
stack the soak is to hold for an hour. collvoid shares positions on ``/position_share`` and
avoids the others, as the multi-robot lesson does.

Usage: python benchmarks/fleet_rtf.py [--sizes 1,3,10] [--duration 10] [--layers robots,fake]
                                     [--repeats 3] [--cpu]
       python benchmarks/fleet_rtf.py --soak [--soak-minutes 60]
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
from scipy import ndimage

ROOT = Path(__file__).resolve().parent.parent
WILLOW = ROOT.parent / "shared" / "data" / "maps" / "willow-full.yaml"
LAYERS = ("engine", "robots", "scans", "fake", "amcl", "irsim")
#: free-space clearance of start poses and goals, m (the lizi's radius is about 0.2 m)
CLEARANCE = 0.6
#: sim seconds IR-SIM runs at most (100 of its robots take minutes per sim second)
IRSIM_SECONDS = 2.0
#: sim seconds run before the measured part (spawn settling, numba compilation, first plans)
WARMUP = 3.0


def clock() -> float:
    """Seconds of wall time, or of this process's CPU time with ``--cpu`` (which the other
    processes on a shared machine disturb far less; numba runs on one thread here)."""
    return (
        time.process_time() if os.environ.get("FLEET_RTF_CLOCK") == "cpu" else time.perf_counter()
    )


# -- the fleet: start poses and goals on free, connected cells --------------------------------
def free_cells(yaml_path: Path = WILLOW) -> tuple[np.ndarray, float, tuple]:
    """(rows, cols) of the cells in the largest free region with ``CLEARANCE`` to walls."""
    from fleetsim.nav.map_io import load_map

    m = load_map(yaml_path)
    free = m.data == 0
    free[[0, -1], :] = free[:, [0, -1]] = False  # the map's edge bounds the free space too
    dist = ndimage.distance_transform_edt(free) * m.resolution
    ok = dist > CLEARANCE
    labels, _ = ndimage.label(ok)
    biggest = np.argmax(np.bincount(labels[ok]))
    return np.argwhere(labels == biggest), m.resolution, m.origin


def fleet(n: int, seed: int, goals_per_robot: int = 4) -> tuple[list, list]:
    """``n`` start poses (x, y, yaw) at least 1 m apart, and ``goals_per_robot`` goals each,
    all in one connected free region of Willow (so every goal is reachable), seeded."""
    rng = np.random.default_rng(seed)
    cells, res, origin = free_cells()
    xy = origin[0] + (cells[:, ::-1] + 0.5) * res  # (row, col) -> (x, y), row 0 at origin y
    starts: list[tuple[float, float, float]] = []
    for k in rng.permutation(len(xy)):
        x, y = xy[k]
        if all((x - s[0]) ** 2 + (y - s[1]) ** 2 > 1.0 for s in starts):
            starts.append((round(float(x), 2), round(float(y), 2), 0.0))
        if len(starts) == n:
            break
    picks = rng.choice(len(xy), size=(n, goals_per_robot))
    goals = [[[round(float(v), 2) for v in xy[k]] + [0.0] for k in row] for row in picks]
    return starts, goals


def launch_xml(layer: str, starts: list, goals: list) -> str:
    """A launch file for ``layer`` (robots, fake or amcl; ``fake:collvoid`` or
    ``amcl:collvoid`` with collvoid's local planner and position sharing in place of
    TrajectoryPlannerROS) with one lizi per start pose."""
    layer, _, planner = layer.partition(":")
    layer = "robots" if layer == "scans" else layer
    out = ["<launch>", '  <param name="/use_sim_time" value="true"/>']
    out.append(
        '  <include file="$(find gazebo_ros)/launch/empty_world.launch">'
        f'<arg name="world_name" value="{WILLOW}"/><arg name="gui" value="false"/></include>'
    )
    if layer != "robots":
        out.append(
            f'  <node pkg="map_server" type="map_server" name="map_server" args="{WILLOW}">'
            '<param name="frame_id" value="/map"/></node>'
        )
    for i, (x, y, _) in enumerate(starts):
        ns = f"lizi{i}"
        out.append(f'  <group ns="{ns}"><param name="tf_prefix" value="{ns}"/>')
        pose = f"-x {x} -y {y} -z 0"
        if layer == "robots":
            out.append(
                '    <param name="robot_description" '
                'command="$(find xacro)/xacro $(find lizi)/urdf/lizi.urdf.xacro"/>'
                f'<node name="spawn_urdf" pkg="gazebo_ros" type="spawn_model" args="{pose} '
                f'-urdf -param robot_description -model {ns}"/>'
                '<node name="joint_state_publisher" pkg="joint_state_publisher" '
                'type="joint_state_publisher"/><node pkg="robot_state_publisher" '
                'type="robot_state_publisher" name="robot_state_publisher"/>'
                '<node pkg="tf" type="static_transform_publisher" name="laser_link_broadcaster" '
                f'args="0 0 1 0 0 0 {ns}/base_link {ns}/laser_link 100"/>'
            )
        else:
            out.append(
                f'    <param name="amcl/initial_pose_x" value="{x}"/>'
                f'<param name="amcl/initial_pose_y" value="{y}"/>'
                '<include file="$(find fleetsim_launch)/include/one_robot.launch">'
                f'<arg name="init_pose" value="{pose}"/><arg name="robot_name" value="{ns}"/>'
                f'<arg name="localization" value="{layer}"/>'
                + (f'<arg name="local_planner" value="{planner}"/>' if planner else "")
                + "</include>"
            )
        out.append("  </group>")
    if layer != "robots":
        lines = "".join(f"\n        lizi{i}: {g}" for i, g in enumerate(goals))
        out.append(
            '  <node pkg="fleetsim" type="send_goals" name="send_goals"><rosparam>\n'
            f"      frame_id: map\n      start_delay: 1.0\n      loop: true\n      goals:{lines}\n"
            "    </rosparam></node>"
        )
    out.append("</launch>")
    return "\n".join(out)


# -- measuring ---------------------------------------------------------------------------------
def rss_mb() -> float:
    """Resident set size of this process, MB (Linux /proc)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


class WarningCounter(logging.Handler):
    """Counts WARNING-or-worse records logged anywhere; keeps the first few texts."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.count = 0
        self.first: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.count += 1
        if len(self.first) < 20:
            self.first.append(record.getMessage())


def measure_engine(n: int, duration: float, seed: int) -> dict:
    from fleetsim.description import load_robot
    from fleetsim.sim import Engine

    rss0 = rss_mb()
    starts, _ = fleet(n, seed)
    rng = np.random.default_rng(seed)
    engine = Engine(WILLOW, rng=np.random.default_rng(seed))
    lizi = load_robot(ROOT / "src/fleetsim/assets/robots/lizi/urdf/lizi.urdf.xacro")
    entries = engine.spawn_robots(
        [(f"lizi{i}", lizi, (x, y, 0.0, 0.0, 0.0, yaw)) for i, (x, y, yaw) in enumerate(starts)]
    )
    engine.advance(0.5)  # warm-up: numba compilation, contacts settle

    def drive() -> None:
        cmds = np.c_[rng.uniform(0.1, 0.5, n), rng.uniform(-0.5, 0.5, n)]
        for e, (vx, wz) in zip(entries, cmds):
            e.plugins[0].command(vx, wz, engine.time)

    t0 = clock()
    sim0 = engine.time
    while engine.time - sim0 < duration - 1e-9:
        if round((engine.time - sim0) / 0.1) % 20 == 0:
            drive()
        engine.advance(0.1)
    wall = clock() - t0
    return {"rtf": duration / wall, "mb": rss_mb() - rss0}


def measure_launch(layer: str, n: int, duration: float, seed: int, chunks: int = 1) -> dict:
    """Run the launch file of ``layer``; RTF of ``duration`` sim s after ``WARMUP``. With
    ``chunks`` > 1 the RTF and memory of each chunk of the run are returned too (the soak)."""
    from fleetsim.launch.runner import LaunchSession, load_plan

    counter = WarningCounter()
    logging.getLogger().addHandler(counter)
    rss0 = rss_mb()
    starts, goals = fleet(n, seed)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"fleet_{layer}_{n}.launch"
        path.write_text(launch_xml(layer, starts, goals))
        with LaunchSession(load_plan(path), seed=seed) as s:
            if layer == "scans":
                from fleetsim.msgs import sensor_msgs

                got = [0]

                def count(msg) -> None:
                    got[0] += 1
                    _ = msg.ranges  # a scan is cast when read: read it, as its reader would

                for i in range(n):
                    s.runtime.graph.subscribe(f"/lizi{i}/base_scan", sensor_msgs.LaserScan, count)
            s.run(duration=WARMUP)
            per_chunk = []
            for _ in range(chunks):
                t0 = clock()
                s.run(duration=duration / chunks)
                per_chunk.append({"rtf": duration / chunks / (clock() - t0), "rss_mb": rss_mb()})
            reached = sum(r.goals_reached for r in s.monitor.results())
            collisions = sum(r.collisions for r in s.monitor.results())
            events = [
                f"{r.model} with {other} at t={t:.1f} s, ({x:.2f}, {y:.2f})"
                for r in s.monitor.results()
                for t, other, x, y in r.collision_events
            ]
    wall_total = sum(duration / chunks / c["rtf"] for c in per_chunk)
    return {
        "rtf": duration / wall_total,
        "mb": per_chunk[-1]["rss_mb"] - rss0,
        "chunks": per_chunk,
        "goals_reached": reached,
        "collisions": collisions,
        "collision_events": events[:20],
        "warnings": counter.count,
        "first_warnings": counter.first,
    }


def measure_irsim(n: int, duration: float, seed: int) -> dict:
    """IR-SIM (pure Python) on the same map: diff-drive circles with a 360-beam lidar."""
    try:
        import irsim
    except ImportError:
        return {"missing": "ir-sim is not installed (pip install 'fleetsim[bench]')"}
    import yaml
    from PIL import Image

    from fleetsim.nav.map_io import load_map

    m = load_map(WILLOW)
    starts, goals = fleet(n, seed)
    rss0 = rss_mb()
    with tempfile.TemporaryDirectory() as tmp:
        png = Path(tmp) / "willow.png"
        occupied = m.data[::-1] > 50  # image row 0 is the top of the map
        Image.fromarray(np.where(occupied, 0, 255).astype(np.uint8)).save(png)
        h, w = m.data.shape
        world = {
            "world": {
                "height": h * m.resolution,
                "width": w * m.resolution,
                "step_time": 0.1,
                "sample_time": 0.1,
                "offset": [m.origin[0], m.origin[1]],
                "obstacle_map": str(png),
                "collision_mode": "unobstructed",
            },
            "robot": [
                {
                    "number": n,
                    "distribution": {"name": "manual"},
                    "kinematics": {"name": "diff"},
                    "shape": {"name": "circle", "radius": 0.2},
                    "state": [[x, y, yaw] for x, y, yaw in starts],
                    "goal": [g[0] for g in goals],
                    "behavior": {"name": "dash"},
                    "vel_max": [0.5, 1.0],
                    "sensors": [
                        {
                            "name": "lidar2d",
                            "range_min": 0.1,
                            "range_max": 10.0,
                            "angle_range": 2 * np.pi,
                            "number": 360,
                        }
                    ],
                }
            ],
        }
        path = Path(tmp) / "world.yaml"
        path.write_text(yaml.safe_dump(world))
        env = irsim.make(str(path), headless=True, log_level="ERROR")
        steps = max(1, round(min(duration, IRSIM_SECONDS) / 0.1))
        env.step()
        t0 = clock()
        for _ in range(steps):
            env.step()
        wall = clock() - t0
    return {"rtf": steps * 0.1 / wall, "mb": rss_mb() - rss0}


def worker(layer: str, n: int, duration: float, seed: int, chunks: int) -> dict:
    logging.basicConfig(level=logging.ERROR)
    logging.getLogger("fleetsim").setLevel(logging.WARNING)
    if layer == "engine":
        return measure_engine(n, duration, seed)
    if layer == "irsim":
        return measure_irsim(n, duration, seed)
    return measure_launch(layer, n, duration, seed, chunks)


def run_layer(
    layer: str, n: int, duration: float, seed: int, chunks: int = 1, repeats: int = 1
) -> dict:
    """The fastest of ``repeats`` measurements, each in a fresh interpreter; its result as a
    dict (``error`` on failure)."""
    best: dict = {}
    for _ in range(repeats):
        cmd = [sys.executable, __file__, "--worker", layer, str(n), str(duration), str(seed)]
        cmd.append(str(chunks))
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
        lines = [x for x in proc.stdout.splitlines() if x.startswith("{")]
        if not lines:
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
            return {"error": " | ".join(tail) or f"exit status {proc.returncode}"}
        got = json.loads(lines[-1])
        if "rtf" not in got or got["rtf"] > best.get("rtf", -1.0):
            best = got
    return best


# -- printing ------------------------------------------------------------------------------------
def table(sizes: list[int], layers: list[str], duration: float, seed: int, repeats: int) -> bool:
    """Print the table; False when a run failed (its cell is '-' and the error is printed)."""
    what = "CPU" if os.environ.get("FLEET_RTF_CLOCK") == "cpu" else "wall"
    print(
        f"Willow, lizis, {duration:g} sim s per run after {WARMUP:g} s warm-up, seed {seed}, "
        f"real-time factors from {what} time, best of {repeats}"
    )
    head = f"{'N':>4}" + "".join(f"{name:>9}" for name in layers)
    head += "  " + "".join(f"{name + '/rob':>10}" for name in layers if name != "robots")
    if "scans" in layers:
        head += "".join(f"{name + '/scans':>11}" for name in layers if name in ("fake", "amcl"))
    head += "   MB per robot (" + ", ".join(layers) + ")"
    print(head)
    notes: list[str] = []
    failed = False
    first: dict[str, tuple[int, float]] = {}  # layer -> (N, MB) of the smallest fleet
    for n in sizes:
        res = {layer: run_layer(layer, n, duration, seed, 1, repeats) for layer in layers}
        row = f"{n:>4}"
        for layer in layers:
            r = res[layer]
            row += f"{r['rtf']:>8.2f}x" if "rtf" in r else f"{'-':>9}"
            if "missing" in r and r["missing"] not in notes:
                notes.append(r["missing"])
            if "error" in r:
                failed = True
                notes.append(f"N={n} {layer}: {r['error']}")
            if r.get("warnings"):
                notes.append(
                    f"N={n} {layer}: {r['warnings']} warnings, first: {r['first_warnings'][0]}"
                )
        base = res.get("robots", {}).get("rtf")
        scans = res.get("scans", {}).get("rtf")
        row += "  "
        for layer in layers:
            if layer == "robots":
                continue
            rtf = res[layer].get("rtf")
            row += f"{rtf / base:>10.2f}" if rtf and base else f"{'-':>10}"
        for layer in layers:
            if layer in ("fake", "amcl") and "scans" in layers:
                rtf = res[layer].get("rtf")
                row += f"{rtf / scans:>11.2f}" if rtf and scans else f"{'-':>11}"
        mem = []
        for layer in layers:
            mb = res[layer].get("mb")
            if mb is not None and layer not in first:
                first[layer] = (n, mb)
            n0, mb0 = first.get(layer, (n, mb))
            mem.append(None if mb is None else (mb - mb0) / (n - n0) if n > n0 else mb / n)
        row += "   " + ", ".join(f"{m:.1f}" if m is not None else "-" for m in mem)
        print(row, flush=True)
    for note in notes:
        print(note)
    print(
        "targets at N=10: robots >= 10x, fake/rob >= 0.6, amcl/rob >= 0.4; "
        "at N=100: fake and amcl >= 1x"
    )
    return not failed


def soak(minutes: float, localization: str, seed: int, planner: str = "collvoid") -> bool:
    """Print the soak's figures; False when the run failed (e.g. a physics instability)."""
    chunks = max(2, round(minutes / 10))
    print(
        f"soak: 10 lizis, {localization}, {planner} local planner, random goals, {minutes:g} "
        f"sim min in {chunks} parts"
    )
    layer = localization if planner == "trajectory" else f"{localization}:{planner}"
    r = run_layer(layer, 10, minutes * 60.0, seed, chunks)
    if "error" in r:
        print("failed:", r["error"])
        return False
    for k, c in enumerate(r["chunks"]):
        print(f"  part {k + 1:>2}: {c['rtf']:6.2f}x real time, resident {c['rss_mb']:7.1f} MB")
    first, last = r["chunks"][0], r["chunks"][-1]
    growth = (last["rss_mb"] - first["rss_mb"]) / first["rss_mb"]
    drift = (last["rtf"] - first["rtf"]) / first["rtf"]
    print(
        f"memory growth {growth:+.1%} (target <= 5 %), RTF drift {drift:+.1%} "
        f"(target within 10 %), goals reached {r['goals_reached']}, "
        f"collisions {r['collisions']}, warnings {r['warnings']}"
    )
    for text in r["first_warnings"]:
        print("  WARNING", text)
    for text in r.get("collision_events", []):
        print("  collision:", text)
    return True


def main() -> int:
    """Exit status 1 when a run failed (not when a target is missed: the figures say that)."""
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--sizes", default="1,3,10,30,100", help="fleet sizes, comma separated")
    ap.add_argument("--duration", type=float, default=10.0, help="measured sim s per run")
    ap.add_argument("--layers", default=",".join(LAYERS), help=f"of {', '.join(LAYERS)}")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=1, help="runs per cell, the best is shown")
    ap.add_argument("--cpu", action="store_true", help="real-time factors from CPU time")
    ap.add_argument("--soak", action="store_true", help="the one-hour soak run instead")
    ap.add_argument("--soak-minutes", type=float, default=60.0)
    ap.add_argument("--soak-localization", choices=("fake", "amcl"), default="fake")
    ap.add_argument(
        "--soak-planner",
        choices=("trajectory", "collvoid"),
        default="collvoid",  # lizis cannot see each other: see the module doc
        help="the soak's local planner: collvoid (position sharing and ORCA; the default) or "
        "TrajectoryPlannerROS (lizis do not see each other: their lasers sweep above the other "
        "bodies, so they collide)",
    )
    ap.add_argument("--worker", nargs=5, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.cpu:
        os.environ["FLEET_RTF_CLOCK"] = "cpu"  # read by the workers
    if args.worker:
        layer, n, duration, seed, chunks = args.worker
        print(json.dumps(worker(layer, int(n), float(duration), int(seed), int(chunks))))
        return 0
    if args.soak:
        return (
            0
            if soak(args.soak_minutes, args.soak_localization, args.seed, args.soak_planner)
            else 1
        )
    layers = [x for x in args.layers.split(",") if x]
    unknown = sorted(set(layers) - set(LAYERS))
    if unknown:
        ap.error(f"unknown layers {unknown}; choose from {', '.join(LAYERS)}")
    if "robots" not in layers:
        layers.insert(0, "robots")
    parts = [x.strip() for x in args.sizes.split(",") if x.strip()]
    if not all(x.isdigit() for x in parts):
        ap.error(f"--sizes: fleet sizes are whole numbers, comma separated; got {args.sizes!r}")
    sizes = [int(x) for x in parts]
    if not sizes or min(sizes) < 1:
        ap.error(f"--sizes: fleet sizes must be >= 1, got {args.sizes!r}")
    return 0 if table(sizes, layers, args.duration, args.seed, max(1, args.repeats)) else 1


if __name__ == "__main__":
    sys.exit(main())
