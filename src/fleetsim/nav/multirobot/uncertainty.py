"""Localization uncertainty as a safety radius (collvoid's me_publisher, radius mode "CALU").

Hennes, Claes, Meeussen, Tuyls, "Multi-robot collision avoidance with localization
uncertainty" (AAMAS 2012): sort amcl's particles by their distance from the pose estimate and
take the distance at which the accumulated weight first exceeds ``1 - eps``; the robot is then
advertised that much larger, so that neighbours keep clear of wherever it probably is.
"""

from __future__ import annotations

import math

import numpy as np


def uncertainty_radius(
    particles: np.ndarray,
    center: np.ndarray,
    eps: float,
    cap: float,
    weights: np.ndarray | None = None,
) -> float:
    """Radius around ``center`` holding more than ``1 - eps`` of the particle weight, m.

    Parameters
    ----------
    particles : (P, 2) particle positions, map frame, m.
    center : (2,) the pose estimate, map frame, m.
    eps : share of the weight allowed outside the radius, in [0, 1).
    cap : m, the largest radius returned (collvoid: twice the robot radius).
    weights : (P,) particle weights (any positive scale); None for equal weights (amcl's
        ``particlecloud`` after resampling carries none).

    Returns 0.0 for an empty particle set (fake_localization: the pose is exact).
    """
    pts = np.asarray(particles, dtype=np.float64).reshape(-1, 2)
    if pts.shape[0] == 0:
        return 0.0
    w = np.ones(pts.shape[0]) if weights is None else np.asarray(weights, dtype=np.float64)
    total = float(w.sum())
    if not total > 0.0:
        return 0.0
    d = np.hypot(pts[:, 0] - center[0], pts[:, 1] - center[1])
    order = np.argsort(d, kind="stable")
    acc = np.cumsum(w[order]) / total
    k = int(np.searchsorted(acc, 1.0 - eps, side="right"))
    k = min(k, pts.shape[0] - 1)
    return float(min(d[order][k], cap))


# -- the spread as a covariance (issue 18) --------------------------------------------------------
# A robot's uncertainty padded as a disc (`uncertainty_radius`) keeps two amcl robots in a 2 m
# corridor 1.6-1.8 m apart: amcl's particles spread 0.3-0.5 m *along* a featureless corridor.
# What keeps two robots apart is their extent across the velocity obstacle's legs, so the spread
# is shared as the cloud's 2x2 position covariance and each pair is padded by it in the
# direction that matters (`pair_padding`).


def gaussian_scale(eps: float) -> float:
    """The 1 - ``eps`` quantile of a 2-D Gaussian in standard deviations (its Mahalanobis
    radius: P(outside) = exp(-k^2 / 2) = eps): 2.15 for eps 0.1; inf for eps 0."""
    return math.inf if eps <= 0.0 else math.sqrt(-2.0 * math.log(eps))


def cloud_covariance(particles: np.ndarray) -> np.ndarray | None:
    """The particles' (P, 2) 2x2 position covariance, m^2; None for fewer than two particles
    (fake_localization's cloud is the true pose: no uncertainty)."""
    pts = np.asarray(particles, dtype=np.float64).reshape(-1, 2)
    if pts.shape[0] <= 1:
        return None
    return np.cov(pts.T)


def spread_along(cov: np.ndarray, directions: np.ndarray, eps: float, cap) -> np.ndarray:
    """The 1 - ``eps`` spread of positions with covariance ``cov`` ((2, 2) or (N, 2, 2), m^2)
    along unit ``directions`` (N, 2): k sqrt(n' cov n) (k: `gaussian_scale`), at most ``cap``
    (m, scalar or (N,)). Exactly 0.0 where the variance along n is 0."""
    n = np.asarray(directions, dtype=np.float64).reshape(-1, 2)
    cov = np.asarray(cov, dtype=np.float64)
    var = np.einsum("ni,ij,nj->n" if cov.ndim == 2 else "ni,nij,nj->n", n, cov, n)
    sd = np.sqrt(np.maximum(var, 0.0))
    k = gaussian_scale(eps)
    spread = np.where(sd > 0.0, sd * k if math.isfinite(k) else np.inf, 0.0)
    return np.minimum(spread, cap)


