"""move_group's kinematics capabilities (MoveIt's MoveGroupKinematicsService and
MoveGroupCartesianPathService): the ``compute_ik``, ``compute_fk`` and ``compute_cartesian_path``
services, each a function of the ``MoveGroup`` node and the request."""

from __future__ import annotations

import numpy as np

from fleetsim.errors import PlanningError
from fleetsim.moveit.cartesian import cartesian_path
from fleetsim.moveit.pipeline import PlanFailure
from fleetsim.msgs import geometry_msgs, moveit_msgs

E = moveit_msgs.MoveItErrorCodes


def compute_ik(mg, req):
    """MoveIt's compute_ik: position-only IK of ``ik_link_name`` (default: the group's tip)
    for ``pose_stamped``'s position (its orientation is not used)."""
    r = req.ik_request
    res = moveit_msgs.GetPositionIKResponse()
    try:
        ctx = mg.pipeline.context(r.group_name)
        start = mg.start_state(
            moveit_msgs.MotionPlanRequest(group_name=r.group_name, start_state=r.robot_state)
        )
        p = r.pose_stamped.pose.position
        target, _ = mg.pose_in_root(r.pose_stamped.header.frame_id, [p.x, p.y, p.z])
        q = mg.pipeline.ik(ctx, r.ik_link_name or ctx.tip, target, start)
    except PlanFailure as e:
        res.error_code.val = e.code
        return res
    except PlanningError:
        res.error_code.val = E.INVALID_LINK_NAME
        return res
    if q is None:
        res.error_code.val = E.NO_IK_SOLUTION
        return res
    res.solution.joint_state.name = list(ctx.joints)
    res.solution.joint_state.position = q
    res.error_code.val = E.SUCCESS
    return res


def compute_cartesian_path(mg, req):
    """MoveIt's compute_cartesian_path: the path reached (timed at scaling 1, as MoveIt's
    service times it) and the fraction of it; errors in error_code."""
    res = moveit_msgs.GetCartesianPathResponse()
    try:
        ctx = mg.pipeline.context(req.group_name)
        start = mg.start_state(
            moveit_msgs.MotionPlanRequest(group_name=req.group_name, start_state=req.start_state)
        )
        if not req.max_step > 0:
            raise PlanFailure(
                E.INVALID_GOAL_CONSTRAINTS, f"max_step must be > 0 m, got {req.max_step}"
            )
        if not req.waypoints:
            raise PlanFailure(E.INVALID_GOAL_CONSTRAINTS, "no waypoints")
        mg.sync_world()
        # the waypoints are in the request's frame (the commander's pose reference frame)
        waypoints = [
            mg.pose_in_root(
                req.header.frame_id,
                [w.position.x, w.position.y, w.position.z],
                np.array([w.orientation.x, w.orientation.y, w.orientation.z, w.orientation.w]),
            )
            for w in req.waypoints
        ]
        path, fraction = cartesian_path(
            ctx, start, waypoints, req.max_step, req.jump_threshold,
            req.avoid_collisions, req.link_name,
        )  # fmt: skip
    except PlanFailure as e:
        mg.get_logger().error("compute_cartesian_path: %s", e)
        res.error_code.val = e.code
        return res
    except PlanningError as e:
        mg.get_logger().error("compute_cartesian_path: %s", e)
        res.error_code.val = E.INVALID_LINK_NAME
        return res
    res.start_state.joint_state.name = list(ctx.joints)
    res.start_state.joint_state.position = start
    res.solution = mg.pipeline.timed_trajectory(ctx, path, 1.0, 1.0)
    res.fraction = fraction
    res.error_code.val = E.SUCCESS
    mg.get_logger().info(
        "compute_cartesian_path: %.1f %% of the path through %d waypoint(s) reached",
        100 * fraction, len(waypoints),
    )  # fmt: skip
    return res


def compute_fk(mg, req):
    """MoveIt's compute_fk: the poses of ``fk_link_names`` in the planning frame."""
    res = moveit_msgs.GetPositionFKResponse(fk_link_names=list(req.fk_link_names))
    group = mg.model.group_names[0]
    ctx = mg.pipeline.context(group)
    q = mg.start_state(moveit_msgs.MotionPlanRequest(group_name=group, start_state=req.robot_state))
    try:
        for link in req.fk_link_names:
            pos, quat = ctx.kin.link_pose(q, link)
            ps = geometry_msgs.PoseStamped()
            ps.header.frame_id = mg.frame(mg.model.robot.root_link())
            ps.header.stamp = mg.now_msg()
            ps.pose.position = geometry_msgs.Point(*pos)
            ps.pose.orientation = geometry_msgs.Quaternion(*quat)
            res.pose_stamped.append(ps)
    except PlanningError:
        res.error_code.val = E.INVALID_LINK_NAME
        res.pose_stamped = []
        return res
    res.error_code.val = E.SUCCESS
    return res
