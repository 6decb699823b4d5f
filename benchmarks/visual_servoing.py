"""The tutorial's visual servoing, measured (issue 15), and fleetsim's predictive follower
against it (issue 19), side by side on the same seeds and scenarios.

Runs ``visual_servoing.launch`` (karl patrols with a marker, the waffle follows it with
aruco_detect) for each patrol (``circle``: the tutorial's; ``building``: move_base goals through
the building's gaps and corners, with stops), follower (``follow_marker``: the tutorial's
move_base goals; ``predictive``: the tracker + MPC of `fleetsim.apps.predictive_follower`),
exploration strategy and seed, and prints per run, then side by side per patrol and strategy
(mean over the seeds, min..max; and follow_marker's losses over the predictive follower's):

- ``detected``: share of camera frames in which aruco_detect found the marker;
- ``in view``: share of those frames in which the true marker was inside the camera's field of
  view (its centre inside the image), within the detector's range, and turned toward the camera
  (its face looks back from the burger); the range is where the marker's image is as big as
  the smallest the detector accepts (``minMarkerPerimeterRate`` of the image's longer side),
  3.75 m for the waffle's camera at any resolution. Occlusion is not counted;
- ``losses``: times the marker went unseen for more than 4 s after having been seen
  (follow_marker's lost timeout);
- ``dist mean`` / ``dist p95``: distance (m) from the follower's base to its desired pose,
  0.8 m behind the true marker in the burger's heading, over every frame;
- ``collisions``: the follower's new contacts with anything but the floor (the run monitor's);
- ``aruco ms``: aruco_detect's wall time per frame (its whole image callback: JPEG decode to
  grey, detection, pose estimation, publishing), median and 95th percentile; target <= 5 ms at
  640x480. ``aruco cpu``: the process's CPU time over the same callback (median); above the
  wall time when OpenCV runs the detector's 13 threshold windows on more than one thread
  (``cv2.getNumThreads()``, printed; OpenCV's default is one per core);
- ``others``: share of the machine's CPU that other processes used during the run (from
  /proc/stat): this shared machine's speed swings 2x with the load, so read the timings with it.

The per-frame times over all runs are printed once more for the frames in which no thread of
ours waited for a CPU (Linux schedstat): what a quiet machine gives. After the runs, the
recorded frames (every 5th, up to 100 a run) are timed again stage by stage (decode, detection
with 1 thread and with OpenCV's default, the node's whole callback), each stage on each frame in
turn, so that the stages are measured under the same load.

Defaults: 10 seeds x both strategies x 180 s of sim time from the tutorial's start poses, the
camera at 640x480 (same horizontal field of view as the real 1920x1080; software rendering
cannot render that at 30 Hz). Shorter: ``--seeds 2 --duration 60``.

``--start behind`` starts the follower 1.8 m behind karl instead of at the tutorial's pose
(from there, with ``rotate``, the marker never comes in range: 0 % seen and so no losses,
which makes the followers' losses incomparable). ``--picture run.png`` draws the first seed's
run of each patrol and follower (the report module ``visual_servoing_report.py``);
``--no-stages`` skips the detector's stage timing.

Usage: python benchmarks/visual_servoing.py [--seeds 10] [--duration 180]
       [--strategies rotate move_to_target] [--followers follow_marker predictive]
       [--patrols circle building] [--width 640 --height 480 --rate 10] [--picture PNG]
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import math
import os
import time
from dataclasses import fields

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import fiducial_msgs, sensor_msgs, std_msgs
from visual_servoing_report import picture, summary

OPTICAL = "camera_rgb_optical_frame"
FOLLOWER, TARGET, MARKER = "turtlebot3_waffle", "karl", "karl_marker"
BEHIND = 0.8  # m, follow_marker's marker_to_target_pose x (negated)
LOST = 4.0  # s
#: the follower's start (launch args x, y, yaw): the tutorial's, across the building, where the
#: marker is out of range until an exploration brings it in (with ``rotate`` it never does);
#: or 1.8 m behind karl, the marker in view from the first frame (the scenario tests')
STARTS = {
    "tutorial": {"x": "4.95", "y": "1.10", "yaw": "-2.65"},
    "behind": {"x": "-3.8", "y": "2.0", "yaw": "0.0"},
}
#: run-queue wait (ms) from which a frame counts as slowed by other processes
PREEMPTED_MS = 0.02


def _pose(engine, model: str) -> tuple[np.ndarray, Rotation]:
    pos, q = engine.model_pose(model)  # w, x, y, z
    return np.asarray(pos, float), Rotation.from_quat([q[1], q[2], q[3], q[0]])


def _yaw(r: Rotation) -> float:
    return float(r.as_euler("xyz")[2])


class Probe:
    """Per frame: detected or not, the true geometry, the follower's distance to its goal."""

    def __init__(self, s: LaunchSession) -> None:
        self.s = s
        self.engine = s.nodes["/gazebo"].engine
        self.detector = s.nodes["/aruco_detect"]
        self.frames: list[tuple[float, bool, bool, float]] = []  # t, detected, in view, dist
        self.paths: list[tuple[float, float, float, float, bool]] = []  # follower xy, target xy
        #: per image: wall s, process CPU s, s the process's threads waited for a CPU
        self.times: list[tuple[float, float, float]] = []
        self.samples: list[bytes] = []  # every 5th JPEG, for the detector-only timing
        self._mount = None
        p = self.detector.params
        self.min_side_rate = p.minMarkerPerimeterRate / 4.0
        self.fiducial_len = p.fiducial_len
        self._time_detector()
        s.runtime.graph.subscribe(
            "/fiducial_transforms", fiducial_msgs.FiducialTransformArray, self.on_frame, 0
        )

    def _time_detector(self) -> None:
        """Wrap aruco_detect's image callback (decode + detect + pose + publish) in a timer:
        wall time, the process's CPU time (every thread, so OpenCV's workers count) and how
        long its threads sat on a run queue, preempted by other processes."""
        for sub in self.detector._subscriptions:
            if sub.topic.name == self.detector.image_topic:
                inner = sub.callback

                def timed(msg, inner=inner):
                    if len(self.times) % 5 == 0 and len(self.samples) < 100:
                        self.samples.append(bytes(msg.data))
                    w0 = run_queue_wait()
                    c0, t0 = time.process_time(), time.perf_counter()
                    inner(msg)
                    t1, c1 = time.perf_counter(), time.process_time()
                    self.times.append((t1 - t0, c1 - c0, run_queue_wait() - w0))

                sub.callback = timed

    def on_frame(self, msg) -> None:
        detected = any(t.fiducial_id == 0 for t in msg.transforms)
        t_wb, r_wb = _pose(self.engine, FOLLOWER)
        t_wm, r_wm = _pose(self.engine, MARKER)
        _, r_wk = _pose(self.engine, TARGET)
        heading = _yaw(r_wk)
        goal = t_wm[:2] - BEHIND * np.array([math.cos(heading), math.sin(heading)])
        dist = float(np.linalg.norm(t_wb[:2] - goal))
        self.frames.append(
            (msg.header.stamp.to_sec(), detected, self._in_view(t_wb, r_wb, t_wm, r_wm), dist)
        )
        self.paths.append((t_wb[0], t_wb[1], t_wm[0], t_wm[1], detected))

    def _in_view(self, t_wb, r_wb, t_wm, r_wm) -> bool:
        k = self.detector.camera_matrix
        if k is None:
            return False
        if self._mount is None:
            t, q = self.s.runtime.tf_buffer.lookup_arrays("base_footprint", OPTICAL, 0.0)
            self._mount = (np.asarray(t), Rotation.from_quat(q))
        t_bc, r_bc = self._mount
        r_wc = r_wb * r_bc
        t_wc = t_wb + r_wb.apply(t_bc)
        p = r_wc.inv().apply(t_wm - t_wc)  # marker centre in the optical frame
        if p[2] <= 0:
            return False
        u, v = k[0, 0] * p[0] / p[2] + k[0, 2], k[1, 1] * p[1] / p[2] + k[1, 2]
        w, h = 2 * k[0, 2], 2 * k[1, 2]
        if not (0 <= u <= w and 0 <= v <= h):
            return False
        rng = k[0, 0] * self.fiducial_len / (self.min_side_rate * max(w, h))
        facing = r_wm.apply([1.0, 0.0, 0.0]) @ (t_wc - t_wm) > 0  # the face is on the model's +x
        return bool(np.linalg.norm(p) <= rng and facing)


