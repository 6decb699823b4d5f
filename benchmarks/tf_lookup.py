"""tf: lookups per second over a 5-frame chain with interpolation, and tuple vs NumPy math.

Chain: ``map -> lizi1/odom -> lizi1/base_footprint -> lizi1/base_link -> lizi1/laser_link``,
odom at 20 Hz, the robot's edges at 50 Hz, the laser static; 10 s of history (the buffer's
default ``cache_time``). Lookups ask for the laser in ``map`` at times between stamps, so every
dynamic edge is interpolated (lerp + slerp). Target: >= 50,000 lookups/s with interpolation.
Also prints the cost of one compose / one interpolation in plain-float tuples
(:mod:`fleetsim.tf.fastmath`, what the buffer uses) against NumPy (:mod:`fleetsim.tf.transforms`),
and batch point transforms. Prints; asserts nothing about time.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/tf_lookup.py``
"""

from __future__ import annotations

import math
import time

import numpy as np

from fleetsim.tf import Buffer, make_transform_stamped
from fleetsim.tf import fastmath as fm
from fleetsim.tf import transforms as tm

SECONDS = 10.0


def yawq(yaw: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def robot_buffer() -> Buffer:
    buf = Buffer(cache_time=10.0)
    for k in range(int(SECONDS * 20) + 1):
        t = k / 20
        buf.set_transform_values("map", "lizi1/odom", t, (0.01 * t, 0.02 * t, 0.0), yawq(0.01 * t))
    for k in range(int(SECONDS * 50) + 1):
        t = k / 50
        buf.set_transform_values(
            "lizi1/odom", "lizi1/base_footprint", t, (0.3 * t, 0.1 * t, 0.0), yawq(0.2 * t)
        )
        buf.set_transform_values(
            "lizi1/base_footprint", "lizi1/base_link", t, (0.0, 0.0, 0.05 + 0.001 * t), yawq(0.0)
        )
    buf.set_transform_values(
        "lizi1/base_link", "lizi1/laser_link", 0.0, (0.1, 0.0, 0.2), yawq(0.0), is_static=True
    )
    return buf


def rate(fn, n: int) -> float:
    """Calls per second of ``fn(i)`` over ``n`` calls (best of 3)."""
    best = math.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for i in range(n):
            fn(i)
        best = min(best, time.perf_counter() - t0)
    return n / best


def main() -> None:
    buf = robot_buffer()
    times = [1.0 + 8.0 * ((i * 0.6180339887) % 1.0) + 0.0037 for i in range(1024)]  # off-stamp
    n = 50_000
    print(f"tf lookup over a 5-frame chain (4 edges, 3 interpolated), {n:,} lookups, best of 3")
    rows = [
        ("lookup_tuple (interpolated)", lambda i: buf.lookup_tuple("map", "lizi1/laser_link",
                                                                    times[i & 1023])),
        ("lookup_tuple (time 0, latest)", lambda i: buf.lookup_tuple("map", "lizi1/laser_link")),
        ("lookup_tuple (inverse direction)", lambda i: buf.lookup_tuple("lizi1/laser_link", "map",
                                                                         times[i & 1023])),
        ("lookup_arrays (t (3,), q (4,))", lambda i: buf.lookup_arrays("map", "lizi1/laser_link",
                                                                        times[i & 1023])),
        ("lookup_matrix (4x4)", lambda i: buf.lookup_matrix("map", "lizi1/laser_link",
                                                            times[i & 1023])),
        ("lookup_transform (TransformStamped)", lambda i: buf.lookup_transform(
            "map", "lizi1/laser_link", times[i & 1023])),
        ("lookup_pose2d (x, y, yaw)", lambda i: buf.lookup_pose2d("map", "lizi1/base_link",
                                                                  times[i & 1023])),
    ]  # fmt: skip
    for label, fn in rows:
        r = rate(fn, n)
        print(f"  {label:38s} {r:>10,.0f} /s   {1e6 / r:6.2f} us")

    msgs = [make_transform_stamped("odom", "base_link", k * 0.01, (k * 0.01, 0.0, 0.0),
                                   yawq(k * 0.001)) for k in range(20_000)]  # fmt: skip
    fresh = Buffer()
    t0 = time.perf_counter()
    for msg in msgs:
        fresh.set_transform(msg)
    r = len(msgs) / (time.perf_counter() - t0)
    print(f"  {'set_transform (TransformStamped)':38s} {r:>10,.0f} /s   {1e6 / r:6.2f} us")

    print("\none transform, plain-float tuples vs NumPy arrays")
    a = (1.0, 2.0, 0.5, *yawq(0.3))
    b = (0.1, -0.2, 0.0, *yawq(-1.1))
    ta, qa, tb, qb = np.array(a[:3]), np.array(a[3:]), np.array(b[:3]), np.array(b[3:])
    m = 100_000
    pairs = [
        ("compose", lambda i: fm.compose(a, b), lambda i: tm.compose_transforms(ta, qa, tb, qb)),
        ("interpolate / lerp+slerp", lambda i: fm.interpolate(a, b, 0.3),
         lambda i: (ta + 0.3 * (tb - ta), tm.slerp(qa, qb, 0.3))),
        ("invert", lambda i: fm.invert(a), lambda i: tm.inverse_transform(ta, qa)),
    ]  # fmt: skip
    for label, f_tuple, f_numpy in pairs:
        rt, rn = rate(f_tuple, m), rate(f_numpy, m // 10)
        print(
            f"  {label:26s} tuple {1e6 / rt:6.2f} us   numpy {1e6 / rn:6.2f} us   "
            f"(tuple {rn and rt / rn:4.1f}x faster)"
        )

    print("\nbatch: transform_points (N, 3) with one transform")
    rng = np.random.default_rng(0)
    for count in (1_000, 100_000):
        pts = rng.normal(size=(count, 3))
        r = rate(lambda i, pts=pts: tm.transform_points(ta, qa, pts), 50)
        print(f"  N = {count:>7,}: {r * count / 1e6:8.1f} M points/s")


if __name__ == "__main__":
    main()