def widest_spread(cov: np.ndarray, eps: float, cap: float) -> float:
    """The largest `spread_along` over all directions (the major axis), m: the radius of a disc
    holding at least 1 - ``eps`` of the Gaussian, at most ``cap``."""
    lam, axes = np.linalg.eigh(np.asarray(cov, dtype=np.float64))
    return float(spread_along(cov, axes[:, -1:].T, eps, cap)[0]) if lam[-1] > 0.0 else 0.0


def pair_padding(
    rel: np.ndarray,
    base: np.ndarray,
    own_cov: np.ndarray | None,
    own_cap: float,
    covs: np.ndarray,
    caps: np.ndarray,
    eps: float,
    vrel: np.ndarray | None = None,
    iterations: int = 12,  # bisection steps (16 neighbours: ~0.7 ms a cycle)
    bodies: np.ndarray | None = None,
) -> np.ndarray:
    """What each pair's combined radius grows by for the two robots' localization spreads, m.

    The pair's shape in the velocity obstacle is the disc of radius ``base`` (both bodies and
    margins) grown by the spread of their relative position; its support along a unit normal
    n is ``base`` + hypot(spread_own(n), spread_other(n)) (`spread_along`, each capped; two
    independent localizations: the 1 - eps spread of the difference, where collvoid adds the
    two radii). A velocity obstacle is the
    cone of the shape's tangents from the robot, and a disc of radius R at distance d has its
    tangents' normals at acos(R / d) from the line between the two. So the padding is the
    support along the normal of the leg on the side the relative velocity ``vrel`` (N, 2) passes
    on (ORCA's half-plane comes from the leg nearest the relative velocity; both legs' larger
    when ``vrel`` is None or points at the other robot): the R with R = base + support(n(R)),
    found by bisection (the support may fall as R grows: a plain fixed-point iteration
    oscillated), so the disc shares the true shape's tangent on that side. Taking the larger
    side always would stall two robots uncertain along a corridor as soon as they stand
    diagonally: the leg behind the other robot runs along the corridor, across their whole
    spread. Far apart the padding is the spread *across* the line between them (a robot
    uncertain only along a corridor is padded by almost nothing against one ahead of it in the
    corridor); in contact (d <= R) it is the spread along the line.

    rel : (N, 2) the others relative to this robot, m, the frame of the covariances;
    base : (N,) combined radii without localization, m; own_cov : (2, 2) or None (exact);
    own_cap : m; covs : (N, 2, 2) the others' covariances (zeros: exact); caps : (N,) m.
    bodies : (N, K, 2) m or None: the others' outlines about their centres (this frame). Given,
    ``base`` leaves the other's body out, and the shape's support (so the result) takes the
    body's support along the normal too: a standing robot's true shape instead of its
    circumscribed disc (a lizi is 0.32 m across, its disc 0.50 m).
    Returns (N,) m, exactly 0.0 where neither robot is uncertain (without ``bodies``).
    """
    rel = np.asarray(rel, dtype=np.float64).reshape(-1, 2)
    support, d, u, perp = _pair_support(rel, own_cov, own_cap, covs, caps, eps)
    if support is None:
        return np.zeros(rel.shape[0])
    # +1: the right leg (the relative velocity passes clockwise of the other robot), -1 the
    # left, 0: both
    side = np.zeros(rel.shape[0])
    if vrel is not None:
        v = np.asarray(vrel, dtype=np.float64).reshape(-1, 2)
        cross = rel[:, 0] * v[:, 1] - rel[:, 1] * v[:, 0]
        side = np.where(np.abs(cross) > 1e-3 * d * np.hypot(v[:, 0], v[:, 1]), -np.sign(cross), 0.0)
    base = np.asarray(base, dtype=np.float64).reshape(-1)

    if bodies is None:
        shape = support
    else:
        pts = np.asarray(bodies, dtype=np.float64).reshape(rel.shape[0], -1, 2)

        def shape(normals: np.ndarray) -> np.ndarray:
            return support(normals) + np.einsum("nkd,nd->nk", pts, normals).max(axis=1)

    def excess(pad: np.ndarray) -> np.ndarray:
        """shape(n(base + pad)) - pad: >= 0 at pad 0, <= 0 at pad = the largest support."""
        s = np.clip((base + pad) / np.maximum(d, 1e-12), 0.0, 1.0)[:, None]
        c = np.sqrt(1.0 - s * s)
        right, left = shape(s * u + c * perp), shape(s * u - c * perp)
        return np.where(side > 0, right, np.where(side < 0, left, np.maximum(right, left))) - pad

    lo = np.zeros(rel.shape[0])
    # each spread is a norm of n (capped), so no support exceeds the sum of two orthogonal ones
    hi = support(u) + support(perp)
    if bodies is not None:
        hi = hi + np.hypot(pts[:, :, 0], pts[:, :, 1]).max(axis=1)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        up = excess(mid) >= 0.0
        lo, hi = np.where(up, mid, lo), np.where(up, hi, mid)
    return hi  # the bracket's upper end: at most hi0 / 2^iterations (~0.3 mm) too large


