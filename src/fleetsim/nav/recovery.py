"""move_base's recovery behaviours: clear_costmap_recovery, rotate_recovery, moveback_recovery.

Each is a class with one main method. `ClearCostmapRecovery.run` forgets what the named
layers sensed outside a square around the robot; `RotateRecovery.command` is called once per
control cycle and returns the next rotation command, or None once a full turn is done (or
the footprint would collide, as ROS aborts); `MoveBackRecovery.command` likewise drives the
robot straight back (mbf_recovery_behaviors' ``moveback_recovery/MoveBackRecovery``, which
ROS 1 users add to move_base's list where rotating in place is not enough: a rectangular
robot nose-first in clutter cannot turn, but can back out the way it came).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from fleetsim.nav.controllers.base import VelocityCommand
from fleetsim.nav.costmap.costmap_2d import Costmap2D
from fleetsim.nav.costmap.footprint import footprint_costs, outline_points
from fleetsim.nav.costmap.layer import CostmapLayer
from fleetsim.nav.costmap.layered_costmap import LayeredCostmap
from fleetsim.runtime import param


@dataclass(frozen=True)
class ClearCostmapRecoveryParams:
    """``clear_costmap_recovery/ClearCostmapRecovery`` (conservative_reset/aggressive_reset)."""

    reset_distance: float = param(
        3.0, unit="m", range=(0.0, None), help="side of the square around the robot kept"
    )
    layer_names: list = param(["obstacle_layer"], help="layers whose data is forgotten")
    affected_maps: str = param(
        "both", choices=("local", "global", "both"), help="which costmaps are cleared"
    )
    force_updating: bool = param(False, help="update the costmaps right after clearing")
    invert_area_to_clear: bool = param(False, help="clear inside the square instead")


def aggressive_reset_params(circumscribed_radius: float) -> ClearCostmapRecoveryParams:
    """move_base's aggressive_reset: reset_distance = 4 x the circumscribed radius."""
    return ClearCostmapRecoveryParams(reset_distance=4.0 * circumscribed_radius)


class ClearCostmapRecovery:
    """Forget sensed obstacles outside a ``reset_distance`` square centred on the robot."""

    Params = ClearCostmapRecoveryParams

    def __init__(self, params: ClearCostmapRecoveryParams | None = None) -> None:
        self.params = params or ClearCostmapRecoveryParams()

    def run(self, costmaps: Iterable[LayeredCostmap], robot_x: float, robot_y: float) -> int:
        """Clear the named layers of each costmap; returns how many layers were cleared."""
        p = self.params
        half = p.reset_distance / 2.0
        cleared = 0
        for lc in costmaps:
            for layer in lc.layers:
                if layer.name not in p.layer_names or not isinstance(layer, CostmapLayer):
                    continue
                g = layer.grid
                x0 = math.floor((robot_x - half - g.origin_x) / g.resolution)
                y0 = math.floor((robot_y - half - g.origin_y) / g.resolution)
                xn = math.floor((robot_x + half - g.origin_x) / g.resolution)
                yn = math.floor((robot_y + half - g.origin_y) / g.resolution)
                layer.clear_area(x0, y0, xn, yn, p.invert_area_to_clear)
                if hasattr(layer, "marked"):  # voxel columns follow their cells
                    layer.marked[layer.grid.costs == 255] = 0
                cleared += 1
            if p.force_updating:
                lc.update_map(robot_x, robot_y, 0.0)
        return cleared


@dataclass(frozen=True)
class RotateRecoveryParams:
    """``rotate_recovery/RotateRecovery`` (limits read from TrajectoryPlannerROS's names)."""

    sim_granularity: float = param(
        0.017, unit="rad", range=(1e-6, None), help="angle step of the collision check"
    )
    frequency: float = param(20.0, unit="Hz", range=(1e-6, None), help="command rate")
    acc_lim_theta: float = param(3.2, unit="rad/s^2", range=(0.0, None), help="from the planner")
    max_rotational_vel: float = param(1.0, unit="rad/s", help="from TrajectoryPlannerROS")
    min_in_place_rotational_vel: float = param(0.4, unit="rad/s", help="from the planner")
    yaw_goal_tolerance: float = param(0.10, unit="rad", range=(0.0, None), help="end tolerance")


