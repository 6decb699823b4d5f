"""World services with gazebo_ros names, served by the ``Simulator`` node.

``/gazebo/spawn_urdf_model``, ``/gazebo/spawn_sdf_model``, ``/gazebo/delete_model``,
``/gazebo/get_model_state``, ``/gazebo/set_model_state``, ``/gazebo/get_world_properties``,
``/gazebo/pause_physics``, ``/gazebo/unpause_physics``, ``/gazebo/reset_world``,
``/gazebo/reset_simulation`` and the link attacher's ``/link_attacher_node/attach`` and
``/detach``. As in Gazebo, failures are answered with ``success=False`` and a status message
(the error text), not raised.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from fleetsim.errors import FleetsimError, SimulationError
from fleetsim.msgs import gazebo_msgs, gazebo_ros_link_attacher, std_srvs
from fleetsim.runtime import names as rnames
from fleetsim.sim.build import quat_from_rpy, rpy_from_quat

WORLD_FRAMES = ("", "world", "map", "/world", "/map")


def pose_tuple(pose) -> tuple[float, ...]:
    """(x, y, z, roll, pitch, yaw) of a geometry_msgs Pose (a zero quaternion means identity)."""
    q = pose.orientation
    quat = np.array([q.w, q.x, q.y, q.z], float)
    rpy = rpy_from_quat(quat / np.linalg.norm(quat)) if np.linalg.norm(quat) > 0 else (0, 0, 0)
    return (pose.position.x, pose.position.y, pose.position.z, *rpy)


def _fill_pose(pose, pos, quat_wxyz) -> None:
    pose.position.x, pose.position.y, pose.position.z = (float(v) for v in pos)
    o = pose.orientation
    o.w, o.x, o.y, o.z = (float(v) for v in quat_wxyz)


class WorldServices:
    def __init__(self, node) -> None:
        self.node = node
        self.engine = node.engine
        srv = node.create_service
        srv(gazebo_msgs.SpawnModel, "~spawn_urdf_model", self.spawn_urdf)
        srv(gazebo_msgs.SpawnModel, "~spawn_sdf_model", self.spawn_sdf)
        srv(gazebo_msgs.DeleteModel, "~delete_model", self.delete)
        srv(gazebo_msgs.GetModelState, "~get_model_state", self.get_state)
        srv(gazebo_msgs.SetModelState, "~set_model_state", self.set_state)
        srv(gazebo_msgs.GetWorldProperties, "~get_world_properties", self.world_properties)
        srv(std_srvs.Empty, "~pause_physics", self.pause)
        srv(std_srvs.Empty, "~unpause_physics", self.unpause)
        srv(std_srvs.Empty, "~reset_world", self.reset_world)
        srv(std_srvs.Empty, "~reset_simulation", self.reset_simulation)
        srv(gazebo_ros_link_attacher.Attach, "/link_attacher_node/attach", self.attach)
        srv(gazebo_ros_link_attacher.Attach, "/link_attacher_node/detach", self.detach)

    def _answer(self, resp: Any, fn) -> Any:
        try:
            fn()
            resp.success, resp.status_message = True, "ok"
        except FleetsimError as exc:
            self.node.get_logger().error("%s", exc)
            resp.success, resp.status_message = False, str(exc)
        return resp

    def _check_frame(self, frame: str) -> None:
        if frame not in WORLD_FRAMES:
            from fleetsim.errors import SimulationError

            raise SimulationError(
                f"reference frame '{frame}' is not supported; use 'world' (= 'map')"
            )

    def _spawn_pose(self, req) -> tuple[float, ...]:
        """The world pose of a spawn request: ``initial_pose`` in ``reference_frame`` (the
        world, a model, or ``model::link``), as gazebo_ros composes it."""
        frame = req.reference_frame
        if frame in WORLD_FRAMES:
            return pose_tuple(req.initial_pose)
        model, _, link = frame.partition("::")
        try:
            if link:
                b = self.engine.link_id(model, link)
                fpos, fquat = self.engine.data.xpos[b], self.engine.data.xquat[b]
            else:
                fpos, fquat = self.engine.model_pose(model)
        except SimulationError as exc:
            raise SimulationError(
                f"reference_frame '{frame}' is not the world, a model or 'model::link': {exc}"
            ) from None
        p, o = req.initial_pose.position, req.initial_pose.orientation
        q = np.array([o.w, o.x, o.y, o.z], float)
        q = q / np.linalg.norm(q) if np.linalg.norm(q) > 0 else np.array([1.0, 0, 0, 0])
        pos, quat = np.zeros(3), np.zeros(4)
        mujoco.mju_rotVecQuat(pos, np.array([p.x, p.y, p.z], float), fquat)
        mujoco.mju_mulQuat(quat, fquat, q)
        return (*(pos + fpos), *rpy_from_quat(quat))

    def spawn_urdf(self, req):
        from fleetsim.description import parse_urdf

        def run():
            pose = self._spawn_pose(req)
            robot = parse_urdf(req.model_xml, source=f"<spawn_urdf_model {req.model_name}>")
            self.node.spawn_robot(req.model_name, robot, pose, req.robot_namespace or None)

        return self._answer(gazebo_msgs.SpawnModel.Response(), run)

    def spawn_sdf(self, req):
        def run():
            pose = self._spawn_pose(req)
            ns = rnames.validate_namespace(req.robot_namespace or "/")
            entry = self.engine.spawn_sdf(req.model_name, req.model_xml, pose)
            # as gazebo_ros, the namespace the model's plugins would use (grobot spawns each
            # marker in its robot's namespace); kept on the model for whoever looks it up
            entry.namespace = ns

        return self._answer(gazebo_msgs.SpawnModel.Response(), run)

    def delete(self, req):
        return self._answer(
            gazebo_msgs.DeleteModel.Response(), lambda: self.node.delete_model(req.model_name)
        )

    def get_state(self, req):
        resp = gazebo_msgs.GetModelState.Response()

        def run():
            pos, quat = self.engine.model_pose(req.model_name)
            lin, ang = self.engine.model_twist(req.model_name)
            ref = req.relative_entity_name.split("::")[0]
            if ref not in WORLD_FRAMES:
                rpos, rquat = self.engine.model_pose(ref)
                qi = np.array([rquat[0], -rquat[1], -rquat[2], -rquat[3]])
                for v in (pos, lin, ang):
                    out = np.zeros(3)
                    mujoco.mju_rotVecQuat(out, v - (rpos if v is pos else 0), qi)
                    v[:] = out
                q = np.zeros(4)
                mujoco.mju_mulQuat(q, qi, quat)
                quat = q
            resp.header.stamp = self.node.now_msg()
            resp.header.frame_id = req.relative_entity_name or "world"
            _fill_pose(resp.pose, pos, quat)
            t = resp.twist
            t.linear.x, t.linear.y, t.linear.z = (float(v) for v in lin)
            t.angular.x, t.angular.y, t.angular.z = (float(v) for v in ang)

        return self._answer(resp, run)

    def set_state(self, req):
        s = req.model_state

        def run():
            self._check_frame(s.reference_frame)
            q = s.pose.orientation
            quat = [q.w, q.x, q.y, q.z] if (q.w, q.x, q.y, q.z) != (0, 0, 0, 0) else None
            p = s.pose.position
            tw = s.twist
            self.engine.set_model_state(
                s.model_name,
                [p.x, p.y, p.z],
                quat,
                [tw.linear.x, tw.linear.y, tw.linear.z],
                [tw.angular.x, tw.angular.y, tw.angular.z],
            )

        return self._answer(gazebo_msgs.SetModelState.Response(), run)

    def world_properties(self, req):
        resp = gazebo_msgs.GetWorldProperties.Response()
        props = self.engine.world_properties()
        resp.sim_time = self.node.now()
        resp.model_names = props["model_names"]
        resp.rendering_enabled = True
        resp.success, resp.status_message = True, "ok"
        return resp

    def pause(self, req):
        self.engine.paused = True
        return std_srvs.Empty.Response()

    def unpause(self, req):
        self.engine.paused = False
        return std_srvs.Empty.Response()

    def reset_world(self, req):
        self.engine.reset_world()
        return std_srvs.Empty.Response()

    def reset_simulation(self, req):
        self.engine.reset_simulation()
        self.node.offset = self.node.now()
        return std_srvs.Empty.Response()

    def _attach(self, req, op: str):
        resp = gazebo_ros_link_attacher.Attach.Response()
        try:
            getattr(self.engine.attacher, op)(
                self.engine, req.model_name_1, req.link_name_1, req.model_name_2, req.link_name_2
            )
            resp.ok = True
        except FleetsimError as exc:
            self.node.get_logger().error("%s", exc)
            resp.ok = False
        return resp

    def attach(self, req):
        return self._attach(req, "attach")

    def detach(self, req):
        return self._attach(req, "detach")


__all__ = ["WorldServices", "pose_tuple", "quat_from_rpy"]
