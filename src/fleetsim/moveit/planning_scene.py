"""move_group's planning scene: collision objects from ``planning_scene`` and the
``apply_planning_scene`` / ``get_planning_scene`` services, placed through tf in the root
link's frame and handed to the planning pipeline's collision scenes."""

from __future__ import annotations

import copy

import mujoco
import numpy as np

from fleetsim.moveit.pipeline import PlanFailure
from fleetsim.msgs import geometry_msgs, moveit_msgs, shape_msgs
from fleetsim.tf.quaternions import quaternion_multiply
from fleetsim.tf.transforms import transform_points

_NO_TURN = np.array([0.0, 0.0, 0.0, 1.0])  # x y z w
SHAPES = {
    shape_msgs.SolidPrimitive.BOX: mujoco.mjtGeom.mjGEOM_BOX,
    shape_msgs.SolidPrimitive.SPHERE: mujoco.mjtGeom.mjGEOM_SPHERE,
    shape_msgs.SolidPrimitive.CYLINDER: mujoco.mjtGeom.mjGEOM_CYLINDER,
}


class PlanningSceneKeeper:
    """The planning-scene part of `MoveGroup` (a node with ``objects``, ``pipeline``,
    ``model``, ``joint_positions`` and `PlanningFrames`)."""

    def _on_scene(self, msg) -> None:
        self._apply(msg)

    def _apply(self, scene) -> bool:
        for obj in scene.world.collision_objects:
            if obj.operation == moveit_msgs.CollisionObject.REMOVE:
                ids = [obj.id] if obj.id else list(self.objects)
                for oid in ids:
                    self.objects.pop(oid, None)
                    self.pipeline.remove_object(oid)
                continue
            geoms, poses = [], []
            try:
                placed = self.frame_transform(self.root_frame, obj.header.frame_id)
            except PlanFailure as e:  # MoveIt: "Unknown frame", and the object is not added
                self.get_logger().error("collision object '%s': %s", obj.id, e)
                return False
            for prim, pose in zip(obj.primitives, obj.primitive_poses, strict=False):
                if prim.type not in SHAPES:
                    self.get_logger().error(
                        "collision object '%s': unsupported shape %d", obj.id, prim.type
                    )
                    return False
                d = np.asarray(prim.dimensions, float)
                size = {
                    mujoco.mjtGeom.mjGEOM_BOX: d[:3] / 2 if len(d) >= 3 else None,
                    mujoco.mjtGeom.mjGEOM_SPHERE: np.array([d[0], 0, 0]) if len(d) >= 1 else None,
                    mujoco.mjtGeom.mjGEOM_CYLINDER: np.array([d[1], d[0] / 2, 0])
                    if len(d) >= 2
                    else None,
                }[SHAPES[prim.type]]
                if size is None:
                    self.get_logger().error("collision object '%s': too few dimensions", obj.id)
                    return False
                pos = np.array([pose.position.x, pose.position.y, pose.position.z])
                o = pose.orientation
                q = np.array([o.x, o.y, o.z, o.w]) if (o.w or o.x or o.y or o.z) else _NO_TURN
                if placed is not None:  # from the object's frame into the root link's
                    pos = transform_points(*placed, [pos])[0]
                    q = quaternion_multiply(placed[1], q)
                geoms.append((int(SHAPES[prim.type]), size, pos, np.array([q[3], *q[:3]])))
                poses.append(
                    geometry_msgs.Pose(
                        position=geometry_msgs.Point(*map(float, pos)),
                        orientation=geometry_msgs.Quaternion(*map(float, q)),
                    )
                )
            # kept as placed, in the root link's frame (get_planning_scene answers with it;
            # an object given in odom would otherwise come back in odom, as of when it came)
            stored = copy.deepcopy(obj)
            stored.header.frame_id, stored.primitive_poses = self.root_frame, poses
            self.objects[obj.id] = stored
            self.pipeline.set_object(obj.id, geoms)
        return True

    def _srv_get_scene(self, req):
        scene = moveit_msgs.PlanningScene(name="(noname)", robot_model_name=self.model.srdf.name)
        scene.robot_state.joint_state.name = list(self.joint_positions)
        scene.robot_state.joint_state.position = np.array(list(self.joint_positions.values()))
        scene.world.collision_objects = list(self.objects.values())
        return moveit_msgs.GetPlanningSceneResponse(scene=scene)

    def _srv_apply(self, req):
        return moveit_msgs.ApplyPlanningSceneResponse(success=self._apply(req.scene))
