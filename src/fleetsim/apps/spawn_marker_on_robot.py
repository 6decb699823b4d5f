"""``spawn_marker_on_robot`` (grobot_utilities): put an ArUco marker on a robot's back.

Launched inside the robot's namespace (``/karl``), it takes the robot's model name from the
namespace, as the original does, waits for the robot to exist in the simulator, then in one go:
pauses physics (``/gazebo/pause_physics``), reads the robot's pose
(``/gazebo/get_model_state``), spawns ``model://aruco_marker`` as ``<robot>_marker`` in the
robot's namespace (``/gazebo/spawn_sdf_model``) at the tutorial's pose relative to the robot's
``base_footprint`` (5 cm behind its centre, 0.30 m up, turned by pi so the textured face looks
backwards), locks it there with the link attacher (``/link_attacher_node/attach``,
``base_footprint`` to the marker's ``link``) and resumes physics (``/gazebo/unpause_physics``).
Then it has nothing left to do.

Differences from the original, deliberately: the pose is read after pausing (the blog's order;
the script read it before), the relative pose is composed with the robot's heading (the script
set an absolute world yaw of pi, right only for a robot spawned at yaw 0, as the tutorial's
are), and every failed call or refused request is a `ServiceError` naming the service and the
simulator's reason (the script ignored every response).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from fleetsim.errors import FleetsimError, ServiceError
from fleetsim.msgs import gazebo_msgs, gazebo_ros_link_attacher, geometry_msgs, std_srvs
from fleetsim.runtime import Node, param
from fleetsim.tf.quaternions import yaw_from_quaternion

#: the marker relative to the robot's base_footprint: x, y (m), absolute centre height z (m), yaw
MARKER_POSE = (-0.05, 0.0, 0.30, math.pi)
#: what the original sends to spawn_sdf_model
MARKER_XML = (
    '<sdf version="1.6"><world name="default"><include><uri>model://{model}</uri></include>'
    "</world></sdf>"
)
PAUSE, UNPAUSE = "/gazebo/pause_physics", "/gazebo/unpause_physics"
GET_STATE, SPAWN = "/gazebo/get_model_state", "/gazebo/spawn_sdf_model"
ATTACH = "/link_attacher_node/attach"


@dataclass(frozen=True)
class SpawnMarkerParams:
    """Parameters (fleetsim additions: the original has none)."""

    robot_name: str = param("", help="the robot's model name; empty: the node's namespace")
    marker_model: str = param("aruco_marker", help="the model:// to spawn")
    robot_link: str = param("base_footprint", help="the robot link the marker is locked to")
    wait_timeout: float = param(
        10.0,
        unit="s",
        range=(0.0, None),
        help="how long to wait for the robot (original: 10 tries)",
    )
    poll_period: float = param(0.1, unit="s", range=(1e-3, None), help="how often to look")


def marker_pose_on(robot: geometry_msgs.Pose) -> geometry_msgs.Pose:
    """The marker's world pose for a robot at ``robot`` (only its x, y and heading count)."""
    dx, dy, z, dyaw = MARKER_POSE
    q = robot.orientation
    yaw = yaw_from_quaternion((q.x, q.y, q.z, q.w))
    c, s = math.cos(yaw), math.sin(yaw)
    half = (yaw + dyaw) / 2
    return geometry_msgs.Pose(
        position=geometry_msgs.Point(
            x=robot.position.x + c * dx - s * dy, y=robot.position.y + s * dx + c * dy, z=z
        ),
        orientation=geometry_msgs.Quaternion(z=math.sin(half), w=math.cos(half)),
    )


class SpawnMarkerOnRobot(Node):
    """Spawns and attaches ``<robot>_marker`` once the robot exists, then idles."""

    Params = SpawnMarkerParams

    def __init__(
        self, runtime, name: str = "spawn_marker_on_robot", namespace: str = "/", **kw: Any
    ) -> None:
        super().__init__(runtime, name, namespace, **kw)
        p: SpawnMarkerParams = self.params
        self.robot = p.robot_name or self.namespace.strip("/")
        if not self.robot:
            raise FleetsimError(
                f"{self.full_name}: no robot to put the marker on: run it in the robot's "
                'namespace (<group ns="karl">) or set ~robot_name'
            )
        self.marker = f"{self.robot}_marker"
        self.done = False
        self.started = self.now()
        self._clients = {
            n: self.create_client(t, n)
            for n, t in (
                (PAUSE, std_srvs.Empty),
                (UNPAUSE, std_srvs.Empty),
                (GET_STATE, gazebo_msgs.GetModelState),
                (SPAWN, gazebo_msgs.SpawnModel),
                (ATTACH, gazebo_ros_link_attacher.Attach),
            )
        }
        self._timer = self.create_timer(p.poll_period, self._try)

    def _call(self, name: str, request: Any = None) -> Any:
        try:
            return self._clients[name].call(request)
        except ServiceError as err:
            raise ServiceError(f"{self.full_name}: {name} failed for {self.robot}: {err}") from None

    def _robot_ready(self) -> bool:
        """True once the simulator's services exist and know the robot."""
        if not all(c.service_is_ready() for c in self._clients.values()):
            return False
        req = gazebo_msgs.GetModelState.Request(model_name=self.robot)
        return bool(self._call(GET_STATE, req).success)

    def _try(self) -> None:
        if self.done:
            return
        if not self._robot_ready():
            waited = self.now() - self.started
            if waited >= self.params.wait_timeout:
                missing = [n for n, c in self._clients.items() if not c.service_is_ready()]
                why = (
                    f"services {', '.join(missing)} do not exist (is the simulator running?)"
                    if missing
                    else f"{GET_STATE} does not know a model '{self.robot}'"
                )
                raise ServiceError(
                    f"{self.full_name}: waited {waited:.1f} s for robot '{self.robot}': {why}"
                )
            return
        self.spawn_and_attach()

    def spawn_and_attach(self) -> None:
        """Pause, read the robot's pose, spawn the marker, attach it, resume."""
        p: SpawnMarkerParams = self.params
        self._call(PAUSE, std_srvs.Empty.Request())
        state = self._call(GET_STATE, gazebo_msgs.GetModelState.Request(model_name=self.robot))
        self._check(GET_STATE, state.success, state.status_message)
        spawn = self._call(
            SPAWN,
            gazebo_msgs.SpawnModel.Request(
                model_name=self.marker,
                model_xml=MARKER_XML.format(model=p.marker_model),
                robot_namespace=self.robot,
                initial_pose=marker_pose_on(state.pose),
            ),
        )
        self._check(SPAWN, spawn.success, spawn.status_message)
        attach = self._call(
            ATTACH,
            gazebo_ros_link_attacher.Attach.Request(
                model_name_1=self.robot,
                link_name_1=p.robot_link,
                model_name_2=self.marker,
                link_name_2="link",
            ),
        )
        self._check(ATTACH, attach.ok, f"could not attach {self.marker}/link to {p.robot_link}")
        self._call(UNPAUSE, std_srvs.Empty.Request())
        self.done = True
        self._timer.cancel()
        self.get_logger().info(f"{self.marker} attached to {self.robot}/{p.robot_link}")

    def _check(self, service: str, ok: bool, why: str) -> None:
        if not ok:
            raise ServiceError(f"{self.full_name}: {service} refused for {self.marker}: {why}")
