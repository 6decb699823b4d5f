"""SLAM: ``gmapping/slam_gmapping`` (an RBPF with shared-tile maps) and ``map_merge``."""

from .errors import SlamError
from .filter import GmappingFilter
from .map_merge import MapMerge
from .node import SlamGmapping
from .params import GmappingParams, gmapping_params

__all__ = [
    "GmappingFilter",
    "GmappingParams",
    "MapMerge",
    "SlamError",
    "SlamGmapping",
    "gmapping_params",
]