def losses(frames: list[tuple[float, bool, bool, float]], end: float) -> int:
    seen = [t for t, d, _, _ in frames if d]
    if not seen:
        return 0
    gaps = np.diff(np.append(seen, end))
    return int(np.sum(gaps > LOST))


def run_queue_wait() -> float:
    """Seconds this process's threads have spent runnable but waiting for a CPU (Linux
    /proc/<pid>/task/*/schedstat; nan elsewhere)."""
    total = 0
    try:
        tids = os.listdir("/proc/self/task")
    except OSError:
        return math.nan
    for tid in tids:
        try:
            with open(f"/proc/self/task/{tid}/schedstat") as f:
                total += int(f.read().split()[1])
        except (OSError, IndexError, ValueError):
            continue  # a thread that ended meanwhile
    return total * 1e-9


class MachineLoad:
    """Share of the machine's CPU that other processes used between ``__init__`` and
    ``others()`` (Linux /proc/stat, less this process's own CPU time; nan elsewhere)."""

    def __init__(self) -> None:
        self.start = self._sample()

    @staticmethod
    def _sample() -> tuple[float, float, float] | None:
        try:
            with open("/proc/stat") as f:
                jiffies = [int(v) for v in f.readline().split()[1:9]]
        except OSError:
            return None
        hz = os.sysconf("SC_CLK_TCK")
        own = os.times()
        idle = jiffies[3] + jiffies[4]  # idle, iowait
        return sum(jiffies) / hz, (sum(jiffies) - idle) / hz, own.user + own.system

    def others(self) -> float:
        end = self._sample()
        if self.start is None or end is None or end[0] <= self.start[0]:
            return math.nan
        total, busy, own = (b - a for a, b in zip(self.start, end))
        return max(busy - own, 0.0) / total