class RotateRecovery:
    """Turn once in place (RotateRecovery::runBehavior), one command per control cycle."""

    Params = RotateRecoveryParams

    def __init__(
        self, costmap: Costmap2D, footprint: np.ndarray, params: RotateRecoveryParams | None = None
    ) -> None:
        self.costmap = costmap
        self.params = params or RotateRecoveryParams()
        self.outline = outline_points(footprint, costmap.resolution)
        self.start_angle: float | None = None
        self.got_180 = False
        self.aborted = ""

    def command(self, x: float, y: float, yaw: float) -> VelocityCommand | None:
        """The next command, or None when the turn is complete or would collide."""
        p = self.params
        if self.start_angle is None:
            self.start_angle, self.got_180, self.aborted = yaw, False, ""

        def diff(a: float, b: float) -> float:
            return abs((b - a + math.pi) % (2 * math.pi) - math.pi)

        if self.got_180 and diff(yaw, self.start_angle) <= p.yaw_goal_tolerance:
            self.start_angle = None
            return None
        if not self.got_180:
            to_180 = diff(yaw, self.start_angle + math.pi)
            dist_left = math.pi + to_180
            if to_180 < p.yaw_goal_tolerance:
                self.got_180 = True
        else:
            dist_left = diff(yaw, self.start_angle)
        angles = yaw + np.arange(0.0, dist_left, p.sim_granularity)
        poses = np.stack([np.full_like(angles, x), np.full_like(angles, y), angles], axis=1)
        m = self.costmap
        fc = footprint_costs(m.costs, m.origin_x, m.origin_y, m.resolution, self.outline, poses)
        if (fc < 0).any():
            self.aborted = (
                f"rotate_recovery: cannot rotate in place at ({x:.2f}, {y:.2f}): the footprint "
                f"would collide at yaw {float(angles[np.argmax(fc < 0)]):.2f}"
            )
            self.start_angle = None
            return None
        vel = math.sqrt(2 * p.acc_lim_theta * dist_left)
        vel = min(max(vel, p.min_in_place_rotational_vel), p.max_rotational_vel)
        return VelocityCommand(0.0, 0.0, vel)


@dataclass(frozen=True)
class MoveBackRecoveryParams:
    """``moveback_recovery/MoveBackRecovery`` (mbf_recovery_behaviors), in its ``~name/``."""

    control_frequency: float = param(20.0, unit="Hz", range=(1e-6, None), help="command rate")
    linear_vel_back: float = param(
        -0.3, unit="m/s", range=(None, 0.0), help="velocity backwards (negative)"
    )
    step_back_length: float = param(
        1.0, unit="m", range=(0.0, None), help="distance to back up before stopping"
    )
    step_back_timeout: float = param(
        15.0, unit="s", range=(0.0, None), help="give up after this long (0: never)"
    )
    look_behind_dist: float = param(
        0.1,
        unit="m",
        range=(0.0, None),
        help="stop when the footprint this far behind meets a lethal cell",
    )


class MoveBackRecovery:
    """Back up straight (MoveBackRecovery::runBehavior), one command per control cycle, until
    ``step_back_length`` is covered, ``step_back_timeout`` has passed, or the footprint
    ``look_behind_dist`` behind the robot would touch a lethal cell of the local costmap (or an
    unknown one, as base_local_planner's costmap model counts them; moveback_recovery lays the
    filled footprint, this the outline, as `RotateRecovery` does)."""

    Params = MoveBackRecoveryParams

    def __init__(
        self,
        costmap: Costmap2D,
        footprint: np.ndarray,
        params: MoveBackRecoveryParams | None = None,
    ) -> None:
        self.costmap = costmap
        self.params = params or MoveBackRecoveryParams()
        self.outline = outline_points(footprint, costmap.resolution)
        self.start: tuple[float, float, float] | None = None  # x, y, time
        #: how the last run ended (moveback_recovery's result message)
        self.outcome = ""

    def command(self, x: float, y: float, yaw: float, now: float) -> VelocityCommand | None:
        """The next command, or None when the run is over (``outcome`` says why)."""
        p = self.params
        if self.start is None:
            self.start, self.outcome = (x, y, now), ""
        x0, y0, t0 = self.start
        if p.step_back_timeout > 0 and now > t0 + p.step_back_timeout:
            return self._end(f"time out after {p.step_back_timeout:g} s, moving backwards")
        behind = np.array([[x - p.look_behind_dist * math.cos(yaw),
                            y - p.look_behind_dist * math.sin(yaw), yaw]])  # fmt: skip
        m = self.costmap
        fc = footprint_costs(m.costs, m.origin_x, m.origin_y, m.resolution, self.outline, behind)
        if fc[0] < 0:
            return self._end(
                f"stopped moving backwards at ({x:.2f}, {y:.2f}): an obstacle behind the robot"
            )
        if math.hypot(x - x0, y - y0) > p.step_back_length:
            return self._end(f"moved backwards {p.step_back_length:g} m")
        return VelocityCommand(p.linear_vel_back, 0.0, 0.0)

    def _end(self, outcome: str) -> None:
        self.start, self.outcome = None, outcome
        return None
