"""The simulator: worlds (SDF, extruded maps), the MuJoCo engine, plugins, world services.

``Engine`` is the physics and sensing core (no runtime needed); ``Simulator`` (``sim.node``) is
the node that publishes its readings and serves the ``/gazebo/*`` services.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering; must precede importing mujoco

from fleetsim.sim.engine import Engine, ModelEntry, load_world
from fleetsim.sim.queries import Contact

__all__ = ["Contact", "Engine", "ModelEntry", "load_world"]
