"""A differential drive's speed along its heading (`speed_along_heading`): the robots'
half-planes when they admit a speed there, else the walls' and the bodies' (`contact_halfplanes`),
else the least violation of the bodies' (`least_violation_speed`, against a grid search)."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from fleetsim.nav.multirobot.holonomic import least_violation_speed, speed_along_heading
from fleetsim.nav.multirobot.orca import contact_halfplanes

EAST = np.array([1.0, 0.0])


def violation(points, dirs, v):
    """Largest distance (m/s) by which v lies beyond a half-plane (0: inside all)."""
    d = dirs[:, 0] * (points[:, 1] - v[1]) - dirs[:, 1] * (points[:, 0] - v[0])
    return max(0.0, float(d.max()))


line = st.tuples(
    st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-math.pi, math.pi)
)  # a point and a direction's angle


@given(lines=st.lists(line, min_size=1, max_size=6), wanted=st.floats(0.0, 0.5))
@settings(max_examples=200, deadline=None)
def test_least_violation_speed_matches_a_grid_search(lines, wanted):
    pts = np.array([[x, y] for x, y, _ in lines])
    dirs = np.array([[math.cos(a), math.sin(a)] for _, _, a in lines])
    v = least_violation_speed(pts, dirs, EAST, 0.0, 0.5, wanted)
    assert 0.0 <= v <= 0.5
    grid = np.linspace(0.0, 0.5, 2001)
    best = min(violation(pts, dirs, g * EAST) for g in grid)
    assert violation(pts, dirs, v * EAST) <= best + 1e-9


def test_heading_into_a_body_it_overlaps_the_drive_stops_instead_of_driving_on():
    """The pioneer3ats of the circle of 8 (seed 7): 0.71 m apart, their bodies' discs 0.74 m,
    the other standing ahead-left; ORCA's line for it admits no forward speed. The speed was
    the one wanted (the robots' lines dropped); now it is the one that closes in least: none."""
    rel = np.array([[0.4, 0.587]])  # 0.71 m
    vel = np.zeros(2)
    hard = contact_halfplanes(rel, vel[None] - 0.0, [0.74], vel, 1.0, [1.0])
    # an agent line that forbids any forward speed along the heading (north-east)
    yaw = math.atan2(0.587, 0.4)
    agent = (np.array([[-0.05, 0.0]]), np.array([[math.sin(yaw), -math.cos(yaw)]]))
    pts = np.concatenate([agent[0], hard[0]])
    dirs = np.concatenate([agent[1], hard[1]])
    assert speed_along_heading(pts, dirs, 0, yaw, 0.4, 0.7) == 0.4  # the old fallback
    assert speed_along_heading(pts, dirs, 0, yaw, 0.4, 0.7, hard) == 0.0


def test_bodies_apart_the_fallback_is_the_walls_alone_and_the_bodies_lines_cap_the_speed():
    yaw = 0.0
    agent = (np.array([[-0.05, 0.0]]), np.array([[0.0, -1.0]]))  # forbids v > -0.05 east
    assert speed_along_heading(*agent, 0, yaw, 0.4, 0.5) == 0.4
    # a body 0.52 m ahead with 0.5 m of discs: closing at most 0.02 m/s
    hard = contact_halfplanes(
        np.array([[0.52, 0.0]]), np.zeros((1, 2)), [0.5], EAST * 0, 1.0, [1.0]
    )
    pts = np.concatenate([agent[0], hard[0]])
    dirs = np.concatenate([agent[1], hard[1]])
    assert math.isclose(speed_along_heading(pts, dirs, 0, yaw, 0.4, 0.5, hard), 0.02)


def test_a_heading_a_hair_off_the_static_half_planes_still_moves():
    """Pioneers' corridor of 4, seed 17: an obstacle point inside the disc asks for at least
    0.02 m/s away from it (east here), a wall ahead caps the speed north at 0.355 m/s, and the
    holonomic velocity (0.02, 0.355) has both; a heading 87 degrees, a hair off it, has
    neither at any speed. Tracking asks no turn of a heading that close, so at speed 0 the
    robot stood for good; within HEADING_SLACK of the half-planes it drives on, and a heading
    well off them still stands."""
    pts = np.array([[0.02, 0.0], [0.0, 0.355]])
    dirs = np.array([[0.0, -1.0], [-1.0, 0.0]])  # x >= 0.02, y <= 0.355 (left of each)
    assert violation(pts, dirs, np.array([0.02, 0.355])) == 0.0
    yaw = math.radians(87.0)
    u = np.array([math.cos(yaw), math.sin(yaw)])
    assert all(violation(pts, dirs, s * u) > 0.0 for s in np.linspace(0.0, 0.7, 141))
    v = speed_along_heading(pts, dirs, 2, yaw, 0.37, 0.7)
    assert 0.3 < v <= 0.37
    assert violation(pts, dirs, v * u) <= 0.01 + 1e-9
    assert speed_along_heading(pts, dirs, 2, math.radians(80.0), 0.37, 0.7) > 0.0
    assert speed_along_heading(pts, dirs, 2, math.radians(95.0), 0.37, 0.7) == 0.0
