"""SDF ``<pose>`` elements and the frames they are expressed in (SDFormat 1.4 to 1.9).

A pose is ``x y z roll pitch yaw`` in metres and radians (``rotation_format="euler_rpy"``, the
default; ``degrees="true"`` for degrees, SDF 1.9) or ``x y z qx qy qz qw``
(``rotation_format="quat_xyzw"``). Without ``relative_to`` a pose is expressed in its parent
element's frame (a model's in the world or its parent model, a link's in its model, a
collision's or visual's in its link). ``relative_to`` (SDF 1.7) names another frame of the same
scope: a link, a ``<frame>`` or a nested model of the model, or a model or frame of the world;
``poses_in_scope`` resolves such chains. The SDF 1.5/1.6 ``frame`` attribute was never honoured
by Gazebo classic and is refused with an error rather than silently ignored.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from fleetsim.errors import SimulationError

Pose = tuple[float, float, float, float, float, float]
ZERO_POSE: Pose = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def pose_of(p, where: str) -> Pose:
    """The pose a ``<pose>`` element holds (its own numbers, ``relative_to`` not applied)."""
    if p.get("frame"):
        raise SimulationError(
            f"{where}:{p.sourceline}: <pose frame='{p.get('frame')}'> (SDF 1.5/1.6) is not "
            "supported, as Gazebo classic ignores it; use <pose relative_to='...'> (SDF 1.7)"
        )
    try:
        vals = [float(v) for v in (p.text or "").split()]
    except ValueError as exc:
        raise SimulationError(
            f"{where}:{p.sourceline}: <pose> must hold numbers, got '{p.text}'"
        ) from exc
    fmt = p.get("rotation_format", "euler_rpy")
    if fmt == "euler_rpy":
        if len(vals) == 0:
            return ZERO_POSE
        if len(vals) != 6:
            raise SimulationError(
                f"{where}:{p.sourceline}: <pose> needs 6 numbers (x y z roll pitch yaw), "
                f"got '{p.text}'"
            )
        degrees = p.get("degrees", "false").strip().lower()
        if degrees not in ("true", "false", "1", "0"):
            raise SimulationError(
                f"{where}:{p.sourceline}: <pose degrees='{degrees}'> must be true or false"
            )
        rpy = np.radians(vals[3:]) if degrees in ("true", "1") else vals[3:]
        return (*vals[:3], *map(float, rpy))
    if fmt == "quat_xyzw":
        if len(vals) != 7 or np.linalg.norm(vals[3:]) < 1e-12:
            raise SimulationError(
                f"{where}:{p.sourceline}: <pose rotation_format='quat_xyzw'> needs 7 numbers "
                f"(x y z qx qy qz qw) with a non-zero quaternion, got '{p.text}'"
            )
        rpy = Rotation.from_quat(vals[3:]).as_euler("xyz")
        return (*vals[:3], *map(float, rpy))
    raise SimulationError(
        f"{where}:{p.sourceline}: <pose rotation_format='{fmt}'> must be euler_rpy or quat_xyzw"
    )


def element_pose(el, where: str) -> tuple[Pose, str]:
    """The pose of an element (its ``<pose>`` child) and the frame it names (``""``: parent)."""
    p = el.find("pose")
    if p is None:
        return ZERO_POSE, ""
    return pose_of(p, where), (p.get("relative_to") or "").strip()


def compose(a: Pose, b: Pose) -> Pose:
    """Pose ``b`` (expressed in frame ``a``) expressed in ``a``'s parent: ``a * b``."""
    ra = Rotation.from_euler("xyz", a[3:])
    t = np.asarray(a[:3]) + ra.apply(b[:3])
    r = (ra * Rotation.from_euler("xyz", b[3:])).as_euler("xyz")
    return (*map(float, t), *map(float, r))


def inverse(a: Pose) -> Pose:
    ra = Rotation.from_euler("xyz", a[3:]).inv()
    return (*map(float, -ra.apply(a[:3])), *map(float, ra.as_euler("xyz")))


def poses_in_scope(
    frames: dict[str, tuple[Pose, str]], where: str, scope: str, own: tuple[str, ...]
) -> dict[str, Pose]:
    """Resolve ``{name: (pose, relative_to)}`` of one scope's frames into poses in the scope's
    own frame (named by any of ``own``, or ``""``).

    Raises
    ------
    SimulationError
        A ``relative_to`` names no frame of the scope, or the frames form a cycle.
    """
    out: dict[str, Pose] = {}

    def resolve(name: str, chain: tuple[str, ...]) -> Pose:
        if name in out:
            return out[name]
        if name in chain:
            raise SimulationError(
                f"{where}: <pose relative_to> in {scope} forms a cycle: "
                + " -> ".join((*chain, name))
            )
        pose, rel = frames[name]
        if rel in ("", *own):
            out[name] = pose
        elif rel in frames:
            out[name] = compose(resolve(rel, (*chain, name)), pose)
        else:
            known = ", ".join(sorted(frames)) or "none"
            raise SimulationError(
                f"{where}: <pose relative_to='{rel}'> of '{name}' names no frame of {scope} "
                f"(frames there: {known})"
            )
        return out[name]

    for name in frames:
        resolve(name, ())
    return out
