"""TrajectoryPlannerROS's escape, bounded by what the global costmap knows (a fleetsim addition).

When no forward move, rotation or sideways move is legal, base_local_planner backs up at
``escape_vel`` "even when the static map shows it as blocked" (trajectory_planner.cpp), on
the local costmap's word alone. A robot whose laser looks forward (the hunter's 180-degree
front laser) has not seen what is behind it since it turned, and a rolling local costmap
without a static layer (the manual's) keeps nothing of it: the hunter backed 0.3 m into a
desk that gmapping's map, in the global costmap, held all along (the office, seed 6).

With ``escape_global_check`` (default true) an escape rollout is refused when it puts the
robot's body (its footprint without ``footprint_padding``) on a lethal cell of the global
costmap that the body does not cover at the start of the rollout (cells it covers already are
where the robot stands: refusing those would pin a robot that the map shows a little off). The
body, not the padded footprint: a robot wedged within its padding of a desk has to back
closer to something, and the padding is there to keep plans away from obstacles, not to stop
a robot getting out (the padded footprint pinned a hunter by a desk for 900 s, office seed 6).
The other escapes (backing while turning) are tried in the usual order; when all are refused
the planner has no valid trajectory and move_base's recoveries take over, as for any robot
with no legal move. ``false`` is ROS's blind escape.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE
from fleetsim.nav.costmap.footprint import footprint_at, padded_footprint, polygon_cells


class EscapeGuard:
    """Checks escape rollouts (poses in the local costmap's frame) against the global costmap.

    global_costmap, local_costmap : move_base's two `Costmap2DROS` (the global one's map; the
        robot's pose in each frame, which relates the frames; the local one's footprint and
        padding give the body).
    """

    def __init__(self, global_costmap: Any, local_costmap: Any) -> None:
        self.global_costmap = global_costmap
        self.local_costmap = local_costmap
        self.refused = ""  # why the last refused rollout was refused, for the error

    def checker(self):
        """A function of one rollout's (T, 3) local poses -> whether it is refused, valid for
        this control cycle; None when the robot's pose in either frame is unknown (then
        nothing is refused: ROS's escape)."""
        local = self.local_costmap.robot_pose()
        glob = self.global_costmap.robot_pose()
        if local is None or glob is None:
            return None
        # local frame -> global frame: the transform that takes the robot's local pose to its
        # global one (the two frames differ by odometry's drift, or are the same)
        dyaw = glob[2] - local[2]
        c, s = math.cos(dyaw), math.sin(dyaw)
        tx = glob[0] - (c * local[0] - s * local[1])
        ty = glob[1] - (c * local[1] + s * local[0])
        grid = self.global_costmap.costmap
        padding = self.local_costmap.layered.params.footprint_padding
        body = padded_footprint(self.local_costmap.footprint, -padding)

        def lethal_cells(x: float, y: float, yaw: float) -> np.ndarray:
            gx, gy = tx + c * x - s * y, ty + s * x + c * y
            rows, cols = polygon_cells(grid, footprint_at(body, gx, gy, yaw + dyaw))
            hit = grid.costs[rows, cols] == LETHAL_OBSTACLE
            return rows[hit] * grid.size_x + cols[hit]

        def refused(poses: np.ndarray) -> bool:
            if poses.shape[0] < 2:
                return False
            start = lethal_cells(*poses[0])
            for x, y, yaw in poses[1:].tolist():
                new = np.setdiff1d(lethal_cells(x, y, yaw), start)
                if new.shape[0]:
                    row, col = divmod(int(new[0]), grid.size_x)
                    wx = grid.origin_x + (col + 0.5) * grid.resolution
                    wy = grid.origin_y + (row + 0.5) * grid.resolution
                    self.refused = (
                        f"backing up would put the robot on a lethal cell of the global "
                        f"costmap at ({wx:.2f}, {wy:.2f}) in {self.global_costmap.global_frame}"
                    )
                    return True
            return False

        return refused
