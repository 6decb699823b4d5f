"""Recording overhead as a fraction of run time (issue: across processes).

Ten robots publish a 720-beam scan at 10 Hz, odometry and tf at 50 Hz; the same run (same
seed, same sim duration) is timed without a recorder and with one (zstd, the default), and the
extra wall time is printed as a fraction of the plain run. Asserts nothing about time.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from fleetsim.msgs import geometry_msgs, nav_msgs, sensor_msgs, tf2_msgs
from fleetsim.record import BagReader, Recorder
from fleetsim.runtime import Node, Runtime

ROBOTS = 10
SIM_SECONDS = 20.0
BEAMS = 720


class Robot(Node):
    def __init__(self, rt: Runtime, i: int) -> None:
        super().__init__(rt, "sensors", f"/robot{i}")
        self.prefix = f"robot{i}"
        self.scan_pub = self.create_publisher(sensor_msgs.LaserScan, "scan")
        self.odom_pub = self.create_publisher(nav_msgs.Odometry, "odom")
        self.tf_pub = self.create_publisher(tf2_msgs.TFMessage, "/tf")
        self.create_timer(0.1, self.on_scan)
        self.create_timer(0.02, self.on_odom)

    def on_scan(self) -> None:
        s = sensor_msgs.LaserScan()
        s.header.stamp = self.now_msg()
        s.header.frame_id = f"{self.prefix}/base_laser"
        s.angle_min, s.angle_max, s.angle_increment = -np.pi, np.pi, 2 * np.pi / BEAMS
        s.range_max = 30.0
        s.ranges = self.rng.uniform(0.2, 30.0, BEAMS).astype(np.float32)
        self.scan_pub.publish(s)

    def on_odom(self) -> None:
        o = nav_msgs.Odometry()
        o.header.stamp = self.now_msg()
        o.header.frame_id = f"{self.prefix}/odom"
        o.child_frame_id = f"{self.prefix}/base_link"
        o.pose.pose.position.x = self.now() * 0.3
        self.odom_pub.publish(o)
        t = geometry_msgs.TransformStamped(header=o.header, child_frame_id=o.child_frame_id)
        t.transform.translation.x = o.pose.pose.position.x
        self.tf_pub.publish(tf2_msgs.TFMessage(transforms=[t]))


def timed_run(path: Path | None, compression: str = "zstd") -> float:
    rt = Runtime(seed=0)
    for i in range(ROBOTS):
        Robot(rt, i)
    rec = Recorder(rt, path, compression=compression) if path is not None else None
    t0 = time.perf_counter()
    try:
        rt.run(SIM_SECONDS)
    finally:
        if rec is not None:
            rec.close()
    return time.perf_counter() - t0


def main() -> None:
    print(
        f"{ROBOTS} robots x ({BEAMS}-beam scan at 10 Hz + odom and tf at 50 Hz), "
        f"{SIM_SECONDS:.0f} s of sim time"
    )
    timed_run(None)  # warm up imports and the CDR serialisers
    base = min(timed_run(None) for _ in range(2))
    print(f"  without recorder: {base:.3f} s wall")
    with tempfile.TemporaryDirectory() as tmp:
        for compression in ("zstd", "lz4", "none"):
            path = Path(tmp) / f"run-{compression}.mcap"
            rec = min(timed_run(path, compression) for _ in range(2))
            info = BagReader(path).info()
            mb = path.stat().st_size / 2**20
            print(
                f"  with recorder ({compression:>4}): {rec:.3f} s wall, overhead "
                f"{(rec - base) / base:.1%} of the run; {info.message_count} messages, "
                f"{mb:.1f} MiB, {(rec - base) / info.message_count * 1e6:.1f} us per message"
            )


if __name__ == "__main__":
    main()
