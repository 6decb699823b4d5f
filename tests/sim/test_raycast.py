import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.sim import raycast

from .ray_triangle import first_hit, horizontal


def brute_force(prims, origin, angle, rmin, rmax):
    """Exact first hit of one ray against every primitive (no grid)."""
    ox, oy, oz = origin
    dx, dy = np.cos(angle), np.sin(angle)
    best = np.inf
    for p in prims:
        if not (p[5] <= oz <= p[6]):
            continue
        if p[0] == 0:
            e = p[3:5] - p[1:3]
            den = dx * e[1] - dy * e[0]
            if abs(den) < 1e-12:
                continue
            w = p[1:3] - (ox, oy)
            t = (w[0] * e[1] - w[1] * e[0]) / den
            s = (w[0] * dy - w[1] * dx) / den
            if t >= rmin and 0 <= s <= 1:
                best = min(best, t)
        else:
            c = np.array([ox - p[1], oy - p[2]])
            b = c @ (dx, dy)
            disc = b * b - (c @ c - p[3] ** 2)
            if disc >= 0:
                for t in (-b - np.sqrt(disc), -b + np.sqrt(disc)):
                    if t >= rmin:
                        best = min(best, t)
                        break
    return best if best <= rmax else np.inf


def random_prims(rng, n):
    prims = np.zeros((n, 7))
    kind = rng.integers(0, 2, n)
    prims[:, 0] = kind
    a = rng.uniform(-10, 10, (n, 2))
    prims[:, 1:3] = a
    prims[:, 3:5] = np.where(
        kind[:, None] == 0,
        a + rng.uniform(-3, 3, (n, 2)),
        np.c_[rng.uniform(0.05, 1.0, n), np.zeros(n)],
    )
    prims[:, 5] = rng.uniform(-1, 0.5, n)
    prims[:, 6] = prims[:, 5] + rng.uniform(0.1, 2, n)
    return prims


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), cell=st.sampled_from([0.3, 1.0, 2.5]))
def test_grid_cast_matches_brute_force(seed, cell):
    rng = np.random.default_rng(seed)
    prims = random_prims(rng, 40)
    grid = raycast.grid_from_primitives(prims, cell=cell)
    origins = np.c_[rng.uniform(-14, 14, (50, 2)), rng.uniform(-0.5, 1.0, 50)]
    angles = rng.uniform(-np.pi, np.pi, 50)
    got = raycast.cast(grid, origins, angles, 0.05, 12.0, -1)
    want = [brute_force(prims, o, a, 0.05, 12.0) for o, a in zip(origins, angles)]
    np.testing.assert_allclose(got, want, atol=1e-9)


def test_owner_primitives_are_skipped():
    prims = np.array([[1, 2.0, 0.0, 0.5, 0, -1, 1], [1, 5.0, 0.0, 0.5, 0, -1, 1]])
    grid = raycast.grid_from_primitives(prims, np.array([3, -1]), cell=1.0)
    own = raycast.cast(grid, np.zeros((1, 3)), np.zeros(1), 0.0, 10.0, 3)
    other = raycast.cast(grid, np.zeros((1, 3)), np.zeros(1), 0.0, 10.0, 4)
    assert own[0] == 4.5 and other[0] == 1.5


def test_range_limits_and_misses():
    prims = np.array([[0, 3.0, -1.0, 3.0, 1.0, -1, 1]])
    grid = raycast.grid_from_primitives(prims, cell=0.5)
    r = raycast.cast(
        grid, np.zeros((3, 3)), np.array([0.0, np.pi, 0.0]), [0.0, 0.0, 0.0], [10.0, 10.0, 2.0], -1
    )
    assert r[0] == 3.0 and np.isinf(r[1]) and np.isinf(r[2])
    # a ray starting outside the grid still finds the wall
    r = raycast.cast(grid, np.array([[-20.0, 0.0, 0.0]]), np.zeros(1), 0.0, 30.0, -1)
    assert abs(r[0] - 23.0) < 1e-12
    # the origin height selects primitives
    r = raycast.cast(grid, np.array([[0.0, 0.0, 2.0]]), np.zeros(1), 0.0, 10.0, -1)
    assert np.isinf(r[0])


def test_empty_grid_returns_inf():
    grid = raycast.grid_from_primitives(np.zeros((0, 7)))
    assert np.isinf(raycast.cast(grid, np.zeros((2, 3)), np.zeros(2), 0.0, 5.0, -1)).all()


def random_triangles(rng, n):
    """Triangle primitives (kind 2): walls (vertical) and tilted triangles of any size."""
    corners = rng.uniform(-10, 10, (n, 3, 3))
    corners[:, :, 2] = rng.uniform(-1, 2, (n, 3))
    walls = rng.random(n) < 0.5  # a vertical triangle: two corners share x, y
    corners[walls, 1, :2] = corners[walls, 0, :2]
    out = np.zeros((n, 16))
    out[:, 0] = 2
    out[:, 1:3] = corners[:, :, :2].min(axis=1)
    out[:, 3:5] = corners[:, :, :2].max(axis=1)
    out[:, 5] = corners[:, :, 2].min(axis=1)
    out[:, 6] = corners[:, :, 2].max(axis=1)
    out[:, 7:] = corners.reshape(n, 9)
    return out, corners


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), cell=st.sampled_from([0.3, 1.0, 2.5]))
def test_triangles_on_the_grid_match_exact_ray_triangle_intersection(seed, cell):
    rng = np.random.default_rng(seed)
    tris, corners = random_triangles(rng, 30)
    mixed = np.vstack([np.pad(random_prims(rng, 10), ((0, 0), (0, 9))), tris])
    grid = raycast.grid_from_primitives(mixed, cell=cell)
    origins = np.c_[rng.uniform(-12, 12, (60, 2)), rng.uniform(-0.5, 1.5, 60)]
    angles = rng.uniform(-np.pi, np.pi, 60)
    got = raycast.cast(grid, origins, angles, 0.05, 15.0, -1)
    for g, o, a in zip(got, origins, angles):
        want = min(
            first_hit(corners, o, horizontal(a), 0.05, 15.0),
            brute_force(mixed[:10, :7], o, a, 0.05, 15.0),
        )
        if np.isinf(want):
            assert np.isinf(g)
        else:
            assert abs(g - want) < 1e-6
