"""In-process publish -> callback throughput (issue: foundation).

Target: >= 200,000 small messages/s on one core. Prints figures; asserts nothing about time.
"""

from __future__ import annotations

import time

import numpy as np

from fleetsim.msgs import sensor_msgs, std_msgs
from fleetsim.runtime import Node, Runtime


def measure(make_msg, n: int) -> float:
    rt = Runtime()
    node = Node(rt, "bench")
    pub = node.create_publisher(type(make_msg()), "chatter")
    count = [0]

    def cb(_msg) -> None:
        count[0] += 1

    node.create_subscription(type(make_msg()), "chatter", cb, queue_size=n)
    msgs = [make_msg() for _ in range(1000)]
    t0 = time.perf_counter()
    done = 0
    while done < n:
        for m in msgs:
            pub.publish(m)
        rt.spin_once()
        done += len(msgs)
    dt = time.perf_counter() - t0
    assert count[0] == done
    return done / dt


def main() -> None:
    small = measure(lambda: std_msgs.Int32(data=1), 500_000)
    print(f"small message (std_msgs/Int32): {small:,.0f} msg/s  (target >= 200,000)")
    ranges = np.linspace(0.1, 10.0, 1081, dtype=np.float32)
    scan = measure(lambda: sensor_msgs.LaserScan(ranges=ranges), 200_000)
    print(f"1081-beam LaserScan:            {scan:,.0f} msg/s")
    print(f"ratio small / target: {small / 200_000:.2f}x")


if __name__ == "__main__":
    main()
