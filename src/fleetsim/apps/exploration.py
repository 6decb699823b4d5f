"""follow_marker's exploration strategies (grobot_navigation ``exploration/*.h``).

When the marker has been lost for more than 4 s, follow_marker calls `Exploration.start`; it
sends one goal on the ``/move_base`` action and reports through `is_exploring` until the action
ends. A detection cancels it (`cancel`, once). Strategies, keyed by ``~exploration/strategy``:

- ``rotate``: turn in place by +120 deg (a goal at the robot's position, its yaw + 2 pi / 3, in
  ``map``); each finished step is followed by the next while the marker stays lost, forever
  (there is no angle limit in the original either).
- ``move_to_target``: drive to a fixed vantage pose (``~exploration/target_pose``) and wait
  there; no goal when the robot is within 0.2 m of it and its signed yaw error is below 0.35
  rad (the original's test, signed as it is).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from fleetsim.errors import ParameterError, TransformError
from fleetsim.msgs import geometry_msgs, move_base_msgs, std_msgs
from fleetsim.runtime.params import load_params, param
from fleetsim.tf.patience import TransformPatience
from fleetsim.tf.quaternions import quaternion_from_yaw, yaw_from_quaternion
from fleetsim.tf.transforms import compose_transforms, inverse_transform

#: the move_base action follow_marker explores with (absolute, as the original's)
MOVE_BASE_ACTION = "/move_base"
#: s an exploration goal may go unanswered before it counts as sent to nobody, and s between
#: two warnings of that
NO_SERVER_TIME, NO_SERVER_WARN_PERIOD = 5.0, 10.0
#: rotate's step (rad)
ROTATE_STEP = 2 * math.pi / 3
#: move_to_target's "already there" test: distance (m) and signed yaw error (rad)
THERE_DISTANCE, THERE_YAW = 0.2, 0.35


@dataclass(frozen=True)
class TargetPose:
    """``~exploration/target_pose`` (move_to_target only); defaults: the tutorial's launch."""

    x: float = param(1.0, unit="m", help="vantage point x")
    y: float = param(0.0, unit="m", help="vantage point y")
    yaw: float = param(3.1416, unit="rad", help="vantage point heading")
    frame_id: str = param("map", help="frame of the vantage point")


@dataclass(frozen=True)
class ExplorationParams:
    """``~exploration``; the original has no defaults, these are the tutorial's launch values."""

    strategy: str = param(
        "rotate", choices=("rotate", "move_to_target"), help="what to do when the marker is lost"
    )
    robot_frame: str = param("base_footprint", help="the robot's frame (tf_prefix applied)")
    target_pose: dict = param({}, help="move_to_target's vantage pose (x, y, yaw, frame_id)")


def pose_stamped(frame: str, stamp: Any, t: np.ndarray, q: np.ndarray) -> Any:
    return geometry_msgs.PoseStamped(
        header=std_msgs.Header(stamp=stamp, frame_id=frame),
        pose=geometry_msgs.Pose(
            position=geometry_msgs.Point(*map(float, t)),
            orientation=geometry_msgs.Quaternion(*map(float, q)),
        ),
    )


class Follower:
    """A follower as the run monitor sees it (`fleetsim.launch.monitor.GoalSender`): it
    follows for as long as the run lasts, so a run waiting for the goals (--until-goals,
    batch) is not ended by its first goal reached, and it is never done, which is no failure;
    the exploration goals it cancels on seeing the marker again are withdrawn, no failure."""

    sends_goals = True
    follows = True
    done = False
    succeeded = True
    exploration: Exploration

    @property
    def withdrawn_goals(self) -> set[str]:
        return self.exploration.withdrawn


