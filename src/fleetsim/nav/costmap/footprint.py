"""Robot footprints: parsing, padding, radii, rasterising, and batched footprint costs.

A footprint is a (K, 2) float64 polygon in the robot's base frame (m), as costmap_2d's
``footprint`` parameter (``[[x, y], ...]`` as a list or a string), or the 16-point circle
costmap_2d makes from ``robot_radius``.
"""

from __future__ import annotations

import math

import numpy as np
import shapely
import yaml
from numba import njit

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE, NO_INFORMATION, Costmap2D
from fleetsim.nav.errors import CostmapError


def footprint_from_radius(radius: float, n: int = 16) -> np.ndarray:
    """The n-gon costmap_2d uses for ``robot_radius`` (makeFootprintFromRadius): (n, 2) m."""
    a = np.arange(n) * (2.0 * math.pi / n)
    return np.stack((radius * np.cos(a), radius * np.sin(a)), axis=1)


def footprint_from_param(value: object, where: str = "footprint") -> np.ndarray:
    """Parse the ``footprint`` parameter: ``[[x, y], ...]`` (>= 3 points) as list or string."""
    raw = value
    if isinstance(value, str):
        try:
            raw = yaml.safe_load(value)
        except yaml.YAMLError:
            raw = None
    try:
        pts = np.asarray(raw, dtype=np.float64)
    except (TypeError, ValueError):
        pts = np.empty((0,))
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3 or not np.isfinite(pts).all():
        raise CostmapError(
            f"{where}: footprint must be a list of at least 3 [x, y] points, e.g. "
            f"[[-0.2, -0.2], [-0.2, 0.2], [0.3, 0.0]]; got {value!r}"
        )
    return pts


def padded_footprint(footprint: np.ndarray, padding: float) -> np.ndarray:
    """costmap_2d's padFootprint: each coordinate moved ``padding`` away from 0 by its sign."""
    fp = np.asarray(footprint, dtype=np.float64)
    return fp + np.sign(fp) * padding


def inside_polygon(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """(N,) bool: which ``points`` (N, 2) lie inside ``polygon`` (M, 2), any winding, convex
    or not (shapely's ``contains_xy``)."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    return shapely.contains_xy(shapely.Polygon(polygon), pts[:, 0], pts[:, 1])


def footprint_radii(footprint: np.ndarray) -> tuple[float, float]:
    """(inscribed, circumscribed) radius of a polygon about the origin, m.

    inscribed: the smallest distance from the origin to an edge (calculateMinAndMaxDistances);
    circumscribed: the largest vertex distance.
    """
    fp = np.asarray(footprint, dtype=np.float64)
    a, b = fp, np.roll(fp, -1, axis=0)
    ab = b - a
    t = np.clip(-(a * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-300), 0.0, 1.0)
    closest = a + t[:, None] * ab
    inscribed = float(np.min(np.hypot(closest[:, 0], closest[:, 1])))
    circumscribed = float(np.max(np.hypot(fp[:, 0], fp[:, 1])))
    return inscribed, circumscribed


def footprint_at(footprint: np.ndarray, x: float, y: float, yaw: float) -> np.ndarray:
    """The footprint moved to pose (x, y, yaw): (K, 2) in the costmap frame."""
    fp = np.asarray(footprint, dtype=np.float64)
    return _moved(fp, x, y, math.cos(yaw), math.sin(yaw))


@njit(cache=True)
def _moved(fp, x, y, c, s):
    """`footprint_at`'s rows, compiled (it runs in every costmap update and control cycle of
    every robot; ``np.stack`` of two few-point columns costs ~6 us)."""
    out = np.empty((fp.shape[0], 2))
    for i in range(fp.shape[0]):
        out[i, 0] = x + c * fp[i, 0] - s * fp[i, 1]
        out[i, 1] = y + s * fp[i, 0] + c * fp[i, 1]
    return out


def polygon_cells(costmap: Costmap2D, polygon: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cells (rows, cols) covered by a world polygon: centres inside it, plus its outline.

    As costmap_2d's convexFillCells, but by an even-odd test on cell centres (any polygon)
    unioned with the outline cells (points at most half a cell apart), clipped to the grid.
    Returns (my, mx) int arrays, row by row. Compiled: footprint clearing calls it for every
    costmap update of every robot, and the NumPy version of these few dozen cells cost
    ~0.2 ms in array overhead.
    """
    poly = np.ascontiguousarray(polygon, dtype=np.float64)
    return _polygon_cells(
        poly, costmap.origin_x, costmap.origin_y, costmap.resolution, costmap.size_x,
        costmap.size_y,
    )  # fmt: skip


