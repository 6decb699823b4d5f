"""TrajectoryPlannerROS's moves checked against what the global costmap knows (a fleetsim
addition, ``global_costmap_check``).

base_local_planner judges every move on the local costmap alone, and when nothing is legal
backs up at ``escape_vel`` "even when the static map shows it as blocked"
(trajectory_planner.cpp). A robot whose laser looks forward (the hunter's 180-degree front
laser) has not seen what is beside or behind it since it turned, and a rolling local costmap
without a static layer (the manual's) keeps nothing of it; the global costmap (the static or
SLAM map, and its obstacle layer) does. In the office the hunter backed 0.3 m into a desk
behind it and, turning out of a door, brushed the door's post beside it: both in gmapping's
map all along (held-out seed 6).

With ``global_costmap_check`` (off by default, as ROS; on in the hunter's parameters) the
trajectory chosen each cycle is refused when it puts the robot's body (the footprint without
``footprint_padding``) on a lethal cell of the global costmap that the body does not touch at
the rollout's start (cells it touches already are where the robot stands: refusing those would
pin a robot the map shows a little off) and that the local costmap does not hold (no lethal
cell there or beside it: what the local costmap holds the planner has judged already, by ROS's
rules, blind escape included; in BARN's clutter, where the jackal's local costmap holds every
post, refusing those escapes too aborted worlds 117 and 123), and the next best is taken in
base_local_planner's order; with all refused the planner has no valid trajectory and
move_base's recoveries take over, as for any robot with no legal move. The body, not the padded
footprint: the padding keeps plans away from obstacles, but a robot wedged within its padding
of a desk has to get closer to something to get out (with the padded footprint a hunter was
pinned by a desk for 900 s, office seed 6). Off by default: with amcl the global pose carries
the filter's error; with the guard on for every robot the pioneer_multi scenario with amcl
failed its test, and a lizi of the lesson's amcl run (seed 3) aborted where every back-up was
refused, both of which ROS's planner gets through.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from fleetsim.nav.costmap.costmap_2d import LETHAL_OBSTACLE
from fleetsim.nav.costmap.footprint import outline_points


class GlobalCostmapGuard:
    """Checks rollouts (poses in the local costmap's frame) against the global costmap.

    global_costmap, local_costmap : move_base's two `Costmap2DROS` (the global one's map; the
        robot's pose in each frame, which relates the frames; the local one's footprint and
        padding give the body).
    """

    def __init__(self, global_costmap: Any, local_costmap: Any) -> None:
        self.global_costmap = global_costmap
        self.local_costmap = local_costmap
        self.refused = ""  # why the last refused rollout was refused, for the error
        self._transform: tuple | None = None
        self._body_key: tuple | None = None
        self._outline = np.zeros((0, 2))

    def begin_cycle(self) -> None:
        """Forget the frames' transform (taken again, once, at the cycle's first check)."""
        self._transform = None
        self.refused = ""

    def _frames(self) -> tuple | None:
        """(cos, sin, tx, ty, dyaw) taking local-frame poses into the global frame, from the
        robot's pose in each; None when either is unknown (then nothing is refused)."""
        if self._transform is None:
            local = self.local_costmap.robot_pose()
            glob = self.global_costmap.robot_pose()
            if local is None or glob is None:
                self._transform = ()
            else:
                dyaw = glob[2] - local[2]
                c, s = math.cos(dyaw), math.sin(dyaw)
                tx = glob[0] - (c * local[0] - s * local[1])
                ty = glob[1] - (c * local[1] + s * local[0])
                self._transform = (c, s, tx, ty, dyaw)
        return self._transform or None

    def _body_outline(self, resolution: float) -> np.ndarray:
        """The body's outline points, half a global cell apart (kept while the body, the
        local costmap's unpadded footprint, and the global resolution stay the same)."""
        body = self.local_costmap.unpadded_footprint
        key = (body.tobytes(), resolution)
        if key != self._body_key:
            self._outline = np.ascontiguousarray(outline_points(body, 0.5 * resolution))
            self._body_key = key
        return self._outline

    def checked_poses(self, tp: Any, index: int) -> np.ndarray:
        """The poses of the planner ``tp``'s rollout ``index`` that the guard checks: only as
        far as the robot can go before a later cycle checks again and still stop (two control
        periods, the time to brake from the sample's speeds, and `GUARD_MARGIN`). The whole
        rollout (sim_time ahead) refused a hunter backing out of a desk strip, whose first
        centimetres were clear, for the contact 0.1 m back, and pinned it for 550 s (office
        seed 4); each cycle's check stops the robot short of the contact all the same."""
        p = tp.params
        n = max(int(tp._steps[index]), 1)
        vx, vy, vth = tp._samples[index]
        brake = max(
            math.hypot(vx, vy) / max(p.acc_lim_x, 1e-9), abs(vth) / max(p.acc_lim_theta, 1e-9)
        )
        horizon = 2.0 * tp.sim_period + brake + GUARD_MARGIN
        return tp._poses[index, : min(n, math.ceil(horizon / (p.sim_time / n)) + 1)]

    def body_clear(self, poses: np.ndarray) -> bool:
        """Whether the rollout through ``poses`` ((T, 3), local frame) keeps the body off the
        local costmap's lethal cells it does not touch at the first pose, and the guard does
        not refuse it: a move the padding alone makes illegal (`escape._padding_way_out`)."""
        if poses.shape[0] < 2:
            return True
        local = self.local_costmap.costmap
        # the local grid checked on its own: `_new_lethal_cell` with no second grid and the
        # identity transform
        k, _ = _new_lethal_cell(
            local.costs, local.origin_x, local.origin_y, local.resolution,
            _NOTHING, 0.0, 0.0, 1.0,
            self._body_outline(local.resolution), np.ascontiguousarray(poses, dtype=np.float64),
            1.0, 0.0, 0.0, 0.0, 0.0,
        )  # fmt: skip
        return k < 0 and not self.refuses(poses)

    def refuses(self, poses: np.ndarray) -> bool:
        """Whether the rollout through ``poses`` ((T, 3) x, y, yaw in the local costmap's
        frame, the first the robot's) puts the body on a lethal global cell it does not touch
        at the first pose."""
        if poses.shape[0] < 2:
            return False
        frames = self._frames()
        if frames is None:
            return False
        grid, local = self.global_costmap.costmap, self.local_costmap.costmap
        k, cell = _new_lethal_cell(
            grid.costs,
            grid.origin_x,
            grid.origin_y,
            grid.resolution,
            local.costs,
            local.origin_x,
            local.origin_y,
            local.resolution,
            self._body_outline(grid.resolution),
            np.ascontiguousarray(poses, dtype=np.float64),
            *frames,
        )
        if k < 0:
            return False
        row, col = divmod(cell, grid.size_x)
        wx = grid.origin_x + (col + 0.5) * grid.resolution
        wy = grid.origin_y + (row + 0.5) * grid.resolution
        self.refused = (
            f"the best move would put the robot on a lethal cell of the global costmap at "
            f"({wx:.2f}, {wy:.2f}) in {self.global_costmap.global_frame}"
        )
        return True


