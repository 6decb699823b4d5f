"""move_base's plugins from its parameters: global planner, local planner, recovery behaviours.

* ``base_global_planner``: ``navfn/NavfnROS`` -> `NavFn` reading ``~NavfnROS/``.
* ``base_local_planner``: ``base_local_planner/TrajectoryPlannerROS`` -> `TrajectoryPlanner`
  reading ``~TrajectoryPlannerROS/``; ``dwa_local_planner/DWAPlannerROS`` -> the same planner in
  its DWA mode (``dwa: true``) reading ``~DWAPlannerROS/``, with DWAPlannerROS's names mapped
  onto TrajectoryPlannerROS's (``max_rot_vel`` -> ``max_vel_theta``, ``path_distance_bias`` ->
  ``pdist_scale`` with metre scoring, ...) and its defaults where they differ. It is the
  trajectory-rollout planner scoring over one control period, not a port of dwa_local_planner's
  critics; names with no counterpart are dropped with a warning.
  ``controller_frequency`` is searched upwards, so move_base's own value is used unless the
  planner's namespace sets one.
  ``nav2_mppi_controller::MPPIController`` (or ``nav2_mppi_controller/MPPIController``) ->
  `fleetsim.nav.controllers.mppi.MPPIController` reading ``~MPPIController/``.
* ``recovery_behaviors``: a list of ``{name, type}`` (types
  ``clear_costmap_recovery/ClearCostmapRecovery``, ``rotate_recovery/RotateRecovery``,
  ``moveback_recovery/MoveBackRecovery`` from mbf_recovery_behaviors), each reading
  ``~<name>/``; when unset, move_base's defaults: ``conservative_reset`` (reset_distance
  ``conservative_reset_dist``), ``rotate_recovery`` (if ``clearing_rotation_allowed``),
  ``aggressive_reset`` (reset_distance 4 x the circumscribed radius), ``rotate_recovery`` again
  (if allowed). RotateRecovery takes its limits from the local planner's namespace
  (``acc_lim_theta``, ``max_vel_theta``, ``min_in_place_vel_theta``, ``yaw_goal_tolerance``
  default 0.10), as rotate_recovery.cpp does.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass
from typing import Any

import numpy as np

from fleetsim.errors import ParameterError, did_you_mean
from fleetsim.nav.controllers import TrajectoryPlanner
from fleetsim.nav.costmap.inflation_layer import InflationLayer, costs_from_distances
from fleetsim.nav.planners import NavFn, NavfnParams
from fleetsim.nav.recovery import (
    ClearCostmapRecovery,
    ClearCostmapRecoveryParams,
    MoveBackRecovery,
    MoveBackRecoveryParams,
    RotateRecovery,
    RotateRecoveryParams,
)
from fleetsim.runtime import load_params
from fleetsim.runtime.param_tree import ParamDict

_log = logging.getLogger("fleetsim.nav.move_base")

GLOBAL_PLANNERS = {"navfn/NavfnROS": "NavfnROS"}
LOCAL_PLANNERS = {
    "base_local_planner/TrajectoryPlannerROS": "TrajectoryPlannerROS",
    "dwa_local_planner/DWAPlannerROS": "DWAPlannerROS",
    "collvoid_local_planner/CollvoidLocalPlanner": "CollvoidLocalPlanner",
    "nav2_mppi_controller::MPPIController": "MPPIController",
    "nav2_mppi_controller/MPPIController": "MPPIController",
}
RECOVERY_TYPES = (
    "clear_costmap_recovery/ClearCostmapRecovery",
    "rotate_recovery/RotateRecovery",
    "moveback_recovery/MoveBackRecovery",
)

#: DWAPlannerROS name -> TrajectoryPlannerROS name
DWA_RENAMES = {
    "max_rot_vel": "max_vel_theta",
    "min_rot_vel": "min_in_place_vel_theta",
    # melodic/noetic's name for min_rot_vel: the least rotational speed, a magnitude (0.4),
    # where TrajectoryPlannerROS's min_vel_theta is the signed lower bound (-1.0); read as that,
    # 0.4 allowed left turns only, and two robots stopped mid-route (a new user's probe)
    "min_vel_theta": "min_in_place_vel_theta",
    "path_distance_bias": "pdist_scale",
    "goal_distance_bias": "gdist_scale",
    "vth_samples": "vtheta_samples",
    "acc_lim_th": "acc_lim_theta",
}
#: DWAPlannerROS defaults that differ from TrajectoryPlannerROS's
DWA_DEFAULTS = {
    "dwa": True,
    "meter_scoring": True,
    "max_vel_x": 0.55,
    "min_vel_x": 0.0,
    "sim_time": 1.7,
    "pdist_scale": 32.0,
    "gdist_scale": 24.0,
    "holonomic_robot": False,
}
DWA_DROPPED = frozenset(
    {"max_trans_vel", "min_trans_vel", "max_vel_y", "min_vel_y", "vy_samples", "trans_stopped_vel",
     "rot_stopped_vel", "forward_point_distance", "stop_time_buffer", "scaling_speed",
     "max_scaling_factor", "use_dwa", "publish_traj_pc", "publish_cost_grid_pc", "restore_defaults",
     "twirling_scale", "acc_limit_trans", "theta_stopped_vel", "max_vel_trans", "min_vel_trans",
     "acc_lim_trans"}
)  # fmt: skip


def _plugin_key(kind: str, value: str, table: dict[str, str], where: str) -> str:
    if value not in table:
        raise ParameterError(
            f"{where}: parameter '{kind}' = '{value}' is not available"
            f"{did_you_mean(value, table)}; known: {', '.join(table)}"
        )
    return table[value]


def global_planner(value: str, ns: dict, costmap_ros: Any, where: str) -> tuple[str, NavFn]:
    """(plugin name, planner) for ``base_global_planner``."""
    name = _plugin_key("base_global_planner", value, GLOBAL_PLANNERS, where)
    params = load_params(NavfnParams, ns.get(name) or {}, f"{where}/{name}", logger=_log)
    planner = NavFn(costmap_ros.costmap, params, costmap_ros.global_frame)
    planner.costmap_revision = lambda: costmap_ros.update_count
    cost, radius = circumscribed_cost(costmap_ros.layered)
    if params.circumscribed_clearance and cost == 0:
        _log.warning(
            "%s/%s: circumscribed_clearance has no effect: the global costmap's inflation "
            "does not reach the footprint's circumscribed radius (%.3f m)",
            where, name, radius,
        )  # fmt: skip
    planner.set_circumscribed(cost, radius)
    return name, planner


def circumscribed_cost(layered: Any) -> tuple[int, float]:
    """(cost, radius in m) of costmap_2d's circumscribed cost (LayeredCostmap's
    getCircumscribedCost: the inflation layer's cost at the footprint's circumscribed radius);
    cost 0 without an inflation layer or where its radius ends before the circumscribed one."""
    radius = float(layered.circumscribed_radius)
    for layer in layered.layers:
        if isinstance(layer, InflationLayer) and layer.enabled:
            ip, res = layer.params, layered.costmap.resolution
            key = (res, layered.inscribed_radius, ip.inflation_radius, ip.cost_scaling_factor)
            return int(costs_from_distances(np.float64(radius / res), *key)), radius
    return 0, radius


def dwa_namespace(ns: dict, where: str) -> dict:
    """DWAPlannerROS's parameters written as TrajectoryPlannerROS's (see the module doc)."""
    out = ParamDict(DWA_DEFAULTS)
    origins = getattr(ns, "origins", None) or {}
    for key, value in ns.items():
        if key in DWA_DROPPED:
            _log.warning("%s: DWAPlannerROS parameter '%s' has no counterpart; ignored", where, key)
        else:
            out[DWA_RENAMES.get(key, key)] = value
            if key in origins:
                out.origins[DWA_RENAMES.get(key, key)] = origins[key]
    # DWAPlannerROS bounds the rotational speed by its magnitude both ways (a value of the wrong
    # type is left to the parameter check, which names its file and line)
    top = out.get("max_vel_theta", 1.0)
    if isinstance(top, int | float) and not isinstance(top, bool):
        out["min_vel_theta"] = -abs(float(top))
    return out


def local_planner_namespace(value: str, ns: dict, controller_frequency: float, where: str):
    """(plugin name, TrajectoryPlannerROS-style namespace dict) for ``base_local_planner``."""
    name = _plugin_key("base_local_planner", value, LOCAL_PLANNERS, where)
    raw = ParamDict.copy_of(ns.get(name))
    if name == "DWAPlannerROS":
        _log.info(
            "%s: dwa_local_planner/DWAPlannerROS runs as base_local_planner's DWA mode", where
        )
        raw = dwa_namespace(raw, f"{where}/{name}")
    raw.setdefault("controller_frequency", controller_frequency)
    return name, raw


def local_planner(value: str, ns: dict, controller_frequency: float, costmap_ros: Any, where: str):
    """(plugin name, TrajectoryPlanner) for ``base_local_planner`` on the local costmap."""
    name, raw = local_planner_namespace(value, ns, controller_frequency, where)
    planner = TrajectoryPlanner.from_namespace(
        costmap_ros.costmap, costmap_ros.footprint, raw, f"{where}/{name}"
    )
    return name, planner


def make_local_planner(node: Any, name: str, ns: dict, costmap_ros: Any, where: str) -> Any:
    """The local planner plugin ``name`` (a `LOCAL_PLANNERS` value) on ``costmap_ros``."""
    if name == "CollvoidLocalPlanner":  # it listens to /position_share through the node
        from fleetsim.nav.controllers.collvoid_planner import CollvoidLocalPlanner

        return CollvoidLocalPlanner.from_namespace(node, costmap_ros, ns, where)
    if name == "MPPIController":  # its noise comes from the runtime's generator
        from fleetsim.nav.controllers.mppi import MPPIController

        return MPPIController.from_namespace(node, costmap_ros, ns, where)
    return TrajectoryPlanner.from_namespace(costmap_ros.costmap, costmap_ros.footprint, ns, where)


@dataclass
class Recovery:
    """One recovery behaviour: a clearing (instant), a rotation or a backing up (over several
    cycles)."""

    name: str
    clear: ClearCostmapRecovery | None = None
    rotate: RotateRecovery | None = None
    moveback: MoveBackRecovery | None = None


def rotate_params(ns: dict, planner_ns: dict, name: str, where: str) -> RotateRecoveryParams:
    """RotateRecovery's parameters: its own ``~name/`` plus the local planner's limits."""
    own = load_params(RotateRecoveryParams, ns.get(name) or {}, f"{where}/{name}", logger=_log)
    tp = planner_ns
    limits = {
        "acc_lim_theta": tp.get("acc_lim_theta", own.acc_lim_theta),
        "max_rotational_vel": tp.get("max_vel_theta", own.max_rotational_vel),
        "min_in_place_rotational_vel": tp.get(
            "min_in_place_vel_theta", own.min_in_place_rotational_vel
        ),
        "yaw_goal_tolerance": tp.get("yaw_goal_tolerance", own.yaw_goal_tolerance),
    }
    values = {**dataclasses.asdict(own), **limits}
    return load_params(RotateRecoveryParams, values, f"{where}/{name}", logger=_log)


def recovery_behaviors(
    p: Any, ns: dict, planner_ns: dict, circumscribed_radius: float, local_cm: Any, where: str
) -> list[Recovery]:
    """The recovery behaviours, in order (see the module doc)."""
    tp = {**planner_ns}
    for old, new in (("max_rotational_vel", "max_vel_theta"),
                     ("min_in_place_rotational_vel", "min_in_place_vel_theta")):  # fmt: skip
        if old in tp:
            tp.setdefault(new, tp[old])

    def rotation(name: str) -> Recovery:
        params = rotate_params(ns, tp, name, where)
        return Recovery(name, rotate=RotateRecovery(local_cm.costmap, local_cm.footprint, params))

    def clearing(name: str, **defaults: Any) -> Recovery:
        values = {**(ns.get(name) or {}), **defaults}  # move_base sets these params itself
        params = load_params(ClearCostmapRecoveryParams, values, f"{where}/{name}", logger=_log)
        return Recovery(name, clear=ClearCostmapRecovery(params))

    if p.recovery_behaviors is None:
        out = [clearing("conservative_reset", reset_distance=p.conservative_reset_dist)]
        if p.clearing_rotation_allowed:
            out.append(rotation("rotate_recovery"))
        out.append(clearing("aggressive_reset", reset_distance=4.0 * circumscribed_radius))
        if p.clearing_rotation_allowed:
            out.append(rotation("rotate_recovery"))
        return out
    out = []
    for i, entry in enumerate(p.recovery_behaviors):
        if not isinstance(entry, dict) or "name" not in entry or "type" not in entry:
            raise ParameterError(
                f"{where}: recovery_behaviors[{i}] must be a mapping with 'name' and 'type', "
                f"got {entry!r}"
            )
        name, kind = str(entry["name"]), str(entry["type"])
        if kind == RECOVERY_TYPES[0]:
            out.append(clearing(name))
        elif kind == RECOVERY_TYPES[1]:
            out.append(rotation(name))
        elif kind == RECOVERY_TYPES[2]:
            params = load_params(
                MoveBackRecoveryParams, ns.get(name) or {}, f"{where}/{name}", logger=_log
            )
            moveback = MoveBackRecovery(local_cm.costmap, local_cm.footprint, params)
            out.append(Recovery(name, moveback=moveback))
        else:
            raise ParameterError(
                f"{where}: recovery_behaviors[{i}] '{name}' has type '{kind}', which is not "
                f"available{did_you_mean(kind, RECOVERY_TYPES)}; known: {', '.join(RECOVERY_TYPES)}"
            )
    return out