def side_by_side_padding(
    rel: np.ndarray,
    own_cov: np.ndarray | None,
    own_cap: float,
    covs: np.ndarray,
    caps: np.ndarray,
    eps: float,
) -> np.ndarray:
    """What each pair's distance must grow by to pass side by side, m: both spreads across the
    line between the two now (side by side, that line will be the one between them). The
    question of a passage wide enough for two; arguments as `pair_padding`'s."""
    rel = np.asarray(rel, dtype=np.float64).reshape(-1, 2)
    support, _, _, perp = _pair_support(rel, own_cov, own_cap, covs, caps, eps)
    return np.zeros(rel.shape[0]) if support is None else support(perp)


def _pair_support(rel, own_cov, own_cap, covs, caps, eps):
    """(support along unit normals (N, 2) -> (N,) m, or None with no spread anywhere;
    distances (N,); unit directions to the others (N, 2); their left normals (N, 2))."""
    n = rel.shape[0]
    cov = np.zeros((2, 2)) if own_cov is None else np.asarray(own_cov, dtype=np.float64)
    covs = np.asarray(covs, dtype=np.float64).reshape(n, 2, 2)
    d = np.hypot(rel[:, 0], rel[:, 1])
    u = np.where(d[:, None] > 0.0, rel / np.maximum(d, 1e-12)[:, None], [1.0, 0.0])
    perp = np.stack((-u[:, 1], u[:, 0]), axis=1)
    if n == 0 or (not cov.any() and not covs.any()):
        return None, d, u, perp

    def support(normals: np.ndarray) -> np.ndarray:
        # the two localizations are independent: their relative position's spread along n is
        # the root of the sum of squares (each robot's capped first), not the sum
        return np.hypot(
            spread_along(cov, normals, eps, own_cap), spread_along(covs, normals, eps, caps)
        )

    return support, d, u, perp


#: support directions of `spread_outline`'s polygon (64: it stands 2 mm off a lizi's body and
#: amcl's spread in a corridor, 6 mm off a thin spread turned off the body's axes; a
#: rectangle's four sides are among them)
OUTLINE_DIRECTIONS = 64


