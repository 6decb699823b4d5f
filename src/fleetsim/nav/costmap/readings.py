"""Sensor messages as points for the obstacle layers: LaserScan, PointCloud2, PointCloud.

Each function returns (N, 3) float64 points in the message's frame, m.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from fleetsim.nav.costmap.obstacle_layer import laser_scan_points
from fleetsim.nav.errors import CostmapError

_CLOUD_DTYPES = {7: "f4", 8: "f8"}  # PointField.FLOAT32, FLOAT64


def points_from_cloud2(msg: Any, where: str = "PointCloud2") -> np.ndarray:
    """The x, y, z of a PointCloud2 (FLOAT32 or FLOAT64 fields), NaN points dropped: (N, 3) m."""
    fields = {f.name: f for f in msg.fields}
    missing = [k for k in "xyz" if k not in fields]
    if missing:
        raise CostmapError(f"{where}: the cloud has no field(s) {', '.join(missing)}")
    n = int(msg.width) * int(msg.height)
    step = int(msg.point_step)
    raw = np.asarray(msg.data, dtype=np.uint8)
    row = int(msg.row_step) or step * int(msg.width)
    if raw.size < row * (int(msg.height) - 1) + step * int(msg.width) or n == 0:
        return np.zeros((0, 3))
    endian = ">" if msg.is_bigendian else "<"
    out = np.empty((n, 3))
    rows = raw[: row * int(msg.height)].reshape(int(msg.height), row)[:, : step * int(msg.width)]
    flat = np.ascontiguousarray(rows).reshape(n, step)
    for i, k in enumerate("xyz"):
        f = fields[k]
        kind = _CLOUD_DTYPES.get(int(f.datatype))
        if kind is None:
            raise CostmapError(f"{where}: field '{k}' has datatype {f.datatype}; need FLOAT32/64")
        size = int(kind[1])
        col = np.ascontiguousarray(flat[:, f.offset : f.offset + size])
        out[:, i] = col.view(endian + kind).ravel()
    return out[np.isfinite(out).all(axis=1)]


#: the last scan projected: (message, inf_is_valid, points). move_base's global and local
#: costmaps get the same scan object and project it once; the points are read only
_last_scan: list[Any] = [None, None, None]


def points_from_scan(msg: Any, inf_is_valid: bool = False) -> np.ndarray:
    """A LaserScan's readings as points (`laser_scan_points`), shared by readers of one message."""
    last = _last_scan
    if last[0] is msg and last[1] == inf_is_valid:
        return last[2]
    points = laser_scan_points(
        msg.ranges,
        msg.angle_min,
        msg.angle_increment,
        msg.range_min,
        msg.range_max,
        inf_is_valid,
    )
    points.flags.writeable = False
    last[:] = (msg, inf_is_valid, points)
    return points


def points_from_cloud1(msg: Any) -> np.ndarray:
    """The points of a ROS 1 sensor_msgs/PointCloud."""
    return np.array([[p.x, p.y, p.z] for p in msg.points], dtype=np.float64).reshape(-1, 3)
