"""World overview images rendered by MuJoCo (EGL): top-down or perspective free camera."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from fleetsim.sim.build import COLLISION_GROUP


def world_bounds(engine) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper (3,) corners around every non-plane geom, world frame (m)."""
    m, d = engine.model, engine.data
    keep = m.geom_type != mujoco.mjtGeom.mjGEOM_PLANE
    if not keep.any():
        return np.array([-5.0, -5.0, 0.0]), np.array([5.0, 5.0, 1.0])
    R = np.abs(d.geom_xmat[keep].reshape(-1, 3, 3))
    aabb = m.geom_aabb[keep]
    centre = d.geom_xpos[keep] + np.einsum(
        "gij,gj->gi", d.geom_xmat[keep].reshape(-1, 3, 3), aabb[:, :3]
    )
    half = np.einsum("gij,gj->gi", R, aabb[:, 3:])
    return (centre - half).min(axis=0), (centre + half).max(axis=0)


def overview_image(
    engine, width: int = 1280, height: int = 960, view: str = "top", margin: float = 1.0
) -> np.ndarray:
    """An (H, W, 3) uint8 RGB picture of the whole world.

    ``view`` is ``"top"`` (looking straight down, +x right, +y up) or ``"perspective"``
    (from the south-west, 35 degrees above the horizon).
    """
    lo, hi = world_bounds(engine)
    centre = (lo + hi) / 2
    half_w = (hi[0] - lo[0]) / 2 + margin
    half_h = (hi[1] - lo[1]) / 2 + margin
    m = engine.model
    fovy = math.radians(m.vis.global_.fovy)
    aspect = width / height
    half = max(half_h, half_w / aspect)
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = [centre[0], centre[1], 0.0]
    if view == "top":
        cam.distance = half / math.tan(fovy / 2) + hi[2]
        cam.elevation = -90.0
        cam.azimuth = 90.0
    elif view == "perspective":
        cam.distance = 1.3 * max(half, half_w) / math.tan(fovy / 2)
        cam.elevation = -35.0
        cam.azimuth = 45.0 + 180.0
    else:
        raise ValueError(f"view must be 'top' or 'perspective', got '{view}'")
    extent = max(m.stat.extent, 1e-6)
    m.vis.map.zfar = (cam.distance + 4 * half) / extent
    m.vis.map.znear = 0.01 / extent
    opt = mujoco.MjvOption()
    opt.geomgroup[COLLISION_GROUP] = 0
    r = engine.renderer(width, height)
    r.update_scene(engine.data, camera=cam, scene_option=opt)
    return r.render().copy()