def run(
    strategy: str,
    seed: int,
    duration: float,
    width: int,
    height: int,
    rate: float,
    follower: str = "follow_marker",
    patrol: str = "circle",
    start: str = "tutorial",
) -> dict:
    args = {
        **STARTS[start],
        "exploration_strategy": strategy,
        "follower": follower,
        "patrol": patrol,
        "gui": "false",
        "camera_width": str(width),
        "camera_height": str(height),
        "camera_rate": str(rate),
    }
    wall = time.perf_counter()
    load = MachineLoad()
    with LaunchSession(load_plan(resolve_launch_file("visual_servoing"), args), seed=seed) as s:
        probe = Probe(s)
        s.runtime.run(duration=duration)
        robot = next(r for r in s.monitor.results() if r.model == FOLLOWER)
        f = np.array([row[1:] for row in probe.frames], dtype=float)
        times = np.array(probe.times, dtype=float).reshape(-1, 3) * 1e3  # wall, cpu, wait (ms)
        det = probe.detector
        return {
            "strategy": strategy,
            "follower": follower,
            "patrol": patrol,
            "paths": np.array(probe.paths, dtype=float).reshape(-1, 5),
            "seed": seed,
            "frames": len(f),
            "detected": float(f[:, 0].mean()) if len(f) else 0.0,
            "in_view": float(f[:, 1].mean()) if len(f) else 0.0,
            "losses": losses(probe.frames, s.runtime.now()),
            "dist_mean": float(f[:, 2].mean()) if len(f) else math.nan,
            "dist_p95": float(np.percentile(f[:, 2], 95)) if len(f) else math.nan,
            "collisions": robot.collisions,
            "aruco_med": float(np.median(times[:, 0])) if len(times) else math.nan,
            "aruco_p95": float(np.percentile(times[:, 0], 95)) if len(times) else math.nan,
            "aruco_cpu": float(np.median(times[:, 1])) if len(times) else math.nan,
            "others": load.others(),
            "wall": time.perf_counter() - wall,
            "times": times,
            "samples": probe.samples,
            "params": {f.name: getattr(det.params, f.name) for f in fields(det.params)},
            "k": det.camera_matrix,
            "d": det.dist_coeffs,
        }


