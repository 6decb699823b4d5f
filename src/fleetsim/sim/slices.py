"""Horizontal slices of MuJoCo geoms as 2-D ray-casting primitives (see ``raycast``).

Each geom becomes segments (the outline of a box-like footprint) or a circle, valid between a
lower and an upper height. Slices are exact for upright boxes, upright cylinders/capsules,
spheres (at their widest) and for boxes/cylinders lying on a side; meshes, ellipsoids and height
fields are replaced by their oriented bounding box. Planes are skipped (a planar laser does not
see the floor).
"""

from __future__ import annotations

import mujoco
import numba
import numpy as np

_PLANE = int(mujoco.mjtGeom.mjGEOM_PLANE)
_SPHERE = int(mujoco.mjtGeom.mjGEOM_SPHERE)
_CAPSULE = int(mujoco.mjtGeom.mjGEOM_CAPSULE)
_CYLINDER = int(mujoco.mjtGeom.mjGEOM_CYLINDER)
_BOX = int(mujoco.mjtGeom.mjGEOM_BOX)


@numba.njit(cache=True)
def _rectangle(out, n, cx, cy, ux, uy, hu, vx, vy, hv, zlo, zhi):
    """Append the 4 sides of a rectangle (centre, unit axes u, v, half extents) to ``out``."""
    px = np.empty(4)
    py = np.empty(4)
    su = (1.0, -1.0, -1.0, 1.0)
    sv = (1.0, 1.0, -1.0, -1.0)
    for k in range(4):
        px[k] = cx + su[k] * hu * ux + sv[k] * hv * vx
        py[k] = cy + su[k] * hu * uy + sv[k] * hv * vy
    for k in range(4):
        j = (k + 1) % 4
        out[n + k, 0] = 0.0
        out[n + k, 1] = px[k]
        out[n + k, 2] = py[k]
        out[n + k, 3] = px[j]
        out[n + k, 4] = py[j]
        out[n + k, 5] = zlo
        out[n + k, 6] = zhi
    return n + 4


@numba.njit(cache=True)
def _circle(out, n, cx, cy, r, zlo, zhi):
    out[n, 0] = 1.0
    out[n, 1] = cx
    out[n, 2] = cy
    out[n, 3] = r
    out[n, 4] = 0.0
    out[n, 5] = zlo
    out[n, 6] = zhi
    return n + 1


