"""move_group's frames: the planning frame (a virtual joint's parent, else the robot's root
link) and goals in other frames brought into the root link's, where the kinematics work,
through tf (MoveIt's planning scene transforms)."""

from __future__ import annotations

import copy

import numpy as np

from fleetsim.errors import FleetsimError
from fleetsim.moveit.pipeline import PlanFailure
from fleetsim.msgs import geometry_msgs, moveit_msgs
from fleetsim.tf.quaternions import quaternion_multiply
from fleetsim.tf.transforms import transform_points

E = moveit_msgs.MoveItErrorCodes


class PlanningFrames:
    """The frame part of `MoveGroup` (a node with ``model``, ``frame()`` and ``tf_buffer``)."""

    @property
    def root_frame(self) -> str:
        """The robot's root link, tf-prefixed: the frame the kinematics work in."""
        return self.frame(self.model.robot.root_link())

    @property
    def planning_frame(self) -> str:
        """MoveIt's planning frame: a virtual joint's parent frame (``odom`` for a planar
        one), else the robot's root link; a target or object without a frame is in it."""
        vj = self.model.srdf.virtual_joints
        return self.frame(vj[0].parent_frame) if vj else self.root_frame

    def _same_as_root(self, frame: str) -> str:
        """The root link's frame for a *fixed* virtual joint's parent frame (``world`` in
        the Setup Assistant's configs): MoveIt's model holds that transform, identity, and no
        one publishes it on tf; a planar or floating one's parent is looked up through tf."""
        vj = self.model.srdf.virtual_joints
        if vj and vj[0].type == "fixed" and frame == self.frame(vj[0].parent_frame):
            return self.root_frame
        return frame

    def frame_transform(self, target: str, source: str):
        """``(t (3,), q (4,) x y z w)`` of frame ``source`` in ``target`` through tf (either
        empty: the planning frame); None when they are the same frame. A frame tf does not
        know fails with MoveIt's FRAME_TRANSFORM_FAILURE."""
        target = self._same_as_root(target.lstrip("/") or self.planning_frame)
        source = self._same_as_root(source.lstrip("/") or self.planning_frame)
        if target == source:
            return None
        try:
            tf = self.tf_buffer.lookup_transform(target, source, 0.0).transform
        except FleetsimError as e:
            raise PlanFailure(
                E.FRAME_TRANSFORM_FAILURE,
                f"Unable to transform from frame '{source}' to frame '{target}': {e}",
            ) from None
        t, q = tf.translation, tf.rotation
        return np.array([t.x, t.y, t.z]), np.array([q.x, q.y, q.z, q.w])

    def pose_in_root(self, frame: str, position, orientation=None):
        """A pose given in ``frame`` (x y z, and x y z w or None) in the root link's frame."""
        tf = self.frame_transform(self.root_frame, frame)
        if tf is None:
            return np.asarray(position, float), orientation
        pos = transform_points(*tf, [position])[0]
        if orientation is not None:
            orientation = quaternion_multiply(tf[1], orientation)
        return pos, orientation

    def _goal_in_root(self, c):
        """A copy of goal constraints ``c`` with its position and orientation constraints in
        the root link's frame (the pose goal's frame: its header's, else the planning frame)."""
        if not (c.position_constraints or c.orientation_constraints):
            return c
        c = copy.deepcopy(c)
        for pc in c.position_constraints:
            for pose in pc.constraint_region.primitive_poses:
                p = pose.position
                pos, _ = self.pose_in_root(pc.header.frame_id, [p.x, p.y, p.z])
                pose.position = geometry_msgs.Point(*map(float, pos))
            pc.header.frame_id = self.root_frame
        for oc in c.orientation_constraints:
            o = oc.orientation
            tf = self.frame_transform(self.root_frame, oc.header.frame_id)
            if tf is not None:
                q = quaternion_multiply(tf[1], [o.x, o.y, o.z, o.w])
                oc.orientation = geometry_msgs.Quaternion(*map(float, q))
            oc.header.frame_id = self.root_frame
        return c