def _ms(w: np.ndarray, c: np.ndarray) -> str:
    """Wall times ``w`` (median, p95) and CPU times ``c`` (median), all in ms."""
    return (
        f"{np.median(w):5.2f} ms median, {np.percentile(w, 95):5.2f} p95, "
        f"CPU {np.median(c):5.2f} ms median"
    )


def stage_timing(jpegs: list[bytes], params: dict, k: np.ndarray, d: np.ndarray) -> None:
    """Time aruco_detect's stages on recorded frames, every stage on each frame in turn (so
    that they share the machine's load): decoding to grey, detection with one thread and with
    OpenCV's default, and the node's whole callback; then detection with OpenCV's default
    threshold windows, for scale."""
    from fleetsim.runtime import Runtime
    from fleetsim.vision import ArucoDetect, aruco_dictionary, detector_parameters

    threads = cv2.getNumThreads()
    node = ArucoDetect(Runtime(), params=params)
    if k is not None:  # the run's camera_info (none: the node times without pose estimation)
        node.on_camera_info(
            sensor_msgs.CameraInfo(
                header=std_msgs.Header(frame_id=OPTICAL), k=k.reshape(-1).tolist(), d=d.tolist()
            )
        )
    fewer = dataclasses.replace(
        node.params, adaptiveThreshWinSizeMax=23, adaptiveThreshWinSizeStep=10
    )
    fewer_windows = cv2.aruco.ArucoDetector(
        aruco_dictionary(node.params.dictionary), detector_parameters(fewer)
    )
    stages: dict[str, list[tuple[float, float, float]]] = {}

    def timed(name: str, fn, *args):
        w0 = run_queue_wait()
        c0, t0 = time.process_time(), time.perf_counter()
        out = fn(*args)
        t1, c1 = time.perf_counter(), time.process_time()
        stages.setdefault(name, []).append((t1 - t0, c1 - c0, run_queue_wait() - w0))
        return out

    found = 0
    try:
        for jpeg in jpegs:
            data = np.frombuffer(jpeg, np.uint8)
            grey = timed("JPEG decode to grey", cv2.imdecode, data, cv2.IMREAD_GRAYSCALE)
            cv2.setNumThreads(1)
            timed("detectMarkers, 1 thread", node.detector.detectMarkers, grey)
            cv2.setNumThreads(threads)
            _, ids, _ = timed(
                f"detectMarkers, {threads} threads", node.detector.detectMarkers, grey
            )
            found += ids is not None
            msg = sensor_msgs.CompressedImage(format="rgb8; jpeg compressed bgr8", data=data)
            timed("the node's whole callback", node.on_compressed, msg)
            node.runtime.graph.drain()
            timed(
                f"  (OpenCV's 3 default windows, {threads} threads)",
                fewer_windows.detectMarkers,
                grey,
            )
    finally:
        cv2.setNumThreads(threads)
    print(f"  marker found in {found} of {len(jpegs)} frames; each stage on all frames, then on")
    print("  those in which no other process preempted it")
    for name, rows in stages.items():
        t = np.array(rows) * 1e3
        alone = t[t[:, 2] < PREEMPTED_MS]
        quiet = f"{len(alone)}: {_ms(alone[:, 0], alone[:, 1])}" if len(alone) else "none"
        print(f"  {name:<42} {_ms(t[:, 0], t[:, 1])} | {quiet}")