@numba.njit(cache=True)
def primitives_from_geoms(types, sizes, xpos, xmat, aabb, ids):
    """Planar-laser primitives of the geoms ``ids``.

    Parameters
    ----------
    types : (G,) int, ``model.geom_type``; sizes : (G, 3), ``model.geom_size`` (m).
    xpos : (G, 3), ``data.geom_xpos`` (world frame, m); xmat : (G, 9), ``data.geom_xmat``.
    aabb : (G, 6), ``model.geom_aabb`` (local centre, half sizes), used for other shapes.
    ids : (N,) int, the geoms to slice.

    Returns
    -------
    prims : (P, 7) float64 primitives (``raycast`` layout); geom : (P,) int64 source geom id.
    """
    out = np.empty((4 * len(ids), 7))
    src = np.empty(4 * len(ids), np.int64)
    n = 0
    for g in ids:
        t = types[g]
        if t == _PLANE:
            continue
        R = xmat[g].reshape(3, 3)
        c = xpos[g]
        n0 = n
        if t == _SPHERE:
            r = sizes[g, 0]
            n = _circle(out, n, c[0], c[1], r, c[2] - r, c[2] + r)
        elif t == _CYLINDER or t == _CAPSULE:  # noqa: SIM109 (numba)
            r = sizes[g, 0]
            hl = sizes[g, 1]
            cap = r if t == _CAPSULE else 0.0
            az = abs(R[2, 2])
            if az >= 0.7:
                hz = hl * az + max(cap, r * np.sqrt(max(0.0, 1.0 - az * az)))
                n = _circle(out, n, c[0], c[1], r, c[2] - hz, c[2] + hz)
            else:
                ax = R[0, 2]
                ay = R[1, 2]
                norm = np.hypot(ax, ay)
                ux = ax / norm
                uy = ay / norm
                hz = r + hl * az
                n = _rectangle(
                    out, n, c[0], c[1], ux, uy, hl * norm + cap, -uy, ux, r, c[2] - hz, c[2] + hz
                )
        else:
            if t == _BOX:
                h = sizes[g].copy()
                cx, cy, cz = c[0], c[1], c[2]
            else:
                h = aabb[g, 3:6].copy()
                off = R @ aabb[g, 0:3].copy()
                cx, cy, cz = c[0] + off[0], c[1] + off[1], c[2] + off[2]
            k = 0
            for a in range(1, 3):
                if abs(R[2, a]) > abs(R[2, k]):
                    k = a
            i = (k + 1) % 3
            j = (k + 2) % 3
            hz = abs(R[2, 0]) * h[0] + abs(R[2, 1]) * h[1] + abs(R[2, 2]) * h[2]
            ni = max(np.hypot(R[0, i], R[1, i]), 1e-12)
            nj = max(np.hypot(R[0, j], R[1, j]), 1e-12)
            n = _rectangle(
                out,
                n,
                cx,
                cy,
                R[0, i] / ni,
                R[1, i] / ni,
                h[i] * ni,
                R[0, j] / nj,
                R[1, j] / nj,
                h[j] * nj,
                cz - hz,
                cz + hz,
            )
        for q in range(n0, n):
            src[q] = g
    return out[:n], src[:n]


def primitives_of(model: mujoco.MjModel, data: mujoco.MjData, ids: np.ndarray):
    """``primitives_from_geoms`` over the current state of ``model``/``data``."""
    return primitives_from_geoms(
        model.geom_type.astype(np.int64),
        model.geom_size,
        data.geom_xpos,
        data.geom_xmat,
        model.geom_aabb,
        np.asarray(ids, np.int64),
    )


def triangle_primitives(model: mujoco.MjModel, data: mujoco.MjData, ids) -> np.ndarray:
    """Triangle primitives (``raycast`` kind 2, 16 columns) of the true triangles of the mesh
    geoms ``ids`` at their current pose, world frame (m). Horizontal triangles (a planar laser
    skims them) and repeated triangles (double-sided meshes) are left out.

    Returns
    -------
    (T, 16) float64: [2, xmin, ymin, xmax, ymax, zmin, zmax, 9 corner coordinates].
    """
    rows = []
    for g in np.asarray(ids, np.int64):
        mid = int(model.geom_dataid[g])
        if mid < 0:
            continue
        v0, nv = model.mesh_vertadr[mid], model.mesh_vertnum[mid]
        f0, nf = model.mesh_faceadr[mid], model.mesh_facenum[mid]
        faces = model.mesh_face[f0 : f0 + nf]
        _, keep = np.unique(np.sort(faces, axis=1), axis=0, return_index=True)
        faces = faces[np.sort(keep)]
        local = model.mesh_vert[v0 : v0 + nv].astype(np.float64)
        world = local @ data.geom_xmat[g].reshape(3, 3).T + data.geom_xpos[g]
        tri = world[faces]  # (F, 3 corners, 3)
        lo, hi = tri.min(axis=1), tri.max(axis=1)
        tall = hi[:, 2] - lo[:, 2] > 1e-9
        out = np.empty((int(tall.sum()), 16))
        out[:, 0] = 2.0
        out[:, 1:3] = lo[tall, :2]
        out[:, 3:5] = hi[tall, :2]
        out[:, 5] = lo[tall, 2]
        out[:, 6] = hi[tall, 2]
        out[:, 7:16] = tri[tall].reshape(-1, 9)
        rows.append(out)
    return np.concatenate(rows) if rows else np.zeros((0, 16))
