from __future__ import annotations

import numpy as np

from fleetsim.msgs import deserialize, nav_msgs, serialize


def test_service_layouts(own_def):
    assert own_def("nav_msgs/GetMapRequest") == []
    assert own_def("nav_msgs/GetMapResponse") == ["nav_msgs/OccupancyGrid map"]
    assert own_def("nav_msgs/GetPlanRequest") == [
        "geometry_msgs/PoseStamped start",
        "geometry_msgs/PoseStamped goal",
        "float32 tolerance",
    ]
    assert own_def("nav_msgs/GetPlanResponse") == ["nav_msgs/Path plan"]
    assert own_def("nav_msgs/SetMapRequest") == [
        "nav_msgs/OccupancyGrid map",
        "geometry_msgs/PoseWithCovarianceStamped initial_pose",
    ]
    assert own_def("nav_msgs/SetMapResponse") == ["bool success"]


def test_occupancy_grid_round_trip():
    grid = nav_msgs.OccupancyGrid()
    grid.info.resolution, grid.info.width, grid.info.height = 0.05, 3, 2
    grid.data = np.array([-1, 0, 100, 50, 0, -1], np.int8)
    back = deserialize(serialize(nav_msgs.GetMap.Response(map=grid)), "nav_msgs/GetMapResponse")
    assert back.map.data.reshape(2, 3)[0].tolist() == [-1, 0, 100]
    assert back.map.info.resolution == np.float32(0.05)