def spread_outline(
    footprint: np.ndarray, cov: np.ndarray | None, cap: float, eps: float, pad: float = 0.0
) -> np.ndarray:
    """A robot's body grown by where it probably is: the outer polygon (`OUTLINE_DIRECTIONS`,
    2), in the frame of ``footprint`` (its robot frame, m), of the body plus the ``1 - eps``
    spread of its position (covariance ``cov``, (2, 2) m^2 in that frame), at most ``cap`` m
    (its ellipse's axes clamped there, which keeps the outline convex where `pair_padding`'s
    cap by direction would not, and is inside it; for ``eps`` 0 a disc of ``cap``), plus
    ``pad`` m in every direction (a planner's padding: costmap_2d's padFootprint, which moves
    each coordinate by its sign, pads a polygon turned off its axes by less).

    The padding is what collvoid's polygon mode ("COCALU") adds to a footprint: the
    particles' outline, here their Gaussian's. Padding the body by its *widest* spread (what a
    robot shares, so that a consumer that reads no covariance keeps clear of it in every
    direction) grows a lizi parked in a 2 m corridor, uncertain 0.25 m along it and 0.06 m
    across, into a 1.37 x 1.31 m box that leaves no way past it; its outline by direction is
    1.37 x 0.58 m. The polygon's support along each unit normal n of `OUTLINE_DIRECTIONS` is
    the body's plus `spread_along` n plus ``pad``; consecutive support lines meet at its
    vertices, so it holds the true sum (2 mm outside it there). The consumer's own spread is
    not added, as collvoid puts the others' shared footprints into a costmap (its
    ``stationary_robots``); ORCA's pairs take both (`pair_padding`). Without a spread (None
    or zero) use the footprint itself (`Neighbour.outline` does)."""
    fp = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    ang = np.arange(OUTLINE_DIRECTIONS) * (2.0 * math.pi / OUTLINE_DIRECTIONS)
    n = np.stack((np.cos(ang), np.sin(ang)), axis=1)
    h = (fp @ n.T).max(axis=0) + pad
    if cov is not None and np.any(cov):
        if math.isfinite(gaussian_scale(eps)):
            h = h + spread_along(_clamped(cov, eps, cap), n, eps, cap)
        else:  # eps 0: all of an unbounded Gaussian, capped in every direction
            h = h + cap
    n2, h2 = np.roll(n, -1, axis=0), np.roll(h, -1)
    det = math.sin(2.0 * math.pi / OUTLINE_DIRECTIONS)  # n x n2, the same for every pair
    x = (h * n2[:, 1] - h2 * n[:, 1]) / det
    y = (n[:, 0] * h2 - n2[:, 0] * h) / det
    return np.stack((x, y), axis=1)


def _clamped(cov: np.ndarray, eps: float, most: float) -> np.ndarray:
    """``cov`` with the eigenvalues whose ``1 - eps`` spread (``eps`` > 0) exceeds ``most`` m
    brought down to it: an ellipse no wider than ``most``."""
    lam, axes = np.linalg.eigh(np.asarray(cov, dtype=np.float64))
    lam = np.clip(lam, 0.0, (most / gaussian_scale(eps)) ** 2)
    return (axes * lam) @ axes.T


def shared_padding(footprint: np.ndarray, widest: float) -> float:
    """The padding a publisher gave ``footprint`` (costmap_2d's padFootprint, each coordinate
    moved away from 0 by its sign) when it padded its body by its widest spread ``widest`` (m,
    uncapped), capped at twice the body's circumscribed radius (`me_publisher`): the p with
    p = min(widest, 2 R(footprint - sign(footprint) p)), m. The result is exact for a message
    padded that way (the right side falls as p grows, so the solution is unique)."""
    fp = np.asarray(footprint, dtype=np.float64)
    nonzero = np.abs(fp[fp != 0.0])
    hi = min(float(widest), float(nonzero.min()) if nonzero.size else 0.0)

    def excess(p: float) -> float:
        body = fp - np.sign(fp) * p
        return p - 2.0 * float(np.max(np.hypot(body[:, 0], body[:, 1])))

    if hi <= 0.0 or excess(hi) <= 0.0:
        return max(hi, 0.0)
    lo = 0.0
    for _ in range(60):  # bisection: the cap's equation has no closed form for a polygon
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) <= 0.0 else (lo, mid)
    return lo
