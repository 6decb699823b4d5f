"""SLAM: ``gmapping/slam_gmapping`` (a Rao-Blackwellised particle filter with shared-tile maps)."""

from .errors import SlamError
from .filter import GmappingFilter
from .node import SlamGmapping
from .params import GmappingParams, gmapping_params

__all__ = ["GmappingFilter", "GmappingParams", "SlamError", "SlamGmapping", "gmapping_params"]
