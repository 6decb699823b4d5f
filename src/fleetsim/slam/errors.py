"""SLAM's errors."""

from fleetsim.errors import FleetsimError


class SlamError(FleetsimError):
    """A scan, laser or map request slam_gmapping or map_merge cannot serve."""