class Exploration(ABC):
    """Base: one move_base action goal at a time, cancelled at most once."""

    STRATEGIES: ClassVar[dict[str, type[Exploration]]] = {}
    name: ClassVar[str] = ""

    def __init_subclass__(cls, **kw: Any) -> None:
        super().__init_subclass__(**kw)
        Exploration.STRATEGIES[cls.name] = cls

    def __init__(self, node, params: ExplorationParams, where: str) -> None:
        self.node = node
        self.params = params
        self.robot_frame = node.frame(params.robot_frame)
        self.map_frame = "map"
        self.client = node.create_action_client(move_base_msgs.MoveBase, MOVE_BASE_ACTION)
        self.exploring = False
        self.cancelled = False
        self.handle = None
        self.goals_sent = 0
        self.sent_at = -math.inf
        self._patience = TransformPatience()
        self.withdrawn: set[str] = set()  # ids of the goals it canceled as no longer wanted

    @classmethod
    def create(cls, node, raw: Any, where: str) -> Exploration:
        """The strategy named in ``~exploration`` (a dict), its parameters validated."""
        if not isinstance(raw, dict):
            raise ParameterError(
                f"{where}: parameter 'exploration' must be a dict (strategy, robot_frame, "
                f"target_pose), got {type(raw).__name__} {raw!r}"
            )
        params = load_params(ExplorationParams, raw, where=where, logger=node.get_logger())
        return cls.STRATEGIES[params.strategy](node, params, where)

    def is_exploring(self) -> bool:
        return self.exploring

    def start(self) -> bool:
        """Send the strategy's goal unless one is running or none is needed; True if sent."""
        if self.exploring:
            if not self._unanswered():
                return False
            self.exploring = False  # sent to nobody: send again (a server may have come)
        goal = self.goal()
        if goal is None:
            return False
        self.exploring, self.cancelled = True, False
        self.goals_sent += 1
        self.handle = self.client.send_goal(
            move_base_msgs.MoveBaseGoal(target_pose=goal), self._done
        )
        self.sent_at = self.node.now()
        self.node.get_logger().info(f"Started exploration ({self.name})")
        return True

    def _unanswered(self) -> bool:
        """The running goal has had no word from any server for `NO_SERVER_TIME` s: warned
        about (every `NO_SERVER_WARN_PERIOD` s). The original blocks in waitForServer() for
        ever; a follower in a namespace has no server at the absolute /move_base, and sent its
        exploration goal to nobody and stood still for good. Judged by the goal's status, not
        the local graph: move_base may run in another process."""
        h, now = self.handle, self.node.now()
        if h is None or h.heard or now - self.sent_at < NO_SERVER_TIME:
            return False
        self.node._warn(
            "exploration: no server",
            f"cannot explore: no move_base action server answers at {self.client.name} "
            f"(follow_marker explores through the absolute {MOVE_BASE_ACTION}, as the "
            f"original does; in a namespace, remap {MOVE_BASE_ACTION} to move_base)",
            NO_SERVER_WARN_PERIOD,
        )
        return True

    def cancel(self) -> None:
        if self.exploring and not self.cancelled and self.handle is not None:
            self.handle.cancel()
            self.cancelled = True
            self.withdrawn.add(self.handle.goal_id.id)  # no longer wanted: no failure
            if not self.handle.heard:  # no server to answer: no done callback will come
                self.exploring = self.cancelled = False

    def _done(self, handle: Any) -> None:
        if handle is self.handle:
            self.exploring = self.cancelled = False
            self.node.get_logger().info("Exploration is done")

    @abstractmethod
    def goal(self) -> Any:
        """The next exploration goal (a PoseStamped in map), or None when there is none yet."""

    def robot_in_map(self) -> tuple[np.ndarray, np.ndarray] | None:
        try:
            found = self.node.tf_buffer.lookup_arrays(self.map_frame, self.robot_frame, 0.0)
        except TransformError as err:
            # said once tf's patience is over, then every 5 s (it is asked for at every image)
            if self._patience.missing_too_long("robot", self.node.now()):
                self.node._warn(
                    "exploration: no robot pose",
                    f"exploration: no robot pose in {self.map_frame}: {err}",
                )
            return None
        self._patience.found("robot")
        return found


class RotateExploration(Exploration):
    name = "rotate"

    def goal(self) -> Any:
        pose = self.robot_in_map()
        if pose is None:
            return None
        t, q = compose_transforms(*pose, np.zeros(3), quaternion_from_yaw(ROTATE_STEP))
        return pose_stamped(self.map_frame, self.node.now_msg(), t, q)


class MoveToTargetExploration(Exploration):
    name = "move_to_target"

    def __init__(self, node, params: ExplorationParams, where: str) -> None:
        super().__init__(node, params, where)
        tp = load_params(
            TargetPose, params.target_pose, where=f"{where}/target_pose", logger=node.get_logger()
        )
        self.target = tp
        # as grobot's move_to_target_exploration.h: the frame_id as given, no tf_prefix (the
        # tutorial's "map" in a namespaced follower is the shared map, not hank/map)
        self.target_frame = tp.frame_id.lstrip("/") or "map"
        self.t_target = np.array([tp.x, tp.y, 0.0])
        self.q_target = quaternion_from_yaw(tp.yaw)

    def goal(self) -> Any:
        pose = self.robot_in_map()
        if pose is None:
            return None
        t_err, q_err = compose_transforms(*inverse_transform(*pose), self.t_target, self.q_target)
        if np.linalg.norm(t_err) < THERE_DISTANCE and yaw_from_quaternion(q_err) < THERE_YAW:
            return None  # already there: wait for the marker to come by
        return pose_stamped(self.target_frame, self.node.now_msg(), self.t_target, self.q_target)
