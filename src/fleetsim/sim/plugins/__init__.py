"""Simulator plugins, registered by their Gazebo filenames (``base.REGISTRY``)."""

from fleetsim.sim.plugins import (  # noqa: F401  (registration side effects)
    camera,
    diff_drive,
    joint_actuation,
    joint_state,
    laser,
    p3d,
    skid_steer,
)
from fleetsim.sim.plugins.base import REGISTRY, Plugin, plugin_class

__all__ = ["REGISTRY", "Plugin", "plugin_class"]
