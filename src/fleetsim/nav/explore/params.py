"""explore_lite's parameters, with their ROS names and defaults, and fleetsim's additions (each
off by default, so the node is explore_lite unless a launch file asks for more)."""

from __future__ import annotations

from dataclasses import dataclass

from fleetsim.runtime import param


@dataclass(frozen=True)
class ExploreParams:
    """explore_lite's parameters (ROS names and defaults)."""

    robot_base_frame: str = param("base_link", help="robot base frame (tf_prefix applied)")
    costmap_topic: str = param("costmap", help="nav_msgs/OccupancyGrid to explore")
    costmap_updates_topic: str = param(
        "costmap_updates", help="accepted; fleetsim's costmaps publish whole grids"
    )
    visualize: bool = param(False, help="publish frontiers as markers on ~frontiers")
    planner_frequency: float = param(1.0, unit="Hz", range=(1e-3, None), help="replanning rate")
    progress_timeout: float = param(
        30.0, unit="s", range=(0.0, None), help="blacklist a goal without progress this long"
    )
    potential_scale: float = param(1e-3, range=(0.0, None), help="weight of frontier distance")
    orientation_scale: float = param(0.0, range=(0.0, None), help="unused, as in explore_lite")
    gain_scale: float = param(1.0, range=(0.0, None), help="weight of frontier size")
    transform_tolerance: float = param(
        0.3, unit="s", range=(0.0, None), help="oldest robot pose (tf) used to plan"
    )
    min_frontier_size: float = param(
        0.5, unit="m", range=(0.0, None), help="smallest frontier considered"
    )
    # fleetsim additions: explorers that share a map leave each other's frontiers alone
    peer_goals: list = param([], help="other explorers' ~goal topics (geometry_msgs/PointStamped)")
    peer_radius: float = param(
        3.0, unit="m", range=(0.0, None), help="frontiers this close to a peer's goal are its"
    )
    peer_frames: list = param(
        [], help="other explorers' base frames: frontiers nearer to one of them are its"
    )
    peer_blacklists: list = param(
        [], help="other explorers' ~blacklist topics (geometry_msgs/PoseArray): skipped too"
    )
    switch_distance: float = param(
        0.0,
        unit="m",
        range=(0.0, None),
        help="keep the frontier it heads for unless another is cheaper by this much distance",
    )
    path_costs: bool = param(
        False,
        help="measure frontiers by the distance driven (navfn's wavefront), not straight lines",
    )
    view_points: bool = param(
        False,
        help="send each frontier's view point (the nearest drivable cell seeing it), measure "
        "progress along the path there, leave a frontier still there once stood at its view point",
    )
    view_range: float = param(
        3.0,
        unit="m",
        range=(0.0, None),
        help="view_points: farthest a frontier cell may be from its view point (<= laser range)",
    )
    observe_delay: float = param(
        10.0,
        unit="s",
        range=(0.0, None),
        help="view_points: a frontier still there this long after the robot reached its view "
        "point is observed (the map shows what the laser saw there only after the SLAM node's "
        "map_update_interval and the costmap's publish period)",
    )
    blacklist_retries: int = param(
        0,
        range=(0, None),
        help="times the frontiers left, all blacklisted, are tried again before giving up",
    )
    peer_observed: list = param(
        [], help="other explorers' ~observed topics (geometry_msgs/PoseArray): view points stood at"
    )
