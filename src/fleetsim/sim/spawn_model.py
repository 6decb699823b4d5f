"""``gazebo_ros/spawn_model``: puts a model into the running simulation, as in Gazebo.

Arguments as gazebo_ros's spawn_model takes them::

    -urdf | -sdf           the description format
    -file FILE | -param P  where the description comes from (-param is resolved in the node's
                           namespace, so `-param robot_description` in group lizi1 reads
                           /lizi1/robot_description)
    -model NAME            the model's name in the world
    -x -y -z -R -P -Y      the initial pose (metres, radians)
    -robot_namespace NS    the namespace its plugins publish in (default: the node's namespace)
    -reference_frame F     the frame the pose is given in (default: world)
    -unpause               unpause physics after spawning
    -wait MODEL_NAME       spawn only once that model is in the world
    -gazebo_namespace NS   where the world services are (default: /gazebo)

The node calls ``/gazebo/spawn_urdf_model`` (or ``spawn_sdf_model``) at start; if the simulator
is not up yet it retries every 0.1 s of sim time, as spawn_model waits for the service.
"""

from __future__ import annotations

import math
from pathlib import Path

from fleetsim.errors import SimulationError
from fleetsim.msgs import gazebo_msgs, geometry_msgs, std_srvs
from fleetsim.runtime import Node
from fleetsim.tf.quaternions import quaternion_from_euler

_FLAGS = {"-urdf", "-sdf", "-unpause", "-trimesh", "-b", "-package_to_model"}
_VALUES = {
    "-file", "-param", "-database", "-model", "-x", "-y", "-z", "-R", "-P", "-Y",
    "-reference_frame", "-gazebo_namespace", "-robot_namespace", "-J", "-urdf_param", "-wait",
}  # fmt: skip
_POSE = {"-x": 0, "-y": 1, "-z": 2, "-R": 3, "-P": 4, "-Y": 5}


def parse_spawn_args(args: list[str], where: str = "spawn_model") -> dict:
    """Read spawn_model's command line into a dict; errors name the offending argument."""
    out: dict = {"pose": [0.0] * 6, "joints": {}, "flags": set()}
    i = 0
    while i < len(args):
        a = args[i]
        if a in _FLAGS:
            out["flags"].add(a)
            i += 1
            continue
        if a not in _VALUES:
            raise SimulationError(
                f"{where}: unknown argument '{a}'; spawn_model takes -urdf|-sdf, -file F|-param P, "
                "-model NAME, -x -y -z -R -P -Y, -robot_namespace NS, -reference_frame F, -unpause"
            )
        if a == "-J":
            if i + 2 >= len(args):
                raise SimulationError(f"{where}: -J needs a joint name and a position")
            out["joints"][args[i + 1]] = _number(args[i + 2], "-J", where)
            i += 3
            continue
        if i + 1 >= len(args):
            raise SimulationError(f"{where}: '{a}' needs a value")
        value = args[i + 1]
        if a in _POSE:
            out["pose"][_POSE[a]] = _number(value, a, where)
        else:
            out[a.lstrip("-")] = value
        i += 2
    if "model" not in out:
        raise SimulationError(f"{where}: -model NAME is required")
    if "-urdf" in out["flags"] and "-sdf" in out["flags"]:
        raise SimulationError(f"{where}: give one of -urdf and -sdf, not both")
    sources = [k for k in ("file", "param", "database") if k in out]
    if len(sources) != 1:
        raise SimulationError(
            f"{where}: give exactly one of -file, -param, -database (got {sources or 'none'})"
        )
    return out


def _number(text: str, flag: str, where: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise SimulationError(f"{where}: {flag} expects a number, got '{text}'") from None
    if not math.isfinite(v):
        raise SimulationError(f"{where}: {flag} must be finite, got '{text}'")
    return v


class SpawnModel(Node):
    """The spawn_model node: one call to the world's spawn service, then done."""

    RETRY_PERIOD = 0.1

    def __init__(self, runtime, name: str = "spawn_model", namespace: str = "/", **kw) -> None:
        super().__init__(runtime, name, namespace, **kw)
        where = f"{self.full_name} args"
        self.spec = parse_spawn_args(self.args, where)
        self.xml = self._description(where)
        self.done = False
        self.response = None
        fmt = "sdf" if "-sdf" in self.spec["flags"] else "urdf"
        gz = self.spec.get("gazebo_namespace", "/gazebo").rstrip("/") or "/gazebo"
        self._client = self.create_client(gazebo_msgs.SpawnModel, f"{gz}/spawn_{fmt}_model")
        self._unpause = self.create_client(std_srvs.Empty, f"{gz}/unpause_physics")
        self._state = self.create_client(gazebo_msgs.GetModelState, f"{gz}/get_model_state")
        self._told_waiting = False
        self._timer = self.create_timer(self.RETRY_PERIOD, self._try_spawn, priority=-60)
        runtime.call_later(0.0, self._try_spawn, priority=-60)

    def _description(self, where: str) -> str:
        spec = self.spec
        if "file" in spec:
            path = Path(spec["file"])
            if not path.is_file():
                raise SimulationError(f"{where}: -file {path} does not exist")
            if path.suffix == ".xacro":
                from fleetsim.description.urdf import urdf_text

                return urdf_text(path)[0]
            return path.read_text()
        if "param" in spec:
            value = self.get_param(spec["param"])
            if not isinstance(value, str) or not value.strip():
                raise SimulationError(
                    f"{where}: parameter {self.resolve_name(spec['param'])} holds no model "
                    "description (load robot_description first)"
                )
            return value
        raise SimulationError(f"{where}: -database models are not available in fleetsim")

    def _request(self):
        s = self.spec
        x, y, z, roll, pitch, yaw = s["pose"]
        qx, qy, qz, qw = quaternion_from_euler(roll, pitch, yaw)
        pose = geometry_msgs.Pose(
            position=geometry_msgs.Point(x=x, y=y, z=z),
            orientation=geometry_msgs.Quaternion(x=qx, y=qy, z=qz, w=qw),
        )
        return gazebo_msgs.SpawnModel.Request(
            model_name=s["model"],
            model_xml=self.xml,
            robot_namespace=s.get("robot_namespace", self.namespace),
            initial_pose=pose,
            reference_frame=s.get("reference_frame", ""),
        )

    def _awaited_model_exists(self) -> bool:
        """``-wait MODEL_NAME``: whether that model is in the world yet (gazebo_ros's spawn_model
        watches model_states for it; asking get_model_state answers the same)."""
        name = self.spec.get("wait")
        if not name:
            return True
        if self._state.wait_for_service():
            req = gazebo_msgs.GetModelState.Request(model_name=name)
            if self._state.call(req).success:
                return True
        if not self._told_waiting:
            self._told_waiting = True
            self.get_logger().info(f"waiting for model '{name}' before spawning")
        return False

    def _try_spawn(self) -> None:
        if self.done:
            return
        if not self._client.wait_for_service():
            return  # the simulator is not up yet; try again next period
        if not self._awaited_model_exists():
            return
        self.response = self._client.call(self._request())
        self.done = True
        self._timer.cancel()
        if not self.response.success:
            raise SimulationError(
                f"{self.full_name}: spawning '{self.spec['model']}' failed: "
                f"{self.response.status_message}"
            )
        self.get_logger().info(f"spawned model '{self.spec['model']}'")
        if "-unpause" in self.spec["flags"] and self._unpause.wait_for_service():
            self._unpause.call(std_srvs.Empty.Request())
