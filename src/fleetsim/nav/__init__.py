"""The ROS 1 navigation stack: map_server, costmap_2d, navfn, base_local_planner, recovery."""