@njit(cache=True)
def _polygon_cells(poly, ox, oy, res, size_x, size_y):
    k = poly.shape[0]
    cx0 = cy0 = 1 << 62
    cx1 = cy1 = -(1 << 62)
    for i in range(k):
        cx = math.floor((poly[i, 0] - ox) / res)
        cy = math.floor((poly[i, 1] - oy) / res)
        cx0, cx1 = min(cx0, cx), max(cx1, cx)
        cy0, cy1 = min(cy0, cy), max(cy1, cy)
    x0, x1 = max(cx0, 0), min(cx1, size_x - 1)
    y0, y1 = max(cy0, 0), min(cy1, size_y - 1)
    if x1 < x0 or y1 < y0:
        return np.empty(0, np.int64), np.empty(0, np.int64)
    w, h = x1 - x0 + 1, y1 - y0 + 1
    inside = np.zeros((h, w), np.bool_)
    for r in range(h):
        py = oy + (y0 + r + 0.5) * res
        for i in range(k):
            ax, ay = poly[i, 0], poly[i, 1]
            bx, by = poly[(i + 1) % k, 0], poly[(i + 1) % k, 1]
            if (ay > py) != (by > py):
                xc = ax + (py - ay) * (bx - ax) / (by - ay)
                for c in range(w):
                    if ox + (x0 + c + 0.5) * res < xc:
                        inside[r, c] = not inside[r, c]
    spacing = res * 0.5
    for i in range(k):  # the outline, as `outline_points`
        ax, ay = poly[i, 0], poly[i, 1]
        dx, dy = poly[(i + 1) % k, 0] - ax, poly[(i + 1) % k, 1] - ay
        n = max(1, math.ceil(math.hypot(dx, dy) / spacing))
        for j in range(n):
            t = j / n
            cx = math.floor((ax + t * dx - ox) / res)
            cy = math.floor((ay + t * dy - oy) / res)
            if 0 <= cx < size_x and 0 <= cy < size_y:
                inside[cy - y0, cx - x0] = True
    count = 0
    for r in range(h):
        for c in range(w):
            count += inside[r, c]
    rows = np.empty(count, np.int64)
    cols = np.empty(count, np.int64)
    count = 0
    for r in range(h):
        for c in range(w):
            if inside[r, c]:
                rows[count] = r + y0
                cols[count] = c + x0
                count += 1
    return rows, cols


def outline_points(polygon: np.ndarray, spacing: float) -> np.ndarray:
    """Points along a closed polygon's edges, at most ``spacing`` apart, vertices included.

    polygon : (K, 2). Returns (M, 2), in the polygon's frame.
    """
    poly = np.asarray(polygon, dtype=np.float64)
    out = []
    for a, b in zip(poly, np.roll(poly, -1, axis=0)):
        n = max(1, math.ceil(float(np.hypot(*(b - a))) / spacing))
        t = np.arange(n)[:, None] / n
        out.append(a + t * (b - a))
    return np.concatenate(out, axis=0)


@njit(cache=True, inline="always")
def footprint_cost_at(costs, origin_x, origin_y, resolution, outline, x, y, yaw):
    """Footprint cost of one pose (see `footprint_costs`); -1.0 when illegal."""
    return footprint_cost_rotated(
        costs, origin_x, origin_y, resolution, outline, x, y, math.cos(yaw), math.sin(yaw)
    )


@njit(cache=True, inline="always")
def footprint_cost_rotated(costs, origin_x, origin_y, resolution, outline, x, y, c, s):
    """`footprint_cost_at` with the heading given as its cosine ``c`` and sine ``s`` (a caller
    that has them already saves the two trig calls)."""
    sy, sx = costs.shape
    worst = 0.0
    for k in range(outline.shape[0]):
        fx = (x + c * outline[k, 0] - s * outline[k, 1] - origin_x) / resolution
        fy = (y + s * outline[k, 0] + c * outline[k, 1] - origin_y) / resolution
        if fx < 0.0 or fy < 0.0 or fx >= sx or fy >= sy:
            return -1.0
        v = costs[int(fy), int(fx)]
        if v == LETHAL_OBSTACLE or v == NO_INFORMATION:  # noqa: SIM109 (numba)
            return -1.0
        if v > worst:
            worst = float(v)
    return worst


@njit(cache=True)
def footprint_costs(
    costs: np.ndarray,
    origin_x: float,
    origin_y: float,
    resolution: float,
    outline: np.ndarray,
    poses: np.ndarray,
) -> np.ndarray:
    """Footprint cost at each pose, as base_local_planner's CostmapModel::footprintCost.

    The footprint's outline (not its inside) is laid on the grid; the cost is the highest cell
    cost under it, -1.0 when the outline touches a LETHAL or NO_INFORMATION cell or leaves
    the grid.

    Parameters
    ----------
    costs : (size_y, size_x) uint8 costmap.
    origin_x, origin_y, resolution : the costmap's origin (m) and cell size (m).
    outline : (M, 2) outline points in the robot frame (see `outline_points`), m.
    poses : (P, 3) x, y, yaw in the costmap frame, m and rad.

    Returns
    -------
    (P,) float64 costs, -1.0 for an illegal pose.
    """
    out = np.empty(poses.shape[0])
    for p in range(poses.shape[0]):
        out[p] = footprint_cost_at(
            costs, origin_x, origin_y, resolution, outline, poses[p, 0], poses[p, 1], poses[p, 2]
        )
    return out
