"""``PlanningSceneInterface`` with moveit_commander's names: world objects for move_group."""

from __future__ import annotations

import numpy as np

from fleetsim.moveit.commander import _Client
from fleetsim.msgs import geometry_msgs, moveit_msgs, shape_msgs
from fleetsim.runtime import names as rnames


class PlanningSceneInterface:
    """moveit_commander.PlanningSceneInterface(ns): add and remove world objects."""

    def __init__(self, ns: str = "", synchronous: bool = True, *, runtime) -> None:
        self._c = _Client(runtime, ns)
        self._pub = self._c.node.create_publisher(moveit_msgs.PlanningScene, "planning_scene")

    def _apply(self, obj: moveit_msgs.CollisionObject) -> None:
        scene = moveit_msgs.PlanningScene(is_diff=True)
        scene.world.collision_objects = [obj]
        self._c.runtime.graph.call_service(
            rnames.join(self._c.ns, "apply_planning_scene"),
            moveit_msgs.ApplyPlanningScene,
            moveit_msgs.ApplyPlanningSceneRequest(scene=scene),
        )

    def _add(self, name: str, pose: geometry_msgs.PoseStamped, prim_type: int, dims) -> None:
        obj = moveit_msgs.CollisionObject(id=name, header=pose.header)
        obj.primitives = [
            shape_msgs.SolidPrimitive(type=prim_type, dimensions=np.asarray(dims, float))
        ]
        obj.primitive_poses = [pose.pose]
        obj.operation = moveit_msgs.CollisionObject.ADD
        self._apply(obj)

    def add_box(self, name: str, pose: geometry_msgs.PoseStamped, size=(1, 1, 1)) -> None:
        self._add(name, pose, shape_msgs.SolidPrimitive.BOX, size)

    def add_sphere(self, name: str, pose: geometry_msgs.PoseStamped, radius: float = 1) -> None:
        self._add(name, pose, shape_msgs.SolidPrimitive.SPHERE, [radius])

    def add_cylinder(
        self, name: str, pose: geometry_msgs.PoseStamped, height: float, radius: float
    ) -> None:
        self._add(name, pose, shape_msgs.SolidPrimitive.CYLINDER, [height, radius])

    def remove_world_object(self, name: str | None = None) -> None:
        obj = moveit_msgs.CollisionObject(
            id=name or "", operation=moveit_msgs.CollisionObject.REMOVE
        )
        self._apply(obj)

    def get_known_object_names(self) -> list[str]:
        res = self._c.runtime.graph.call_service(
            rnames.join(self._c.ns, "get_planning_scene"), moveit_msgs.GetPlanningScene
        )
        return [o.id for o in res.scene.world.collision_objects]
