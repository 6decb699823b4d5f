"""Frontier exploration: ``explore_lite/explore``."""

from .explore import Explore, ExploreParams
from .frontier_search import Frontier, frontiers_from_grid

__all__ = ["Explore", "ExploreParams", "Frontier", "frontiers_from_grid"]
