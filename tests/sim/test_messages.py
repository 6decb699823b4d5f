"""Readings as ROS messages: the depth camera's point cloud."""

import math

import numpy as np

from fleetsim.nav.costmap.costmap_ros import points_from_cloud2
from fleetsim.sim import messages


def test_cloud_of_a_flat_wall_in_the_optical_frame():
    w, h, hfov = 8, 6, 1.2
    fx = (w / 2) / math.tan(hfov / 2)
    K = np.array([[fx, 0, (w + 1) / 2], [0, fx, (h + 1) / 2], [0, 0, 1.0]])
    depth = np.full((h, w), 2.0, np.float32)
    depth[0, 0] = np.nan  # outside the cutoffs
    rgb = np.zeros((h, w, 3), np.uint8)
    rgb[..., 0], rgb[..., 2] = 200, 7
    msg = messages.cloud_msg(1.5, "cam_optical", depth, rgb, K)
    assert (msg.height, msg.width, msg.point_step, msg.row_step) == (h, w, 32, 32 * w)
    assert [f.name for f in msg.fields] == ["x", "y", "z", "rgb"] and not msg.is_dense
    assert msg.header.frame_id == "cam_optical" and msg.header.stamp.to_sec() == 1.5
    pts = points_from_cloud2(msg)  # the costmap's reader drops the NaN point
    assert pts.shape == (h * w - 1, 3)
    np.testing.assert_allclose(pts[:, 2], 2.0)
    # the last column lies right of centre (x > 0), the bottom row below it (y > 0)
    grid = np.frombuffer(msg.data.tobytes(), np.float32).reshape(h, w, 8)
    u, v = w - 1, h - 1
    np.testing.assert_allclose(grid[v, u, :3], [(u - K[0, 2]) * 2 / fx, (v - K[1, 2]) * 2 / fx, 2])
    packed = grid[v, u, 4:5].view(np.uint32)[0]
    assert (packed >> 16, (packed >> 8) & 255, packed & 255) == (200, 0, 7)
