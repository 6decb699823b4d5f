"""ORCA kernels against brute-force references: the linear program against a grid search, the
half-planes against exact closest approach of two moving discs, and RVO2's reference
behaviours (head-on, crossing, a static neighbour) in a small holonomic simulation."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.nav.multirobot.orca import contact_halfplanes, orca_halfplanes, orca_velocity


def closest_approach(p: np.ndarray, v: np.ndarray, horizon: float) -> float:
    """Smallest distance over t in [0, horizon] of a point starting at p moving at v."""
    vv = float(v @ v)
    t = 0.0 if vv == 0 else min(max(-float(p @ v) / vv, 0.0), horizon)
    return float(np.linalg.norm(p + t * v))


def inside(points, dirs, v, tol=1e-7):
    d = dirs[:, 0] * (points[:, 1] - v[1]) - dirs[:, 1] * (points[:, 0] - v[0])
    return bool(np.all(d <= tol))


coord = st.floats(-4.0, 4.0, allow_nan=False)
speed = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(coord, coord, speed, speed, speed, speed, speed, speed)
def test_reciprocal_choices_do_not_collide_within_the_horizon(px, py, ax, ay, bx, by, gx, gy):
    """Both agents pick a velocity in their own half-plane: no collision within tau."""
    r, tau, dt = 0.6, 2.0, 0.1
    pa, pb = np.zeros(2), np.array([px, py])
    if np.linalg.norm(pb) <= r + 1e-3:
        return
    va, vb = np.array([ax, ay]), np.array([bx, by])
    pref_a, pref_b = np.array([gx, gy]), -np.array([gx, gy])
    la = orca_halfplanes((pb - pa)[None], (va - vb)[None], [r], va, tau, dt, [0.5])
    lb = orca_halfplanes((pa - pb)[None], (vb - va)[None], [r], vb, tau, dt, [0.5])
    new_a, ok_a = orca_velocity(*la, 10.0, pref_a)
    new_b, ok_b = orca_velocity(*lb, 10.0, pref_b)
    assert ok_a and ok_b
    assert closest_approach(pb - pa, new_b - new_a, tau) >= r - 1e-6


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(coord, coord, speed, speed), min_size=1, max_size=6), speed, speed)
def test_linear_program_matches_a_grid_search(neigh, gx, gy):
    """The 2-D program's answer is the permitted velocity nearest the preferred one."""
    v = np.array([0.1, 0.0])
    rel = np.array([[n[0], n[1]] for n in neigh])
    far = np.linalg.norm(rel, axis=1) > 0.8
    if not far.any():
        return
    rel = rel[far]
    rel_vel = v - np.array([[n[2], n[3]] for n in neigh])[far]
    pts, dirs = orca_halfplanes(rel, rel_vel, np.full(len(rel), 0.5), v, 2.0, 0.1, 0.5)
    pref = np.array([gx, gy]) * 2.0
    got, feasible = orca_velocity(pts, dirs, 1.5, pref)
    g = np.linspace(-1.5, 1.5, 301)
    cand = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    cand = cand[np.linalg.norm(cand, axis=1) <= 1.5]
    ok = np.all(
        dirs[:, 0] * (pts[:, 1] - cand[:, 1:2]) - dirs[:, 1] * (pts[:, 0] - cand[:, :1]) <= 0,
        axis=1,
    )
    if not ok.any():
        return  # infeasible (or thinner than the grid): the 3-D program's case
    assert feasible
    assert inside(pts, dirs, got, 1e-6) and np.linalg.norm(got) <= 1.5 + 1e-9
    best = np.min(np.linalg.norm(cand[ok] - pref, axis=1))
    assert np.linalg.norm(got - pref) <= best + 1e-9


