"""nav_msgs: odometry, occupancy grids, paths, grid cells, and the map/plan services."""

from __future__ import annotations

from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.msgs.fields import Seq, bool_, float32, int8, string, uint32
from fleetsim.msgs.geometry_msgs import (
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    PoseWithCovarianceStamped,
    TwistWithCovariance,
)
from fleetsim.msgs.interfaces import make_srv_type
from fleetsim.msgs.registry import message
from fleetsim.msgs.std_msgs import Header


@message("nav_msgs/msg/Odometry")
class Odometry:
    """Pose in ``header.frame_id`` and twist in ``child_frame_id``."""

    header: Header
    child_frame_id: string
    pose: PoseWithCovariance
    twist: TwistWithCovariance


@message("nav_msgs/msg/MapMetaData")
class MapMetaData:
    """Grid geometry: cell size (m/cell), size in cells, and the pose of cell (0, 0)'s corner."""

    map_load_time: Time
    resolution: float32
    width: uint32
    height: uint32
    origin: Pose


@message("nav_msgs/msg/OccupancyGrid")
class OccupancyGrid:
    """Row-major int8 cells (row = y): -1 unknown, 0 free .. 100 occupied."""

    header: Header
    info: MapMetaData
    data: Seq[int8]


@message("nav_msgs/msg/Path")
class Path:
    header: Header
    poses: Seq[PoseStamped]


@message("nav_msgs/msg/GridCells")
class GridCells:
    header: Header
    cell_width: float32
    cell_height: float32
    cells: Seq[Point]


@message("nav_msgs/srv/GetMap_Request")
class GetMapRequest:
    pass


@message("nav_msgs/srv/GetMap_Response")
class GetMapResponse:
    map: OccupancyGrid


GetMap = make_srv_type("nav_msgs/srv/GetMap", GetMapRequest, GetMapResponse)


@message("nav_msgs/srv/GetPlan_Request")
class GetPlanRequest:
    """Plan from ``start`` to ``goal``; a goal within ``tolerance`` metres is acceptable."""

    start: PoseStamped
    goal: PoseStamped
    tolerance: float32


@message("nav_msgs/srv/GetPlan_Response")
class GetPlanResponse:
    plan: Path


GetPlan = make_srv_type("nav_msgs/srv/GetPlan", GetPlanRequest, GetPlanResponse)


@message("nav_msgs/srv/SetMap_Request")
class SetMapRequest:
    map: OccupancyGrid
    initial_pose: PoseWithCovarianceStamped


@message("nav_msgs/srv/SetMap_Response")
class SetMapResponse:
    success: bool_


SetMap = make_srv_type("nav_msgs/srv/SetMap", SetMapRequest, SetMapResponse)
