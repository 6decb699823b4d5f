"""Which class runs a launch file's ``<node pkg= type=>``.

ROS package and executable names map to fleetsim node classes; user nodes are written
``pkg="module" type="Class"`` or ``type="module:Class"``. An unknown ``pkg/type`` is an error
that lists what exists.
"""

from __future__ import annotations

import importlib
import re
import sys
from pathlib import Path
from typing import Any

from fleetsim.errors import LaunchError, did_you_mean

#: (pkg, type) -> "module:Class"
NODES: dict[tuple[str, str], str] = {
    ("tf", "static_transform_publisher"): "fleetsim.tf.static_transform_publisher:StaticTransformPublisher",
    ("tf2_ros", "static_transform_publisher"): "fleetsim.tf.static_transform_publisher:StaticTransformPublisher",
    ("robot_state_publisher", "robot_state_publisher"): "fleetsim.description.robot_state_publisher:RobotStatePublisher",
    ("robot_state_publisher", "state_publisher"): "fleetsim.description.robot_state_publisher:RobotStatePublisher",
    ("amcl", "amcl"): "fleetsim.localization.amcl.node:Amcl",
    ("fake_localization", "fake_localization"): "fleetsim.nav.fake_localization:FakeLocalization",
    ("collvoid", "me_publisher"): "fleetsim.nav.multirobot.me_publisher:MePublisher",
    ("map_server", "map_server"): "fleetsim.nav.map_server:MapServer",
    ("map_server", "map_saver"): "fleetsim.nav.map_server:MapSaver",
    ("move_base", "move_base"): "fleetsim.nav.move_base:MoveBase",
    ("gmapping", "slam_gmapping"): "fleetsim.slam.node:SlamGmapping",
    ("explore_lite", "explore"): "fleetsim.nav.explore.explore:Explore",
    ("multirobot_map_merge", "map_merge"): "fleetsim.slam.map_merge:MapMerge",
    ("map_merge", "map_merge"): "fleetsim.slam.map_merge:MapMerge",
    ("fleetsim", "send_goals"): "fleetsim.nav.send_goals:SendGoals",
    ("navigation_multi", "send_goals"): "fleetsim.nav.send_goals:SendGoals",
    ("gazebo_ros", "gzserver"): "fleetsim.sim.node:Simulator",
    ("gazebo_ros", "spawn_model"): "fleetsim.sim.spawn_model:SpawnModel",
    ("joint_state_publisher", "joint_state_publisher"): "fleetsim.description.joint_state_publisher:JointStatePublisher",
    ("grobot_utilities", "patrol_server"): "fleetsim.apps.patrol_server:PatrolServer",
    ("grobot_utilities", "patrol_client"): "fleetsim.apps.patrol_client:PatrolClient",
    ("aruco_detect", "aruco_detect"): "fleetsim.vision.aruco_detect:ArucoDetect",
    ("grobot_utilities", "spawn_marker_on_robot"): "fleetsim.apps.spawn_marker_on_robot:SpawnMarkerOnRobot",
    ("grobot_navigation", "follow_marker"): "fleetsim.apps.follow_marker:FollowMarker",
    ("fleetsim", "patrol_route"): "fleetsim.apps.patrol_route:PatrolRoute",
    ("fleetsim", "predictive_follower"): "fleetsim.apps.predictive_follower:PredictiveFollower",
    ("controller_manager", "spawner"): "fleetsim.control.spawner:Spawner",
    ("moveit_ros_move_group", "move_group"): "fleetsim.moveit.move_group:MoveGroup",
}  # fmt: skip


def register(pkg: str, type_: str, target: str) -> None:
    """Add a node class: ``register("my_pkg", "my_node", "my_module:MyNode")``."""
    if ":" not in target:
        raise LaunchError(f"node target {target!r} must be 'module:Class'")
    NODES[(pkg, type_)] = target


def _import(target: str, what: str, where: str = "") -> Any:
    module, _, attr = target.partition(":")
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as e:
        mod = import_beside(module, e, where)
        if mod is None:
            raise LaunchError(
                f"{what}: cannot import module '{module}': {e} (looked on the Python path, "
                "beside the launch file and in the working directory; set PYTHONPATH for "
                "elsewhere)"
            ) from None
    except ImportError as e:
        raise LaunchError(f"{what}: cannot import module '{module}': {e}") from None
    try:
        return getattr(mod, attr)
    except AttributeError:
        raise LaunchError(
            f"{what}: module '{module}' has no '{attr}'{did_you_mean(attr, dir(mod))}"
        ) from None


def import_beside(module: str, error: ModuleNotFoundError, where: str) -> Any:
    """A user's node module (``type="my_teleop:Teleop"``) beside the launch file (``where``
    is its file:line) or in the working directory, as ``fleetsim batch`` finds it there:
    that folder is put on the Python path. None when the module is not there either."""
    top = module.split(".")[0]
    if error.name != top:
        return None  # the module was found; something it imports was not
    # ``where`` is "file:line <node>", perhaps "(included from other.launch:3 <include>)"
    found = re.match(r"(.*?):\d+( <|$)", where)
    dirs = [Path(found.group(1)).resolve().parent] if found else []
    dirs.append(Path.cwd())
    for d in dirs:
        if (d / f"{top}.py").is_file() or (d / top / "__init__.py").is_file():
            if str(d) not in sys.path:
                sys.path.append(str(d))  # after the path's own: a stray yaml.py shadows nothing
            try:
                return importlib.import_module(module)
            except ImportError as e:
                raise LaunchError(f"{where}: cannot import module '{module}' ({d}): {e}") from None
    return None


def resolve_node(pkg: str, type_: str, where: str = "") -> Any:
    """The class for ``pkg/type``; ``where`` (file:line) prefixes errors."""
    what = f"{where + ': ' if where else ''}node {pkg}/{type_}"
    target = NODES.get((pkg, type_))
    if target is not None:
        return _import(target, what)
    if ":" in type_:
        return _import(type_, what, where)
    if "." in pkg or pkg.startswith("fleetsim"):
        try:
            importlib.import_module(pkg)
        except ModuleNotFoundError as e:
            if e.name != pkg and not pkg.startswith(f"{e.name}."):
                raise LaunchError(f"{what}: cannot import module '{pkg}': {e}") from None
        else:
            return _import(f"{pkg}:{type_}", what)
    known = [f"{p}/{t}" for p, t in sorted(NODES)]
    raise LaunchError(
        f"{what} is unknown{did_you_mean(f'{pkg}/{type_}', known)}; known nodes: "
        f'{", ".join(known)}; user nodes are written type="module:Class"'
    )