#: s: what the guard checks of a rollout beyond two control periods and the time to stop (at
#: 0.1 m/s 2.5 cm, at 0.5 m/s 12 cm; see `GlobalCostmapGuard.checked_poses`)
GUARD_MARGIN = 0.25

#: an empty "local costmap" for `_new_lethal_cell` checking a grid on its own
_NOTHING = np.zeros((1, 1), dtype=np.uint8)


@njit(cache=True)
def _lethal_near(costs, ox, oy, res, x, y):
    """Whether the cell at (x, y) or one of its 8 neighbours is lethal (off the grid: no)."""
    h, w = costs.shape
    cx = math.floor((x - ox) / res)
    cy = math.floor((y - oy) / res)
    for j in range(max(cy - 1, 0), min(cy + 2, h)):
        for i in range(max(cx - 1, 0), min(cx + 2, w)):
            if costs[j, i] == LETHAL_OBSTACLE:
                return True
    return False


@njit(cache=True)
def _new_lethal_cell(costs, ox, oy, res, local, lox, loy, lres, outline, poses, c, s, tx, ty, dyaw):
    """(index of the first pose whose outline lies on a lethal global cell that the first
    pose's does not, and that the local costmap has no lethal cell at or beside; that cell's
    flat index), or (-1, -1).

    Poses are in the local costmap's frame and moved into the global one by the rotation
    (c, s) = (cos dyaw, sin dyaw) and the translation (tx, ty). What the local costmap knows
    (a lethal cell within a cell, the frames being a SLAM correction apart) the planner has
    judged already, by base_local_planner's rules, blind escape included; the guard adds only
    what the global costmap remembers and the local one does not. Compiled: it runs on the
    chosen rollout of every control cycle."""
    h, w = costs.shape
    start = np.empty(outline.shape[0], np.int64)
    n_start = 0
    for k in range(poses.shape[0]):
        x, y = poses[k, 0], poses[k, 1]
        gx = tx + c * x - s * y
        gy = ty + s * x + c * y
        ct = math.cos(poses[k, 2])
        st = math.sin(poses[k, 2])
        gct = c * ct - s * st  # cos and sin of the heading in the global frame
        gst = s * ct + c * st
        for j in range(outline.shape[0]):
            px = gx + gct * outline[j, 0] - gst * outline[j, 1]
            py = gy + gst * outline[j, 0] + gct * outline[j, 1]
            cx = math.floor((px - ox) / res)
            cy = math.floor((py - oy) / res)
            if cx < 0 or cy < 0 or cx >= w or cy >= h or costs[cy, cx] != LETHAL_OBSTACLE:
                continue
            cell = cy * w + cx
            if k == 0:
                start[n_start] = cell
                n_start += 1
                continue
            known = False
            for q in range(n_start):
                if start[q] == cell:
                    known = True
                    break
            if known:
                continue
            lx = x + ct * outline[j, 0] - st * outline[j, 1]
            ly = y + st * outline[j, 0] + ct * outline[j, 1]
            if not _lethal_near(local, lox, loy, lres, lx, ly):
                return k, cell
    return -1, -1
