"""What the run monitor knows of the world: each robot's true pose (the simulator's engine in
this process, else ``/gazebo/model_states``), its estimate through tf (localization error), and
goals placed in the world frame (through tf, or for a robot's own SLAM map by its estimate)."""

from __future__ import annotations

import math
from typing import Any

from fleetsim.errors import FleetsimError
from fleetsim.tf.transforms import compose_transforms, inverse_transform, transform_points

#: goal frames that are the simulator's world frame (fleetsim's ``map`` is the world)
WORLD_FRAMES = ("", "map", "world")


class GroundTruth:
    """The ground-truth part of `RunMonitor` (``sim``, ``tf``, ``_states``)."""

    def _goal_in_map(self, target, ns: str) -> tuple[float, float] | None:
        """The goal's x, y in the map (= world) frame, or None if its frame does not resolve."""
        p = target.pose.position
        frame = target.header.frame_id.lstrip("/")
        if frame in WORLD_FRAMES:
            return (float(p.x), float(p.y))
        try:
            tf = self.tf.lookup_transform("map", frame, 0.0).transform
        except FleetsimError:
            return self._goal_by_estimate(ns, frame, (float(p.x), float(p.y)))
        t, q = tf.translation, tf.rotation
        x, y = transform_points((t.x, t.y, t.z), (q.x, q.y, q.z, q.w), [[p.x, p.y]])[0]
        return (float(x), float(y))

    def _goal_by_estimate(
        self, ns: str, frame: str, xy: tuple[float, float]
    ) -> tuple[float, float] | None:
        """A goal in a frame with no transform to the world, a robot's own SLAM map
        (``lizi1/map``, which gmapping starts wherever the robot is): placed in the world where
        the robot's estimate put it when the goal was given (the transform that makes the
        robot's pose in ``frame`` its true pose, now). Arriving there is then checked by ground
        truth as any goal is, so drift of the robot's estimate on the way still shows. None
        when the frame is not in the robot's tf tree or no simulator runs here."""
        found = self._base_in(frame, ns)
        if found is None:
            return None
        model, tf = found
        t, q = tf.translation, tf.rotation
        base_in_frame = ((t.x, t.y, t.z), (q.x, q.y, q.z, q.w))
        pos, (w, x, y, z) = self.sim.engine.model_pose(model)
        frame_in_world = compose_transforms(pos, (x, y, z, w), *inverse_transform(*base_in_frame))
        gx, gy = transform_points(*frame_in_world, [list(xy)])[0]
        return (float(gx), float(gy))

    def _on_states(self, msg) -> None:
        self._states = {
            n: (float(p.position.x), float(p.position.y)) for n, p in zip(msg.name, msg.pose)
        }

    def _true_xy(self, ns: str) -> tuple[float, float] | None:
        """The robot's true x, y (world = map frame), or None where nothing tells it."""
        if self.sim is None:
            return self._states.get(ns.strip("/"))
        model = self._robot_models().get(ns)
        if model is None:
            return None
        pos, _ = self.sim.engine.model_pose(model)
        return (float(pos[0]), float(pos[1]))

    def _localization_error(self, ns: str, truth: tuple[float, float]) -> float | None:
        """Distance between the map -> base tf and ground truth (None without a map frame)."""
        found = self._base_in("map", ns)
        if found is None:
            return None
        t = found[1].translation
        return math.hypot(t.x - truth[0], t.y - truth[1])

    def _base_in(self, frame: str, ns: str) -> tuple[str, Any] | None:
        """The model of robot namespace ``ns`` and the latest transform of its root link in
        ``frame`` (the robot's estimate there); None without a simulator here, the robot or
        the transform."""
        if self.sim is None:
            return None
        entry = self.sim.engine.models.get(self._robot_models().get(ns, ""))
        if entry is None or entry.robot is None:
            return None
        root = entry.robot.root_link()
        base = f"{entry.tf_prefix}/{root}" if entry.tf_prefix else root
        try:
            return entry.name, self.tf.lookup_transform(frame, base, 0.0).transform
        except FleetsimError:
            return None

    def _robot_models(self) -> dict[str, str]:
        engine = self.sim.engine
        out = {}
        for name, entry in engine.models.items():
            if entry.kind == "robot":
                out[entry.namespace.rstrip("/") or "/"] = name
        return out
