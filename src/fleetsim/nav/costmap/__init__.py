"""costmap_2d: a layered uint8 cost grid (static, obstacle, voxel and inflation layers)."""

from fleetsim.nav.costmap.costmap_2d import (
    FREE_SPACE,
    INSCRIBED_INFLATED_OBSTACLE,
    LETHAL_OBSTACLE,
    NO_INFORMATION,
    Costmap2D,
)
from fleetsim.nav.costmap.inflation_layer import InflationLayer, InflationLayerParams
from fleetsim.nav.costmap.layer import Bounds, CostmapLayer, Layer
from fleetsim.nav.costmap.layered_costmap import CostmapParams, LayeredCostmap
from fleetsim.nav.costmap.obstacle_layer import (
    ObstacleLayer,
    ObstacleLayerParams,
    laser_scan_points,
)
from fleetsim.nav.costmap.static_layer import StaticLayer, StaticLayerParams
from fleetsim.nav.costmap.voxel_layer import VoxelLayer, VoxelLayerParams

__all__ = [
    "FREE_SPACE",
    "INSCRIBED_INFLATED_OBSTACLE",
    "LETHAL_OBSTACLE",
    "NO_INFORMATION",
    "Bounds",
    "Costmap2D",
    "CostmapLayer",
    "CostmapParams",
    "InflationLayer",
    "InflationLayerParams",
    "Layer",
    "LayeredCostmap",
    "ObstacleLayer",
    "ObstacleLayerParams",
    "StaticLayer",
    "StaticLayerParams",
    "VoxelLayer",
    "VoxelLayerParams",
    "laser_scan_points",
]
