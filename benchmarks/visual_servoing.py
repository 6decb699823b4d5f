"""The tutorial's visual servoing, measured (issue 15): baseline figures for the next issue.

Runs ``visual_servoing.launch`` (karl patrols with a marker, the waffle follows it with
aruco_detect and follow_marker, as grobot does) for each strategy and seed, and prints per
strategy, over the seeds (mean, and the spread across seeds):

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
- ``aruco ms``: aruco_detect's wall time per frame (JPEG decode, detection, pose estimation,
  publishing), mean and 95th percentile; target <= 5 ms at 640x480.

Defaults: 10 seeds x both strategies x 180 s of sim time from the tutorial's start poses, the
camera at 640x480 (same horizontal field of view as the real 1920x1080; software rendering
cannot render that at 30 Hz). Shorter: ``--seeds 2 --duration 60``.

Usage: python benchmarks/visual_servoing.py [--seeds 10] [--duration 180]
       [--strategies rotate move_to_target] [--width 640 --height 480 --rate 10]
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.spatial.transform import Rotation

from fleetsim.cli.launch import resolve_launch_file
from fleetsim.launch.runner import LaunchSession, load_plan
from fleetsim.msgs import fiducial_msgs

OPTICAL = "camera_rgb_optical_frame"
FOLLOWER, TARGET, MARKER = "turtlebot3_waffle", "karl", "karl_marker"
BEHIND = 0.8  # m, follow_marker's marker_to_target_pose x (negated)
LOST = 4.0  # s


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
        self.times: list[float] = []
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
        """Wrap aruco_detect's image callback (decode + detect + pose + publish) in a timer."""
        for sub in self.detector._subscriptions:
            if sub.topic.name == self.detector.image_topic:
                inner = sub.callback

                def timed(msg, inner=inner):
                    if len(self.times) % 5 == 0 and len(self.samples) < 100:
                        self.samples.append(bytes(msg.data))
                    t0 = time.perf_counter()
                    inner(msg)
                    self.times.append(time.perf_counter() - t0)

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


def run(strategy: str, seed: int, duration: float, width: int, height: int, rate: float) -> dict:
    args = {
        "exploration_strategy": strategy,
        "gui": "false",
        "camera_width": str(width),
        "camera_height": str(height),
        "camera_rate": str(rate),
    }
    wall = time.perf_counter()
    with LaunchSession(load_plan(resolve_launch_file("visual_servoing"), args), seed=seed) as s:
        probe = Probe(s)
        s.runtime.run(duration=duration)
        follower = next(r for r in s.monitor.results() if r.model == FOLLOWER)
        f = np.array([row[1:] for row in probe.frames], dtype=float)
        times = np.array(probe.times) * 1e3
        return {
            "strategy": strategy,
            "seed": seed,
            "frames": len(f),
            "detected": float(f[:, 0].mean()) if len(f) else 0.0,
            "in_view": float(f[:, 1].mean()) if len(f) else 0.0,
            "losses": losses(probe.frames, s.runtime.now()),
            "dist_mean": float(f[:, 2].mean()) if len(f) else math.nan,
            "dist_p95": float(np.percentile(f[:, 2], 95)) if len(f) else math.nan,
            "collisions": follower.collisions,
            "aruco_mean": float(times.mean()) if len(times) else math.nan,
            "aruco_p95": float(np.percentile(times, 95)) if len(times) else math.nan,
            "wall": time.perf_counter() - wall,
            "samples": probe.samples,
        }


def detector_timing(jpegs: list[bytes], **overrides) -> tuple[float, float, int]:
    """aruco_detect's detection alone on recorded frames: (mean ms, p95 ms, frames with a
    marker), with the package's detector parameters changed by ``overrides``."""
    import cv2

    from fleetsim.vision import ArucoDetectParams, aruco_dictionary, detector_parameters

    det = cv2.aruco.ArucoDetector(
        aruco_dictionary(0), detector_parameters(ArucoDetectParams(**overrides))
    )
    grays = [cv2.imdecode(np.frombuffer(b, np.uint8), cv2.IMREAD_GRAYSCALE) for b in jpegs]
    ms, found = [], 0
    for g in grays:
        t0 = time.perf_counter()
        _, ids, _ = det.detectMarkers(g)
        ms.append((time.perf_counter() - t0) * 1e3)
        found += ids is not None
    return float(np.mean(ms)), float(np.percentile(ms, 95)), found


COLUMNS = [
    ("detected", "{:.1%}"),
    ("in_view", "{:.1%}"),
    ("losses", "{:.1f}"),
    ("dist_mean", "{:.2f}"),
    ("dist_p95", "{:.2f}"),
    ("collisions", "{:.1f}"),
    ("aruco_mean", "{:.1f}"),
    ("aruco_p95", "{:.1f}"),
]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--duration", type=float, default=180.0, help="sim seconds per run")
    ap.add_argument("--strategies", nargs="+", default=["rotate", "move_to_target"])
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--rate", type=float, default=10.0, help="camera Hz")
    a = ap.parse_args()
    print(
        f"visual_servoing.launch: {a.seeds} seeds x {a.duration:.0f} s, camera {a.width}x"
        f"{a.height} at {a.rate:g} Hz"
    )
    head = "".join(f"{n:>13}" for n, _ in COLUMNS)
    print(f"{'strategy':>15} {'seed':>4}{head}{'wall s':>9}")
    rows = []
    for strategy in a.strategies:
        for seed in range(a.seeds):
            r = run(strategy, seed, a.duration, a.width, a.height, a.rate)
            rows.append(r)
            cells = "".join(f"{fmt.format(r[n]):>13}" for n, fmt in COLUMNS)
            print(f"{strategy:>15} {seed:>4}{cells}{r['wall']:>9.0f}", flush=True)
    print("\nper strategy: mean over seeds (min..max)")
    for strategy in a.strategies:
        rs = [r for r in rows if r["strategy"] == strategy]
        cells = []
        for n, fmt in COLUMNS:
            v = np.array([r[n] for r in rs], float)
            cells.append(
                f"{n} {fmt.format(v.mean())} ({fmt.format(v.min())}..{fmt.format(v.max())})"
            )
        print(f"{strategy}: " + ", ".join(cells))
    jpegs = [b for r in rows for b in r["samples"]]
    if jpegs:
        print(
            f"\naruco_detect's detection alone, {len(jpegs)} recorded {a.width}x{a.height} frames:"
        )
        for label, kw in (
            ("the package's parameters (13 threshold windows, 3..53 px)", {}),
            (
                "OpenCV's default windows (adaptiveThreshWinSizeMax 23, Step 10)",
                {"adaptiveThreshWinSizeMax": 23, "adaptiveThreshWinSizeStep": 10},
            ),
        ):
            mean, p95, found = detector_timing(jpegs, **kw)
            print(f"  {label}: {mean:.1f} ms mean, {p95:.1f} ms p95, marker in {found}")


if __name__ == "__main__":
    main()
