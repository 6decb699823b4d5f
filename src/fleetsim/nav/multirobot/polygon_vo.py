"""ORCA half-planes of robots as convex polygons (collvoid's ``use_polygon_footprint``).

collvoid's polygon mode (COCALU, Claes et al.) gives each pair the Minkowski sum of the two
footprints instead of the sum of their circumscribed discs: two robots longer than they are
wide may then pass side by side closer than their discs allow (two jackals, 0.62 x 0.54 m
padded, need 0.82 m between centres as discs and 0.54 m abreast as rectangles; two of them
meeting in a 2 m corridor under amcl's spread did not pass as discs).

The geometry, for this robot's footprint A (at its heading, about its centre) and a
neighbour's B (at its heading) at ``rel`` (its centre minus ours): the two touch after t s
at relative velocity v (ours minus theirs) when t v lies in P = rel + B (+) -A (Minkowski sum),
grown here by the pair's padding (margins, tracking allowance, localization spreads) as a
polygon around a disc. The velocity obstacle truncated at the horizon tau is
P / tau (+) cone(P), the convex hull of P / tau and of P scaled far out; ORCA's u is the
vector from v to the nearest point of its boundary, the half-plane's normal the boundary's
outward normal there, exactly as RVO2 builds them for discs (RVO2 is the reference:
`orca_halfplanes`; a many-sided polygon round a disc gives its half-planes). When the padded
shapes already overlap (0 in P), the obstacle is P / time_step, as RVO2's collision branch.

Why our own: no maintained Python library builds polygonal velocity obstacles (RVO2 and its
bindings take discs), and scipy's Qhull (used for meshes in `fleetsim.sim.decompose`) cannot be
called from the numba kernels, which build a hull per neighbour each cycle. The kernels loop
over the neighbours: a hull of at most a few hundred points each, sequential by nature.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: sides of the polygon standing for a disc of padding (circumscribed: its sides touch the
#: disc, so the polygon holds it; 16 sides stand at most 2 % of the radius off it)
PAD_SIDES = 16
#: how far P is scaled out to stand for the cone's unbounded legs: its nearest vertex this far
#: (m/s) from the origin, beyond any speed a robot commands
FAR_SPEED = 1.0e3


@numba.njit(cache=True)
def _turns_left(out, k, px, py):
    """out[k - 2] -> out[k - 1] -> (px, py) turns counter-clockwise."""
    ax, ay = out[k - 2, 0], out[k - 2, 1]
    return (out[k - 1, 0] - ax) * (py - ay) - (out[k - 1, 1] - ay) * (px - ax) > 0.0


@numba.njit(cache=True)
def _hull(pts: np.ndarray) -> np.ndarray:
    """Convex hull of (n, 2) points, counter-clockwise, no repeated or collinear vertices
    (Andrew's monotone chain: the lower chain left to right, then the upper one back)."""
    n = pts.shape[0]
    order_y = np.argsort(pts[:, 1], kind="mergesort")
    p = pts[order_y[np.argsort(pts[order_y, 0], kind="mergesort")]]
    out = np.empty((2 * n + 1, 2))
    k = 0
    for chain in range(2):
        low = k + 1 if chain else 2
        for j in range(n) if chain == 0 else range(n - 2, -1, -1):
            while k >= low and not _turns_left(out, k, p[j, 0], p[j, 1]):
                k -= 1
            out[k] = p[j]
            k += 1
    m = max(k - 1, 1)
    if m == 2 and out[0, 0] == out[1, 0] and out[0, 1] == out[1, 1]:
        m = 1  # all the points the same
    return out[:m].copy()


@numba.njit(cache=True)
def _nearest(poly: np.ndarray, vx: float, vy: float):
    """Nearest point (qx, qy) of the boundary of the convex counter-clockwise ``poly`` to v,
    the boundary's outward unit normal there (nx, ny) and whether v lies inside (for a
    ``poly`` without area, a point or a segment, only a v on it)."""
    m = poly.shape[0]
    best = np.inf
    qx = qy = nx = ny = 0.0
    inside = True
    for i in range(m):
        ax, ay = poly[i, 0], poly[i, 1]
        bx, by = poly[(i + 1) % m, 0], poly[(i + 1) % m, 1]
        ex, ey = bx - ax, by - ay
        ee = ex * ex + ey * ey
        if ex * (vy - ay) - ey * (vx - ax) < 0.0:
            inside = False
        t = 0.0 if ee <= 0.0 else min(1.0, max(0.0, ((vx - ax) * ex + (vy - ay) * ey) / ee))
        px, py = ax + t * ex, ay + t * ey
        d = (vx - px) ** 2 + (vy - py) ** 2
        if d < best:
            best = d
            qx, qy = px, py
            le = math.sqrt(ee) if ee > 0.0 else 1.0
            nx, ny = ey / le, -ex / le  # the edge's outward normal (interior on the left)
    if m < 3:
        inside = best <= 1e-24
    if not inside:
        dx, dy = vx - qx, vy - qy
        dl = math.sqrt(dx * dx + dy * dy)
        if dl > 1e-12:  # off a vertex the normal points at v, off an edge it is the edge's
            nx, ny = dx / dl, dy / dl
    return qx, qy, nx, ny, inside


@numba.njit(cache=True)
def _pair_shapes(rel, own, others, counts, pads, sides):
    """rel + others[k] (+) -own (+) a ``sides``-gon round a disc of pads[j, k], as convex
    counter-clockwise polygons packed in (J, N, M, 2) with their vertex counts (J, N): the
    core sum is built once per pair for all J pads."""
    n = rel.shape[0]
    ring = np.empty((sides, 2))
    for j in range(sides):
        a = 2.0 * math.pi * (j + 0.5) / sides
        ring[j, 0] = math.cos(a) / math.cos(math.pi / sides)
        ring[j, 1] = math.sin(a) / math.cos(math.pi / sides)
    ka = own.shape[0]
    width = others.shape[1] * ka + sides  # at most this many hull vertices per pair
    shapes = np.zeros((pads.shape[0], n, width, 2))
    sizes = np.zeros((pads.shape[0], n), dtype=np.int64)
    for k in range(n):
        kb = counts[k]
        pts = np.empty((kb * ka, 2))
        for i in range(kb):
            for j in range(ka):
                pts[i * ka + j, 0] = others[k, i, 0] - own[j, 0]
                pts[i * ka + j, 1] = others[k, i, 1] - own[j, 1]
        core = _hull(pts)
        for q in range(pads.shape[0]):
            grown = core
            if pads[q, k] > 0.0:
                grown = np.empty((core.shape[0] * sides, 2))
                for i in range(core.shape[0]):
                    for j in range(sides):
                        grown[i * sides + j, 0] = core[i, 0] + pads[q, k] * ring[j, 0]
                        grown[i * sides + j, 1] = core[i, 1] + pads[q, k] * ring[j, 1]
                grown = _hull(grown)
            m = grown.shape[0]
            shapes[q, k, :m, 0] = grown[:, 0] + rel[k, 0]
            shapes[q, k, :m, 1] = grown[:, 1] + rel[k, 1]
            sizes[q, k] = m
    return shapes, sizes


def disc_polygon(radius: float, sides: int = PAD_SIDES) -> np.ndarray:
    """A ``sides``-gon holding the disc of ``radius`` m about 0 (its sides touch the disc):
    (sides, 2) m, counter-clockwise; what a disc stands as among polygons."""
    a = 2.0 * math.pi * (np.arange(sides) + 0.5) / sides
    r = radius / math.cos(math.pi / sides)
    return np.stack((r * np.cos(a), r * np.sin(a)), axis=1)


def pair_shapes(
    rel: np.ndarray,
    own: np.ndarray,
    others: list[np.ndarray] | np.ndarray,
    pads: np.ndarray,
    sides: int = PAD_SIDES,
) -> tuple[np.ndarray, np.ndarray]:
    """Each pair's collision shape in relative-velocity space: rel[k] + others[k] (+) -own,
    grown by ``pads`` (N,) m (a ``sides``-gon holding the disc).

    rel : (N, 2) the neighbours' centres minus ours, m; own : (K, 2) our footprint at our
    heading about our centre, m; others : N arrays (K_k, 2), each neighbour's footprint at its
    heading about its centre, m. Returns (shapes (N, M, 2) m, counter-clockwise, and their
    vertex counts (N,)); the two touch now when 0 lies in shape k. ``pads`` (J, N): J sets
    of shapes, (J, N, M, 2) and (J, N), the sums built once.
    """
    rel = np.ascontiguousarray(rel, dtype=np.float64).reshape(-1, 2)
    n = rel.shape[0]
    most = max((len(o) for o in others), default=1)
    packed = np.zeros((n, most, 2))
    counts = np.zeros(n, dtype=np.int64)
    for k, o in enumerate(others):
        o = np.asarray(o, dtype=np.float64).reshape(-1, 2)
        packed[k, : len(o)] = o
        counts[k] = len(o)
    own = np.ascontiguousarray(own, dtype=np.float64).reshape(-1, 2)
    pads = np.asarray(pads, dtype=np.float64)
    # a writable C copy either way: a read-only broadcast view is another type, which numba
    # compiles the kernel for again (~5 s)
    sets = pads.reshape(-1, n) if pads.ndim == 2 else np.broadcast_to(pads, (1, n))
    shapes, sizes = _pair_shapes(rel, own, packed, counts, np.array(sets, order="C"), int(sides))
    return (shapes, sizes) if pads.ndim == 2 else (shapes[0], sizes[0])


@numba.njit(cache=True)
def _halfplanes(shapes, sizes, rel_vel, velocity, tau, dt, resp):
    n = shapes.shape[0]
    points = np.empty((n, 2))
    directions = np.empty((n, 2))
    touching = np.zeros(n, dtype=np.bool_)
    for k in range(n):
        poly = shapes[k, : sizes[k]]
        q0x, q0y, _, _, inside0 = _nearest(poly, 0.0, 0.0)
        touching[k] = inside0
        if inside0:  # RVO2's collision branch: out of the shape within one step
            vo = poly / dt
        else:
            near = math.hypot(q0x, q0y)  # scaled by FAR_SPEED / near, P's nearest point
            pts = np.empty((2 * poly.shape[0], 2))
            pts[: poly.shape[0]] = poly / tau
            pts[poly.shape[0] :] = poly * (FAR_SPEED / max(near, 1e-9))
            vo = _hull(pts)
        vx, vy = rel_vel[k, 0], rel_vel[k, 1]
        qx, qy, nx, ny, _ = _nearest(vo, vx, vy)
        points[k, 0] = velocity[0] + resp[k] * (qx - vx)
        points[k, 1] = velocity[1] + resp[k] * (qy - vy)
        directions[k, 0] = ny  # permitted: left of the direction, the outward normal's side
        directions[k, 1] = -nx
    return points, directions, touching


def polygon_orca_halfplanes(
    shapes: np.ndarray,
    sizes: np.ndarray,
    rel_vel: np.ndarray,
    velocity: np.ndarray,
    time_horizon: float,
    time_step: float,
    responsibility: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ORCA half-planes of one agent against N neighbours given as `pair_shapes`.

    rel_vel : (N, 2) own velocity minus each neighbour's, m/s; velocity : (2,) own, m/s;
    time_horizon, time_step : s, as `fleetsim.nav.multirobot.orca.orca_halfplanes`;
    responsibility : (N,) or scalar share of the avoidance this agent takes.
    Returns (points (N, 2), directions (N, 2): permitted velocities lie left of each line, as
    `orca_halfplanes`'s, and touching (N,) bool: the padded shapes overlap now).
    """
    n = shapes.shape[0]
    rv = np.ascontiguousarray(rel_vel, dtype=np.float64).reshape(-1, 2)
    vel = np.ascontiguousarray(velocity, dtype=np.float64).reshape(2)
    resp = np.ascontiguousarray(np.broadcast_to(responsibility, (n,)), dtype=np.float64)
    return _halfplanes(
        np.ascontiguousarray(shapes, dtype=np.float64),
        np.asarray(sizes, dtype=np.int64),
        rv,
        vel,
        float(time_horizon),
        float(time_step),
        resp,
    )


@numba.njit(cache=True)
def _gaps(shapes, sizes):
    n = shapes.shape[0]
    normals = np.empty((n, 2))
    gaps = np.empty(n)
    for k in range(n):
        qx, qy, nx, ny, inside = _nearest(shapes[k, : sizes[k]], 0.0, 0.0)
        d = math.hypot(qx, qy)
        gaps[k] = -d if inside else d
        normals[k, 0] = -nx  # towards the other: into the shape
        normals[k, 1] = -ny
    return normals, gaps


def shape_gaps(shapes: np.ndarray, sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How far each pair's bodies are apart along the way they would meet: (normals (N, 2),
    unit, the direction of relative motion that closes the gap fastest; gaps (N,) m, the
    distance from 0 to `pair_shapes`' shape, negative by the depth when they overlap). What
    `fleetsim.nav.multirobot.orca.contact_halfplanes` takes as the line of centres and
    distance minus radii, for polygons."""
    return _gaps(np.ascontiguousarray(shapes, dtype=np.float64), np.asarray(sizes, np.int64))
