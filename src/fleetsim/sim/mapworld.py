"""Map worlds: an occupancy map (map_server YAML + PGM/PNG) extruded into walls.

The walls are placed so that the world frame *is* the map frame: cell ``(row, col)`` of the
image (row 0 at the top, as map_server reads it) covers
``x in origin_x + [col, col + 1) * resolution`` and ``y in origin_y + [H - 1 - row, H - row) *
resolution`` (rotated by the origin yaw about the origin), exactly where map_server puts it, so a
map loaded by map_server lines up with the simulated walls by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
import yaml

from fleetsim.errors import SimulationError


@dataclass(frozen=True)
class OccupancyMap:
    """An occupancy map with rows ordered bottom-up (row 0 at ``origin`` y, as OccupancyGrid)."""

    occupied: np.ndarray  # (H, W) bool, row 0 = lowest y
    resolution: float  # metres per cell
    origin: tuple[float, float, float]  # x, y (m), yaw (rad) of cell (0, 0)'s lower-left corner
    source: str


def _read_image(path: Path) -> np.ndarray:
    from PIL import Image  # pillow reads PGM (P2/P5), PNG, BMP

    try:
        with Image.open(path) as im:
            if im.mode in ("RGBA", "LA"):
                arr = np.asarray(im.convert("LA"), dtype=np.float64)
                return arr[..., 0]
            return np.asarray(im.convert("L"), dtype=np.float64)
    except (OSError, ValueError) as exc:
        raise SimulationError(f"{path}: cannot read map image ({exc})") from exc


def load_map(yaml_path: str | Path) -> OccupancyMap:
    """Read a map_server YAML file and its image into an ``OccupancyMap`` (trinary mode)."""
    path = Path(yaml_path)
    try:
        meta = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise SimulationError(f"{path}: cannot read map file ({exc.strerror})") from exc
    except yaml.YAMLError as exc:
        raise SimulationError(f"{path}: map YAML does not parse ({exc})") from exc
    if not isinstance(meta, dict):
        raise SimulationError(f"{path}: a map YAML must be a mapping with 'image', 'resolution'")
    for key in ("image", "resolution"):
        if key not in meta:
            raise SimulationError(f"{path}: map YAML lacks the field '{key}'")
    try:
        res = float(meta["resolution"])
        origin = [float(v) for v in meta.get("origin", [0.0, 0.0, 0.0])]
        occ_th = float(meta.get("occupied_thresh", 0.65))
        negate = int(meta.get("negate", 0))
    except (TypeError, ValueError) as exc:
        raise SimulationError(f"{path}: bad number in map YAML ({exc})") from exc
    if res <= 0 or len(origin) != 3:
        raise SimulationError(
            f"{path}: 'resolution' must be > 0 and 'origin' [x, y, yaw]; got {res}, {origin}"
        )
    img_path = Path(meta["image"])
    if not img_path.is_absolute():
        img_path = path.parent / img_path
    if not img_path.exists():
        raise SimulationError(f"{path}: map image '{meta['image']}' not found at {img_path}")
    pixels = _read_image(img_path)
    p = pixels / 255.0 if negate else (255.0 - pixels) / 255.0
    occupied = np.ascontiguousarray((p > occ_th)[::-1])
    return OccupancyMap(occupied, res, (origin[0], origin[1], origin[2]), str(path))


@numba.njit(cache=True)
def rectangles_from_occupancy(occ):
    """Cover the True cells of ``occ`` with few disjoint axis-aligned rectangles (greedy).

    Parameters
    ----------
    occ : (H, W) bool grid.

    Returns
    -------
    (K, 4) int64 rows ``[r0, c0, r1, c1]`` (half-open cell ranges), whose union is exactly the
    set of True cells. Each rectangle grows right along its first row, then down while the whole
    span is free to take.
    """
    h, w = occ.shape
    used = np.zeros((h, w), np.bool_)
    out = np.empty((h * w // 2 + 1, 4), np.int64)
    k = 0
    for r in range(h):
        c = 0
        while c < w:
            if not occ[r, c] or used[r, c]:
                c += 1
                continue
            c1 = c
            while c1 < w and occ[r, c1] and not used[r, c1]:
                c1 += 1
            r1 = r + 1
            while r1 < h:
                ok = True
                for cc in range(c, c1):
                    if not occ[r1, cc] or used[r1, cc]:
                        ok = False
                        break
                if not ok:
                    break
                r1 += 1
            used[r:r1, c:c1] = True
            if k == out.shape[0]:
                bigger = np.empty((2 * k, 4), np.int64)
                bigger[:k] = out
                out = bigger
            out[k, 0] = r
            out[k, 1] = c
            out[k, 2] = r1
            out[k, 3] = c1
            k += 1
            c = c1
    return out[:k]


def wall_boxes(grid: OccupancyMap, height: float = 1.0) -> np.ndarray:
    """Wall boxes of an occupancy map in the world (= map) frame.

    Returns
    -------
    (K, 7) float64 rows ``[cx, cy, cz, hx, hy, hz, yaw]``: box centre (m), half sizes (m) and
    yaw (rad) about z; the boxes stand on z = 0 and are ``height`` metres tall.
    """
    if height <= 0:
        raise SimulationError(f"{grid.source}: wall height must be > 0, got {height}")
    rects = rectangles_from_occupancy(grid.occupied).astype(np.float64)
    res = grid.resolution
    return _placed(
        grid,
        (rects[:, 1] + rects[:, 3]) * 0.5 * res,
        (rects[:, 0] + rects[:, 2]) * 0.5 * res,
        (rects[:, 3] - rects[:, 1]) * 0.5 * res,
        (rects[:, 2] - rects[:, 0]) * 0.5 * res,
        height,
    )


def boundary_boxes(grid: OccupancyMap, height: float, segment: float) -> np.ndarray:
    """One cell thick walls just outside the map's edges, as Stage's ``floorplan`` builds with
    ``boundary 1`` ("most maps will need a bounding box"; the lesson's Willow map came from
    Stage's ``willow-full`` world). Without them a robot pushed past the map's edge where its
    cells are free (Willow's grey surround reads as free with map_server's thresholds) drives
    into space no costmap covers. Rows as `wall_boxes`; each side is split into pieces no
    longer than ``segment`` m (so they join the wall tiles of their stretch).
    """
    res = grid.resolution
    h, w = grid.occupied.shape
    width, top = w * res, h * res
    t = res  # thickness: one cell, outside the map
    # each side's centre line, (x0, y0) to (x1, y1), in the map's own frame
    sides = [
        (-t / 2, -t, -t / 2, top + t),  # west
        (width + t / 2, -t, width + t / 2, top + t),  # east
        (0.0, -t / 2, width, -t / 2),  # south
        (0.0, top + t / 2, width, top + t / 2),  # north
    ]
    cols: list[tuple[float, float, float, float]] = []  # centre x, y, half sizes x, y
    for x0, y0, x1, y1 in sides:
        length = math.hypot(x1 - x0, y1 - y0)
        n = max(1, math.ceil(length / segment))
        half = length / n / 2
        for k in range(n):
            b = (k + 0.5) / n
            hx, hy = (t / 2, half) if x0 == x1 else (half, t / 2)
            cols.append((x0 + (x1 - x0) * b, y0 + (y1 - y0) * b, hx, hy))
    lx, ly, hx, hy = np.asarray(cols, dtype=np.float64).T
    return _placed(grid, lx, ly, hx, hy, height)


def _placed(grid: OccupancyMap, lx, ly, hx, hy, height: float) -> np.ndarray:
    """Box rows ``[cx, cy, cz, hx, hy, hz, yaw]`` from centres (``lx``, ``ly``) and half sizes
    (``hx``, ``hy``), m, in the map's own frame (its lower-left corner, along its rows):
    placed by the map's ``origin``, standing on z = 0, ``height`` m tall."""
    ox, oy, yaw = grid.origin
    c, s = np.cos(yaw), np.sin(yaw)
    out = np.empty((len(lx), 7))
    out[:, 0] = ox + c * lx - s * ly
    out[:, 1] = oy + s * lx + c * ly
    out[:, 2] = height / 2
    out[:, 3] = hx
    out[:, 4] = hy
    out[:, 5] = height / 2
    out[:, 6] = yaw
    return out
