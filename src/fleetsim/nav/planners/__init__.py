"""Global planners (navfn)."""

from fleetsim.nav.planners.base import GlobalPlanner, Path
from fleetsim.nav.planners.navfn import NavFn, NavfnParams

__all__ = ["GlobalPlanner", "NavFn", "NavfnParams", "Path"]
