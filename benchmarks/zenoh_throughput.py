"""Zenoh bridge: cross-process latency and throughput on loopback, small messages and scans.

Two processes, each a `Runtime` with a `ZenohBridge`: this one publishes ``/ping`` and the
other (started here as a subprocess) republishes every message on ``/pong``. Both spin their
bridge in a tight loop (no sim-time pacing), so the figures are the transport's: CDR encode,
zenoh over TCP loopback, inbox, CDR decode, graph delivery, and back.

- latency: one message in flight; one-way = round trip / 2 (median and 99th percentile).
- throughput: up to WINDOW messages in flight for DURATION s; messages/s that complete the
  round trip (each crosses the process boundary twice) and the one-way payload rate.

Messages: geometry_msgs/PoseStamped (small, ~60 B of CDR) and a 720-beam sensor_msgs/LaserScan
(~5.8 kB with intensities). Prints; asserts nothing about time.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/zenoh_throughput.py``
"""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROUNDS = 500
DURATION = 2.0
WINDOW = 32

ECHO = """
import sys, time
from fleetsim.msgs import get_type
from fleetsim.runtime import Node, Runtime
from fleetsim.transport import ZenohBridge
rt = Runtime()
bridge = ZenohBridge(rt, listen=[sys.argv[1]], publish_clock=False)
n = Node(rt, "echo")
pubs = {}
for t in sys.argv[2:]:
    cls = get_type(t)
    key = t.rsplit("/", 1)[1]
    pubs[key] = n.create_publisher(cls, f"/pong_{key}")
    n.create_subscription(cls, f"/ping_{key}", pubs[key].publish, queue_size=0)
print("ready", flush=True)
while True:
    if bridge.spin_once() == 0:
        time.sleep(0)  # lets zenoh's callback threads take the GIL
"""


def free_endpoint() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return f"tcp/127.0.0.1:{s.getsockname()[1]}"


def messages() -> dict[str, object]:
    from fleetsim.msgs import geometry_msgs, sensor_msgs

    rng = np.random.default_rng(0)
    scan = sensor_msgs.LaserScan(
        ranges=rng.uniform(0.1, 30.0, 720).astype(np.float32),
        intensities=rng.uniform(0.0, 1.0, 720).astype(np.float32),
    )
    scan.header.frame_id = "lizi1/laser"
    pose = geometry_msgs.PoseStamped()
    pose.header.frame_id = "map"
    return {"PoseStamped": pose, "LaserScan": scan}


def main() -> None:
    from fleetsim.msgs import serialize
    from fleetsim.runtime import Node, Runtime
    from fleetsim.transport import ZenohBridge

    msgs = messages()
    ep = free_endpoint()
    root = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(root / "src"))
    types = [m.__msgtype__ for m in msgs.values()]
    echo = subprocess.Popen(
        [sys.executable, "-c", ECHO, ep, *types], env=env, stdout=subprocess.PIPE, text=True
    )
    try:
        assert echo.stdout is not None and echo.stdout.readline().strip() == "ready"
        rt = Runtime()
        bridge = ZenohBridge(rt, mode="client", connect=[ep])
        node = Node(rt, "ping")
        print(f"Zenoh bridge on loopback ({ep}), two processes, python {sys.version.split()[0]}")
        print(
            f"{'message':<12} {'CDR bytes':>9} {'one-way median':>15} {'p99':>9} "
            f"{'round trips/s':>14} {'one-way MB/s':>13}"
        )

        def spin() -> None:
            if bridge.spin_once() == 0:
                time.sleep(0)  # lets zenoh's callback threads take the GIL

        for key, msg in msgs.items():
            got: list[float] = []
            arrived = got.append
            pub = node.create_publisher(type(msg), f"/ping_{key}")
            node.create_subscription(
                type(msg),
                f"/pong_{key}",
                lambda m, arrived=arrived: arrived(time.perf_counter()),
                queue_size=0,
            )
            deadline = time.monotonic() + 10
            while pub.get_num_connections() == 0 or not bridge.remote_graphs:
                spin()
                if time.monotonic() > deadline:
                    raise RuntimeError("the echo process did not subscribe")
            time.sleep(0.2)
            bridge.spin_once()
            # warm-up until a round trip completes (routes are being set up)
            while not got:
                pub.publish(msg)
                t0 = time.perf_counter()
                while not got and time.perf_counter() - t0 < 0.2:
                    spin()
            got.clear()
            rtts = []
            for _ in range(ROUNDS):
                n0 = len(got)
                t0 = time.perf_counter()
                pub.publish(msg)
                while len(got) == n0:
                    spin()
                rtts.append(got[-1] - t0)
            one_way = np.array(rtts) / 2 * 1e6
            got.clear()
            sent = 0
            t0 = time.perf_counter()
            while time.perf_counter() - t0 < DURATION:
                if sent - len(got) < WINDOW:
                    pub.publish(msg)
                    sent += 1
                spin()
            elapsed = time.perf_counter() - t0
            done = len(got)
            size = len(serialize(msg))
            print(
                f"{key:<12} {size:>9d} {np.median(one_way):>12.0f} us "
                f"{np.percentile(one_way, 99):>6.0f} us "
                f"{done / elapsed:>14.0f} {done * size / elapsed / 1e6:>13.2f}"
            )
        rt.shutdown()
    finally:
        echo.kill()
        echo.wait()


if __name__ == "__main__":
    main()
