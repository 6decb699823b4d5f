"""What move_group knows of the robot: planning groups, their active joints, limits and poses.

Built from the URDF (``robot_description``), the SRDF (``robot_description_semantic``) and the
joint limits (``robot_description_planning``), as MoveIt's RobotModel and joint_limits.yaml
combine them: a joint_limits.yaml entry overrides the URDF's velocity limit; a joint without an
acceleration limit gets MoveIt's default of 1 rad/s^2.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from fleetsim.description.srdf import Srdf
from fleetsim.errors import PlanningError, did_you_mean

DEFAULT_ACCELERATION = 1.0  # rad/s^2: MoveIt's DEFAULT_ACCEL_MAX for joints without a limit
DEFAULT_VELOCITY = 1.0  # rad/s: DEFAULT_VEL_MAX
MOVABLE = ("revolute", "continuous", "prismatic")
SCALING_KEYS = ("default_velocity_scaling_factor", "default_acceleration_scaling_factor")
#: joint_limits.yaml's keys (joint_limits_interface's getJointLimits) and their kinds
LIMIT_KEYS = {
    "has_position_limits": bool,
    "min_position": float,
    "max_position": float,
    "has_velocity_limits": bool,
    "max_velocity": float,
    "has_acceleration_limits": bool,
    "max_acceleration": float,
    "has_deceleration_limits": bool,  # pilz_industrial_motion_planner's
    "max_deceleration": float,
    "has_jerk_limits": bool,
    "max_jerk": float,
    "has_effort_limits": bool,
    "max_effort": float,
    "angle_wraparound": bool,
    "has_soft_limits": bool,
    "k_position": float,
    "k_velocity": float,
    "soft_lower_limit": float,
    "soft_upper_limit": float,
}
_log = logging.getLogger("fleetsim.moveit")


def _is_number(v) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _set_at(values, key: str) -> str:
    origin = (getattr(values, "origins", None) or {}).get(key)
    return f" (set at {origin})" if origin else ""


def _checked_limits(joint: str, joint_limits) -> dict:
    """A joint's joint_limits.yaml entry, each value of the kind getJointLimits reads: a bad
    one (``max_velocity: '0.2 rad/s'``) is an error naming it and where it was set, when
    move_group starts, not at the first plan; a key it does not read is warned about (it would
    be ignored), with the nearest it does."""
    entry = joint_limits.get(joint) or {}
    base = f"robot_description_planning/joint_limits/{joint}"
    if not isinstance(entry, dict):
        raise PlanningError(f"{base}{_set_at(joint_limits, joint)}: {entry!r} is not a mapping")
    for key, v in entry.items():
        kind = LIMIT_KEYS.get(key)
        where = f"{base}/{key}{_set_at(entry, key)}"
        if kind is None:
            _log.warning(
                "%s is not a joint limit fleetsim reads; ignored%s",
                where, did_you_mean(key, LIMIT_KEYS),
            )  # fmt: skip
        elif kind is bool and not isinstance(v, bool):
            raise PlanningError(f"{where}: {v!r} is not true or false")
        elif kind is float and not _is_number(v):
            raise PlanningError(f"{where}: {v!r} is not a number")
    for flag, key in (
        ("has_velocity_limits", "max_velocity"),
        ("has_acceleration_limits", "max_acceleration"),
    ):
        if entry.get(flag) and key not in entry:
            raise PlanningError(f"{base}: {flag} is true but {key} is not given")
    return entry


@dataclass(frozen=True)
class GroupLimits:
    """Per active joint of a group, in its order: bounds (rad), max velocity, max acceleration."""

    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    max_acceleration: np.ndarray


class RobotModel:
    """Groups and limits of one robot; errors name the group, joint or state asked for."""

    def __init__(self, robot, srdf: Srdf, planning: dict | None = None, source: str = "") -> None:
        self.robot = robot
        self.srdf = srdf
        self.planning = planning or {}
        self.source = source or srdf.source
        joint_limits = self.planning.get("joint_limits", {}) or {}
        for j in joint_limits:
            if j not in robot.joints:
                raise PlanningError(
                    f"robot_description_planning/joint_limits: joint '{j}' is not in the URDF"
                    f"{did_you_mean(j, robot.joints)}"
                )
        self.joint_limits = {j: _checked_limits(j, joint_limits) for j in joint_limits}
        for (group, name), values in srdf.group_states.items():
            if group not in srdf.groups:
                continue  # the SRDF's reader refuses those
            missing = [j for j in self.active_joints(group) if j not in values]
            if missing:  # MoveIt's SRDF loader says so too; the joint is taken as 0
                _log.warning(
                    "%s: group state '%s' doesn't specify all joints of group '%s' (%s missing: "
                    "taken as 0)", self.source, name, group, ", ".join(missing),
                )  # fmt: skip
        for key in SCALING_KEYS:
            v = self.planning.get(key)
            if v is None:
                continue
            where = f"robot_description_planning/{key}{_set_at(self.planning, key)}"
            if not _is_number(v):
                raise PlanningError(f"{where}: {v!r} is not a number")
            if not 0 < float(v) <= 1:
                _log.warning("%s is %g, outside (0, 1]: planning at full speed (1.0)", where, v)

    @property
    def group_names(self) -> list[str]:
        return list(self.srdf.groups)

    def check_group(self, group: str) -> str:
        if group not in self.srdf.groups:
            raise PlanningError(
                f"{self.source}: no planning group '{group}'{did_you_mean(group, self.srdf.groups)}"
                f"; groups: {', '.join(self.srdf.groups)}"
            )
        return group

    def active_joints(self, group: str) -> list[str]:
        """The group's movable joints, root to tip."""
        self.check_group(group)
        joints = self.srdf.group_joints(group, self.robot)
        return [j for j in joints if self.robot.joints[j].type in MOVABLE]

    def links(self, group: str) -> list[str]:
        """Links moved by the group's joints (children of its joints and below)."""
        out: list[str] = []
        for j in self.active_joints(group):
            stack = [self.robot.joints[j].child]
            while stack:
                link = stack.pop()
                if link not in out:
                    out.append(link)
                    stack.extend(c.child for c in self.robot.joints.values() if c.parent == link)
        return out

    def tip_link(self, group: str) -> str:
        """The end-effector link: the chain's tip, else the last link of the group's joints."""
        g = self.srdf.groups[self.check_group(group)]
        if g.chains:
            return g.chains[-1][1]
        joints = self.active_joints(group)
        if joints:
            return self.robot.joints[joints[-1]].child
        return g.links[-1] if g.links else ""  # a group of links only (an end effector's)

    def end_effector_link(self, group: str) -> str:
        """MoveIt's rule: an end effector whose parent group is ``group`` gives its group's
        first link; otherwise the group's tip link."""
        for ee in self.srdf.end_effectors:
            if ee.parent_group == group:
                eg = self.srdf.groups.get(ee.group)
                if eg is not None and eg.links:
                    return eg.links[0]
        return self.tip_link(group)

    def limits(self, group: str) -> GroupLimits:
        lo, hi, vel, acc = [], [], [], []
        for j in self.active_joints(group):
            joint = self.robot.joints[j]
            lim = joint.limit
            if joint.type == "continuous" or lim is None:
                lo.append(-math.pi)
                hi.append(math.pi)
            else:
                lo.append(lim.lower)
                hi.append(lim.upper)
            v = lim.velocity if lim is not None and lim.velocity > 0 else DEFAULT_VELOCITY
            a = DEFAULT_ACCELERATION
            jl = self.joint_limits.get(j, {}) or {}
            if jl.get("has_velocity_limits") and float(jl.get("max_velocity", 0)) > 0:
                v = float(jl["max_velocity"])
            if jl.get("has_acceleration_limits") and float(jl.get("max_acceleration", 0)) > 0:
                a = float(jl["max_acceleration"])
            vel.append(v)
            acc.append(a)
        return GroupLimits(np.array(lo), np.array(hi), np.array(vel), np.array(acc))

    def named_targets(self, group: str) -> dict[str, np.ndarray]:
        """The SRDF's group states of ``group``, as arrays in active-joint order."""
        joints = self.active_joints(group)
        out = {}
        for (g, name), values in self.srdf.group_states.items():
            if g == group:
                out[name] = np.array([values.get(j, 0.0) for j in joints])
        return out

    def named_target(self, group: str, name: str) -> np.ndarray:
        targets = self.named_targets(group)
        if name not in targets:
            raise PlanningError(
                f"Unable to set target {name}: group '{group}' has no named state '{name}'"
                f"{did_you_mean(name, targets)}; named states: {', '.join(targets) or 'none'}"
            )
        return targets[name]

    def default_scaling(self) -> tuple[float, float]:
        """``default_velocity_scaling_factor``, ``default_acceleration_scaling_factor``, else
        0.1 each as MoveGroupInterface falls back to."""
        return (
            float(self.planning.get("default_velocity_scaling_factor", 0.1)),
            float(self.planning.get("default_acceleration_scaling_factor", 0.1)),
        )

    def check_within_bounds(self, group: str, q: np.ndarray, what: str = "target") -> None:
        lim = self.limits(group)
        joints = self.active_joints(group)
        for j, v, lo, hi in zip(joints, q, lim.lower, lim.upper, strict=True):
            if not (lo - 1e-9 <= v <= hi + 1e-9):
                raise PlanningError(
                    f"{what}: joint '{j}' value {v:.4f} is outside its limits [{lo:.4f}, {hi:.4f}]"
                )
