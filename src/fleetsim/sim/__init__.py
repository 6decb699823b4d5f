"""The simulator: worlds (SDF, extruded maps), the MuJoCo engine, plugins, world services.

``Engine`` is the physics and sensing core (no runtime needed); ``Simulator`` (``sim.node``) is
the node that publishes its readings and serves the ``/gazebo/*`` services.
"""

from fleetsim.sim.engine import Contact, Engine, ModelEntry, load_world

__all__ = ["Contact", "Engine", "ModelEntry", "load_world"]