def test_infeasible_set_relaxes_agents_but_keeps_obstacle_lines():
    # two agent lines that exclude each other, and one obstacle line: v_y <= 0.2
    pts = np.array([[0.0, 0.2], [0.5, 0.0], [-0.5, 0.0]])
    dirs = np.array([[-1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])  # vy<=0.2, vx>=0.5, vx<=-0.5
    v, feasible = orca_velocity(pts, dirs, 1.0, np.array([0.0, 1.0]), num_obstacle_lines=1)
    assert not feasible
    assert v[1] <= 0.2 + 1e-9
    assert abs(v[0]) < 1e-6  # the middle minimises the larger of the two violations


def simulate(starts, goals, radius=0.2, vmax=0.5, static=(), steps=600, dt=0.1, tau=2.0):
    """Holonomic discs running ORCA (as RVO2's examples); returns (final, min gap, paths)."""
    pos = np.array(starts, dtype=float)
    goals = np.array(goals, dtype=float)
    vel = np.zeros_like(pos)
    n = len(pos)
    min_gap = math.inf
    path = np.zeros(n)
    for _ in range(steps):
        new = np.zeros_like(vel)
        for i in range(n):
            to_goal = goals[i] - pos[i]
            d = np.linalg.norm(to_goal)
            pref = to_goal / d * min(vmax, d / dt) if d > 1e-9 else np.zeros(2)
            others = [j for j in range(n) if j != i]
            rel = np.concatenate([pos[others] - pos[i], np.array(static).reshape(-1, 2) - pos[i]])
            other_vel = np.concatenate([vel[others], np.zeros((len(static), 2))])
            resp = np.r_[np.full(len(others), 0.5), np.ones(len(static))]
            lines = orca_halfplanes(
                rel, vel[i] - other_vel, np.full(len(rel), 2 * radius), vel[i], tau, dt, resp
            )
            new[i], _ = orca_velocity(*lines, vmax, pref)
        vel = new
        pos = pos + vel * dt
        path += np.linalg.norm(vel, axis=1) * dt
        pts = np.concatenate([pos, np.array(static).reshape(-1, 2)])
        d = np.linalg.norm(pts[:, None] - pts[None], axis=-1) - 2 * radius
        d[np.diag_indices(len(pts))] = np.inf
        min_gap = min(min_gap, float(d[:n].min()))
    return pos, min_gap, path


def test_exact_head_on_pair_stops_short_as_plain_orca_does():
    """Exact symmetry is a deadlock for plain ORCA (the reference's corridor measurement with
    RVO2: "1 pair head-on, exact: 0/2"): both stop, touching at most."""
    final, gap, _ = simulate([(-3, 0), (3, 0)], [(3, 0), (-3, 0)], steps=300)
    assert np.all(np.abs(final[:, 0]) < 1.0)
    assert gap >= -1e-3


def test_jittered_head_on_pair_passes_without_contact():
    """With 0.01 rad of jitter (the reference's second row) the pair swaps, path ~1.0 x."""
    s = 3.0 * np.array([math.cos(0.01), math.sin(0.01)])
    final, gap, path = simulate([-s, (3, 0)], [s, (-3, 0)])
    assert np.allclose(final, [s, (-3, 0)], atol=0.05)
    assert gap >= -1e-3
    assert np.all(path < 6.0 * 1.1)


def test_crossing_pair_passes_without_contact():
    """Two agents crossing at right angles, one 0.1 m farther from the crossing. Exactly
    symmetric, the crossing is a tie like the exact head-on pair above: only rounding breaks
    it, and on an AMD EPYC host (numba's code for it rounds otherwise) both stopped short."""
    final, gap, _ = simulate([(-3, 0), (0, -3.1)], [(3, 0), (0, 3)])
    assert np.allclose(final, [(3, 0), (0, 3)], atol=0.05)
    assert gap >= -1e-3


def test_static_neighbour_is_walked_around():
    final, gap, path = simulate([(-3, 0.0)], [(3, 0.0)], static=[(0.0, 0.05)])
    assert np.allclose(final, [(3, 0)], atol=0.05)
    assert gap >= -1e-3 and path[0] > 6.0


def test_lines_differing_by_rounding_alone_stay_feasible():
    """Two neighbours 1e-14 m apart (hypothesis found it): their half-planes are parallel and
    one lies beyond the other by rounding only; the program must not call that infeasible."""
    v = np.array([0.1, 0.0])
    rel = np.array([[1.0, 1.0424538626254102e-14], [1.0, 0.0]])
    rel_vel = v - np.array([[0.0, 0.0], [0.0, 1.0424538626254102e-14]])
    pts, dirs = orca_halfplanes(rel, rel_vel, np.full(2, 0.5), v, 2.0, 0.1, 0.5)
    got, feasible = orca_velocity(pts, dirs, 1.5, np.array([2.0, 2.0]))
    assert feasible and inside(pts, dirs, got, 1e-6)


def approach(rel, v):
    """m/s the robot at the origin moving at ``v`` closes in on a standing neighbour at ``rel``."""
    return float(v @ rel / np.linalg.norm(rel))


def test_overlap_parted_slowly_still_admits_a_pass_through_the_other_robot():
    """The flaw `contact_halfplanes` closes (circle of 16, seed 50: lizi2 drove into lizi3 at
    0.25 m/s): two discs overlapping (0.5 m apart, combined radius 0.52), the other robot
    standing, ORCA's overlap half-plane over 1 s admits a velocity that closes in on it at
    0.3 m/s, to be past it by the end of the second."""
    rel = np.array([0.5, 0.0])
    v = np.array([0.3, 0.6])
    pts, dirs = orca_halfplanes(rel[None], v[None], [0.52], v, 3.0, 1.0, [1.0])
    assert inside(pts, dirs, v)
    assert approach(rel, v) == 0.3


@given(
    ang=st.floats(-math.pi, math.pi),
    d=st.floats(0.3, 0.6),
    vx=speed,
    vy=speed,
    resp=st.sampled_from([0.5, 1.0]),
)
@settings(max_examples=200, deadline=None)
def test_contact_halfplane_caps_the_approach_along_the_line_of_centres(ang, d, vx, vy, resp):
    """Every velocity the half-plane admits closes in on a standing neighbour no faster than
    resp x (its gap to the bodies' discs / the closing time) beyond what the current velocity
    does; inside the bodies' radius that is a parting speed. Sideways motion is free."""
    hard, closing = 0.5, 1.0
    rel = d * np.array([math.cos(ang), math.sin(ang)])
    v = np.array([vx, vy])
    pts, dirs = contact_halfplanes(rel[None], v[None], [hard], v, closing, [resp])
    n = rel / d
    limit = approach(rel, v) + resp * ((d - hard) / closing - approach(rel, v))
    side = np.array([-n[1], n[0]])
    boundary = limit * n
    assert inside(pts, dirs, boundary + 0.7 * side) and inside(pts, dirs, boundary - 0.7 * side)
    assert not inside(pts, dirs, boundary + 0.01 * n)
    assert inside(pts, dirs, boundary - 0.01 * n)
    if resp == 1.0:
        assert math.isclose(limit, (d - hard) / closing, abs_tol=1e-12)


def test_with_the_contact_halfplane_the_pass_through_is_refused():
    rel = np.array([0.5, 0.0])
    v = np.array([0.3, 0.6])
    lines = [orca_halfplanes(rel[None], v[None], [0.52], v, 3.0, 1.0, [1.0])]
    lines.append(contact_halfplanes(rel[None], v[None], [0.5], v, 1.0, [1.0]))
    pts, dirs = (np.concatenate(x) for x in zip(*lines))
    got, feasible = orca_velocity(pts, dirs, 0.8, v)
    assert feasible
    assert approach(rel, got) <= 1e-9  # at the bodies' radius: no closer
    assert got[1] == pytest.approx(0.6)  # going by sideways as before