COLUMNS = [
    ("detected", "{:.1%}"),
    ("in_view", "{:.1%}"),
    ("losses", "{:.1f}"),
    ("dist_mean", "{:.2f}"),
    ("dist_p95", "{:.2f}"),
    ("collisions", "{:.1f}"),
    ("aruco_med", "{:.2f}"),
    ("aruco_p95", "{:.2f}"),
    ("aruco_cpu", "{:.2f}"),
    ("others", "{:.0%}"),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--first-seed", type=int, default=0, help="seeds first..first+seeds-1")
    ap.add_argument("--duration", type=float, default=180.0, help="sim seconds per run")
    ap.add_argument("--strategies", nargs="+", default=["rotate", "move_to_target"])
    ap.add_argument("--followers", nargs="+", default=["follow_marker", "predictive"])
    ap.add_argument("--patrols", nargs="+", default=["circle", "building"])
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--rate", type=float, default=10.0, help="camera Hz")
    ap.add_argument("--start", choices=sorted(STARTS), default="tutorial", help="follower start")
    ap.add_argument("--picture", help="write a PNG of the first seed's paths here")
    ap.add_argument("--no-stages", action="store_true", help="skip aruco_detect's stage timing")
    a = ap.parse_args()
    print(
        f"visual_servoing.launch: {a.seeds} seeds x {a.duration:.0f} s from the {a.start} "
        f"start, camera {a.width}x"
        f"{a.height} at {a.rate:g} Hz; OpenCV {cv2.__version__}, {cv2.getNumThreads()} threads "
        f"on {os.cpu_count()} CPUs"
    )
    head = "".join(f"{n:>11}" for n, _ in COLUMNS)
    print(f"{'patrol':>9} {'follower':>14} {'strategy':>15} {'seed':>4}{head}{'wall s':>8}")
    rows = []
    for patrol, follower, strategy, seed in itertools.product(
        a.patrols, a.followers, a.strategies, range(a.first_seed, a.first_seed + a.seeds)
    ):
        r = run(strategy, seed, a.duration, a.width, a.height, a.rate, follower, patrol, a.start)
        rows.append(r)
        cells = "".join(f"{fmt.format(r[n]):>11}" for n, fmt in COLUMNS)
        print(
            f"{patrol:>9} {follower:>14} {strategy:>15} {seed:>4}{cells}{r['wall']:>8.0f}",
            flush=True,
        )
    summary(rows, COLUMNS)
    if a.picture:
        picture(rows, a.picture)
    times = np.concatenate([r["times"] for r in rows])
    if len(times):
        print(f"\naruco_detect per {a.width}x{a.height} frame (target: 5 ms):")
        print(f"  all {len(times)} frames: {_ms(times[:, 0], times[:, 1])}")
        alone = times[times[:, 2] < PREEMPTED_MS]
        if np.isnan(times[:, 2]).all():
            print("  (no schedstat here: frames preempted by other processes cannot be told)")
        else:
            print(
                f"  the {len(alone)} frames no other process preempted (run-queue wait < "
                f"{PREEMPTED_MS} ms; what a quiet machine gives, slightly optimistic: short "
                "frames are preempted less often): "
                + (_ms(alone[:, 0], alone[:, 1]) if len(alone) else "-")
            )
    jpegs = [b for r in rows for b in r["samples"]]
    if jpegs and not a.no_stages:
        print(f"\naruco_detect's stages on {len(jpegs)} recorded frames, timed now:")
        stage_timing(jpegs, rows[0]["params"], rows[0]["k"], rows[0]["d"])


if __name__ == "__main__":
    main()
