"""A small synthetic world for the amcl tests: boxes, their occupancy grid, an exact ray caster.

The world is a set of axis-aligned boxes with corners on the 0.05 m grid, so the rasterised
map (cell occupied iff its centre is inside a box) matches the geometry exactly; the ray
caster intersects rays with the boxes analytically (slab method), independent of the grid.
"""

from __future__ import annotations

import numpy as np

from fleetsim.localization.amcl import AmclMap

RES = 0.05
WIDTH_M, HEIGHT_M = 16.0, 10.0

# (xmin, ymin, xmax, ymax), m: outer walls, then an asymmetric set of obstacles
BOXES = np.array(
    [
        [0.0, 0.0, 16.0, 0.2],
        [0.0, 9.8, 16.0, 10.0],
        [0.0, 0.0, 0.2, 10.0],
        [15.8, 0.0, 16.0, 10.0],
        [4.0, 0.2, 4.2, 4.0],  # wall stub from the bottom
        [8.0, 6.0, 8.2, 9.8],  # wall stub from the top
        [11.0, 2.0, 13.0, 3.0],  # a table
        [2.0, 6.5, 3.0, 7.0],  # a shelf
        [12.0, 7.0, 12.5, 7.5],  # a pillar
        [6.0, 2.5, 6.4, 2.9],  # a small box
    ]
)


def world_map() -> AmclMap:
    """The rasterised world: (200, 320) cells, origin (0, 0)."""
    w, h = round(WIDTH_M / RES), round(HEIGHT_M / RES)
    xs = (np.arange(w) + 0.5) * RES
    ys = (np.arange(h) + 0.5) * RES
    gx, gy = np.meshgrid(xs, ys)
    occ = np.zeros((h, w), dtype=bool)
    for x0, y0, x1, y1 in BOXES:
        occ |= (gx > x0) & (gx < x1) & (gy > y0) & (gy < y1)
    data = np.where(occ, 100, 0).astype(np.int8).ravel()
    return AmclMap.from_occupancy(data, w, h, RES)


def exact_ranges(pose: np.ndarray, angles: np.ndarray, max_range: float) -> np.ndarray:
    """(B,) exact ranges from sensor pose ``(x, y, yaw)`` along ``angles`` (sensor frame).

    Beams that hit nothing within ``max_range`` return ``inf`` (REP 117).
    """
    a = pose[2] + np.asarray(angles, dtype=float)
    dx, dy = np.cos(a), np.sin(a)
    best = np.full(len(a), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for x0, y0, x1, y1 in BOXES:
            tx1, tx2 = (x0 - pose[0]) / dx, (x1 - pose[0]) / dx
            ty1, ty2 = (y0 - pose[1]) / dy, (y1 - pose[1]) / dy
            tmin = np.maximum(np.minimum(tx1, tx2), np.minimum(ty1, ty2))
            tmax = np.minimum(np.maximum(tx1, tx2), np.maximum(ty1, ty2))
            hit = (tmax >= tmin) & (tmax > 0) & ~np.isnan(tmin)
            t = np.where(tmin > 0, tmin, 0.0)
            best = np.where(hit & (t < best), t, best)
    return np.where(best <= max_range, best, np.inf)


def scan(
    pose: np.ndarray, n: int, max_range: float, noise: float, rng: np.random.Generator
) -> tuple[np.ndarray, float, float]:
    """A 360-degree scan: ``(ranges (n,), angle_min, angle_increment)`` with Gaussian noise."""
    inc = 2.0 * np.pi / n
    angles = -np.pi + inc * np.arange(n)
    r = exact_ranges(pose, angles, max_range)
    return r + noise * rng.standard_normal(n), -np.pi, inc


# a loop through free space (>= 0.5 m from every obstacle), about 55 m long
ROUTE = np.array(
    [
        [1.5, 5.0],
        [9.5, 5.0],
        [9.5, 1.2],
        [14.5, 1.2],
        [14.5, 8.5],
        [9.5, 8.5],
        [9.5, 5.0],
        [1.5, 5.0],
        [1.5, 8.5],
        [7.0, 8.5],
        [7.0, 5.0],
    ]
)


def drive(
    waypoints: np.ndarray,
    rng: np.random.Generator,
    speed: float = 0.5,
    dt: float = 0.1,
    odom_noise: float = 0.05,
    odom_bias: float = 0.03,
):
    """Yield ``(true_pose, odom_pose)`` at each step of a drive through ``waypoints``.

    The robot turns in place towards the next waypoint and drives straight to it. Odometry
    integrates body-frame increments scaled by ``1 + bias + noise`` (translation) and offset by
    a yaw bias, so it drifts like wheel odometry.
    """
    true = np.array([waypoints[0, 0], waypoints[0, 1], 0.0])
    d = waypoints[1] - waypoints[0]
    true[2] = np.arctan2(d[1], d[0])
    odom = np.zeros(3)
    yield true.copy(), odom.copy()
    for target in waypoints[1:]:
        while True:
            d = target - true[:2]
            dist = float(np.hypot(*d))
            if dist < 1e-6:
                break
            heading_err = (np.arctan2(d[1], d[0]) - true[2] + np.pi) % (2 * np.pi) - np.pi
            if abs(heading_err) > 1e-3:
                dth = float(np.clip(heading_err, -1.0 * dt, 1.0 * dt))
                ds = 0.0
            else:
                dth = 0.0
                ds = min(speed * dt, dist)
            true = true + np.array([ds * np.cos(true[2] + dth), ds * np.sin(true[2] + dth), dth])
            ods = ds * (1.0 + odom_bias + odom_noise * rng.standard_normal())
            odth = dth * (1.0 + odom_noise * rng.standard_normal()) + odom_bias * ds
            odom = odom + np.array(
                [ods * np.cos(odom[2] + odth), ods * np.sin(odom[2] + odth), odth]
            )
            yield true.copy(), odom.copy()
