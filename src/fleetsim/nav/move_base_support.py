"""move_base's services (``~make_plan``, ``~clear_costmaps``, ``~NavfnROS/make_plan``) and the
pose / path / quaternion helpers it shares with them."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numba import njit

from fleetsim.errors import ServiceError
from fleetsim.msgs import geometry_msgs, nav_msgs, std_msgs, std_srvs
from fleetsim.msgs.builtin_interfaces import Time
from fleetsim.nav.errors import PlannerError


def pose_of(pose: geometry_msgs.Pose) -> tuple[float, float, float]:
    """(x, y, yaw) of a Pose, m and rad."""
    q = pose.orientation
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return float(pose.position.x), float(pose.position.y), yaw


def pose_stamped(x: float, y: float, yaw: float, frame: str, stamp: Time) -> Any:
    return geometry_msgs.PoseStamped(
        header=std_msgs.Header(stamp=stamp, frame_id=frame),
        pose=geometry_msgs.Pose(
            position=geometry_msgs.Point(x=float(x), y=float(y)),
            orientation=geometry_msgs.Quaternion(z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0)),
        ),
    )


def path_msg(poses: np.ndarray, frame: str, stamp: Time) -> nav_msgs.Path:
    """A nav_msgs/Path of (N, 3) x, y, yaw poses in ``frame``."""
    return nav_msgs.Path(
        header=std_msgs.Header(stamp=stamp, frame_id=frame),
        poses=[pose_stamped(x, y, yaw, frame, stamp) for x, y, yaw in np.asarray(poses)],
    )


def poses_in_frame(buffer: Any, poses: np.ndarray, source: str, target: str) -> np.ndarray:
    """(N, 3) planar poses in ``source`` re-expressed in ``target`` with the newest tf."""
    tx, ty, tyaw = buffer.lookup_pose2d(target, source, 0.0)
    p = np.asarray(poses, dtype=np.float64)
    return poses_moved(p, float(tx), float(ty), float(tyaw))


@njit(cache=True)
def poses_moved(p, tx, ty, tyaw):
    """(N, 3) planar poses ``p`` moved by the 2-D transform (tx, ty, tyaw), yaw wrapped to
    [-pi, pi): ``tx + c x - s y``, ``ty + s x + c y``, ``(yaw + tyaw + pi) mod 2 pi - pi``,
    compiled (move_base hands its whole plan to the controller every control cycle when the
    local costmap's frame is not the plan's; NumPy's six passes cost ~30 us a plan)."""
    c, s = math.cos(tyaw), math.sin(tyaw)
    out = np.empty((p.shape[0], 3))
    for i in range(p.shape[0]):
        x, y = p[i, 0], p[i, 1]
        out[i, 0] = tx + c * x - s * y
        out[i, 1] = ty + s * x + c * y
        out[i, 2] = (p[i, 2] + tyaw + math.pi) % (2 * math.pi) - math.pi
    return out


def quaternion_problem(q: geometry_msgs.Quaternion) -> str:
    """Why a goal orientation is unusable (move_base's isQuaternionValid), or ``""``."""
    v = np.array([q.x, q.y, q.z, q.w], dtype=np.float64)
    if not np.isfinite(v).all():
        return "it has NaN or infinite components"
    n2 = float(v @ v)
    if n2 < 1e-6:
        return "its length is close to zero"
    x, y, _z, _w = v / math.sqrt(n2)
    up_dot = 1.0 - 2.0 * (x * x + y * y)  # z of the rotated z axis
    if abs(up_dot - 1.0) > 1e-3:
        return "for navigation the z-axis of the quaternion must be close to vertical"
    return ""


class MoveBaseServices:
    """The services of a `MoveBase` node ``mb``."""

    def __init__(self, mb: Any) -> None:
        self.mb = mb
        mb.create_service(nav_msgs.GetPlan, "~make_plan", self.on_make_plan)
        mb.create_service(std_srvs.Empty, "~clear_costmaps", self.on_clear_costmaps)
        mb.create_service(
            nav_msgs.GetPlan, f"~{mb.planner_name}/make_plan", self.on_planner_make_plan
        )

    def on_clear_costmaps(self, req: Any) -> Any:
        """Forget everything sensed in both costmaps (move_base's clearCostmapsService)."""
        self.mb.global_costmap.reset_layers()
        self.mb.local_costmap.reset_layers()
        return std_srvs.Empty.Response()

    def _endpoints(self, req: Any) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        mb = self.mb
        if not mb.global_costmap.initialized:
            raise ServiceError("the global costmap is not ready yet (no map or no tf)")
        start = mb.to_global(req.start, warn=False) if req.start.header.frame_id else None
        if not req.start.header.frame_id:
            start = mb.global_costmap.robot_pose()
        if start is None:
            raise ServiceError(
                "Unable to get starting pose of robot, unable to create global plan"
                + (f": {mb._goal_error}" if req.start.header.frame_id else "")
            )
        goal = mb.to_global(req.goal, warn=False)
        if goal is None:
            raise ServiceError(mb._goal_error)
        return start, goal

    def on_make_plan(self, req: Any) -> Any:
        """A plan from the robot (or ``start``) to ``goal``, searching ``tolerance`` around it."""
        mb = self.mb
        if mb.server.is_active():
            raise ServiceError(
                "move_base must be in an inactive state to make a plan for an external user"
            )
        start, goal = self._endpoints(req)
        if mb.params.make_plan_clear_costmap:
            self._clear_windows()
        poses = self._plan_within(start, goal, float(req.tolerance))
        add = poses is not None and mb.params.make_plan_add_unreachable_goal
        if add and (poses[-1, 0], poses[-1, 1]) != goal[:2]:
            poses = np.vstack([poses, np.asarray(goal)[None, :]])
        stamp = mb.now_msg()
        if poses is None:
            mb.get_logger().warning(f"make_plan: no plan: {mb.last_plan_error}")
            return nav_msgs.GetPlan.Response(
                plan=nav_msgs.Path(header=std_msgs.Header(stamp=stamp, frame_id=mb.global_frame))
            )
        return nav_msgs.GetPlan.Response(plan=path_msg(poses, mb.global_frame, stamp))

    def on_planner_make_plan(self, req: Any) -> Any:
        """NavfnROS's own make_plan: plan between the two poses as given (no tolerance)."""
        mb = self.mb
        start, goal = self._endpoints(req)
        stamp = mb.now_msg()
        try:
            poses = mb.planner.create_plan(start, goal).poses
        except PlannerError as err:
            mb.get_logger().warning(f"{mb.planner_name}/make_plan: {err}")
            return nav_msgs.GetPlan.Response(
                plan=nav_msgs.Path(header=std_msgs.Header(stamp=stamp, frame_id=mb.global_frame))
            )
        return nav_msgs.GetPlan.Response(plan=path_msg(poses, mb.global_frame, stamp))

    def _clear_windows(self) -> None:
        """Free a square of half side ``clearing_radius`` around the robot in both master grids
        (clearCostmapWindows); the next update restores what the layers hold there."""
        mb = self.mb
        r = mb.params.clearing_radius
        if r is None:
            r = mb.global_costmap.layered.circumscribed_radius
        for cm in (mb.global_costmap, mb.local_costmap):
            pose = cm.robot_pose()
            if pose is None:
                continue
            m = cm.costmap
            x0 = max(0, math.floor((pose[0] - r - m.origin_x) / m.resolution))
            y0 = max(0, math.floor((pose[1] - r - m.origin_y) / m.resolution))
            xn = min(m.size_x, math.floor((pose[0] + r - m.origin_x) / m.resolution) + 1)
            yn = min(m.size_y, math.floor((pose[1] + r - m.origin_y) / m.resolution) + 1)
            m.costs[y0:yn, x0:xn] = 0
            cm.mark_full_update()

    def _plan_within(self, start, goal, tolerance: float) -> np.ndarray | None:
        """move_base's planService search: the goal, then squares of growing offset around it."""
        mb = self.mb

        def attempt(x: float, y: float) -> np.ndarray | None:
            try:
                poses = mb.planner.create_plan(start, (x, y, goal[2])).poses
            except PlannerError as err:
                mb.last_plan_error = str(err)
                return None
            return poses if len(poses) else None

        found = attempt(goal[0], goal[1])
        if found is not None or tolerance <= 0:
            return found
        step = mb.global_costmap.costmap.resolution * 3.0
        step = min(step, tolerance)
        max_offset = step
        while max_offset <= tolerance + 1e-9:
            for yo in np.arange(0.0, max_offset + 1e-9, step):
                for xo in np.arange(0.0, max_offset + 1e-9, step):
                    if xo < max_offset - 1e-9 and yo < max_offset - 1e-9:
                        continue
                    for ym in (-1.0, 1.0) if yo > 1e-9 else (1.0,):
                        for xm in (-1.0, 1.0) if xo > 1e-9 else (1.0,):
                            found = attempt(goal[0] + xo * xm, goal[1] + yo * ym)
                            if found is not None:
                                return found
            max_offset += step
        return None
